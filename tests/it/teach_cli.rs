//! `sapnet teach --headless` as a user runs it.

use std::process::{Command, Output};

fn sapnet(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("running sapnet")
}

#[test]
fn json_is_one_object_with_the_fig2_values() {
    let out = sapnet(&["teach", "--headless", "--json", "--activate", "1"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON value");
    let object = json.as_object().unwrap();
    let mut keys: Vec<_> = object.keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        ["activations", "probabilities", "through_time", "trace"]
    );

    let numbers = |key: &str| -> Vec<f64> {
        json[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let a = numbers("activations");
    // See tests/sapnet_spreading.rs for the arithmetic.
    for (got, want) in a.iter().zip([0.9375, 1.0 + 20.0 / 48.0, 0.9375, 5.0 / 6.0]) {
        assert!((got - want).abs() < 1e-12, "{a:?}");
    }
    assert!((numbers("probabilities").iter().sum::<f64>() - 1.0).abs() < 1e-9);

    let trace = json["trace"].as_array().unwrap();
    assert_eq!(trace.len(), 21);
    let first = &trace[0];
    assert_eq!(first["from"], 1);
    assert_eq!(first["to"], 0);
    assert_eq!(first["h"], 1);
    assert_eq!(first["omega"], 0.4);
    assert_eq!(first["stopped"], false);
    assert!((first["eta"].as_f64().unwrap() - 1.0 / 3.0).abs() < 1e-15);
    assert!((first["delta"].as_f64().unwrap() - 5.0 / 6.0).abs() < 1e-15);
}

#[test]
fn the_table_shows_every_call_and_the_final_state() {
    let out = sapnet(&["teach", "--headless", "--activate", "1", "--activate", "3"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("activate π1"), "{text}");
    assert!(text.contains("activate π3"), "{text}");
    assert!(text.contains("stopped"), "{text}");
    assert!(text.contains("probability"), "{text}");
}

#[test]
fn a_teach_file_can_be_given() {
    let out = sapnet(&[
        "teach",
        "--headless",
        "--json",
        "--config",
        "assets/teach_table2.ron",
        "--activate",
        "0",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let a: Vec<f64> = json["activations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    // π0 has two same-category neighbours: each gets (1/2)/0.95.
    assert_eq!(a[..3], [1.0, 0.5 / 0.95, 0.5 / 0.95]);
    assert!(a[3..].iter().all(|&x| x == 0.0));
}

#[test]
fn a_bad_index_exits_with_code_2_and_names_it() {
    let out = sapnet(&[
        "teach",
        "--headless",
        "--json",
        "--activate",
        "1",
        "--activate",
        "7",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("--activate 7"), "{err}");
    assert!(err.contains("4 policies"), "{err}");
}

#[test]
fn a_broken_teach_file_is_located() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ron");
    std::fs::write(&path, "(policies: 2,\n edges: [(0, 1, 0.0)])").unwrap();
    let out = sapnet(&[
        "teach",
        "--headless",
        "--config",
        path.to_str().unwrap(),
        "--activate",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("bad.ron"), "{err}");
    assert!(err.contains("edge (0, 1) weighs 0"), "{err}");
}

#[test]
fn the_interactive_view_is_not_there_yet() {
    let out = sapnet(&["teach", "--activate", "1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--headless"));
}

/// Issue 13: `coefficient: 1e308` printed inf and NaN (and panicked in the interactive
/// view); it is refused at its field, before anything is activated.
#[test]
fn a_coefficient_that_would_overflow_is_refused_at_its_field() {
    let tmp = tempfile::tempdir().unwrap();
    let lesson = tmp.path().join("big.ron");
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teach_fig2.ron"),
    )
    .unwrap()
    .replace("coefficient: 1.0", "coefficient: 1e308");
    std::fs::write(&lesson, text).unwrap();
    let output = sapnet(&[
        "teach",
        "--headless",
        "--config",
        lesson.to_str().unwrap(),
        "--activate",
        "1",
        "--activate",
        "1",
    ]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("field `coefficient`"), "{stderr}");
    assert!(stderr.contains("1e308"), "{stderr}");
    assert!(output.stdout.is_empty());
}

/// Issue 27: a lesson with 𝒜 ≤ 0 was accepted (activations went negative) while the
/// training config refuses it; now both refuse it at the field.
#[test]
fn a_coefficient_of_zero_or_less_is_refused_at_its_field() {
    let tmp = tempfile::tempdir().unwrap();
    for value in ["-0.5", "0.0"] {
        let lesson = tmp.path().join("lesson.ron");
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teach_fig2.ron"),
        )
        .unwrap()
        .replace("coefficient: 1.0", &format!("coefficient: {value}"));
        std::fs::write(&lesson, text).unwrap();
        let output = sapnet(&["teach", "--headless", "--config", lesson.to_str().unwrap()]);
        assert_eq!(output.status.code(), Some(2), "{value}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("field `coefficient`"), "{stderr}");
        assert!(stderr.contains("> 0"), "{stderr}");
    }
}

/// Issue 15: a training config given to teach was refused as "Unexpected field `env` in
/// TeachConfig"; it is now told what teach reads.
#[test]
fn a_training_config_is_told_teach_reads_a_lesson() {
    let output = sapnet(&["teach", "--headless", "--config", "assets/cartpole.ron"]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("this is a training config"), "{stderr}");
    assert!(stderr.contains("assets/teach_fig2.ron"), "{stderr}");
}

/// Fig. 2 with an edge π0–π3 of weight 0.3, written by hand as a lesson file.
const FIG2_WITH_0_3: &str = "(policies: 4, edges: [(0, 1, 0.4), (0, 2, 0.4), (1, 2, 0.4), \
    (1, 3, 0.4), (0, 3, 0.3)], threshold: 1.0, coefficient: 1.0, temperature: 1.0, \
    paths: Literal)";

#[test]
fn an_edge_added_by_flag_or_saved_walks_as_the_lesson_written_by_hand() {
    let tmp = tempfile::tempdir().unwrap();
    let by_hand = tmp.path().join("by_hand.ron");
    std::fs::write(&by_hand, FIG2_WITH_0_3).unwrap();
    let walk = |extra: &[&str]| {
        let mut args = vec!["teach", "--headless", "--activate", "1", "--json"];
        args.extend_from_slice(extra);
        let output = sapnet(&args);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        output.stdout
    };
    let reference = walk(&["--config", by_hand.to_str().unwrap()]);
    assert_eq!(walk(&["--add-edge", "0", "3", "0.3"]), reference);
    assert_ne!(walk(&[]), reference, "the edge changes the walk");

    let saved = tmp.path().join("lesson.ron");
    let output = sapnet(&[
        "teach",
        "--add-edge",
        "0",
        "3",
        "0.3",
        "--save",
        saved.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(walk(&["--config", saved.to_str().unwrap()]), reference);
    // Applied in order: added then cut leaves Fig. 2.
    assert_eq!(
        walk(&["--add-edge", "0", "3", "0.3", "--cut-edge", "3", "0"]),
        walk(&[])
    );
}

#[test]
fn edits_the_lesson_refuses_are_said_and_nothing_is_saved() {
    let tmp = tempfile::tempdir().unwrap();
    let saved = tmp.path().join("lesson.ron");
    let out = saved.to_str().unwrap();
    for (edits, says) in [
        (
            vec!["--cut-edge", "0", "3", "--add-edge", "0", "3", "0.3"],
            "--cut-edge 0 3: there is no edge between 0 and 3",
        ),
        (vec!["--add-edge", "0", "7", "0.3"], "there is no policy 7"),
        (vec!["--add-edge", "2", "2", "0.3"], "to itself"),
        (vec!["--add-edge", "0", "3", "-0.3"], "above 0"),
        (
            vec!["--add-edge", "0", "x", "0.3"],
            "J: expected a policy's index",
        ),
    ] {
        let mut args = vec!["teach"];
        args.extend(edits.iter().copied());
        args.extend(["--save", out]);
        let output = sapnet(&args);
        assert_eq!(output.status.code(), Some(2), "{edits:?}");
        let error = String::from_utf8_lossy(&output.stderr);
        assert!(error.contains(says), "{edits:?}: {error}");
        assert!(!saved.exists(), "{edits:?}: a refused lesson was saved");
    }
}

/// Two policies joined at 0.4 (see the hand count in `one_decay_step_between_two_activations_by_hand`,
/// src/teach/session.rs): π0's walk ends at A = (1.625, 2.5); D = 0.5 halves it to
/// (0.8125, 1.25); π1's walk adds (2.5, 1.625): (3.3125, 2.875).
#[test]
fn decay_between_activations_and_the_table_through_time() {
    let tmp = tempfile::tempdir().unwrap();
    let lesson = tmp.path().join("two.ron");
    std::fs::write(&lesson, "(policies: 2, edges: [(0, 1, 0.4)])").unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["teach", "--headless", "--config", lesson.to_str().unwrap()];
        args.extend_from_slice(&["--activate", "0", "--activate", "1"]);
        args.extend_from_slice(extra);
        sapnet(&args)
    };
    let out = run(&["--decay", "0.5", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = json["through_time"].as_array().unwrap();
    let values = |row: &serde_json::Value, key: &str| -> Vec<f64> {
        row[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["activated"], 0);
    assert_eq!(rows[1]["activated"], 1);
    for (got, want) in [
        (values(&rows[0], "activations"), [1.625, 2.5]),
        (values(&rows[1], "activations"), [3.3125, 2.875]),
        (values(&json, "activations"), [3.3125, 2.875]),
    ] {
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-12),
            "{got:?}"
        );
    }
    let p0 = 1.0 / (1.0 + 0.875f64.exp());
    assert!((values(&rows[0], "probabilities")[0] - p0).abs() < 1e-12);

    // D = 0 is the paper: the two walks simply add up.
    let paper: serde_json::Value = serde_json::from_slice(&run(&["--json"]).stdout).unwrap();
    let a = values(&paper, "activations");
    assert!((a[0] - (1.625 + 2.5)).abs() < 1e-12, "{a:?}");

    // The table says the decay and has a column pair per walk.
    let text = String::from_utf8(run(&["--decay", "0.5"]).stdout).unwrap();
    assert!(
        text.contains("through time: A and P after each walk (decay D = 0.5"),
        "{text}"
    );
    assert!(text.contains("  3.312500"), "{text}");

    let out = run(&["--decay", "1.5"]);
    assert_eq!(out.status.code(), Some(2));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("--decay 1.5: expected a number from 0 to 1"),
        "{said}"
    );
}

/// A lesson file's questions are checked as a config is: file, field, what was expected.
#[test]
fn a_bad_question_is_refused_naming_its_file_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    let lesson = tmp.path().join("quiz.ron");
    std::fs::write(
        &lesson,
        "(policies: 2, edges: [(0, 1, 0.4)], questions: [(ask: \"Which?\", answer: Policy(5))])",
    )
    .unwrap();
    let out = sapnet(&["teach", "--headless", "--config", lesson.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(said.contains("quiz.ron"), "{said}");
    assert!(
        said.contains("field `questions[0].answer`: expected Policy(0) to Policy(1)"),
        "{said}"
    );
    assert!(!said.contains("panicked"), "{said}");
}

/// Table II with policy 0 moved to the two-layer category and a three-layer policy added
/// (π10, copying 3×100): activating π10 reaches its category's three at Ω = 0.95 with
/// η = 𝒜/k = 1/3, ΔA = (1/3)/(1×0.95) = 0.350877 each; the saved lesson walks the same.
/// Fig. 2, given by edges, has no category to add a policy to, and says so (exit 2).
#[test]
fn policies_added_and_recategorised_by_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let saved = tmp.path().join("t2.ron");
    let edits = [
        "--config",
        "assets/teach_table2.ron",
        "--set-category",
        "0",
        "2",
        "--add-policy",
        "3",
    ];
    let mut save = vec!["teach"];
    save.extend(edits);
    save.extend(["--save", saved.to_str().unwrap()]);
    assert!(sapnet(&save).status.success());
    let mut direct = vec!["teach", "--headless", "--json", "--activate", "10"];
    direct.extend(edits);
    let direct = sapnet(&direct);
    assert!(
        direct.status.success(),
        "{}",
        String::from_utf8_lossy(&direct.stderr)
    );
    let from_file = sapnet(&[
        "teach",
        "--headless",
        "--json",
        "--activate",
        "10",
        "--config",
        saved.to_str().unwrap(),
    ]);
    assert_eq!(direct.stdout, from_file.stdout);
    let json: serde_json::Value = serde_json::from_slice(&direct.stdout).unwrap();
    let a: Vec<f64> = json["activations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(a.len(), 11);
    for i in 7..10 {
        assert!((a[i] - 1.0 / 3.0 / 0.95).abs() < 1e-12, "{a:?}");
    }
    assert_eq!(
        a[0], 0.0,
        "policy 0 left the one-layer category, not joined to π10"
    );

    let out = sapnet(&["teach", "--headless", "--add-policy", "2"]);
    assert_eq!(out.status.code(), Some(2));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("--add-policy 2: this lesson gives its graph by `edges`"),
        "{said}"
    );
}

/// Issue 52, item 7: `teach --save` once renamed over whatever PATH was. A FIFO, a socket,
/// a directory and (as root) a device node are refused naming the path and what was
/// expected (exit 2), and left as they were; nothing is left beside them.
#[test]
fn save_refuses_a_fifo_a_socket_and_a_directory_and_leaves_them() {
    use std::os::unix::fs::FileTypeExt;
    let tmp = tempfile::tempdir().unwrap();
    let fifo = tmp.path().join("fifo");
    let path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a NUL-terminated path and a mode, as mkfifo(3) takes them.
    assert_eq!(unsafe { libc::mkfifo(path.as_ptr(), 0o644) }, 0);
    let socket = tmp.path().join("socket");
    let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    let directory = tmp.path().join("folder");
    std::fs::create_dir(&directory).unwrap();
    // /dev/null's twin (major 1, minor 3), made here rather than risking /dev/null itself:
    // only root may make one, as only root could have had /dev/null replaced.
    let device = tmp.path().join("null");
    let path = std::ffi::CString::new(device.to_str().unwrap()).unwrap();
    // SAFETY: a NUL-terminated path, a mode and a device number, as mknod(2) takes them.
    let made = unsafe { libc::mknod(path.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) };
    let mut refused = vec![
        (&fifo, "a FIFO"),
        (&socket, "a socket"),
        (&directory, "a directory"),
    ];
    if made == 0 {
        refused.push((&device, "a device"));
    }
    for (target, what) in refused {
        let named = target.to_str().unwrap();
        let output = sapnet(&["teach", "--save", named]);
        assert_eq!(output.status.code(), Some(2), "{what}");
        let error = String::from_utf8_lossy(&output.stderr);
        assert!(
            error.contains(named) && error.contains(what) && error.contains("a regular file"),
            "{what}: {error}"
        );
    }
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    assert!(std::fs::symlink_metadata(&socket)
        .unwrap()
        .file_type()
        .is_socket());
    assert_eq!(std::fs::read_dir(&directory).unwrap().count(), 0);
    let mut left: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name != "null")
        .collect();
    left.sort();
    assert_eq!(left, ["fifo", "folder", "socket"], "no temporary file left");
    if made == 0 {
        let kind = std::fs::symlink_metadata(&device).unwrap().file_type();
        assert!(kind.is_char_device(), "the device node is left as it was");
    }
}

/// A lesson saved over a file of 0600 keeps 0600 (it once became 0644), and is replaced
/// whole; a new file is made as any other.
#[test]
fn save_keeps_an_existing_files_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let private = tmp.path().join("private.ron");
    std::fs::write(
        &private,
        "an older lesson, much longer than the new one ".repeat(100),
    )
    .unwrap();
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).unwrap();
    let output = sapnet(&["teach", "--save", private.to_str().unwrap()]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let mode = std::fs::metadata(&private).unwrap().permissions().mode();
    assert_eq!(mode & 0o7777, 0o600);
    let text = std::fs::read_to_string(&private).unwrap();
    assert!(text.starts_with("// A sapnet lesson"), "{text}");
    assert!(!text.contains("an older lesson"), "{text}");
}

/// Issue 52, item 12: a received lesson whose names hold an OSC title and a screen clear.
/// `--headless` prints them as visible escapes, never as the bytes a terminal acts on.
#[test]
fn control_characters_in_a_lessons_names_are_printed_as_escapes() {
    let tmp = tempfile::tempdir().unwrap();
    let lesson = tmp.path().join("hostile.ron");
    std::fs::write(
        &lesson,
        "(names: [\"\u{1b}]0;owned\u{7}\", \"\u{1b}[2J\u{1b}[H\"], edges: [(0, 1, 0.4)])",
    )
    .unwrap();
    let config = lesson.to_str().unwrap();
    let out = sapnet(&["teach", "--headless", "--config", config, "--activate", "0"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(!text.contains(['\u{1b}', '\u{7}']), "{text:?}");
    assert!(
        text.contains("activate \\u{1b}]0;owned\\u{7}: A[\\u{1b}]0;owned\\u{7}] += 𝒜 = 1"),
        "{text}"
    );
    assert!(text.contains("\\u{1b}[2J\\u{1b}[H"), "{text}");
}
