//! The library's import map: no two modules import each other, and no library module imports
//! the command line (`crate::cli`), which sits on top of the library.
//!
//! The rule, kept simple: a module is a file of `src/` (`a/mod.rs` is `a`); it imports module
//! *m* when its code (comments left out) names `crate::` or `super::` followed by *m* (also
//! inside `use super::{…}` and `use crate::{…}` lists), resolved to the longest module path
//! that exists. A module's own ancestors and descendants do not count (a parent declares its
//! children; a child may use what its parent re-exports).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Every module of `src/` (but the crate roots) and the modules it imports.
fn import_map(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut texts = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path
                    .strip_prefix(src)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                let module = rel.trim_end_matches(".rs").trim_end_matches("/mod");
                if module != "lib" && module != "main" {
                    let text = std::fs::read_to_string(&path).unwrap();
                    texts.insert(module.replace('/', "::"), text);
                }
            }
        }
    }
    let modules: BTreeSet<String> = texts.keys().cloned().collect();
    texts
        .iter()
        .map(|(module, text)| {
            let parent: Vec<&str> = module.split("::").collect();
            let parent = parent[..parent.len() - 1].join("::");
            let imports = named_paths(text)
                .into_iter()
                .filter_map(|(base, path)| {
                    let full = match (base, parent.is_empty()) {
                        ("crate", _) | ("super", true) => path,
                        _ => format!("{parent}::{path}"),
                    };
                    longest_module(&modules, &full)
                })
                .filter(|m| {
                    m != module
                        && !m.starts_with(&format!("{module}::"))
                        && !module.starts_with(&format!("{m}::"))
                })
                .collect();
            (module.clone(), imports)
        })
        .collect()
}

/// The `crate::…` and `super::…` paths `text` names outside comments, as (base, rest).
fn named_paths(text: &str) -> Vec<(&'static str, String)> {
    let code: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let mut paths = Vec::new();
    for base in ["crate", "super"] {
        let prefix = format!("{base}::");
        for (i, _) in code.match_indices(&prefix) {
            if code[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let rest = &code[i + prefix.len()..];
            if let Some(list) = rest.strip_prefix('{') {
                // A `use super::{…}` list: each of its paths.
                let list = &list[..list.find('}').unwrap_or(list.len())];
                for item in list.split(',') {
                    let item = item.trim();
                    if !item.is_empty() && item != "self" {
                        paths.push((base, path_at(item)));
                    }
                }
            } else {
                paths.push((base, path_at(rest)));
            }
        }
    }
    paths
}

/// The path (names joined by `::`) at the start of `s`.
fn path_at(s: &str) -> String {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .unwrap_or(s.len());
    s[..end].trim_end_matches(':').to_string()
}

/// The longest prefix of `path` that is a module.
fn longest_module(modules: &BTreeSet<String>, path: &str) -> Option<String> {
    let parts: Vec<&str> = path.split("::").collect();
    (1..=parts.len())
        .rev()
        .map(|k| parts[..k].join("::"))
        .find(|m| modules.contains(m))
}

#[test]
fn no_two_library_modules_import_each_other_and_none_imports_the_cli() {
    let map = import_map(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    // The map sees the imports it should (a known edge), so an empty answer is not a pass.
    assert!(
        map["solver::progressive"].contains("solver::find_max_energy"),
        "{map:#?}"
    );
    let mut wrong = Vec::new();
    for (module, imports) in &map {
        for m in imports {
            if module < m && map.get(m).is_some_and(|back| back.contains(module)) {
                wrong.push(format!("{module} and {m} import each other"));
            }
            let cli = |x: &str| x == "cli" || x.starts_with("cli::");
            if cli(m) && !cli(module) {
                wrong.push(format!("{module} (library) imports {m} (command line)"));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_map_reads_use_lists_and_inline_paths() {
    let text = "use super::{error::SceneError, Scene};\n// crate::cli::nothing\n\
                fn f() { crate::cli::run(); super::super::x(); }\n";
    let paths = named_paths(text);
    assert!(paths.contains(&("super", "error::SceneError".into())));
    assert!(paths.contains(&("super", "Scene".into())));
    assert!(paths.contains(&("crate", "cli::run".into())));
    assert!(!paths.iter().any(|(_, p)| p.contains("nothing")));
}

/// The modules' imports lifted to folders: each module stands for the folder (or top-level file)
/// that holds it `depth` levels below `src/` (`solver::engine::culling` is `solver` at depth 1,
/// `solver::engine` at depth 2), edges between different folders only, self-loops dropped.
fn folder_map(
    map: &BTreeMap<String, BTreeSet<String>>,
    depth: usize,
) -> BTreeMap<String, BTreeSet<String>> {
    let folder = |m: &str| m.split("::").take(depth).collect::<Vec<_>>().join("::");
    let mut folders: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (module, imports) in map {
        let from = folder(module);
        let entry = folders.entry(from.clone()).or_default();
        for m in imports {
            let to = folder(m);
            // At depth 2, only siblings in one parent folder: a cycle through a parent's
            // re-exports is depth 1's to find.
            let siblings = depth == 1 || from.split("::").next() == to.split("::").next();
            if to != from && siblings && !from.starts_with(&format!("{to}::")) {
                entry.insert(to);
            }
        }
    }
    folders
}

/// The cycles of `graph`: each strongly connected set of more than one node, sorted.
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    let reaches = |from: &String| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(n) = stack.pop() {
            for m in graph.get(&n).into_iter().flatten() {
                if seen.insert(m.clone()) {
                    stack.push(m.clone());
                }
            }
        }
        seen
    };
    let reach: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|k| (k, reaches(k))).collect();
    let mut found: BTreeSet<Vec<String>> = BTreeSet::new();
    for (a, from_a) in &reach {
        let set: Vec<String> = (from_a.iter())
            .filter(|b| *b != *a && reach.get(b).is_some_and(|r| r.contains(*a)))
            .cloned()
            .chain(std::iter::once((*a).clone()))
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect();
        if set.len() > 1 {
            found.insert(set);
        }
    }
    found.into_iter().collect()
}

#[test]
fn no_folders_import_each_other_round_a_cycle() {
    let map = import_map(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    let top = folder_map(&map, 1);
    // The lift sees the edges it should, so an empty answer is not a pass.
    assert!(top["solver"].contains("scene"), "{top:#?}");
    let mut wrong = Vec::new();
    for depth in [1, 2] {
        for cycle in cycles(&folder_map(&map, depth)) {
            wrong.push(format!("a cycle between folders: {}", cycle.join(" ↔ ")));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn a_cycle_through_three_folders_is_found() {
    let edges = |pairs: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in pairs {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    let g = edges(&[("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")]);
    assert_eq!(cycles(&g), vec![vec!["a", "b", "c"]]);
    assert!(cycles(&edges(&[("a", "b"), ("b", "c")])).is_empty());
}
