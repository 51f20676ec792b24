//! The docs cannot drift from the code: every reference they make to the tree exists.
//!
//! Read: `README.md`, `paper_notes.md`, `docs/*.md` (their whole text), and the comments (`//`
//! to the end of the line) of `glsl/*` and of every Rust file (`src/`, `tests/`, `benches/`,
//! `examples/`, `fuzz/`, `tools/`).
//!
//! The rule, kept simple and strict (a reference either holds or is reported with its file and
//! line):
//! - **Paths.** A word starting with `src/`, `tests/`, `glsl/`, `docs/`, `tools/`, `scenes/`,
//!   `benches/`, `examples/` or `fuzz/`, backticked or not, names a file or folder that exists.
//!   `*` in a name matches any run of characters; a name whose stem is in capitals (`NAME.obj`,
//!   `ROOM`) is a placeholder for any name (with the same extension); a `#anchor` is not part of
//!   the path. In a file under `tools/NAME/` a path may also be relative to `tools/NAME/`.
//! - **Links.** A Markdown link target that is not a URL exists, relative to the Markdown file.
//! - **File names.** A word ending in `.rs`, `.frag`, `.vert`, `.glsl` or `.md` without a folder,
//!   backticked in Markdown or anywhere in a comment of code, is the name of some file of the tree.
//! - **Items.** Every *A*::*b* (and each neighbouring pair of *a*::*b*::*c*), backticked in
//!   Markdown or anywhere in a comment of code, holds when some file that defines *A* declares
//!   *b*. A file defines *A* when *A* is a type (it starts with a capital) and the file has
//!   `struct`, `enum`, `trait`, `type` or `union` *A*, or an `impl` of *A* (also, for `type` *A* =
//!   *B*, the files that define *B*); when *A* is a module, the file is *A*.rs or *A*/mod.rs, or
//!   holds an inline `mod` *A* `{`; `crate` and `gpu_radiosity` are `src/lib.rs`. A file declares
//!   *b* when it has `fn`, `const`, `static`, `struct`, `enum`, `trait`, `type`, `union`, `mod` or
//!   `macro_rules!` *b*; a line that starts with *b* then `:` (a field), or with a capitalised *b*
//!   then `,`, `(`, `{`, `=` or its end (a variant); *b* in a `pub use`, or *b* declared by a
//!   module it re-exports with `pub use m::*`. Pairs whose *A* is `self`, `super` or `Self` are
//!   skipped (they need the context), and so are names outside this crate: the [`EXTERNAL`] list.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// First segments of *A*::*b* names that are not this crate's: other crates, and the standard
/// library's types and primitives. Kept short: a name of this crate never belongs here.
const EXTERNAL: &str = "std core alloc glam glow egui winit glutin image serde clap rayon anyhow \
    thiserror Box Vec String Option Result str f32 f64 u32 i32 i64 usize";

/// The folders a path may start with.
const ROOTS: &[&str] = &[
    "src/",
    "tests/",
    "glsl/",
    "docs/",
    "tools/",
    "scenes/",
    "benches/",
    "examples/",
    "fuzz/",
];

/// What the tree holds: its files and folders, and what each Rust file declares.
struct Tree {
    /// Every file and folder, relative to the root, with `/` between names.
    entries: BTreeSet<String>,
    /// The names in each folder ("" for the root).
    children: BTreeMap<String, BTreeSet<String>>,
    /// Every file's name, without its folder.
    names: BTreeSet<String>,
    /// The Rust files, by path.
    rust: BTreeMap<String, RustFile>,
}

/// What one Rust file declares, as far as the rule above looks.
#[derive(Default)]
struct RustFile {
    /// Names after `fn`, `const`, `static`, `struct`, ... and at the start of a line.
    declared: BTreeSet<String>,
    /// Types it defines (`struct`, `enum`, `trait`, `type`, `union`) or implements.
    types: BTreeSet<String>,
    /// Modules it holds inline (`mod a {`).
    inline_modules: BTreeSet<String>,
    /// Names in its `pub use` lines.
    reexported: BTreeSet<String>,
    /// Modules it re-exports whole (`pub use m::*`).
    glob_reexports: BTreeSet<String>,
    /// `type A = B<…>`: A → B.
    aliases: BTreeMap<String, String>,
}

/// Folders never read: build output and git's.
fn skipped(rel: &str) -> bool {
    rel == "target" || rel.ends_with("/target") || rel.starts_with('.') || rel.contains("/.")
}

impl Tree {
    fn read(root: &Path) -> Tree {
        let mut tree = Tree {
            entries: BTreeSet::new(),
            children: BTreeMap::new(),
            names: BTreeSet::new(),
            rust: BTreeMap::new(),
        };
        let mut stack = vec![String::new()];
        while let Some(dir) = stack.pop() {
            let full = root.join(&dir);
            for entry in std::fs::read_dir(&full).unwrap() {
                let entry = entry.unwrap();
                let name = entry.file_name().to_string_lossy().into_owned();
                let rel = if dir.is_empty() {
                    name.clone()
                } else {
                    format!("{dir}/{name}")
                };
                if skipped(&rel) {
                    continue;
                }
                tree.children
                    .entry(dir.clone())
                    .or_default()
                    .insert(name.clone());
                tree.entries.insert(rel.clone());
                if entry.file_type().unwrap().is_dir() {
                    stack.push(rel);
                } else {
                    if rel.ends_with(".rs") {
                        let text = std::fs::read_to_string(root.join(&rel)).unwrap();
                        tree.rust.insert(rel.clone(), RustFile::parse(&text));
                    }
                    tree.names.insert(name);
                }
            }
        }
        tree
    }

    /// Whether `path` (relative to the root; `*` and capital placeholders allowed) exists.
    fn has_path(&self, path: &str) -> bool {
        let path = path.trim_end_matches('/');
        let mut current = vec![String::new()];
        for segment in path.split('/') {
            let mut next = Vec::new();
            for dir in &current {
                for name in self.children.get(dir).into_iter().flatten() {
                    if name_matches(segment, name) {
                        next.push(if dir.is_empty() {
                            name.clone()
                        } else {
                            format!("{dir}/{name}")
                        });
                    }
                }
            }
            if next.is_empty() {
                return false;
            }
            current = next;
        }
        true
    }

    /// The Rust files that define `a` (see the rule at the top).
    fn defining(&self, a: &str, depth: u32) -> Vec<&str> {
        let mut files = Vec::new();
        for (path, file) in &self.rust {
            let defines = if a == "crate" || a == "gpu_radiosity" {
                path == "src/lib.rs"
            } else if a.starts_with(|c: char| c.is_ascii_uppercase()) {
                file.types.contains(a)
            } else {
                module_name(path) == Some(a) || file.inline_modules.contains(a)
            };
            if defines {
                files.push(path.as_str());
            }
            if let (Some(target), true) = (file.aliases.get(a), depth < 2) {
                files.extend(self.defining(target, depth + 1));
            }
        }
        files
    }

    /// Whether the file at `path` declares `b` (see the rule at the top).
    fn declares(&self, path: &str, b: &str, depth: u32) -> bool {
        let file = &self.rust[path];
        if file.declared.contains(b) || file.reexported.contains(b) {
            return true;
        }
        // A module's own folder: `a/b.rs`, `a/b/mod.rs`.
        let folder = path
            .strip_suffix("/mod.rs")
            .or_else(|| path.strip_suffix("/lib.rs"))
            .map(str::to_string)
            .or_else(|| path.strip_suffix(".rs").map(str::to_string))
            .unwrap_or_default();
        if self.entries.contains(&format!("{folder}/{b}.rs"))
            || self.entries.contains(&format!("{folder}/{b}/mod.rs"))
        {
            return true;
        }
        depth < 3
            && file.glob_reexports.iter().any(|m| {
                self.defining(m, 0)
                    .iter()
                    .any(|f| self.declares(f, b, depth + 1))
            })
    }

    /// Whether *a*::*b* holds.
    fn has_item(&self, a: &str, b: &str) -> bool {
        self.defining(a, 0).iter().any(|f| self.declares(f, b, 0))
    }
}

/// The module a Rust file is, by its path: *a*.rs and *a*/mod.rs are *a*.
fn module_name(path: &str) -> Option<&str> {
    let path = path.strip_suffix(".rs")?;
    let path = path.strip_suffix("/mod").unwrap_or(path);
    path.rsplit('/').next()
}

/// Whether `name` matches one segment of a referenced path.
fn name_matches(segment: &str, name: &str) -> bool {
    if segment == name {
        return true;
    }
    // A placeholder: the stem in capitals, with the same extension (if any).
    let (stem, ext) = match segment.split_once('.') {
        Some((s, e)) => (s, Some(e)),
        None => (segment, None),
    };
    if stem.len() >= 2 && stem.chars().all(|c| c.is_ascii_uppercase() || c == '_') {
        return match ext {
            Some(e) => name.ends_with(&format!(".{e}")),
            None => true,
        };
    }
    segment.contains('*') && glob(segment.as_bytes(), name.as_bytes())
}

/// `*` matches any run of characters.
fn glob(pattern: &[u8], name: &[u8]) -> bool {
    match pattern.split_first() {
        None => name.is_empty(),
        Some((b'*', rest)) => (0..=name.len()).any(|i| glob(rest, &name[i..])),
        Some((c, rest)) => name.first() == Some(c) && glob(rest, &name[1..]),
    }
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The identifier at the start of `s`, if any.
fn ident(s: &str) -> Option<&str> {
    let end = s.find(|c: char| !is_ident_char(c)).unwrap_or(s.len());
    (end > 0 && !s.starts_with(|c: char| c.is_ascii_digit())).then(|| &s[..end])
}

impl RustFile {
    fn parse(text: &str) -> RustFile {
        let mut file = RustFile::default();
        let code: String = text
            .lines()
            .map(|l| &l[..comment_start(l).unwrap_or(l.len())])
            .collect::<Vec<_>>()
            .join("\n");
        let words: Vec<&str> = code
            .split(|c: char| !is_ident_char(c) && c != '!')
            .filter(|w| !w.is_empty())
            .collect();
        for pair in words.windows(2) {
            let (keyword, name) = (pair[0], pair[1]);
            match keyword {
                "fn" | "const" | "static" | "mod" | "macro_rules!" => {
                    file.declared.insert(name.to_string());
                }
                "struct" | "enum" | "trait" | "type" | "union" => {
                    file.declared.insert(name.to_string());
                    file.types.insert(name.to_string());
                }
                _ => {}
            }
        }
        for (i, _) in code.match_indices("impl") {
            let before = code[..i].chars().next_back();
            if before.is_some_and(is_ident_char) {
                continue;
            }
            if let Some(ty) = impl_target(&code[i + 4..]) {
                file.types.insert(ty.to_string());
            }
        }
        for (i, _) in code.match_indices("mod ") {
            if let Some(name) = ident(&code[i + 4..]) {
                if code[i + 4 + name.len()..].trim_start().starts_with('{') {
                    file.inline_modules.insert(name.to_string());
                }
            }
        }
        for (i, _) in code.match_indices("type ") {
            let rest = &code[i + 5..];
            if let (Some(name), Some(eq)) = (ident(rest), rest.find('=')) {
                let target = rest[eq + 1..].trim_start();
                let target = target.split('<').next().unwrap_or("");
                let last = target.rsplit("::").next().unwrap_or("").trim();
                if let Some(t) = ident(last) {
                    file.aliases.insert(name.to_string(), t.to_string());
                }
            }
        }
        for (i, _) in code.match_indices("pub use ") {
            let list = &code[i + 8..];
            let list = &list[..list.find(';').unwrap_or(list.len())];
            for w in list
                .split(|c: char| !is_ident_char(c))
                .filter(|w| !w.is_empty())
            {
                file.reexported.insert(w.to_string());
            }
            for (j, _) in list.match_indices("::*") {
                if let Some(m) = list[..j].rsplit("::").next().and_then(|s| {
                    let s = s.trim_start_matches(|c: char| !is_ident_char(c));
                    ident(s)
                }) {
                    file.glob_reexports.insert(m.to_string());
                }
            }
        }
        for line in code.lines() {
            let mut rest = line.trim_start();
            for prefix in ["pub(crate) ", "pub(super) ", "pub "] {
                rest = rest.strip_prefix(prefix).unwrap_or(rest);
            }
            if let Some(name) = ident(rest) {
                let after = rest[name.len()..].trim_start();
                let field = after.starts_with(':') && !after.starts_with("::");
                let variant = name.starts_with(|c: char| c.is_ascii_uppercase())
                    && (after.is_empty() || after.starts_with([',', '(', '{', '=']));
                if field || variant {
                    file.declared.insert(name.to_string());
                }
            }
        }
        file
    }
}

/// The type an `impl` names (after `impl<…>`, and after `for` if it implements a trait).
fn impl_target(rest: &str) -> Option<&str> {
    let mut rest = rest.trim_start();
    if rest.starts_with('<') {
        rest = skip_generics(rest)?.trim_start();
    }
    let (path, after) = type_path(rest)?;
    let after = after.trim_start();
    match after.strip_prefix("for ") {
        Some(t) => type_path(t.trim_start()).map(|(p, _)| p),
        None => Some(path),
    }
}

/// The last name of the type path at the start of `s` and what follows it (generics skipped).
fn type_path(s: &str) -> Option<(&str, &str)> {
    let mut s = s.trim_start_matches('&');
    let mut last;
    loop {
        last = ident(s)?;
        s = &s[last.len()..];
        if s.starts_with('<') {
            s = skip_generics(s)?;
        }
        match s.strip_prefix("::") {
            Some(r) => s = r,
            None => return Some((last, s)),
        }
    }
}

/// `s` after the generic arguments it starts with.
fn skip_generics(s: &str) -> Option<&str> {
    let mut depth = 0;
    for (i, c) in s.char_indices() {
        match c {
            '<' => depth += 1,
            '>' => {
                depth -= 1;
                if depth == 0 {
                    return Some(&s[i + 1..]);
                }
            }
            _ => {}
        }
    }
    None
}

/// Where a `//` comment starts in a line of Rust or GLSL, outside string literals and URLs.
fn comment_start(line: &str) -> Option<usize> {
    let mut in_string = false;
    let bytes = line.as_bytes();
    let mut i = 0;
    while i + 1 < bytes.len() {
        match bytes[i] {
            b'\\' if in_string => i += 1,
            b'"' => in_string = !in_string,
            b'/' if !in_string && bytes[i + 1] == b'/' => return Some(i),
            _ => {}
        }
        i += 1;
    }
    None
}

/// The backticked spans of a line.
fn backticked(line: &str) -> impl Iterator<Item = &str> {
    line.split('`').skip(1).step_by(2)
}

/// The stale references in `text`, the contents of `file` (a path relative to the root), each
/// as `file:line: what`.
fn stale_references(tree: &Tree, file: &str, text: &str) -> Vec<String> {
    let markdown = file.ends_with(".md");
    let tool_root = file
        .strip_prefix("tools/")
        .and_then(|r| r.split_once('/'))
        .map(|(t, _)| format!("tools/{t}/"));
    let mut stale = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = if markdown {
            line
        } else {
            match comment_start(line) {
                Some(i) => &line[i..],
                None => continue,
            }
        };
        let mut report = |what: String| stale.push(format!("{file}:{}: {what}", n + 1));
        // Paths: words made of path characters that start with one of the roots.
        for word in line.split(|c: char| !(is_ident_char(c) || "./*-".contains(c))) {
            if !ROOTS.iter().any(|r| word.starts_with(r)) {
                continue;
            }
            let path = word.trim_end_matches(['.', ',', ':', ';']);
            let relative = tool_root
                .as_ref()
                .is_some_and(|t| tree.has_path(&format!("{t}{path}")));
            if !tree.has_path(path) && !relative {
                report(format!("no such path `{path}`"));
            }
        }
        if markdown {
            for (i, _) in line.match_indices("](") {
                let target = &line[i + 2..];
                let target = &target[..target.find([')', ' ']).unwrap_or(target.len())];
                let target = target.split('#').next().unwrap_or("");
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let base = Path::new(file).parent().unwrap_or(Path::new(""));
                let joined = normalize(&base.join(target).to_string_lossy());
                if !joined.as_deref().is_some_and(|p| tree.has_path(p)) {
                    report(format!("link to a missing file `{target}`"));
                }
            }
        }
        // In comments of code every word counts; in Markdown, what is backticked.
        let spans: Vec<&str> = if markdown {
            backticked(line).collect()
        } else {
            vec![line]
        };
        for span in spans {
            for word in span.split(|c: char| !(is_ident_char(c) || c == '.' || c == '-')) {
                let bare_file = [".rs", ".frag", ".vert", ".glsl", ".md"]
                    .iter()
                    .any(|e| word.ends_with(e) && word.len() > e.len());
                let known = || tree.names.iter().any(|n| name_matches(word, n));
                if bare_file && !span.contains(&format!("/{word}")) && !known() {
                    report(format!("no file named `{word}`"));
                }
            }
            for name in span.split(|c: char| !(is_ident_char(c) || c == ':')) {
                let segments: Vec<&str> = name.split("::").collect();
                if segments.len() < 2 || segments.iter().any(|s| ident(s) != Some(*s)) {
                    continue;
                }
                if EXTERNAL.split_whitespace().any(|e| e == segments[0]) {
                    continue;
                }
                for pair in segments.windows(2) {
                    let (a, b) = (pair[0], pair[1]);
                    if ["self", "super", "Self"].contains(&a) {
                        continue;
                    }
                    if !tree.has_item(a, b) {
                        report(format!("`{name}`: no `{b}` where `{a}` is defined"));
                        break;
                    }
                }
            }
        }
    }
    stale
}

/// `a/./b/../c` as `a/c`; `None` when it climbs out of the root.
fn normalize(path: &str) -> Option<String> {
    let mut parts: Vec<&str> = Vec::new();
    for p in path.split('/') {
        match p {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            p => parts.push(p),
        }
    }
    Some(parts.join("/"))
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The files the rule reads, relative to the root.
fn checked_files(tree: &Tree) -> Vec<String> {
    tree.entries
        .iter()
        .filter(|p| {
            let doc = *p == "README.md"
                || *p == "paper_notes.md"
                || (p.starts_with("docs/") && p.ends_with(".md") && !p[5..].contains('/'));
            let shader = p.starts_with("glsl/") && !p[5..].contains('/');
            doc || shader || p.ends_with(".rs")
        })
        .cloned()
        .collect()
}

#[test]
fn every_reference_in_the_docs_and_comments_exists() {
    let tree = Tree::read(root());
    let files = checked_files(&tree);
    // The rule reads what it should: the docs, every shader, the Rust sources.
    for must in [
        "README.md",
        "docs/testing.md",
        "glsl/reconstruct.frag",
        "src/lib.rs",
    ] {
        assert!(files.iter().any(|f| f == must), "{must} is not read");
    }
    let mut stale = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(root().join(file)).unwrap();
        stale.extend(stale_references(&tree, file, &text));
    }
    assert!(
        stale.is_empty(),
        "{} stale references (the rule: tests/docs_drift.rs):\n{}",
        stale.len(),
        stale.join("\n")
    );
}

#[test]
fn the_checker_reports_planted_stale_references() {
    let tree = Tree::read(root());
    let planted = "See `src/solver/nope.rs` and `Ledger::no_such_fn`, [usage](nope.md),\n\
                   `gone.frag` and `solver::visibility::no_such_item`; tests/nothing_here.rs.\n";
    let stale = stale_references(&tree, "docs/planted.md", planted);
    for what in [
        "docs/planted.md:1: no such path `src/solver/nope.rs`",
        "docs/planted.md:1: `Ledger::no_such_fn`: no `no_such_fn` where `Ledger` is defined",
        "docs/planted.md:1: link to a missing file `nope.md`",
        "docs/planted.md:2: no file named `gone.frag`",
        "docs/planted.md:2: `solver::visibility::no_such_item`: no `no_such_item` where \
         `visibility` is defined",
        "docs/planted.md:2: no such path `tests/nothing_here.rs`",
    ] {
        assert!(
            stale.iter().any(|s| s == what),
            "not reported: {what}\n{stale:#?}"
        );
    }
    assert_eq!(stale.len(), 6, "{stale:#?}");
    // In a shader or Rust file only comments count.
    let shader = "uniform float x; // from `Ledger::no_such_fn`\nvoid main() {}\n";
    assert_eq!(stale_references(&tree, "glsl/x.frag", shader).len(), 1);
    let code = "let s = \"src/nope.rs\"; // fine\n";
    assert!(stale_references(&tree, "src/x.rs", code).is_empty());
    // In a comment of code, backticks or not.
    let code = "//! load the scene -- Backend::new, nope.rs\n";
    assert_eq!(stale_references(&tree, "src/x.rs", code).len(), 2);
}

#[test]
fn the_checker_accepts_what_exists() {
    let tree = Tree::read(root());
    let good = "`src/solver/find_max_energy.rs`, `src/solver/`, `glsl/*.frag`, `scenes/NAME/NAME.obj`,\n\
                [usage](usage.md#solve), [readme](../README.md), `reconstruct.frag`, `mod.rs`,\n\
                `Ledger::new`, `Ledger::max_energy_polygons`, `solver::visibility::VisibilityPass`,\n\
                `crate::solver::Tuning`, `SolveOptions::whole_polygons` (glob re-export),\n\
                `solver::item_buffer_side`, `GpuSolver::load_atlases` (an alias of `Solver`),\n\
                `Tuning::marking_below` (a field), `VisibilityKind::Hemicube` (a variant),\n\
                `glam::Vec3::ZERO`, `std::thread::scope`, `Self::nothing`, docs/testing.md#ci.\n";
    let stale = stale_references(&tree, "docs/good.md", good);
    assert!(stale.is_empty(), "{stale:#?}");
    // A call at the start of a line is not a declaration; a trait has no `new` of its own.
    let bad = "`Backend::new`, `Ledger::count_passes_made_up`\n";
    assert_eq!(stale_references(&tree, "docs/bad.md", bad).len(), 2);
}
