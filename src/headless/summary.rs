//! What a headless protocol says when it ends: where its files are and each run on stderr,
//! the comparison table on stdout.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};

use crate::{report, results};

/// Where a protocol ran: a stopped one is advised to resume where it was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RanIn {
    Headless,
    Ui,
}

/// What a protocol did: where its files are, each run on stderr, the comparison on stdout.
pub fn print_summary(summary: &results::Summary, dir: &Path, ran_in: RanIn) -> Result<()> {
    let config = &summary.config;
    let dir = dir.display();
    if summary.stopped() {
        let resume = match ran_in {
            RanIn::Headless => format!("`sapnet --headless --resume --out {dir}` finishes it"),
            RanIn::Ui => format!(
                "`sapnet --resume --out {dir}` finishes it in the UI (with --headless, without it)"
            ),
        };
        eprintln!("stopped by the user: what was done so far is in {dir} (episodes.csv, tests.csv, summary.json, plots); {resume}");
    } else {
        eprintln!("results in {dir}: episodes.csv, tests.csv, activations.csv, comparison.csv, improvement.csv, scores.csv, summary.json, runs/, policies/, intervals.png, profiles.png, improvement.png, learning_curve.png, sample_efficiency.csv, sample_efficiency.png, tests.png, activations.png, selections.png (the plots also as .svg)");
    }
    for run in &summary.runs {
        let tests: Vec<String> = run
            .record
            .test_returns
            .iter()
            .map(|r| format!("{r:.0}"))
            .collect();
        // A run stopped before its tests has none: said so, not as an empty list.
        let tests = if tests.is_empty() {
            "not tested".to_string()
        } else {
            format!("greedy tests [{}]", tests.join(", "))
        };
        eprintln!(
            "{} run {}: {} episodes, best MA{} {}, {tests}",
            run.record.method,
            run.record.run,
            run.record.episodes,
            config.protocol.moving_average,
            run.best_moving_average
                .map_or("—".into(), |a| format!("{a:.1}")),
        );
        if let Some(chosen) = &run.record.chosen {
            eprintln!(
                "  chosen policy {} {:?} ({} {:.2})",
                chosen.name, chosen.hidden, chosen.score_name, chosen.score
            );
        }
        if let Some(copy) = &run.library_copy {
            eprintln!("  added to the policy library as {}", copy.display());
        }
    }
    print_comparison(summary)
}

/// The comparison table of a protocol, on stdout.
pub fn print_comparison(summary: &results::Summary) -> Result<()> {
    let mut table = if summary.comparison.is_empty() {
        String::new()
    } else {
        let mut table = report::comparison::table(
            &summary.comparison,
            report::Units::Returns,
            report::TestScore::Greedy,
        );
        let pairs = report::improvement::verdicts(&summary.pairs, "return");
        if !pairs.is_empty() {
            table.push('\n');
            table.push_str(&pairs);
        }
        table
    };
    let stopped: Vec<String> = summary
        .runs
        .iter()
        .filter(|r| r.record.stopped)
        .map(|r| {
            format!(
                "{} run {} at episode {} (step {}) of {}",
                r.record.method.label(),
                r.record.run,
                r.record.episodes,
                r.record.steps,
                summary.config.protocol.budget
            )
        })
        .collect();
    if !stopped.is_empty() {
        table.push_str(&format!(
            "not in the table, stopped before their end: {}\n",
            stopped.join(", ")
        ));
    }
    if table.is_empty() {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    write!(out, "{table}")
        .and_then(|()| out.flush())
        .context("writing to stdout")
}
