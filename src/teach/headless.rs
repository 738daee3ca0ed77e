//! `sapnet teach --headless`: activate policies in order (the activations decayed by D
//! between two) and print every `spread` call, the final state and A and P through time;
//! or, for a lesson saved mid-walk and no `--activate`, that walk as far as it was made.

use std::io::Write;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::Serialize;

use super::lesson::{Lesson, TeachConfig, WalkPosition};
use super::session::{Teach, TimeRow};
use crate::cli::TeachArgs;
use crate::sapnet::TraceStep;

/// What `--json` prints: one object, nothing else.
#[derive(Debug, Serialize)]
struct JsonTrace<'a> {
    activations: &'a [f64],
    probabilities: &'a [f64],
    trace: Vec<TraceStep>,
    /// A and P after each activation's walk.
    through_time: &'a [TimeRow],
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
    let Lesson {
        names,
        mut net,
        walk,
        decay,
        ..
    } = lesson;
    if let Some(&i) = args.activate.iter().find(|&&i| i >= net.len()) {
        bail!(
            "--activate {i}: there is no policy {i}; {origin} has {} policies, numbered 0 to {}",
            net.len(),
            net.len().saturating_sub(1)
        );
    }
    // A lesson may come from anyone: its names reach the terminal as data, an escape
    // sequence in one printed as visible escapes, never acted on.
    let names: Vec<String> = names.iter().map(|name| escape_controls(name)).collect();
    let walks = make_walks(&names, &mut net, &args.activate, walk, decay);
    if args.json {
        let report = JsonTrace {
            activations: net.activations(),
            probabilities: &net.probabilities(),
            trace: walks.traces.into_iter().flat_map(|(_, t)| t).collect(),
            through_time: &walks.through_time,
        };
        serde_json::to_writer(&mut *out, &report)?;
        writeln!(out)?;
        return Ok(());
    }
    write_report(out, &net, &names, &walks, decay)
}

/// `text` with each control character written as its escape (`\u{1b}`, `\n`): this prints
/// straight to the terminal, where ratatui would have dropped them.
fn escape_controls(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// The walks made: each activation's calls, and A and P after each walk.
struct Walks {
    traces: Vec<(usize, Vec<TraceStep>)>,
    through_time: Vec<TimeRow>,
}

/// Activates `activate` in order on `net` (decayed by D between two), or, without any and
/// with a saved walk, makes that walk as far as it was.
fn make_walks(
    names: &[String],
    net: &mut crate::sapnet::SapNet,
    activate: &[usize],
    saved: Option<WalkPosition>,
    decay: f64,
) -> Walks {
    let mut walks = Walks {
        traces: Vec::with_capacity(activate.len()),
        through_time: Vec::with_capacity(activate.len()),
    };
    if let (true, Some(position)) = (activate.is_empty(), saved) {
        let (trace, row) = saved_walk(names, net, position);
        walks.traces.push((position.activate, trace));
        walks.through_time.push(row);
        return walks;
    }
    for (k, &i) in activate.iter().enumerate() {
        if k > 0 && decay > 0.0 {
            let kept = 1.0 - decay;
            let decayed = net.activations().iter().map(|a| a * kept).collect();
            net.set_activations(decayed)
                .expect("activations of the same graph, scaled down");
        }
        let mut trace = Vec::new();
        net.activate_traced(i, true, &mut trace);
        walks.traces.push((i, trace));
        walks.through_time.push(TimeRow {
            activated: i,
            activations: net.activations().to_vec(),
            probabilities: net.probabilities(),
        });
    }
    walks
}

/// The table: the net, each activation's calls, the final A and P, and A and P through
/// time where there was more than one walk.
fn write_report(
    out: &mut impl Write,
    net: &crate::sapnet::SapNet,
    names: &[String],
    walks: &Walks,
    decay: f64,
) -> Result<()> {
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
    for (i, trace) in &walks.traces {
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
        write_trace(out, trace, names, width).context("writing the trace")?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "{:<width$}  {:>12}  {:>11}",
        "policy", "activation", "probability"
    )?;
    let probabilities = net.probabilities();
    for ((name, a), prob) in names.iter().zip(net.activations()).zip(&probabilities) {
        writeln!(out, "{name:<width$}  {a:>12.6}  {prob:>11.6}")?;
    }
    if walks.through_time.len() > 1 {
        writeln!(out)?;
        write_through_time(out, &walks.through_time, names, decay)?;
    }
    Ok(())
}

/// A lesson saved mid-walk (`w`): its walk from `initial`, made as teach mode makes it,
/// as far as it was; `net` is left with the activations the screen showed.
fn saved_walk(
    names: &[String],
    net: &mut crate::sapnet::SapNet,
    position: WalkPosition,
) -> (Vec<TraceStep>, TimeRow) {
    let mut teach = Teach::new(names.to_vec(), net.clone());
    teach.resume_walk(position);
    let trace = teach.walk().map(|w| w.trace.to_vec()).unwrap_or_default();
    *net = teach.net().clone();
    let row = TimeRow {
        activated: position.activate,
        activations: net.activations().to_vec(),
        probabilities: net.probabilities(),
    };
    (trace, row)
}

/// A and P of every policy after each activation's walk, a row per policy and a column
/// pair per walk.
fn write_through_time(
    out: &mut impl Write,
    rows: &[TimeRow],
    names: &[String],
    decay: f64,
) -> std::io::Result<()> {
    writeln!(
        out,
        "through time: A and P after each walk (decay D = {decay} between activations)"
    )?;
    let width = names
        .iter()
        .map(|n| n.chars().count())
        .max()
        .unwrap_or(0)
        .max(6);
    write!(out, "{:<width$}", "policy")?;
    for (t, row) in rows.iter().enumerate() {
        let head = format!("{}:{}", t + 1, names[row.activated]);
        write!(out, "  {head:>10}  {:>8}", "P")?;
    }
    writeln!(out)?;
    for (i, name) in names.iter().enumerate() {
        write!(out, "{name:<width$}")?;
        for row in rows {
            write!(
                out,
                "  {:>10.6}  {:>8.4}",
                row.activations[i], row.probabilities[i]
            )?;
        }
        writeln!(out)?;
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

    /// Issue 52, item 12: an OSC title and a screen clear in a name print as escapes.
    #[test]
    fn control_characters_are_printed_as_escapes() {
        assert_eq!(
            escape_controls("\u{1b}]0;owned\u{7}π1\u{1b}[2J\n×"),
            "\\u{1b}]0;owned\\u{7}π1\\u{1b}[2J\\n×"
        );
    }

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
