//! Which run of a protocol the UI follows in its Run view: `--follow` (a method) and
//! `--follow-run` (its run), else run 0 of the first method that spreads activation
//! (SAP-Net), else of the first that reuses, else of the first method.

use anyhow::Result;

use crate::trainer::MethodId;

/// The method followed first: `follow` (a method's label, refused if the config has none),
/// else the first that spreads activation (SAP-Net), else the first that reuses, else the
/// first; `None` for a protocol of no method.
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
            Some(id.clone())
        }
        None => ids
            .iter()
            .find(|m| m.kind.spreads)
            .or_else(|| ids.iter().find(|m| m.kind.reuses))
            .or_else(|| ids.first())
            .cloned(),
    })
}

/// The run followed first, as (method label, run): `follow_run` (from 0, as in the
/// results' files; refused past the protocol's `runs`) of [`followed_method`].
pub fn followed_run(
    ids: &[MethodId],
    follow: Option<&str>,
    follow_run: Option<u32>,
    runs: u32,
) -> Result<Option<(String, u32)>> {
    let run = follow_run.unwrap_or(0);
    anyhow::ensure!(
        run < runs,
        "--follow-run {run}: expected a run from 0 to {} (the config's {runs} runs per method, \
         numbered from 0 as in the results' files)",
        runs.saturating_sub(1)
    );
    Ok(followed_method(ids, follow)?.map(|m| (m.label().to_string(), run)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reuse::Method;

    fn ids() -> Vec<MethodId> {
        MethodId::all(&[
            Method::Dqn { hidden: vec![8] },
            Method::Random,
            Method::SapNet,
        ])
    }

    #[test]
    fn sapnet_run_0_is_followed_unless_told_otherwise() {
        assert_eq!(
            followed_run(&ids(), None, None, 2).unwrap(),
            Some(("sapnet".to_string(), 0))
        );
        assert_eq!(
            followed_run(&ids(), Some("dqn[8]"), Some(1), 2).unwrap(),
            Some(("dqn[8]".to_string(), 1))
        );
        // Without a reusing method, the first method is followed.
        let baselines = MethodId::all(&[Method::Dqn { hidden: vec![8] }]);
        assert_eq!(
            followed_run(&baselines, None, None, 1).unwrap(),
            Some(("dqn[8]".to_string(), 0))
        );
    }

    #[test]
    fn a_run_or_method_the_config_does_not_have_is_refused() {
        for run in [2, 3] {
            let err = followed_run(&ids(), None, Some(run), 2)
                .unwrap_err()
                .to_string();
            assert!(err.contains(&format!("--follow-run {run}")), "{err}");
            assert!(err.contains("from 0 to 1"), "{err}");
        }
        let err = followed_run(&ids(), Some("ucb1"), None, 2)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("--follow ucb1: the config has no such method; its methods are dqn[8], random, sapnet"),
            "{err}"
        );
    }
}
