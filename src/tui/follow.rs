//! Which runs the dashboard trains: the followed method (`--follow`), run `--follow-run`
//! of every method that reuses, and the same run of the first DQN baseline.

use anyhow::Result;

use crate::trainer::{MethodId, RunSpec, StreamOptions};

/// The method the dashboard follows first: `follow` (a method's label, refused if the
/// config has none or it does not reuse the library), else the first that spreads activation
/// (SAP-Net), else the first that reuses; `None` when no method reuses.
pub fn followed_method(ids: &[MethodId], follow: Option<&str>) -> Result<Option<MethodId>> {
    Ok(match follow {
        Some(label) => {
            let Some(id) = ids.iter().find(|m| m.label() == label) else {
                let labels: Vec<&str> = ids.iter().map(|m| m.label()).collect();
                anyhow::bail!(
                    "--follow {label}: the config has no such method; its methods are {}",
                    labels.join(", ")
                );
            };
            anyhow::ensure!(
                id.kind.reuses,
                "--follow {label}: the dashboard follows a method that reuses the library; \
                 the DQN baseline runs beside it anyway"
            );
            Some(id.clone())
        }
        None => ids
            .iter()
            .find(|m| m.kind.spreads)
            .or_else(|| ids.iter().find(|m| m.kind.reuses))
            .cloned(),
    })
}

/// Run `run` (`--follow-run`, from 0 as in the results' files) of every reusing method,
/// streaming every step, and of the first DQN baseline: what the dashboard can train.
pub fn dashboard_specs(specs: &[RunSpec], run: u32) -> Result<(Vec<RunSpec>, Option<RunSpec>)> {
    let runs = specs.iter().map(|s| s.run + 1).max().unwrap_or(0);
    anyhow::ensure!(
        run < runs,
        "--follow-run {run}: expected a run from 0 to {} (the config's {runs} runs per method, \
         numbered from 0 as in the results' files)",
        runs.saturating_sub(1)
    );
    let followable = specs
        .iter()
        .filter(|s| s.run == run && s.method.kind.reuses)
        .map(|s| {
            let mut spec = s.clone();
            spec.stream = StreamOptions::live();
            spec
        })
        .collect();
    let baseline = specs
        .iter()
        .find(|s| s.run == run && !s.method.kind.reuses)
        .cloned();
    Ok((followable, baseline))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::DqnConfig;
    use crate::env::EnvConfig;

    /// Two runs of a reusing method and of a DQN baseline, as a plan lists them.
    fn specs() -> Vec<RunSpec> {
        let spec = |run, label: &str, kind| {
            let mut s = RunSpec::scratch(
                run,
                label,
                EnvConfig::CartPole(Default::default()),
                DqnConfig::default(),
                vec![4],
                10,
                1,
                u64::from(run) + 7,
            );
            s.method.kind = kind;
            s
        };
        (0..2)
            .flat_map(|run| {
                [
                    spec(run, "sapnet", crate::reuse::sapnet::KIND),
                    spec(run, "dqn[4]", crate::reuse::from_scratch::KIND),
                ]
            })
            .collect()
    }

    #[test]
    fn the_dashboard_trains_the_run_asked_for() {
        let (followable, baseline) = dashboard_specs(&specs(), 1).unwrap();
        assert_eq!(followable.len(), 1);
        assert_eq!((followable[0].run, followable[0].seed), (1, 8));
        assert_eq!(followable[0].stream, StreamOptions::live());
        assert_eq!(baseline.map(|b| (b.run, b.seed)), Some((1, 8)));
        let (first, _) = dashboard_specs(&specs(), 0).unwrap();
        assert_eq!(first[0].run, 0);
    }

    #[test]
    fn a_run_the_config_does_not_have_is_refused_with_the_range() {
        for run in [2, 3] {
            let err = dashboard_specs(&specs(), run).unwrap_err().to_string();
            assert!(err.contains(&format!("--follow-run {run}")), "{err}");
            assert!(err.contains("from 0 to 1"), "{err}");
        }
    }
}
