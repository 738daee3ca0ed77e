//! `sapnet teach --headless`: activate policies in order and print every `spread` call.

use std::io::Write;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::Serialize;

use super::lesson::{Lesson, TeachConfig};
use crate::cli::TeachArgs;
use crate::sapnet::TraceStep;

/// What `--json` prints: one object, nothing else.
#[derive(Debug, Serialize)]
struct JsonTrace<'a> {
    activations: &'a [f64],
    probabilities: &'a [f64],
    trace: Vec<TraceStep>,
}

/// Loads the teach file (the embedded Fig. 2 without one), activates `args.activate` in
/// order as positive transitions, and writes the trace and the final state to `out`.
pub fn run(config: Option<&Path>, args: &TeachArgs, out: &mut impl Write) -> Result<()> {
    let lesson = TeachConfig::load(config)?;
    let origin = config.map_or("the embedded Fig. 2".to_string(), |p| {
        p.display().to_string()
    });
    run_lesson(lesson, &origin, args, out)
}

/// [`run`] on a lesson already built (`origin` names it in messages).
pub fn run_lesson(
    lesson: Lesson,
    origin: &str,
    args: &TeachArgs,
    out: &mut impl Write,
) -> Result<()> {
    let Lesson { names, mut net, .. } = lesson;
    if let Some(&i) = args.activate.iter().find(|&&i| i >= net.len()) {
        bail!(
            "--activate {i}: there is no policy {i}; {origin} has {} policies, numbered 0 to {}",
            net.len(),
            net.len().saturating_sub(1)
        );
    }

    let mut per_activation = Vec::with_capacity(args.activate.len());
    for &i in &args.activate {
        let mut trace = Vec::new();
        net.activate_traced(i, true, &mut trace);
        per_activation.push((i, trace));
    }
    let probabilities = net.probabilities();

    if args.json {
        let report = JsonTrace {
            activations: net.activations(),
            probabilities: &probabilities,
            trace: per_activation.into_iter().flat_map(|(_, t)| t).collect(),
        };
        serde_json::to_writer(&mut *out, &report)?;
        writeln!(out)?;
        return Ok(());
    }

    let p = net.params();
    writeln!(
        out,
        "SAP-Net: {} policies, {} edges; T_ω = {}, 𝒜 = {}, τ = {}, paths {:?}",
        net.len(),
        net.graph().edges().count(),
        p.threshold,
        p.coefficient,
        p.temperature,
        p.paths
    )?;
    let width = names
        .iter()
        .map(|n| n.chars().count())
        .max()
        .unwrap_or(0)
        .max(4);
    for (i, trace) in &per_activation {
        let k = net.graph().degree(*i);
        writeln!(out)?;
        let name = &names[*i];
        write!(
            out,
            "activate {name}: A[{name}] += 𝒜 = {}, k = {k}",
            p.coefficient
        )?;
        if k > 0 {
            write!(
                out,
                ", η = 𝒜/k = {:.6} to each neighbour",
                p.coefficient / k as f64
            )?;
        }
        writeln!(out)?;
        write_trace(out, trace, &names, width).context("writing the trace")?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "{:<width$}  {:>12}  {:>11}",
        "policy", "activation", "probability"
    )?;
    for ((name, a), prob) in names.iter().zip(net.activations()).zip(&probabilities) {
        writeln!(out, "{name:<width$}  {a:>12.6}  {prob:>11.6}")?;
    }
    Ok(())
}

/// One row per `spread` call, in the order the recursion makes them.
fn write_trace(
    out: &mut impl Write,
    trace: &[TraceStep],
    names: &[String],
    width: usize,
) -> std::io::Result<()> {
    // As wide as the last call's number: a long walk makes hundreds of thousands.
    let calls = trace.len().to_string().len().max(5);
    writeln!(
        out,
        "{:>calls$}  {:<width$}  {:<width$}  {:>2}  {:>8}  {:>10}  {:>10}",
        "call", "from", "to", "h", "Ω", "η", "ΔA"
    )?;
    for (n, s) in trace.iter().enumerate() {
        let delta = if s.stopped {
            format!("{:>10}  stopped: Ω ≥ T_ω", "0")
        } else {
            format!("{:>10.6}", s.delta)
        };
        writeln!(
            out,
            "{:>calls$}  {:<width$}  {:<width$}  {:>2}  {:>8.4}  {:>10.6}  {delta}",
            n + 1,
            names[s.from],
            names[s.to],
            s.h,
            s.omega,
            s.eta,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 27: past 99,999 calls the numbers pushed the row's columns right of the
    /// header's; the column now widens with the last number.
    #[test]
    fn the_call_column_keeps_its_alignment_past_100000_calls() {
        let step = TraceStep {
            from: 0,
            to: 1,
            h: 1,
            omega: 0.95,
            eta: 0.5,
            delta: 0.526316,
            stopped: false,
        };
        let names = ["a".to_string(), "b".to_string()];
        for calls in [3, 123_456] {
            let mut out = Vec::new();
            write_trace(&mut out, &vec![step; calls], &names, 4).unwrap();
            let text = String::from_utf8(out).unwrap();
            let mut lines = text.lines();
            let from = lines.next().unwrap().find("from").unwrap();
            for row in lines {
                assert_eq!(
                    row.find("  a ").map(|i| i + 2),
                    Some(from),
                    "{calls} calls: {row}"
                );
            }
            assert_eq!(
                text.lines().last().unwrap().split_whitespace().next(),
                Some(calls.to_string().as_str())
            );
        }
    }
}
