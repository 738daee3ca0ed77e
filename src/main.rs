use std::process::ExitCode;

// candle allocates a buffer for every tensor op (loading, saving, the reference forward);
// mimalloc more than halved a DQN update against glibc's malloc while candle ran it.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    // candle reads RAYON_NUM_THREADS on every matmul; for these small networks one thread
    // beats two. Respect the user's choice when there is one.
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        std::env::set_var("RAYON_NUM_THREADS", "1");
    }
    let cli = sapnet::cli::parse();
    // A kernel path the CPU lacks (or a typo) is said before anything runs.
    if let Err(message) = sapnet::dqn::kernels::Isa::from_env() {
        eprintln!("error: {message}");
        return ExitCode::from(2);
    }
    let result = sapnet::app::run(cli);
    if let Err(err) = &result {
        // `sapnet teach --headless --json | head`: the reader left, nothing to report.
        if is_broken_pipe(err) {
            return ExitCode::SUCCESS;
        }
        // A refusal may quote a received file: shown as data, never the terminal's
        // commands.
        eprintln!(
            "error: {}",
            sapnet::shown_text::escaped_lines(&format!("{err:#}"))
        );
    }
    // A run stopped by a signal wrote what it had; the exit code says which signal.
    if let Some(signal) = sapnet::signals::received() {
        return ExitCode::from(sapnet::signals::exit_code(signal));
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(_) => ExitCode::from(2),
    }
}

/// The reader of stdout left (`| head`): an `io::Error`, or one inside serde_json's.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    use std::io::ErrorKind::BrokenPipe;
    err.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == BrokenPipe)
            || cause
                .downcast_ref::<serde_json::Error>()
                .and_then(serde_json::Error::io_error_kind)
                == Some(BrokenPipe)
    })
}
