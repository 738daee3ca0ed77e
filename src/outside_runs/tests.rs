//! Each format read from a small file the test writes, each refusal with the place it
//! names, and a real Stable-Baselines3 monitor file (`tests/fixtures/outside/`).

use std::path::{Path, PathBuf};

use super::*;
use crate::tensorboard::EventWriter;

fn write(dir: &Path, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

fn read(path: &Path) -> Result<OutsideRun, OutsideRunError> {
    read_run(path, &ReadOptions::default())
}

/// `(step at its end, return)` of each episode of a run whose lengths are known.
fn episodes(run: &OutsideRun) -> Vec<(u64, f64)> {
    let placed = run.placed().expect("every length known");
    placed
        .ends()
        .into_iter()
        .zip(placed.returns.iter().copied())
        .collect()
}

fn message(result: Result<OutsideRun, OutsideRunError>) -> String {
    result.unwrap_err().to_string()
}

#[test]
fn a_monitor_file_places_each_episode_at_the_sum_of_the_lengths_so_far() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "0.monitor.csv",
        "#{\"t_start\": 1.5, \"env_id\": \"CartPole-v1\"}\nr,l,t\n9.0,10,0.1\n-2.5,5,0.2\n31,31,0.3\n",
    );
    let run = read(&path).unwrap();
    assert_eq!((run.format, run.axis), (Format::Monitor, Axis::Steps));
    assert_eq!(
        (run.series.as_str(), run.path.as_path()),
        ("r", path.as_path())
    );
    assert_eq!(episodes(&run), [(10, 9.0), (15, -2.5), (46, 31.0)]);
    assert_eq!(run.episodes.lengths, [10, 5, 31]);
    assert_eq!(run.steps(), Some(46));
}

#[test]
fn a_real_stable_baselines3_monitor_file_reads_and_scores() {
    // Written by tests/fixtures/outside/make_monitor.py: 300 random steps on CartPole-v1,
    // 15 whole episodes (288 steps); CartPole pays 1 a step, so each return is its length.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/outside/monitor.csv");
    let run = read(&path).unwrap();
    assert_eq!(run.format, Format::Monitor);
    assert_eq!(run.episodes.len(), 15);
    assert_eq!(run.steps(), Some(288));
    for (&r, &length) in run.episodes.returns.iter().zip(&run.episodes.lengths) {
        assert_eq!(r as u32, length);
    }
    // Its returns sum to its steps, 288; the last five: 14 + 20 + 10 + 12 + 17 = 73.
    let returns: Vec<f64> = run.returns().collect();
    assert_eq!(returns.iter().sum::<f64>(), 288.0);
    assert_eq!(returns[10..].iter().sum::<f64>(), 73.0);
}

#[test]
fn an_export_skips_rows_where_the_return_was_not_logged() {
    let dir = tempfile::tempdir().unwrap();
    // As a W&B export of a CleanRL run: losses logged on rows of their own, steps written
    // as floats.
    let path = write(
        dir.path(),
        "export.csv",
        "global_step,charts/episodic_return,charts/episodic_length,losses/td_loss\n\
         120.0,15.0,15,\n\
         500,,,0.25\n\
         640, 28.5 ,28,\n",
    );
    let run = read(&path).unwrap();
    assert_eq!((run.format, run.axis), (Format::Csv, Axis::Steps));
    assert_eq!(run.series, "charts/episodic_return");
    // Placed by their steps: each episode's length is the steps since the one before (the
    // length column is checked as numbers, its values not needed).
    assert_eq!(episodes(&run), [(120, 15.0), (640, 28.5)]);
    assert_eq!(run.episodes.lengths, [120, 520]);
}

#[test]
fn columns_named_by_the_caller_are_read_and_an_episode_column_counts_episodes() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "scores.csv",
        "episode,score,return\n1,5,100\n2,7,200\n",
    );
    let defaults = read(&path).unwrap();
    assert_eq!(defaults.axis, Axis::Episodes);
    assert_eq!(defaults.series, "return");
    assert_eq!(defaults.episodes.returns, [100.0, 200.0]);
    assert_eq!((defaults.placed(), defaults.steps()), (None, None));
    let named = ReadOptions {
        return_column: Some("score".into()),
        position_column: Some(PositionColumn::Step("return".into())),
        ..ReadOptions::default()
    };
    let run = read_run(&path, &named).unwrap();
    assert_eq!((run.axis, run.series.as_str()), (Axis::Steps, "score"));
    assert_eq!(episodes(&run), [(100, 5.0), (200, 7.0)]);
}

/// An event file in `dir` as CleanRL writes one: each episode's return and length at the
/// step it ended, among other scalars.
fn cleanrl_events(dir: &Path, episodes: &[(i64, f32, f32)]) -> PathBuf {
    let mut writer = EventWriter::create(dir).unwrap();
    for &(step, episode_return, length) in episodes {
        writer.scalar("charts/SPS", step, 1000.0).unwrap();
        writer.scalar(RETURN_TAG, step, episode_return).unwrap();
        writer.scalar(LENGTH_TAG, step, length).unwrap();
    }
    writer.path().to_path_buf()
}

#[test]
fn an_event_file_or_a_folder_of_them_reads_the_return_tag_with_its_lengths() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    let first = cleanrl_events(&run_dir, &[(20, 20.0, 20.0), (45, 25.0, 25.0)]);
    let run = read(&first).unwrap();
    assert_eq!((run.format, run.axis), (Format::EventFiles, Axis::Steps));
    assert_eq!(run.series, RETURN_TAG);
    assert_eq!(episodes(&run), [(20, 20.0), (45, 25.0)]);
    // A resumed run: a second file, later by name, read after the first.
    cleanrl_events(&run_dir, &[(80, 35.0, 35.0)]);
    std::fs::write(run_dir.join("notes.txt"), "not an event file").unwrap();
    let folder = read(&run_dir).unwrap();
    assert_eq!(folder.path, run_dir);
    assert_eq!(episodes(&folder), [(20, 20.0), (45, 25.0), (80, 35.0)]);
}

/// Stable-Baselines3's `tensorboard_log`: `tb/<seed>/DQN_1/events…`. The seed's folder is
/// its one run; their parent holds each seed's run, in the order of their paths; a linked
/// folder is never entered, and a folder with none within two levels is refused.
#[test]
fn a_folder_without_event_files_holds_the_runs_of_the_folders_under_it() {
    let dir = tempfile::tempdir().unwrap();
    let tb = dir.path().join("tb");
    cleanrl_events(&tb.join("dqn-1/DQN_1"), &[(30, 30.0, 30.0)]);
    cleanrl_events(
        &tb.join("dqn-0/DQN_1"),
        &[(20, 20.0, 20.0), (45, 25.0, 25.0)],
    );
    std::os::unix::fs::symlink(tb.join("dqn-0"), tb.join("dqn-link")).unwrap();
    let options = ReadOptions::default();
    let seed = read_runs(&tb.join("dqn-0"), &options).unwrap();
    assert_eq!(seed.len(), 1);
    assert_eq!(seed[0].path, tb.join("dqn-0/DQN_1"));
    assert_eq!(episodes(&seed[0]), [(20, 20.0), (45, 25.0)]);
    let seeds = read_runs(&tb, &options).unwrap();
    let paths: Vec<&Path> = seeds.iter().map(|r| r.path.as_path()).collect();
    assert_eq!(paths, [tb.join("dqn-0/DQN_1"), tb.join("dqn-1/DQN_1")]);
    // A file is one run, and a folder of event files one run, as before.
    assert_eq!(
        read_runs(&tb.join("dqn-1/DQN_1"), &options).unwrap().len(),
        1
    );
    let deep = dir.path().join("deep");
    cleanrl_events(&deep.join("a/b/c"), &[(10, 10.0, 10.0)]);
    let err = read_runs(&deep, &options).unwrap_err().to_string();
    assert!(err.contains("two levels under it"), "{err}");
}

#[test]
fn stable_baselines3s_rollout_mean_is_read_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let mut writer = EventWriter::create(dir.path()).unwrap();
    writer.scalar(ROLLOUT_MEAN_TAG, 2048, 22.5).unwrap();
    writer.scalar("train/loss", 2048, 0.5).unwrap();
    let path = writer.path().to_path_buf();
    drop(writer);
    let err = message(read(&path));
    assert!(
        err.contains("no scalar tagged \"charts/episodic_return\"")
            && err.contains("the tags are \"rollout/ep_rew_mean\", \"train/loss\"")
            && err.contains("`--rollout-mean` reads it"),
        "{err}"
    );
    let asked = ReadOptions {
        rollout_mean: true,
        ..ReadOptions::default()
    };
    let run = read_run(&path, &asked).unwrap();
    assert_eq!(run.series, ROLLOUT_MEAN_TAG);
    assert_eq!(episodes(&run), [(2048, 22.5)]);
}

#[test]
fn a_file_of_no_known_format_is_refused_saying_so() {
    let dir = tempfile::tempdir().unwrap();
    let png = write(dir.path(), "plot.csv", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR");
    let err = message(read(&png));
    assert!(err.starts_with(&png.display().to_string()), "{err}");
    assert!(err.contains("not a run sapnet can read (binary"), "{err}");
    let empty = write(dir.path(), "empty.csv", "");
    assert!(message(read(&empty)).contains("(an empty file)"));
    let folder = dir.path().join("no-events");
    std::fs::create_dir(&folder).unwrap();
    write(&folder, "monitor.csv", "#{}\nr,l,t\n");
    assert!(message(read(&folder)).contains("a folder without event files"));
}

#[test]
fn a_run_without_an_episode_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let monitor = write(dir.path(), "m.csv", "#{\"t_start\": 0}\nr,l,t\n");
    let err = message(read(&monitor));
    assert!(
        err.ends_with("no episode: the column \"r\" holds no value"),
        "{err}"
    );
    let export = write(dir.path(), "e.csv", "global_step,episodic_return\n10,\n");
    let err = message(read(&export));
    assert!(
        err.contains("the column \"episodic_return\" holds no value"),
        "{err}"
    );
}

#[test]
fn a_non_finite_return_is_refused_at_its_cell_or_event() {
    let dir = tempfile::tempdir().unwrap();
    let monitor = write(dir.path(), "m.csv", "#{}\nr,l,t\n1,1,0\nnan,2,0\n");
    let err = message(read(&monitor));
    assert!(
        err.contains("line 4, column 1 (r): the return NaN is not finite"),
        "{err}"
    );
    let mut writer = EventWriter::create(&dir.path().join("run")).unwrap();
    writer.scalar(RETURN_TAG, 1, 3.0).unwrap();
    writer.scalar(RETURN_TAG, 2, f32::INFINITY).unwrap();
    let path = writer.path().to_path_buf();
    drop(writer);
    let bad =
        crate::tensorboard::read_events(&path, crate::safe_io::Links::Refuse).unwrap()[2].offset;
    let err = message(read(&dir.path().join("run")));
    assert!(err.starts_with(&path.display().to_string()), "{err}");
    assert!(
        err.contains(&format!(
            "the event at byte {bad} (charts/episodic_return): the return inf is not finite"
        )),
        "{err}"
    );
}

#[test]
fn a_missing_column_is_refused_listing_the_columns_there_are() {
    let dir = tempfile::tempdir().unwrap();
    let no_return = write(dir.path(), "a.csv", "global_step,loss\n1,0.5\n");
    let err = message(read(&no_return));
    assert!(
        err.contains(
            "no column \"charts/episodic_return\", \"episodic_return\", \"return\" or \"r\" \
             (the columns are \"global_step\", \"loss\")"
        ),
        "{err}"
    );
    let no_step = write(dir.path(), "b.csv", "return,time\n1,0.5\n");
    let err = message(read(&no_step));
    assert!(
        err.contains("\"_step\" or \"episode\" (the columns are \"return\", \"time\")"),
        "{err}"
    );
    let monitor = write(dir.path(), "c.csv", "#{}\nr,t\n1,0.5\n");
    assert!(message(read(&monitor)).contains("no column \"l\""));
    let named = ReadOptions {
        length_column: Some("len".into()),
        ..ReadOptions::default()
    };
    let export = write(dir.path(), "d.csv", "step,return\n1,2\n");
    assert!(message(read_run(&export, &named)).contains("no column \"len\""));
}

#[test]
fn a_cell_that_is_not_a_number_is_refused_with_its_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let export = write(dir.path(), "a.csv", "step,return\n1,2\n2,abc\n");
    let err = message(read(&export));
    assert!(
        err.ends_with("a.csv: line 3, column 2 (return): \"abc\" is not a number"),
        "{err}"
    );
    let fractional_step = write(dir.path(), "b.csv", "step,return\n1.5,2\n");
    assert!(message(read(&fractional_step))
        .contains("line 2, column 1 (step): \"1.5\" is not a whole number"));
    let negative_length = write(dir.path(), "c.csv", "#{}\nr,l,t\n1,-1,0\n");
    assert!(message(read(&negative_length))
        .contains("line 3, column 2 (l): \"-1\" is not a whole number of steps"));
    let ragged = write(dir.path(), "d.csv", "step,return\n1,2\n3\n");
    let err = message(read(&ragged));
    assert!(err.starts_with(&ragged.display().to_string()), "{err}");
    assert!(err.contains("line: 3"), "{err}");
}

#[test]
fn a_link_inside_a_folder_of_event_files_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let elsewhere = cleanrl_events(&dir.path().join("elsewhere"), &[(1, 1.0, 1.0)]);
    let run_dir = dir.path().join("run");
    std::fs::create_dir(&run_dir).unwrap();
    std::os::unix::fs::symlink(&elsewhere, run_dir.join("events.out.tfevents.1.host")).unwrap();
    let err = message(read(&run_dir));
    assert!(err.contains("symbolic link"), "{err}");
    // The path the user names may be a link: the user chose it.
    let named_link = dir.path().join("chosen");
    std::os::unix::fs::symlink(&elsewhere, &named_link).unwrap();
    assert_eq!(read(&named_link).unwrap().episodes.len(), 1);
}

#[test]
fn a_monitor_file_is_read_up_to_its_bound_of_rows_and_refused_past_it() {
    // MAX_EPISODES (10 M rows) scaled down to 3: at the bound it reads, past it the first
    // row too many is named.
    let dir = tempfile::tempdir().unwrap();
    let rows = |n: usize| {
        let mut text = String::from("#{\"t_start\": 0}\nr,l,t\n");
        for i in 1..=n {
            text.push_str(&format!("{i}.0,{i},0.1\n"));
        }
        write(dir.path(), &format!("{n}.monitor.csv"), text)
    };
    let at = rows(3);
    let run = monitor::read_at_most(std::fs::File::open(&at).unwrap(), &at, 3).unwrap();
    assert_eq!(run.episodes.returns, [1.0, 2.0, 3.0]);
    assert_eq!(run.steps(), Some(6));
    let past = rows(4);
    let err = monitor::read_at_most(std::fs::File::open(&past).unwrap(), &past, 3)
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&past.display().to_string()), "{err}");
    assert!(err.contains("line 6") && err.contains('3'), "{err}");
}
