//! RON files, as every file of sapnet is read (configs, lessons, grids, policy metadata,
//! manifests): bounded, regular files only, with errors located at the line, column and
//! field; and the one wording every field check uses (``field `dqn.gamma`: expected …,
//! got …``).

use std::fmt;
use std::path::{Path, PathBuf};

use crate::safe_io::Links;

/// A config that could not be read: where, and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    // The OS error is part of the message, not a `source`: a chain prints it once.
    #[error("reading {}: {cause}", path.display())]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error(
        "{} is larger than {} bytes: not a config, lesson or policy file (those are a few \
         kilobytes of RON text)",
        path.display(),
        MAX_TEXT_BYTES
    )]
    TooLarge { path: PathBuf },
    #[error("{} is not UTF-8 text", path.display())]
    NotText { path: PathBuf },
    #[error("{0}")]
    Parse(Box<ParseError>),
    #[error("config {}: {message}", origin)]
    Invalid { origin: String, message: String },
}

/// The largest RON file read (configs, teach lessons, policy metadata, manifests): 16 MiB,
/// room for a lesson listing every edge of a 1,000-policy graph, so that `--config
/// /dev/zero` is an error, not a machine out of memory.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// Reads the RON text at `path`, a file the user named (a link is followed), refusing
/// more than [`MAX_TEXT_BYTES`] and anything but a regular file (a FIFO would block).
pub fn read_text(path: &Path) -> Result<String, ConfigError> {
    read_text_with(path, Links::Follow)
}

/// [`read_text`] of a file inside a folder that may have come from elsewhere (a library's
/// manifest and metadata, a sweep's cells): a symbolic link there is refused.
pub fn read_folder_text(path: &Path) -> Result<String, ConfigError> {
    read_text_with(path, Links::Refuse)
}

fn read_text_with(path: &Path, links: Links) -> Result<String, ConfigError> {
    use std::io::Read;
    let io = |cause| ConfigError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let file = crate::safe_io::open(path, links, u64::MAX).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_TEXT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_TEXT_BYTES {
        return Err(ConfigError::TooLarge {
            path: path.to_path_buf(),
        });
    }
    String::from_utf8(bytes).map_err(|_| ConfigError::NotText {
        path: path.to_path_buf(),
    })
}

/// A located syntax or type error in a RON file.
#[derive(Debug)]
pub struct ParseError {
    /// What the file is, as messages name it: `config`, `policy metadata`, ….
    pub kind: &'static str,
    /// The file name, or a label for text that did not come from a file.
    pub origin: String,
    pub line: usize,
    pub column: usize,
    /// Dotted path of the field being read, e.g. `dqn.gamma` (empty at the top level).
    pub field: String,
    pub message: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} {}: line {}, column {}",
            self.kind, self.origin, self.line, self.column
        )?;
        if !self.field.is_empty() && self.field != "." {
            write!(f, ", field `{}`", self.field)?;
        }
        write!(f, ": {}", self.message)
    }
}

/// The RON options every file of this project is read with: a newtype variant's struct may
/// drop its extra parentheses (`CartPole(gravity: 9.8)` rather than `CartPole((…))`).
pub fn ron_options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES)
}

/// Reads a config, lesson or grid from RON, with located errors. `origin` names the text
/// in messages.
pub fn parse_ron<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
) -> Result<T, ConfigError> {
    parse_ron_as(text, origin, "config")
}

/// Reads any RON document, with located errors naming it as `kind` (`policy metadata`,
/// `library manifest`, …) and `origin`.
pub fn parse_ron_as<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
    kind: &'static str,
) -> Result<T, ConfigError> {
    let options = ron_options();
    let mut de = ron::Deserializer::from_str_with_options(text, &options).map_err(|e| {
        ConfigError::Parse(Box::new(ParseError {
            kind,
            origin: origin.to_string(),
            line: e.span.start.line,
            column: e.span.start.col,
            field: String::new(),
            message: e.code.to_string(),
        }))
    })?;
    let located = |de: &ron::Deserializer, field: String, code: ron::Error| {
        let spanned = de.span_error(code);
        let (line, column) = (spanned.span.start.line, spanned.span.start.col);
        let (field, message) = explained(text, line, column, field, spanned.code.to_string());
        ConfigError::Parse(Box::new(ParseError {
            kind,
            origin: origin.to_string(),
            line,
            column,
            field,
            message,
        }))
    };
    let value = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // A syntax error between fields ends the path in `?` (no field was being read):
        // name the innermost field that was, and let the line and column say the rest.
        let path = e.path().to_string();
        let field = path.trim_end_matches(['?', '.']).to_string();
        located(&de, field, e.into_inner())
    })?;
    de.end().map_err(|e| located(&de, String::new(), e))?;
    Ok(value)
}

/// RON's wording for two number mistakes, said as the field sees them: a fraction where a
/// whole number belongs reads to RON as a number followed by something other than a comma
/// (`episodes: 5.5` → "Expected comma", at the struct around it), and a negative count as
/// "Integer is out of bounds" without the bound.
fn explained(
    text: &str,
    line: usize,
    column: usize,
    field: String,
    message: String,
) -> (String, String) {
    let Some(row) = text.lines().nth(line.saturating_sub(1)) else {
        return (field, message);
    };
    let chars: Vec<char> = row.chars().collect();
    let at = column.saturating_sub(1).min(chars.len());
    // The token around the error: back to `:`, forward to `,` or `)`.
    let start = chars[..at]
        .iter()
        .rposition(|c| *c == ':' || *c == '(' || *c == ',')
        .map_or(0, |i| i + 1);
    let end = chars[at..]
        .iter()
        .position(|c| *c == ',' || *c == ')')
        .map_or(chars.len(), |i| at + i);
    let token: String = chars[start..end]
        .iter()
        .collect::<String>()
        .trim()
        .to_string();
    let name: String = chars[..start.saturating_sub(1)]
        .iter()
        .rev()
        .skip_while(|c| c.is_whitespace())
        .take_while(|c| c.is_alphanumeric() || **c == '_')
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    let is_fraction = message == "Expected comma"
        && chars.get(at) == Some(&'.')
        && token.parse::<f64>().is_ok()
        && !name.is_empty();
    if is_fraction {
        let field = if field.is_empty() {
            name
        } else {
            format!("{field}.{name}")
        };
        return (field, format!("expected a whole number, got {token}"));
    }
    if message == "Integer is out of bounds" {
        let why = if token.starts_with('-') {
            format!("expected a whole number ≥ 0, got {token}")
        } else {
            format!("{token} is too large a whole number for this field")
        };
        return (field, why);
    }
    (field, message)
}

/// `Ok` if `ok`, else the error every field check words the same way: ``field `dqn.gamma`:
/// expected a number in [0, 1], got 1.5``.
pub fn check(ok: bool, field: &str, expected: &str, got: impl Got) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(format!(
            "field `{field}`: expected {expected}, got {}",
            got.got()
        ))
    }
}

/// A bad SAP-Net parameter worded as every field of a config is (`field `sapnet.delta`:
/// expected …, got …`), `prefix` naming where the parameters sit; `None` for other errors.
pub fn sapnet_field(error: &crate::sapnet::SapNetError, prefix: &str) -> Option<String> {
    match error {
        crate::sapnet::SapNetError::BadParameter {
            name,
            value,
            expected,
        } => Some(format!(
            "field `{prefix}{name}`: expected {expected}, got {}",
            value.got()
        )),
        _ => None,
    }
}

/// A value as an error message's "got" shows it: numbers in their shortest form (`1e308`,
/// not 309 digits).
pub trait Got {
    fn got(&self) -> String;
}

impl Got for f64 {
    fn got(&self) -> String {
        format!("{self:?}")
    }
}

macro_rules! got_as_displayed {
    ($($t:ty),*) => {$(
        impl Got for $t {
            fn got(&self) -> String {
                self.to_string()
            }
        }
    )*};
}
got_as_displayed!(u32, u64, usize, i64, String, &str);
