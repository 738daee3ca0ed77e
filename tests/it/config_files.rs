//! The shipped configs load, and a malformed config gives a located error.

use std::path::Path;

use sapnet::config::Config;
use sapnet::env::EnvConfig;
use sapnet::ron_file::ConfigError;

fn asset(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name)
}

#[test]
fn the_cartpole_config_spells_out_the_defaults() {
    // assets/cartpole.ron writes every field; it must say exactly what the code defaults
    // to, so that reading the file tells the truth about a run without it.
    let config = Config::from_file(&asset("cartpole.ron")).unwrap();
    assert_eq!(config, Config::default());
}

#[test]
fn the_mountain_car_config_uses_table_one() {
    let config = Config::from_file(&asset("mountain_car.ron")).unwrap();
    assert!(matches!(config.env, EnvConfig::MountainCar(_)));
    assert_eq!(config.dqn.replay_start_size, 100);
    assert_eq!(
        config.protocol.budget,
        sapnet::config::Budget::Episodes(10_000)
    );
}

fn parse_error(text: &str) -> String {
    match Config::from_ron(text, "bad.ron") {
        Err(err @ ConfigError::Parse(_)) => err.to_string(),
        Err(other) => panic!("expected a parse error, got {other}"),
        Ok(_) => panic!("expected an error for {text:?}"),
    }
}

#[test]
fn an_unknown_field_is_named_with_its_line_and_column() {
    let text = "(\n    dqn: (\n        gamma: 0.99,\n        gamm: 0.5,\n    ),\n)\n";
    let message = parse_error(text);
    assert!(
        message.starts_with("config bad.ron: line 4, column "),
        "{message}"
    );
    assert!(message.contains("gamm"), "{message}");
    assert!(message.contains("field `dqn"), "{message}");
}

#[test]
fn a_wrong_type_names_the_field_path() {
    let text = "(\n    dqn: (\n        batch_size: \"thirty-two\",\n    ),\n)\n";
    let message = parse_error(text);
    assert!(message.contains("line 3"), "{message}");
    assert!(message.contains("field `dqn.batch_size`"), "{message}");
}

#[test]
fn a_wrong_type_deep_in_the_physics_is_located() {
    let text = "(env: CartPole(\n  gravity: 9.8,\n  masspole: true,\n))";
    let message = parse_error(text);
    assert!(message.contains("line 3"), "{message}");
    assert!(message.contains("masspole"), "{message}");
}

#[test]
fn an_unknown_environment_is_rejected() {
    let message = parse_error("(env: LunarLander())");
    assert!(message.contains("LunarLander"), "{message}");
}

#[test]
fn a_syntax_error_is_located() {
    let message = parse_error("(\n  seed: 1,\n  dqn: (gamma: 0.9\n");
    assert!(message.starts_with("config bad.ron: line "), "{message}");
}

#[test]
fn an_out_of_range_value_names_the_field() {
    let err = Config::from_ron("(dqn: (gamma: 1.5))", "bad.ron").unwrap_err();
    let message = err.to_string();
    assert!(message.contains("dqn.gamma"), "{message}");
    assert!(message.contains("[0, 1]"), "{message}");
}

#[test]
fn a_missing_file_names_the_path() {
    let err = Config::from_file(Path::new("no/such/config.ron")).unwrap_err();
    assert!(err.to_string().contains("no/such/config.ron"), "{err}");
}

#[test]
fn every_shipped_config_loads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dirs = [
        root.join("assets"),
        root.join("benches/configs"),
        root.join("tests/configs"),
    ];
    let mut loaded = 0;
    for dir in dirs {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.extension().is_none_or(|e| e != "ron") || name.starts_with("teach_") {
                // Teaching graphs have their own schema (tests/teach_cli.rs loads them).
                continue;
            }
            if name.starts_with("sweep_") {
                // A sweep's grid: it loads, names a base that loads, and expands.
                let grid =
                    sapnet::sweep::grid::Grid::read(&path).unwrap_or_else(|e| panic!("{e:#}"));
                let base = grid
                    .base_config(&path, None)
                    .unwrap_or_else(|e| panic!("{e:#}"));
                let cells = grid.cells(&base, &name).unwrap_or_else(|e| panic!("{e:#}"));
                assert!(cells.len() >= 4, "{name}: {} cells", cells.len());
            } else {
                Config::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
            }
            loaded += 1;
        }
    }
    assert!(loaded >= 10, "only {loaded} configs found");
}

#[test]
fn adam_betas_must_be_below_one() {
    let err = Config::from_ron("(dqn: (adam_betas: (1.0, 0.999)))", "bad.ron").unwrap_err();
    assert!(err.to_string().contains("dqn.adam_betas"), "{err}");
}

#[test]
fn prototype_weights_that_would_make_a_distance_nonpositive_are_refused() {
    // 1 + δ·ω = 1 − 0.5·3 = −0.5: two policies of one category would be at distance −0.5.
    let text = "(sapnet: (prototypes: [(prototype: HiddenLayers, omega: 3.0)], delta: -0.5))";
    let err = Config::from_ron(text, "bad.ron").unwrap_err();
    assert!(err.to_string().contains("delta"), "{err}");
}

#[test]
fn configs_that_cannot_work_are_refused_with_the_field() {
    for (text, field) in [
        ("(protocol: (episodes: 0))", "protocol.budget"),
        ("(protocol: (max_steps: Some(0)))", "protocol.budget"),
        ("(protocol: (budget: Steps(0)))", "protocol.budget"),
        ("(protocol: (budget: Episodes(0)))", "protocol.budget"),
        ("(dqn: (gradient_steps: 0))", "dqn.gradient_steps"),
        (
            "(dqn: (replay_capacity: 100, replay_start_size: 101))",
            "dqn.replay_start_size",
        ),
        (
            "(sources: (dqn: Some(gradient_steps: 0)))",
            "sources.dqn.gradient_steps",
        ),
        (
            "(sources: (training_episodes: 0))",
            "sources.training_episodes",
        ),
        ("(sapnet: (coefficient: 0.0))", "sapnet.coefficient"),
        ("(sapnet: (coefficient: -1.0))", "sapnet.coefficient"),
    ] {
        let err = Config::from_ron(text, "bad.ron").unwrap_err().to_string();
        assert!(
            err.starts_with("config bad.ron: field `") && err.contains(&format!("`{field}`")),
            "{text}: {err}"
        );
    }
}

fn invalid(text: &str) -> String {
    match Config::from_ron(text, "bad.ron") {
        Err(err @ ConfigError::Invalid { .. }) => err.to_string(),
        Err(other) => panic!("expected a validation error for {text:?}, got {other}"),
        Ok(_) => panic!("expected an error for {text:?}"),
    }
}

/// Issue 13: physics that make no sense are refused at their field, for the target task
/// and for the sources' task alike; a negative push (CartPole's mirrored actions) is not.
#[test]
fn physics_that_make_no_sense_are_refused_at_their_field() {
    for (text, field) in [
        ("(env: CartPole(tau: 0.0))", "env.tau"),
        ("(env: CartPole(tau: -0.02))", "env.tau"),
        ("(env: CartPole(masspole: -0.1))", "env.masspole"),
        ("(env: CartPole(gravity: inf))", "env.gravity"),
        ("(env: CartPole(x_threshold: -2.4))", "env.x_threshold"),
        (
            "(env: CartPole(max_episode_steps: 0))",
            "env.max_episode_steps",
        ),
        ("(env: MountainCar(max_speed: 0.0))", "env.max_speed"),
        (
            "(env: MountainCar(goal_position: 0.7))",
            "env.goal_position",
        ),
        ("(env: Acrobot(link_mass_2: 0.0))", "env.link_mass_2"),
        ("(env: Acrobot(dt: NaN))", "env.dt"),
        (
            "(sources: (env: Some(CartPole(length: 0.0))))",
            "sources.env.length",
        ),
    ] {
        let message = invalid(text);
        assert!(
            message.contains(&format!("field `{field}`")),
            "{text}: {message}"
        );
    }
    let mirrored = Config::from_ron("(env: CartPole(force_mag: -10.0))", "ok.ron").unwrap();
    assert!(matches!(mirrored.env, EnvConfig::CartPole(ref p) if p.force_mag == -10.0));
}

#[test]
fn no_greedy_tests_is_allowed_but_said() {
    let config = Config::from_ron("(protocol: (test_episodes: 0))", "ok.ron").unwrap();
    let warnings = config.warnings();
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].contains("test_episodes is 0"), "{warnings:?}");
    assert!(Config::default().warnings().is_empty());
}
