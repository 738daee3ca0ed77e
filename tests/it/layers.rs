//! The crate's shape, kept (issue 35, item 8): no file of `src/` imports another that
//! imports it back, directly or through others, and no file imports one of a higher layer.
//!
//! What counts as an import: every path of a `use` declaration (`pub use` included) and
//! every path in code that starts at `crate`, `super`, `self` or a name a `use` of this
//! crate bound (`plots::curves::draw` after `use crate::report::plots;`). Each is resolved
//! to the file that defines what it names: a module path to `src/a/b.rs` or
//! `src/a/b/mod.rs`; an item path to the file of the module holding the item, or, when
//! that module only imports it (`pub use x::Y;`, or a plain `use` that `super::Y` reaches),
//! on to where it is defined. A module naming its own descendants (`mod x; pub use x::Y;`,
//! `x::helper()`) is the module tree, not an import. Comments, strings and the items under
//! `#[cfg(test)]` (the unit tests' `mod tests { … }`) are not read: unit tests may reach
//! anywhere. `src/main.rs` is the binary's own crate and reaches the library from outside.
//!
//! The sources are read with a small tokenizer rather than a Rust parser, which is enough
//! for paths, with known blind spots: a glob (`use x::*`) binds no names, so an item
//! reached through one is taken as the globbing module's own (only unit tests glob this
//! crate's modules);
//! a `use` inside a function binds its name for the whole module; `#[cfg(test)]` is
//! recognised written so, not inside `cfg(all(test, …))`.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::fmt::Write as _;
use std::path::Path;

/// The layers of `src/`, top to bottom: a file may import files of its own layer and of the
/// layers below it. Each entry is a module path (`sources::train` for one file of a
/// folder); a file is in the layer of the longest entry that holds it. docs/dev/layout.md's
/// table says what each module is; the order is the one its descriptions imply ("below both
/// front ends", "pure maths") and the modules' imports after issue 35's items 1 and 3
/// (which brought `ron_file`).
const LAYERS: &[(&str, &[&str])] = &[
    ("the dispatch", &["app"]),
    ("front ends", FRONT_ENDS),
    ("the command line's arguments", &["cli"]),
    ("the teaching session", &["teach"]),
    (
        "protocols: planning them, running them into results folders",
        &["experiment"],
    ),
    ("results folders", &["results"]),
    ("the comparison and its plots", &["report"]),
    ("training the source library", &["sources::train"]),
    ("the source library", &["sources"]),
    ("the run configuration", &["config"]),
    (
        "runs on their own threads",
        &["trainer", "progress", "signals"],
    ),
    ("policy reuse", &["reuse"]),
    (
        "policies on disk and from elsewhere",
        &["policy_store", "checkpoints"],
    ),
    ("the DQN", &["dqn"]),
    ("RON files", &["ron_file"]),
    ("other tools' run files", &["outside_runs", "tensorboard"]),
    (
        "the paper's maths, the tasks, the statistics",
        &["sapnet", "env", "stats"],
    ),
    (
        "files, limits and seeds",
        &[
            "safe_io",
            "folder_lock",
            "failpoint",
            "limits",
            "seeds",
            "assets",
            "shown_text",
        ],
    ),
];

/// The front ends, each its own: a front end drives the engine below it and never another
/// front end (the protocol runner moved from `headless` to `experiment`, the sweep folder's
/// format from `sweep` to `results`, for that). Teach's front end is its printed lesson;
/// the teaching session below is what both it and the terminal UI drive.
const FRONT_ENDS: &[&str] = &[
    "tui",
    "headless",
    "sweep",
    "teach::headless",
    "env_command",
    "compare",
];

#[test]
fn src_imports_only_downward_and_in_no_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let krate = Crate::read(&src);
    let findings = Findings::of(&krate, LAYERS);
    assert!(findings.is_empty(), "{findings}");
}

#[test]
fn front_ends_never_import_each_other() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let krate = Crate::read(&src);
    let found = crosswise(&krate, FRONT_ENDS);
    assert!(
        found.is_empty(),
        "front ends importing each other (FRONT_ENDS in tests/it/layers.rs):\n{}",
        found.join("\n")
    );
}

/// Each import from a file of one of `front_ends` to a file of another.
fn crosswise(krate: &Crate, front_ends: &[&str]) -> Vec<String> {
    let holder = |module: &[String]| {
        layer_of(module, &[("front ends", front_ends)]).and_then(|_| {
            front_ends
                .iter()
                .filter(|e| {
                    let e: Vec<&str> = e.split("::").collect();
                    module.len() >= e.len() && module.iter().zip(&e).all(|(m, e)| m == e)
                })
                .max_by_key(|e| e.len())
                .copied()
        })
    };
    let mut found = Vec::new();
    for (from, tos) in krate.imports() {
        let Some(own) = holder(&from) else {
            continue;
        };
        for (to, names) in tos {
            match holder(&to) {
                Some(other) if other != own => found.push(format!(
                    "{} ({own}) imports {} from {} ({other})",
                    krate.name(&from),
                    join(&names),
                    krate.name(&to)
                )),
                _ => {}
            }
        }
    }
    found
}

/// The seams issue 35 sealed, kept: policy reuse knows nothing of the DQN or of policies on
/// disk (the trainer fills its feedback), and the DQN is told to stop by the trainer, never
/// by the process's signals. The layers allow both imports; the seams do not.
#[test]
fn the_sealed_seams_stay_sealed() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let krate = Crate::read(&src);
    let forbidden: [(&str, &[&str]); 2] =
        [("reuse", &["dqn", "policy_store"]), ("dqn", &["signals"])];
    let mut found = Vec::new();
    for (from, to) in krate.imports() {
        for (below, names) in to {
            for (layer, sealed) in forbidden {
                let reaches = sealed.iter().any(|s| below.first().is_some_and(|b| b == s));
                if from.first().is_some_and(|f| f == layer) && reaches {
                    found.push(format!(
                        "{} imports {names:?} from {}",
                        krate.name(&from),
                        krate.name(&below)
                    ));
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// A module's path from the crate root: `["tui", "view"]` for `crate::tui::view`.
type ModulePath = Vec<String>;

/// The library's sources, as their imports.
struct Crate {
    /// Each file's name (`src/tui/view.rs`) by the module it defines.
    files: BTreeMap<ModulePath, String>,
    /// Modules written inline (`mod x { … }`), which have no file of their own.
    inline: BTreeSet<ModulePath>,
    /// Every path a file names, with the module it is named in.
    references: Vec<Reference>,
    /// The names `use` declarations bind in each module, and the paths they stand for.
    binds: BTreeMap<(ModulePath, String), Reference>,
}

/// A path as written (`super::graph::Graph`), in the module whose scope it is read in.
#[derive(Clone, Debug)]
struct Reference {
    file: ModulePath,
    scope: ModulePath,
    path: Vec<String>,
}

/// Where a path leads: the file defining it and the name it imports from there.
struct Target {
    file: ModulePath,
    name: String,
}

/// Imports between files: from → to → the names imported.
type Imports = BTreeMap<ModulePath, BTreeMap<ModulePath, BTreeSet<String>>>;

impl Crate {
    /// Every `.rs` file under `src`, but the binary's `main.rs`.
    fn read(src: &Path) -> Crate {
        let mut sources = Vec::new();
        collect_sources(src, src, &mut sources);
        sources.retain(|(name, _)| name != "src/main.rs");
        Crate::of(sources.iter().map(|(n, s)| (n.as_str(), s.as_str())))
    }

    /// A crate from `(file name, source)` pairs, names as `src/a/b.rs`.
    fn of<'a>(sources: impl IntoIterator<Item = (&'a str, &'a str)>) -> Crate {
        let mut krate = Crate {
            files: BTreeMap::new(),
            inline: BTreeSet::new(),
            references: Vec::new(),
            binds: BTreeMap::new(),
        };
        for (name, source) in sources {
            let module = module_of(name);
            let read = read_file(&tokens(source), &module);
            krate.files.insert(module, name.to_string());
            krate.inline.extend(read.inline);
            krate.references.extend(read.references);
            krate.binds.extend(read.binds);
        }
        krate
    }

    fn is_module(&self, module: &[String]) -> bool {
        self.files.contains_key(module) || self.inline.contains(module)
    }

    /// The file a module is written in: its own, or its nearest ancestor's for an inline one.
    fn file_of(&self, module: &[String]) -> ModulePath {
        (0..=module.len())
            .rev()
            .map(|n| &module[..n])
            .find(|m| self.files.contains_key(*m))
            .expect("the crate root has a file")
            .to_vec()
    }

    /// `reference`'s path from the crate root, or `None` for another crate's (`std::…`)
    /// and for names this crate does not bind (a local type, a generic parameter).
    fn absolute(&self, reference: &Reference) -> Option<ModulePath> {
        let (first, rest) = reference.path.split_first()?;
        if let Some(bound) = self.binds.get(&(reference.scope.clone(), first.clone())) {
            // Once: a `use` path that starts at another `use`'s name is not followed on.
            let unbound = Reference {
                path: bound.path.clone(),
                ..reference.clone()
            };
            let base = self.absolute_unbound(&unbound)?;
            return Some([base.as_slice(), rest].concat());
        }
        self.absolute_unbound(reference)
    }

    /// `reference`'s path from the crate root, if it starts at `crate`, `super`, `self` or a
    /// child module of its scope.
    fn absolute_unbound(&self, reference: &Reference) -> Option<ModulePath> {
        let (first, rest) = reference.path.split_first()?;
        let mut base = match first.as_str() {
            "crate" => Vec::new(),
            "self" => reference.scope.clone(),
            "super" => parent(&reference.scope)?,
            // A path that starts at a child module, as `pub use graph::Graph;` does.
            _ if self.is_module(&child(&reference.scope, first)) => {
                return Some([reference.scope.as_slice(), reference.path.as_slice()].concat());
            }
            _ => return None,
        };
        let mut rest = rest;
        while let Some((_, after)) = rest.split_first().filter(|(s, _)| *s == "super") {
            base = parent(&base)?;
            rest = after;
        }
        Some([base.as_slice(), rest].concat())
    }

    /// The file defining what `path` (from the crate root) names, through `use` lines.
    fn target(&self, path: &[String]) -> Target {
        // An import of an import is followed as far as it goes; the bound keeps a
        // (non-compiling) loop of `use` lines from looping here.
        self.target_within(path, 16)
    }

    fn target_within(&self, path: &[String], hops: usize) -> Target {
        let mut module = Vec::new();
        for (k, segment) in path.iter().enumerate() {
            module.push(segment.clone());
            if self.is_module(&module) {
                continue;
            }
            module.pop();
            let bound = self.binds.get(&(module.clone(), segment.clone()));
            if let Some(to) = bound.and_then(|r| self.absolute(r)).filter(|_| hops > 0) {
                return self.target_within(&[to.as_slice(), &path[k + 1..]].concat(), hops - 1);
            }
            return Target {
                file: self.file_of(&module),
                name: segment.clone(),
            };
        }
        Target {
            file: self.file_of(&module),
            name: module.last().cloned().unwrap_or_else(|| "crate".into()),
        }
    }

    /// Every import between two files: a module's descendants and itself left out.
    fn imports(&self) -> Imports {
        let mut imports = Imports::new();
        for reference in &self.references {
            let Some(path) = self.absolute(reference) else {
                continue;
            };
            let Target { file, name } = self.target(&path);
            if !file.starts_with(&reference.file) {
                imports
                    .entry(reference.file.clone())
                    .or_default()
                    .entry(file)
                    .or_default()
                    .insert(name);
            }
        }
        imports
    }

    fn name(&self, file: &[String]) -> &str {
        &self.files[file]
    }
}

fn parent(module: &[String]) -> Option<ModulePath> {
    module.split_last().map(|(_, parent)| parent.to_vec())
}

fn child(module: &[String], name: &str) -> ModulePath {
    let mut child = module.to_vec();
    child.push(name.to_string());
    child
}

/// `(name, source)` of every `.rs` file under `dir`, names relative to `src`'s parent.
fn collect_sources(src: &Path, dir: &Path, out: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            collect_sources(src, &path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(src.parent().unwrap()).unwrap();
            let source = std::fs::read_to_string(&path).unwrap();
            out.push((relative.to_string_lossy().into_owned(), source));
        }
    }
}

/// The module a file defines: `src/lib.rs` the root, `src/a/mod.rs` and `src/a.rs` `a`.
fn module_of(name: &str) -> ModulePath {
    let path = name.strip_prefix("src/").expect("a file under src/");
    let path = path.strip_suffix(".rs").expect("a .rs file");
    let mut module: ModulePath = path.split('/').map(str::to_string).collect();
    if module == ["lib"] || module.last().is_some_and(|m| m == "mod") {
        module.pop();
    }
    module
}

/// A source's tokens, as far as paths need them: comments, strings, characters and
/// lifetimes' quotes dropped.
#[derive(Clone, Debug, PartialEq)]
enum Token {
    Word(String),
    /// `::`
    PathSep,
    Punct(char),
}

fn tokens(source: &str) -> Vec<Token> {
    let chars: Vec<char> = source.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let (c, next) = (chars[i], chars.get(i + 1).copied());
        i = match c {
            _ if c.is_whitespace() => i + 1,
            '/' if next == Some('/') => line_end(&chars, i),
            '/' if next == Some('*') => block_comment_end(&chars, i),
            '"' => string_end(&chars, i + 1),
            '\'' => quote_end(&chars, i),
            ':' if next == Some(':') => {
                out.push(Token::PathSep);
                i + 2
            }
            _ if is_word_char(c) => {
                let end = (i..chars.len())
                    .find(|&j| !is_word_char(chars[j]))
                    .unwrap_or(chars.len());
                let word: String = chars[i..end].iter().collect();
                match prefixed_string_end(&word, &chars, end) {
                    Some(string_end) => string_end,
                    None => {
                        out.push(Token::Word(word));
                        end
                    }
                }
            }
            _ => {
                out.push(Token::Punct(c));
                i + 1
            }
        };
    }
    out
}

fn is_word_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

fn line_end(chars: &[char], from: usize) -> usize {
    (from..chars.len())
        .find(|&j| chars[j] == '\n')
        .unwrap_or(chars.len())
}

/// After the `*/` closing the comment opened at `from` (they nest).
fn block_comment_end(chars: &[char], from: usize) -> usize {
    let (mut depth, mut i) = (0, from);
    while i + 1 < chars.len() {
        match (chars[i], chars[i + 1]) {
            ('/', '*') => (depth, i) = (depth + 1, i + 2),
            ('*', '/') if depth == 1 => return i + 2,
            ('*', '/') => (depth, i) = (depth - 1, i + 2),
            _ => i += 1,
        }
    }
    chars.len()
}

/// After the `"` closing a string whose first character is at `from`.
fn string_end(chars: &[char], from: usize) -> usize {
    let mut i = from;
    while i < chars.len() {
        match chars[i] {
            '\\' => i += 2,
            '"' => return i + 1,
            _ => i += 1,
        }
    }
    chars.len()
}

/// After the string a `b`, `c`, `r`, `br` or `cr` prefix at `from` opens, if it opens one.
fn prefixed_string_end(prefix: &str, chars: &[char], from: usize) -> Option<usize> {
    let raw = matches!(prefix, "r" | "br" | "cr");
    if !raw {
        return (matches!(prefix, "b" | "c") && chars.get(from) == Some(&'"'))
            .then(|| string_end(chars, from + 1));
    }
    let hashes = chars[from..].iter().take_while(|&&c| c == '#').count();
    if chars.get(from + hashes) != Some(&'"') {
        return None; // a raw identifier, `r#type`
    }
    let closing: Vec<char> = std::iter::once('"')
        .chain(std::iter::repeat_n('#', hashes))
        .collect();
    let body = from + hashes + 1;
    Some(
        (body..chars.len())
            .find(|&j| chars[j..].starts_with(&closing))
            .map_or(chars.len(), |j| j + closing.len()),
    )
}

/// After a character literal at `from` (`'x'`, `'\n'`, `'\u{41}'`), or after the quote of a
/// lifetime or label (`'a`), whose name is then read as a word.
fn quote_end(chars: &[char], from: usize) -> usize {
    if chars.get(from + 1) == Some(&'\\') {
        let close = (from + 3..chars.len()).find(|&j| chars[j] == '\'');
        return close.map_or(chars.len(), |j| j + 1);
    }
    if chars.get(from + 2) == Some(&'\'') {
        return from + 3;
    }
    from + 1
}

/// What one file names: its references, inline modules and the names its `use`s bind.
#[derive(Default)]
struct FileRead {
    references: Vec<Reference>,
    inline: Vec<ModulePath>,
    binds: Vec<((ModulePath, String), Reference)>,
}

fn read_file(tokens: &[Token], file: &[String]) -> FileRead {
    let mut read = FileRead::default();
    // The module paths are read in: the file's, then any inline module's within it, each
    // with the brace depth at which it closes.
    let mut scope = file.to_vec();
    let mut closes_at: Vec<usize> = Vec::new();
    let mut depth = 0;
    let mut i = 0;
    while i < tokens.len() {
        i = match &tokens[i] {
            Token::Punct('#') if is_cfg_test(tokens, i) => skip_item(tokens, i + CFG_TEST.len()),
            Token::Word(w) if w == "mod" => match (tokens.get(i + 1), tokens.get(i + 2)) {
                (Some(Token::Word(name)), Some(Token::Punct('{'))) => {
                    scope.push(name.clone());
                    closes_at.push(depth + 1);
                    read.inline.push(scope.clone());
                    i + 2
                }
                _ => i + 1,
            },
            Token::Word(w) if w == "use" => read_use(tokens, i + 1, file, &scope, &mut read),
            Token::Word(_) if starts_path(tokens, i) => {
                let path = path_at(tokens, i);
                let end = i + 2 * path.len() - 1;
                read.references.push(Reference {
                    file: file.to_vec(),
                    scope: scope.clone(),
                    path,
                });
                end
            }
            Token::Punct('{') => {
                depth += 1;
                i + 1
            }
            Token::Punct('}') => {
                if closes_at.last() == Some(&depth) {
                    closes_at.pop();
                    scope.pop();
                }
                depth = depth.saturating_sub(1);
                i + 1
            }
            _ => i + 1,
        };
    }
    read
}

/// The paths of the `use` tree at `i`, each a reference and the name it binds in `scope`;
/// returns the index after the tree.
fn read_use(
    tokens: &[Token],
    i: usize,
    file: &[String],
    scope: &[String],
    read: &mut FileRead,
) -> usize {
    let mut paths = Vec::new();
    let end = use_tree(tokens, i, Vec::new(), &mut paths);
    for UsePath { path, binds } in paths {
        let reference = Reference {
            file: file.to_vec(),
            scope: scope.to_vec(),
            path,
        };
        if let Some(name) = binds {
            read.binds.push(((scope.to_vec(), name), reference.clone()));
        }
        read.references.push(reference);
    }
    end
}

/// `#[cfg(test)]`'s tokens.
const CFG_TEST: [&str; 7] = ["#", "[", "cfg", "(", "test", ")", "]"];

/// Whether `#[cfg(test)]` starts at `i`.
fn is_cfg_test(tokens: &[Token], i: usize) -> bool {
    tokens.len() >= i + CFG_TEST.len()
        && tokens[i..i + CFG_TEST.len()]
            .iter()
            .zip(CFG_TEST)
            .all(|(t, e)| match t {
                Token::Word(w) => w == e,
                Token::Punct(c) => e.len() == 1 && e.starts_with(*c),
                Token::PathSep => false,
            })
}

/// After the item starting at `from`: its `;`, or the `}` closing its body.
fn skip_item(tokens: &[Token], from: usize) -> usize {
    let mut nesting = 0;
    for (i, token) in tokens.iter().enumerate().skip(from) {
        match token {
            Token::Punct('(' | '[' | '{') => nesting += 1,
            Token::Punct(')' | ']') => nesting -= 1,
            Token::Punct('}') => {
                nesting -= 1;
                match nesting {
                    0 => return i + 1,
                    // The enclosing block closed: the item had no end of its own.
                    ..0 => return i,
                    _ => {}
                }
            }
            Token::Punct(';') if nesting == 0 => return i + 1,
            _ => {}
        }
    }
    tokens.len()
}

/// Whether a path of two words or more starts at `i` (`a::b`, not the `b` of `a::b`), and
/// not a macro's `$crate::` nor a `pub(in crate::…)` visibility.
fn starts_path(tokens: &[Token], i: usize) -> bool {
    let before = |k: usize| i.checked_sub(k).map(|j| &tokens[j]);
    let visibility =
        before(1) == Some(&Token::Word("in".into())) && before(2) == Some(&Token::Punct('('));
    matches!(tokens.get(i + 1), Some(Token::PathSep))
        && matches!(tokens.get(i + 2), Some(Token::Word(_)))
        && !matches!(before(1), Some(Token::PathSep | Token::Punct('$')))
        && !visibility
}

/// The words of the path starting at `i`: `a::b::c`, up to what is not a word after `::`.
fn path_at(tokens: &[Token], i: usize) -> Vec<String> {
    let mut path = Vec::new();
    let mut j = i;
    while let Some(Token::Word(w)) = tokens.get(j) {
        path.push(w.clone());
        match (tokens.get(j + 1), tokens.get(j + 2)) {
            (Some(Token::PathSep), Some(Token::Word(_))) => j += 2,
            _ => break,
        }
    }
    path
}

/// One path of a `use` tree, and the name it binds (none for a glob).
struct UsePath {
    path: Vec<String>,
    binds: Option<String>,
}

/// Reads the `use` tree at `i` under `prefix` (`a::{b, c::{self, D as E}}` gives `a::b`,
/// `a::c`, `a::c::D` bound as `E`); returns the index after it.
fn use_tree(
    tokens: &[Token],
    mut i: usize,
    mut path: Vec<String>,
    out: &mut Vec<UsePath>,
) -> usize {
    let mut alias = None;
    loop {
        match tokens.get(i) {
            Some(Token::PathSep) => i += 1, // a leading `::`: another crate's path
            Some(Token::Word(w)) => {
                path.push(w.clone());
                i += 1;
            }
            Some(Token::Punct('*')) => {
                out.push(UsePath { path, binds: None });
                return i + 1;
            }
            Some(Token::Punct('{')) => {
                i += 1;
                while !matches!(tokens.get(i), Some(Token::Punct('}')) | None) {
                    let next = use_tree(tokens, i, path.clone(), out);
                    // Past the comma; a token no tree starts with is stepped over.
                    i = if tokens.get(next) == Some(&Token::Punct(',')) || next == i {
                        next + 1
                    } else {
                        next
                    };
                }
                return i + 1;
            }
            _ => break,
        }
        match (tokens.get(i), tokens.get(i + 1)) {
            (Some(Token::PathSep), _) => i += 1,
            (Some(Token::Word(w)), Some(Token::Word(name))) if w == "as" => {
                alias = Some(name.clone());
                i += 2;
                break;
            }
            _ => break,
        }
    }
    // `{self, …}` names the group's module itself.
    if path.last().is_some_and(|s| s == "self") && path.len() > 1 {
        path.pop();
    }
    let binds = alias.or_else(|| path.last().cloned());
    out.push(UsePath { path, binds });
    i
}

/// A circle's files in import order, each with the names it imports from the next.
type Circle = Vec<(String, BTreeSet<String>)>;

/// Files that import each other, directly or through others (a strongly connected
/// component of the import graph), and circles through them that pass by every one.
struct Tangle {
    files: Vec<String>,
    circles: Vec<Circle>,
}

/// What the check found: tangles of imports, imports upward, files in no layer.
struct Findings {
    tangles: Vec<Tangle>,
    upward: Vec<String>,
    unplaced: Vec<String>,
}

impl Findings {
    fn of(krate: &Crate, layers: &[(&str, &[&str])]) -> Findings {
        let imports = krate.imports();
        let named = |files: Vec<ModulePath>| -> Circle {
            let next = files.iter().cycle().skip(1);
            let steps = files.iter().zip(next);
            steps
                .map(|(from, to)| (krate.name(from).into(), imports[from][to].clone()))
                .collect()
        };
        let tangles = tangles(&imports)
            .into_iter()
            .map(|(files, circles)| Tangle {
                files: files.iter().map(|f| krate.name(f).to_string()).collect(),
                circles: circles.into_iter().map(named).collect(),
            })
            .collect();
        let mut upward = Vec::new();
        let mut unplaced = Vec::new();
        for module in krate.files.keys().filter(|m| !m.is_empty()) {
            if layer_of(module, layers).is_none() {
                unplaced.push(krate.name(module).to_string());
            }
        }
        for (from, tos) in &imports {
            let Some(low) = layer_of(from, layers) else {
                continue;
            };
            for (to, names) in tos {
                match layer_of(to, layers) {
                    Some(high) if high < low => upward.push(format!(
                        "{} ({}) imports {} from {} ({})",
                        krate.name(from),
                        layers[low].0,
                        join(names),
                        krate.name(to),
                        layers[high].0,
                    )),
                    _ => {}
                }
            }
        }
        Findings {
            tangles,
            upward,
            unplaced,
        }
    }

    fn is_empty(&self) -> bool {
        self.tangles.is_empty() && self.upward.is_empty() && self.unplaced.is_empty()
    }

    /// The files of each circle of each tangle, in import order.
    fn circle_files(&self) -> Vec<Vec<Vec<&str>>> {
        let tangles = self.tangles.iter();
        tangles
            .map(|t| {
                t.circles
                    .iter()
                    .map(|c| c.iter().map(|(f, _)| f.as_str()).collect())
                    .collect()
            })
            .collect()
    }
}

impl std::fmt::Display for Findings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut out = String::new();
        if !self.tangles.is_empty() {
            writeln!(
                out,
                "{} import circle(s) in src/, each of files importing each other:",
                self.tangles.len()
            )?;
        }
        for tangle in &self.tangles {
            writeln!(
                out,
                "  {} files: {}",
                tangle.files.len(),
                tangle.files.join(", ")
            )?;
            for circle in &tangle.circles {
                let files: Vec<&str> = circle.iter().map(|(file, _)| file.as_str()).collect();
                writeln!(out, "    {} → {}", files.join(" → "), files[0])?;
                for (k, (file, names)) in circle.iter().enumerate() {
                    let next = &circle[(k + 1) % circle.len()].0;
                    writeln!(out, "      {file} imports {} from {next}", join(names))?;
                }
            }
        }
        if !self.upward.is_empty() {
            writeln!(
                out,
                "{} import(s) from a higher layer (LAYERS in tests/it/layers.rs):",
                self.upward.len()
            )?;
        }
        for line in &self.upward {
            writeln!(out, "  {line}")?;
        }
        if !self.unplaced.is_empty() {
            writeln!(
                out,
                "files in no layer (add their module to LAYERS in tests/it/layers.rs):"
            )?;
        }
        for file in &self.unplaced {
            writeln!(out, "  {file}")?;
        }
        f.write_str(&out)
    }
}

fn join(names: &BTreeSet<String>) -> String {
    names.iter().cloned().collect::<Vec<_>>().join(", ")
}

/// The index in `layers` of the longest entry holding `module`.
fn layer_of(module: &[String], layers: &[(&str, &[&str])]) -> Option<usize> {
    let holds = |entry: &str| {
        let entry: Vec<&str> = entry.split("::").collect();
        module.len() >= entry.len() && module.iter().zip(&entry).all(|(m, e)| m == e)
    };
    layers
        .iter()
        .enumerate()
        .flat_map(|(k, (_, entries))| {
            entries
                .iter()
                .filter(|e| holds(e))
                .map(move |e| (e.len(), k))
        })
        .max()
        .map(|(_, k)| k)
}

/// Each group of files that import each other (a strongly connected component of two
/// files or more), with shortest circles through its files until every file is on one.
fn tangles(imports: &Imports) -> Vec<(Vec<ModulePath>, Vec<Vec<ModulePath>>)> {
    let components = components(imports).into_iter().filter(|c| c.len() > 1);
    components
        .map(|component| {
            let mut circles: Vec<Vec<ModulePath>> = Vec::new();
            for file in &component {
                if !circles.iter().any(|c| c.contains(file)) {
                    circles.push(shortest_circle(imports, &component, file));
                }
            }
            (component, circles)
        })
        .collect()
}

/// The strongly connected components of the import graph (Tarjan's algorithm), each
/// sorted, in the order of their first files.
fn components(imports: &Imports) -> Vec<Vec<ModulePath>> {
    struct Tarjan<'a> {
        imports: &'a Imports,
        index: BTreeMap<&'a ModulePath, usize>,
        low: BTreeMap<&'a ModulePath, usize>,
        stack: Vec<&'a ModulePath>,
        found: Vec<Vec<ModulePath>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, file: &'a ModulePath) {
            let n = self.index.len();
            self.index.insert(file, n);
            self.low.insert(file, n);
            self.stack.push(file);
            for to in self
                .imports
                .get(file)
                .into_iter()
                .flat_map(|tos| tos.keys())
            {
                if !self.index.contains_key(to) {
                    self.visit(to);
                    self.low.insert(file, self.low[file].min(self.low[to]));
                } else if self.stack.contains(&to) {
                    self.low.insert(file, self.low[file].min(self.index[to]));
                }
            }
            if self.low[file] == self.index[file] {
                let at = self.stack.iter().rposition(|f| *f == file).unwrap();
                let mut component: Vec<ModulePath> = self.stack.drain(at..).cloned().collect();
                component.sort();
                self.found.push(component);
            }
        }
    }
    let mut tarjan = Tarjan {
        imports,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        found: Vec::new(),
    };
    for file in imports.keys() {
        if !tarjan.index.contains_key(file) {
            tarjan.visit(file);
        }
    }
    tarjan.found.sort();
    tarjan.found
}

/// A shortest path of imports from `start` back to it within its component (breadth first).
fn shortest_circle(
    imports: &Imports,
    component: &[ModulePath],
    start: &ModulePath,
) -> Vec<ModulePath> {
    let mut came_from: BTreeMap<&ModulePath, &ModulePath> = BTreeMap::new();
    let mut queue = VecDeque::from([start]);
    while let Some(file) = queue.pop_front() {
        for to in imports[file].keys().filter(|to| component.contains(to)) {
            if to == start {
                let mut circle = vec![file.clone()];
                while let Some(&before) = came_from.get(circle.last().unwrap()) {
                    circle.push(before.clone());
                }
                circle.reverse();
                return circle;
            }
            if !came_from.contains_key(to) {
                came_from.insert(to, file);
                queue.push_back(to);
            }
        }
    }
    unreachable!("a strongly connected component holds a circle through each file")
}

/// The resolver on tiny crates.
mod tests {
    use super::*;

    fn findings(sources: &[(&str, &str)], layers: &[(&str, &[&str])]) -> Findings {
        Findings::of(&Crate::of(sources.iter().copied()), layers)
    }

    /// Every file in one layer: only circles can be found.
    const FLAT: &[(&str, &[&str])] = &[("all", &["a", "b", "c", "m"])];

    #[test]
    fn two_files_importing_each_other_are_a_circle() {
        let found = findings(
            &[
                ("src/lib.rs", "pub mod a; pub mod b;"),
                ("src/a.rs", "use crate::b::B; pub struct A;"),
                (
                    "src/b.rs",
                    "pub struct B; fn f() -> crate::a::A { todo!() }",
                ),
            ],
            FLAT,
        );
        assert_eq!(found.circle_files(), [[["src/a.rs", "src/b.rs"]]]);
        assert_eq!(
            found.to_string(),
            "1 import circle(s) in src/, each of files importing each other:\n  \
             2 files: src/a.rs, src/b.rs\n    src/a.rs → src/b.rs → src/a.rs\n      \
             src/a.rs imports B from src/b.rs\n      src/b.rs imports A from src/a.rs\n"
        );
    }

    #[test]
    fn three_files_in_a_ring_are_one_circle_in_import_order() {
        let found = findings(
            &[
                ("src/lib.rs", "mod a; mod b; mod c;"),
                ("src/a.rs", "use crate::c::{self, C};"),
                ("src/b.rs", "use super::a::A;"),
                ("src/c.rs", "pub use crate::b::B as Bee;"),
            ],
            FLAT,
        );
        assert_eq!(
            found.circle_files(),
            [[["src/a.rs", "src/c.rs", "src/b.rs"]]]
        );
        let circle = &found.tangles[0].circles[0];
        let names: Vec<String> = circle.iter().map(|(_, n)| join(n)).collect();
        assert_eq!(names, ["C, c", "B", "A"]);
    }

    #[test]
    fn every_file_of_a_tangle_is_shown_on_a_circle() {
        // `a` imports `b` and `c`, each of which imports it back: one tangle, two circles.
        let found = findings(
            &[
                ("src/lib.rs", "mod a; mod b; mod c;"),
                ("src/a.rs", "use crate::{b::B, c::C};"),
                ("src/b.rs", "pub struct B; use crate::a;"),
                ("src/c.rs", "pub struct C; fn f() { crate::a::g(); }"),
            ],
            FLAT,
        );
        assert_eq!(found.tangles[0].files, ["src/a.rs", "src/b.rs", "src/c.rs"]);
        assert_eq!(
            found.circle_files(),
            [[["src/a.rs", "src/b.rs"], ["src/c.rs", "src/a.rs"]]]
        );
    }

    #[test]
    fn a_module_naming_its_own_files_is_the_tree_not_an_import() {
        let found = findings(
            &[
                ("src/lib.rs", "pub mod m;"),
                (
                    "src/m/mod.rs",
                    "mod x; mod y; pub use x::X; pub use self::y::Y; \
                     pub trait Seam {} fn f() { y::helper(); }",
                ),
                ("src/m/x.rs", "use super::{Seam, Y}; pub struct X;"),
                (
                    "src/m/y.rs",
                    "pub struct Y; impl super::Seam for Y {} pub fn helper() {}",
                ),
            ],
            FLAT,
        );
        assert!(found.is_empty(), "{found}");
    }

    #[test]
    fn an_item_is_imported_from_the_file_its_re_exports_lead_to() {
        let krate = Crate::of([
            ("src/lib.rs", "pub mod m; pub mod a;"),
            ("src/m/mod.rs", "mod x; pub use x::X;"),
            ("src/m/x.rs", "pub use self::deep::Z as X; pub mod deep;"),
            ("src/m/x/deep.rs", "pub struct Z;"),
            (
                "src/a.rs",
                "use crate::m::X; fn f() { crate::m::x::deep::Z; }",
            ),
        ]);
        let from_a = &krate.imports()[&vec!["a".to_string()]];
        let deep: ModulePath = ["m", "x", "deep"].map(String::from).to_vec();
        assert_eq!(from_a.keys().collect::<Vec<_>>(), [&deep]);
        assert_eq!(join(&from_a[&deep]), "Z");
    }

    #[test]
    fn a_lower_layer_importing_a_higher_one_is_said() {
        // `b::c` is lifted into the front layer: it may import `a`; the rest of `b` may not.
        let layers: &[(&str, &[&str])] = &[("front", &["a", "b::c"]), ("core", &["b"])];
        let found = findings(
            &[
                ("src/lib.rs", "mod a; mod b;"),
                ("src/a.rs", "pub fn run() {}"),
                ("src/b/mod.rs", "mod c; fn f() { crate::a::run(); }"),
                ("src/b/c.rs", "use crate::a;"),
            ],
            layers,
        );
        assert!(found.tangles.is_empty());
        assert_eq!(
            found.upward,
            ["src/b/mod.rs (core) imports run from src/a.rs (front)"]
        );
    }

    /// Two front ends side by side in one layer: the layers allow the import, the rule
    /// that front ends never import each other does not; a front end's own files and a
    /// file below it are fine.
    #[test]
    fn a_front_end_importing_another_is_said() {
        let krate = Crate::of([
            ("src/lib.rs", "mod ui; mod cli; mod t; mod engine;"),
            (
                "src/ui/mod.rs",
                "mod view; use crate::cli::print; use crate::engine::run;",
            ),
            ("src/ui/view.rs", "pub fn item() {}"),
            ("src/cli.rs", "pub fn print() {}"),
            ("src/t/mod.rs", "mod front; pub fn session() {}"),
            (
                "src/t/front.rs",
                "use crate::t::session; use crate::ui::view::item;",
            ),
            ("src/engine.rs", "pub fn run() {}"),
        ]);
        let found = crosswise(&krate, &["ui", "cli", "t::front"]);
        assert_eq!(
            found,
            [
                "src/t/front.rs (t::front) imports item from src/ui/view.rs (ui)",
                "src/ui/mod.rs (ui) imports print from src/cli.rs (cli)",
            ]
        );
    }

    #[test]
    fn a_path_through_an_imported_module_is_an_import_of_its_file() {
        let krate = Crate::of([
            ("src/lib.rs", "mod a; mod b;"),
            ("src/a/mod.rs", "pub mod inner;"),
            ("src/a/inner.rs", "pub fn f() {}"),
            (
                "src/b.rs",
                "use crate::a; fn g() { a::inner::f(); Vec::<u8>::new(); }",
            ),
        ]);
        let from_b = &krate.imports()[&vec!["b".to_string()]];
        let files: Vec<String> = from_b.keys().map(|m| krate.name(m).to_string()).collect();
        assert_eq!(files, ["src/a/mod.rs", "src/a/inner.rs"]);
    }

    #[test]
    fn a_file_in_no_layer_is_said() {
        let found = findings(
            &[
                ("src/lib.rs", "mod a; mod z;"),
                ("src/a.rs", ""),
                ("src/z.rs", ""),
            ],
            FLAT,
        );
        assert_eq!(found.unplaced, ["src/z.rs"]);
    }

    #[test]
    fn comments_strings_tests_and_other_crates_are_not_imports() {
        let found = findings(
            &[
                ("src/lib.rs", "mod a; mod b;"),
                ("src/a.rs", "pub struct A;"),
                (
                    "src/b.rs",
                    r####"
                    // use crate::a::A;
                    /* crate::a::A /* nested */ crate::a::A */
                    const S: &str = "crate::a::A \" crate::a::A";
                    const R: &str = r#"crate::a::A"#;
                    const C: char = '"'; const Q: char = '\'';
                    fn f<'a>(x: &'a str) -> &'a str { x }
                    use std::crate_like::A;
                    macro_rules! m { () => { $crate::a::A } }
                    #[cfg(test)]
                    mod tests { use crate::a::A; }
                    #[cfg(test)]
                    use crate::a::A;
                    "####,
                ),
            ],
            FLAT,
        );
        assert!(found.is_empty(), "{found}");
    }

    #[test]
    fn super_in_an_inline_module_is_its_file() {
        let krate = Crate::of([
            ("src/lib.rs", "mod a; mod b;"),
            ("src/a.rs", "pub struct A;"),
            (
                "src/b.rs",
                "mod inner { use super::super::a::A; fn f() { super::g(); } } fn g() {}",
            ),
        ]);
        let imports = krate.imports();
        let b = &imports[&vec!["b".to_string()]];
        assert_eq!(b.keys().collect::<Vec<_>>(), [&vec!["a".to_string()]]);
    }
}
