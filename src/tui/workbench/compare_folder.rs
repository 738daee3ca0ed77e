//! A `sapnet compare` folder as the Comparison and Curves views read it: the runs compare
//! recorded in it ([`compare_folder`]: `run_episodes.csv` and `compare.json`, never the
//! files `runs.csv` names), each a finished run of its method, and the report made again
//! from them by the scoring compare wrote `comparison.csv` with
//! ([`scored::compare_report`]), on a thread of its own so that the screen opens at once.
//! A compare folder does not change: it is read once.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result};

use super::folder::Compared;
use crate::config::Budget;
use crate::outside_runs::compare_folder::{self, Alignment, Scoring};
use crate::report::scored::{self, RunEpisodes};
use crate::report::{Report, TrainingEpisodes};
use crate::results::folder_state::{RunProgress, RunStatus};
use crate::results::run_metrics::RunFiles;
use crate::trainer::MethodId;

/// What a run's scores read besides its episodes: whether every length is known, and the
/// steps its file said it took.
#[derive(Debug, Clone, Copy)]
struct ScoredAs {
    lengths_known: bool,
    steps: Option<u64>,
}

/// A compare folder, read.
pub struct CompareFolder {
    pub dir: PathBuf,
    pub scoring: Scoring,
    methods: Vec<MethodId>,
    /// Every run, method by method, each done.
    runs: Vec<RunProgress>,
    /// Beside each run, what its scores read besides its episodes.
    scored_as: Vec<ScoredAs>,
    pub report: Option<Report>,
    /// The report is being made.
    pub computing: bool,
}

impl CompareFolder {
    /// The compare folder `dir` as recorded, its report not made yet; a folder written
    /// before compare recorded its runs is refused saying what makes it openable.
    pub fn read(dir: &Path) -> Result<Self> {
        if !compare_folder::is_recorded(dir) {
            anyhow::bail!(
                "{}: a `sapnet compare` folder written before compare recorded its runs (it \
                 has no {}): run `sapnet compare` again, with the --method flags of the runs \
                 runs.csv lists, to make it openable; its table is comparison.csv, its plots \
                 the .png files beside it",
                dir.display(),
                compare_folder::SCORING
            );
        }
        let recorded =
            compare_folder::read(dir).with_context(|| format!("sapnet open {}", dir.display()))?;
        let scoring = recorded.scoring;
        let budget = scored::budget(scoring.alignment);
        let kinds = scored::outside_kinds(recorded.methods.len());
        let mut methods = Vec::new();
        let mut runs = Vec::new();
        let mut scored_as = Vec::new();
        for (index, ((name, method_runs), kind)) in
            recorded.methods.into_iter().zip(kinds).enumerate()
        {
            let id = MethodId {
                index,
                kind,
                label: name.into(),
            };
            for (r, mut run) in method_runs.into_iter().enumerate() {
                scored_as.push(ScoredAs {
                    lengths_known: run.lengths_known,
                    steps: run.steps(),
                });
                runs.push(RunProgress {
                    method: id.clone(),
                    run: r as u32,
                    status: RunStatus::Done,
                    training: Arc::new(std::mem::take(&mut run.episodes)),
                    planned: budget,
                    source: None,
                    wall_s: None,
                });
            }
            methods.push(id);
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            scoring,
            methods,
            runs,
            scored_as,
            report: None,
            computing: false,
        })
    }

    /// The work that makes the folder's report, on any thread: its runs scored and
    /// compared as compare did it.
    pub fn report_job(&self) -> impl FnOnce() -> Report + Send + 'static {
        let scoring = self.scoring.clone();
        let labels: Vec<String> = self.methods.iter().map(|m| m.label().to_string()).collect();
        let runs: Vec<(usize, Arc<TrainingEpisodes>, ScoredAs)> = self
            .runs
            .iter()
            .zip(&self.scored_as)
            .map(|(r, &scored_as)| (r.method.index, r.training.clone(), scored_as))
            .collect();
        move || {
            let methods: Vec<(&str, Vec<RunEpisodes>)> = labels
                .iter()
                .enumerate()
                .map(|(index, label)| {
                    let episodes = runs
                        .iter()
                        .filter(|(m, _, _)| *m == index)
                        .map(|(_, episodes, scored_as)| RunEpisodes {
                            episodes,
                            lengths_known: scored_as.lengths_known,
                            steps: scored_as.steps,
                        })
                        .collect();
                    (label.as_str(), episodes)
                })
                .collect();
            scored::compare_report(&scoring, &methods).1
        }
    }

    /// How the runs were set side by side, as the header says it.
    pub fn alignment_text(&self) -> String {
        match self.scoring.alignment {
            Alignment::Steps(n) => format!("compared by step, to step {n}"),
            Alignment::Episodes(_) => "compared by episode".into(),
        }
    }
}

impl Compared for CompareFolder {
    fn dir(&self) -> &Path {
        &self.dir
    }

    fn methods(&self) -> Vec<MethodId> {
        self.methods.clone()
    }

    fn planned_runs(&self, index: usize) -> usize {
        self.runs.iter().filter(|r| r.method.index == index).count()
    }

    fn runs(&self) -> &[RunProgress] {
        &self.runs
    }

    /// Only their returns and lengths: the files they came from are not read.
    fn run_files(&self) -> Vec<RunFiles> {
        self.runs
            .iter()
            .map(|r| RunFiles {
                method: r.method.index,
                dir: None,
                spreads: false,
                training: r.training.clone(),
            })
            .collect()
    }

    fn sources(&self) -> Vec<String> {
        Vec::new()
    }

    fn budget(&self) -> Budget {
        scored::budget(self.scoring.alignment)
    }

    fn window(&self) -> usize {
        self.scoring.window
    }

    fn report(&self) -> Option<&Report> {
        self.report.as_ref()
    }

    fn computing(&self) -> bool {
        self.computing
    }
}
