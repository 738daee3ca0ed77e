//! SAP-Net's judgments beyond the loss end to end: `assets/judgments_cartpole.ron` run
//! headless with `--quick` on a copy of the shipped CartPole library. Every method is in
//! the summary, and each judges as its rule says: the TD error's change and eq. 7 with the
//! return once per update, the advantage once per acting step (one update per step here:
//! the same count), each with positives and negatives.

use crate::common::library::quick_protocol;

use std::path::Path;

fn sum(run: &serde_json::Value, key: &str) -> u64 {
    run[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} in {run}"))
        .iter()
        .map(|n| n.as_u64().unwrap())
        .sum()
}

#[test]
fn the_quick_judgments_protocol_counts_every_new_judgment() {
    let dir = tempfile::tempdir().unwrap();
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/judgments_cartpole.ron");
    let (out, summary) = quick_protocol(&config, "cartpole", dir.path());
    let runs = summary["runs"].as_array().unwrap();
    for method in [
        "sapnet",
        "sapnet-episode",
        "sapnet-td",
        "sapnet-advantage",
        "sapnet-episode-and-loss",
        "sapnet-exclude10x1000",
    ] {
        let of_method: Vec<_> = runs.iter().filter(|r| r["method"] == method).collect();
        assert_eq!(of_method.len(), 2, "{method}: {} runs", of_method.len());
        for run in of_method {
            let (positive, negative) = (sum(run, "positive"), sum(run, "negative"));
            assert!(
                positive > 0 && negative > 0,
                "{method}: {positive} / {negative}"
            );
            let updates = run["updates"].as_u64().unwrap();
            if method == "sapnet-episode" {
                // Once per episode for each source that acted in it.
                assert!(positive + negative < updates, "{method}");
            } else {
                // No run's last episode is cut (no step budget): every judgment is made.
                assert_eq!(positive + negative, updates, "{method}: run {}", run["run"]);
            }
        }
    }
    // Candidates by category: 10 negatives in a row of a category happen within a quick
    // run; only the method with the knob excludes.
    for run in runs {
        let excluding = run["method"] == "sapnet-exclude10x1000";
        let exclusions = run["exclusions"].as_u64().unwrap();
        assert_eq!(exclusions > 0, excluding, "{}: {exclusions}", run["method"]);
    }
    // DQN from scratch reuses nothing and judges nothing.
    let dqn = runs.iter().find(|r| r["method"] == "dqn[100]").unwrap();
    assert_eq!(dqn["positive"], serde_json::json!([]));
    let comparison = std::fs::read_to_string(out.join("comparison.csv")).unwrap();
    for method in ["sapnet-td", "sapnet-advantage", "sapnet-episode-and-loss"] {
        assert!(
            comparison
                .lines()
                .any(|l| l.starts_with(&format!("{method},"))),
            "{method} in comparison.csv:\n{comparison}"
        );
    }
}

/// The new judgments carry no value, so what can be wrong is the name: refused at the
/// field with the judgments there are. A judgment with a knob beside it loads.
#[test]
fn a_judgment_is_named_or_refused_at_its_field() {
    use sapnet::config::Config;
    let err = Config::from_ron(
        "(protocol: (methods: [SapNet, SapNetWith(judgment: Td)]))",
        "x.ron",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("field `protocol.methods[1].SapNetWith.judgment`")
            && err.contains("`TdChange`, `Advantage`, or `EpisodeAndLoss`"),
        "{err}"
    );
    let config = Config::from_ron(
        "(protocol: (methods: [SapNetWith(judgment: EpisodeAndLoss, decay: 0.99), \
         SapNetWith(judgment: Advantage, label: Some(\"adv\"))]))",
        "x.ron",
    )
    .unwrap();
    let labels: Vec<String> = config.protocol.methods.iter().map(|m| m.label()).collect();
    assert_eq!(labels, ["sapnet-episode-and-loss-decay0.99", "adv"]);
    let err = Config::from_ron(
        "(protocol: (methods: [SapNetWith(exclusion: Some(after: 0, steps: 5))]))",
        "x.ron",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("field `protocol.methods[0].exclusion.after`: expected at least 1"),
        "{err}"
    );
}
