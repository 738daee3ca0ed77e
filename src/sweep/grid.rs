//! The grid of a sweep: a base config and axes over its fields, expanded into cells.
//!
//! ```ron
//! (
//!     base: "cartpole.ron",         // beside this file, or absolute
//!     quick: false,                 // cut every cell as `--quick` does
//!     episodes: Some(20),           // as `--episodes`
//!     seeds: Some(2),               // an axis `seed`: the base seed, +1, …
//!     axes: [(path: "sapnet.temperature", values: [0.5, 1.0, 4.0])],
//! )
//! ```
//!
//! A path names struct fields from the top of the config (`sapnet.temperature`,
//! `protocol.methods`, `seed`, `env`); a value is RON, read as that field reads it. An
//! enum such as `env` is given whole (`CartPole(length: 1.0)`), or one field of the base's
//! task at a time (`env.length`), or one keyword of a Gymnasium task
//! (`env.kwargs.gravity`, `env.attributes.length`): a task variant per value.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use ron::value::RawValue;
use serde::Deserialize;
use serde_json::Value;

use crate::config::Config;
use crate::ron_file::{parse_ron, read_text};

/// The most cells a grid may expand into.
pub const MAX_CELLS: usize = 100_000;

/// The grid file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// The base config's path, relative to the grid file.
    pub base: PathBuf,
    #[serde(default)]
    pub quick: bool,
    #[serde(default)]
    pub episodes: Option<u32>,
    #[serde(default)]
    pub seeds: Option<u64>,
    #[serde(default)]
    pub axes: Vec<Axis>,
}

/// One axis: a config field and the values it takes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    pub path: String,
    pub values: Vec<Box<RawValue>>,
}

/// One cell of the grid: the value of every axis, and the complete config they make.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// `(path, value as RON text)` per axis, in the grid's order.
    pub axes: Vec<(String, String)>,
    pub config: Config,
}

impl Grid {
    /// Reads a grid file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = read_text(path)?;
        Ok(parse_ron(&text, &path.display().to_string())?)
    }

    /// The base config: `config` when given (`--config`), else the grid's `base`.
    pub fn base_config(&self, grid_path: &Path, config: Option<&Path>) -> Result<Config> {
        let path = match config {
            Some(path) => path.to_path_buf(),
            None => grid_path
                .parent()
                .unwrap_or(Path::new("."))
                .join(&self.base),
        };
        Config::from_file(&path)
            .with_context(|| format!("the sweep's base config {}", path.display()))
    }

    /// Every cell, the first axis slowest; `origin` names the grid in errors.
    pub fn cells(&self, base: &Config, origin: &str) -> Result<Vec<Cell>> {
        let mut base = base.clone();
        if self.quick {
            base.quick();
        }
        if let Some(episodes) = self.episodes {
            base.protocol.budget = crate::config::Budget::Episodes(episodes);
        }
        let mut axes: Vec<(String, Vec<String>)> = self
            .axes
            .iter()
            .map(|a| {
                let values = a
                    .values
                    .iter()
                    .map(|v| v.trim().get_ron().to_string())
                    .collect();
                (a.path.clone(), values)
            })
            .collect();
        if let Some(n) = self.seeds {
            if axes.iter().any(|(path, _)| path == "seed") {
                bail!("{origin}: `seeds` and an axis `seed` both set the seed; keep one");
            }
            if n == 0 || n > MAX_CELLS as u64 || base.seed.checked_add(n - 1).is_none() {
                bail!(
                    "{origin}: field `seeds`: expected Some(n) with 1 ≤ n ≤ {MAX_CELLS} (and the \
                     base seed {} + n − 1 a 64-bit seed), got Some({n})",
                    base.seed
                );
            }
            axes.push((
                "seed".into(),
                (0..n).map(|k| (base.seed + k).to_string()).collect(),
            ));
        }
        for (i, (path, values)) in axes.iter().enumerate() {
            if values.is_empty() {
                bail!("{origin}: axis `{path}` has no values");
            }
            if axes[..i].iter().any(|(p, _)| p == path) {
                bail!(
                    "{origin}: axes[{i}]: `{path}` is an axis already; one axis per field \
                     (list every value in one)"
                );
            }
        }
        let total = axes
            .iter()
            .try_fold(1usize, |n, (_, v)| n.checked_mul(v.len()))
            .filter(|&n| n <= MAX_CELLS);
        let Some(total) = total else {
            bail!(
                "{origin}: the axes make more than {MAX_CELLS} cells ({}): a sweep that large \
                 is several sweeps",
                axes.iter()
                    .map(|(p, v)| format!("{} {p}", v.len()))
                    .collect::<Vec<_>>()
                    .join(" × ")
            );
        };
        let base_json = serde_json::to_value(&base).context("the base config as JSON")?;
        let mut cells = Vec::new();
        for k in 0..total {
            // Mixed radix, the last axis fastest.
            let mut rest = k;
            let mut chosen = vec![0; axes.len()];
            for (a, (_, values)) in axes.iter().enumerate().rev() {
                chosen[a] = rest % values.len();
                rest /= values.len();
            }
            let mut json = base_json.clone();
            let mut cell_axes = Vec::new();
            for (a, (path, values)) in axes.iter().enumerate() {
                let value = &values[chosen[a]];
                set(&mut json, path, value, origin)?;
                cell_axes.push((path.clone(), value.clone()));
            }
            let config: Config =
                serde_json::from_value(json).with_context(|| format!("{origin}: cell {k}"))?;
            config.validate().map_err(|message| {
                anyhow::anyhow!("{origin}: cell {k} ({}): {message}", describe(&cell_axes))
            })?;
            cells.push(Cell {
                axes: cell_axes,
                config,
            });
        }
        Ok(cells)
    }
}

pub use crate::results::sweep::describe;

/// Sets field `path` of the config `json` to `value` (RON text), read as the config reads
/// that field: the value goes into a config of defaults at that path, whose JSON then gives
/// the field's representation.
fn set(json: &mut Value, path: &str, value: &str, origin: &str) -> Result<()> {
    let fields: Vec<&str> = path.split('.').collect();
    if fields.iter().any(|f| f.is_empty()) {
        bail!("{origin}: axis path {path:?} is not a dotted list of config fields");
    }
    if let ["env", task_fields @ ..] = fields.as_slice() {
        if !task_fields.is_empty() {
            return set_task_field(json, task_fields, path, value, origin);
        }
    }
    let mut patch = value.to_string();
    for field in fields.iter().rev() {
        patch = format!("({field}: {patch})");
    }
    let parsed: Config = parse_ron(&patch, &format!("{origin}, axis `{path}` value {value}"))
        .map_err(|e| {
            anyhow::anyhow!(
                "{e} (a path names struct fields from the top of the config; an enum such \
                 as `env` is given whole)"
            )
        })?;
    let parsed = serde_json::to_value(&parsed).context("a config as JSON")?;
    let pointer = format!("/{}", fields.join("/"));
    let (Some(new), Some(slot)) = (parsed.pointer(&pointer), json.pointer_mut(&pointer)) else {
        bail!("{origin}: axis path {path:?} names no config field");
    };
    *slot = new.clone();
    Ok(())
}

/// Sets `env.<field>` (of the base's task, whichever it is) or `env.kwargs.<name>` /
/// `env.attributes.<name>` (one keyword of a Gymnasium task) to `value`.
fn set_task_field(
    json: &mut Value,
    fields: &[&str],
    path: &str,
    value: &str,
    origin: &str,
) -> Result<()> {
    let Some((task, params)) = json
        .get_mut("env")
        .and_then(Value::as_object_mut)
        .and_then(|env| env.iter_mut().next())
    else {
        bail!("{origin}: axis path {path:?}: the base config has no task");
    };
    let located = format!("{origin}, axis `{path}` value {value}");
    match fields {
        [map @ ("kwargs" | "attributes"), name] => {
            if task != "Gymnasium" {
                bail!(
                    "{located}: `env.{map}` is a Gymnasium task's; the base's task is {task} \
                     (set its fields as `env.<field>`)"
                );
            }
            let keyword: Value = parse_ron(value, &located)?;
            let Some(map) = params.get_mut(*map).and_then(Value::as_object_mut) else {
                bail!("{located}: the base's task has no `{map}`");
            };
            map.insert(name.to_string(), keyword);
            Ok(())
        }
        [field] => {
            // The value goes into a task of defaults of the base's kind, whose JSON gives
            // the field's representation, as [`set`] does for the whole config.
            let patch = format!("(env: {task}({field}: {value}))");
            let parsed: Config = parse_ron(&patch, &located).map_err(|e| {
                anyhow::anyhow!("{e} (`env.<field>` names a field of the base's task, {task})")
            })?;
            let parsed = serde_json::to_value(&parsed).context("a config as JSON")?;
            let Some(new) = parsed.pointer(&format!("/env/{task}/{field}")) else {
                bail!("{located}: {task} has no field `{field}`");
            };
            params[*field] = new.clone();
            Ok(())
        }
        _ => bail!(
            "{origin}: axis path {path:?}: under `env`, a field of the task (`env.length`) or \
             a Gymnasium keyword (`env.kwargs.gravity`)"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(text: &str) -> Grid {
        parse_ron(text, "grid.ron").unwrap()
    }

    #[test]
    fn cells_are_the_product_of_the_axes_the_last_fastest() {
        let g = grid(
            "(base: \"x.ron\", seeds: Some(2), axes: [(path: \"sapnet.temperature\", \
             values: [0.5, 4.0]), (path: \"protocol.methods\", values: [[SapNet], [Ucb1, Dqn(hidden: [8])]])])",
        );
        let cells = g.cells(&Config::default(), "grid.ron").unwrap();
        assert_eq!(cells.len(), 8);
        assert_eq!(
            cells[0].axes,
            [
                ("sapnet.temperature".to_string(), "0.5".to_string()),
                ("protocol.methods".to_string(), "[SapNet]".to_string()),
                ("seed".to_string(), "0".to_string()),
            ]
        );
        assert_eq!(cells[1].config.seed, 1);
        assert_eq!(cells[2].config.protocol.methods.len(), 2);
        assert_eq!(cells[7].config.sapnet.temperature, 4.0);
        // Everything not on an axis is the base's.
        assert_eq!(cells[5].config.dqn, Config::default().dqn);
        assert_eq!(cells, g.cells(&Config::default(), "grid.ron").unwrap());
    }

    #[test]
    fn a_path_that_names_no_field_is_a_located_error() {
        let g = grid("(base: \"x.ron\", axes: [(path: \"sapnet.temprature\", values: [1.0])])");
        let err = format!("{:#}", g.cells(&Config::default(), "grid.ron").unwrap_err());
        assert!(err.contains("axis `sapnet.temprature`"), "{err}");
        assert!(err.contains("temprature"), "{err}");
        let g = grid("(base: \"x.ron\", axes: [(path: \"env.lenght\", values: [1.0])])");
        let err = format!("{:#}", g.cells(&Config::default(), "grid.ron").unwrap_err());
        assert!(err.contains("lenght") && err.contains("CartPole"), "{err}");
        let g = grid("(base: \"x.ron\", axes: [(path: \"env.kwargs.gravity\", values: [1.0])])");
        let err = format!("{:#}", g.cells(&Config::default(), "grid.ron").unwrap_err());
        assert!(err.contains("Gymnasium task's"), "{err}");
        let g = grid("(base: \"x.ron\", axes: [(path: \"sapnet.temperature\", values: [-1.0])])");
        let err = format!("{:#}", g.cells(&Config::default(), "grid.ron").unwrap_err());
        assert!(err.contains("cell 0 (sapnet.temperature=-1.0)"), "{err}");
    }

    #[test]
    fn an_enum_is_set_whole() {
        let g = grid(
            "(base: \"x.ron\", axes: [(path: \"env\", values: [CartPole(length: 1.0), MountainCar()])])",
        );
        let cells = g.cells(&Config::default(), "grid.ron").unwrap();
        assert_eq!(cells[0].config.env.label(), "cartpole(length=1.0)");
        assert_eq!(cells[1].config.env.label(), "mountain_car");
    }

    #[test]
    fn a_task_field_or_a_gymnasium_keyword_is_a_variant_per_value() {
        let g = grid("(base: \"x.ron\", axes: [(path: \"env.length\", values: [0.25, 1.0])])");
        let cells = g.cells(&Config::default(), "grid.ron").unwrap();
        assert_eq!(cells[0].config.env.label(), "cartpole(length=0.25)");
        assert_eq!(cells[1].config.env.label(), "cartpole(length=1.0)");

        let base = Config {
            env: parse_ron(
                "Gymnasium(id: \"LunarLander-v3\", kwargs: {\"enable_wind\": true})",
                "env",
            )
            .unwrap(),
            ..Config::default()
        };
        let g = grid(
            "(base: \"x.ron\", axes: [(path: \"env.kwargs.gravity\", values: [-6.0, -11.5]), \
             (path: \"env.max_episode_steps\", values: [Some(400)])])",
        );
        let cells = g.cells(&base, "grid.ron").unwrap();
        let labels: Vec<String> = cells.iter().map(|c| c.config.env.label()).collect();
        assert_eq!(
            labels,
            [
                "LunarLander-v3(enable_wind=true, gravity=-6.0, max_episode_steps=400)",
                "LunarLander-v3(enable_wind=true, gravity=-11.5, max_episode_steps=400)",
            ]
        );
        assert_eq!(
            cells[0].axes[0],
            ("env.kwargs.gravity".into(), "-6.0".into())
        );
    }
}
