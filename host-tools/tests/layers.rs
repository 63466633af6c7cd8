//! The PC side's layering, checked from the sources as they are (ARCHITECTURE.md):
//! - no import circle among the top-level modules of each host-tools crate (a `crate::X` or
//!   `super::X` from a file of module A to module B is an arrow A -> B);
//! - the crates depend the way the arrows point: bowl -> {lab, virtual-rig, rig-client} ->
//!   model-core; lab may use rig-client and virtual-rig; rig-client and virtual-rig use neither
//!   lab nor each other; nothing in the product uses the test crate;
//! - every path ARCHITECTURE.md names exists;
//! - every arrow ARCHITECTURE.md draws between a crate's modules is one the crate has;
//! - no source file of the four crates is over 500 lines (a file with one job).

#[path = "../../tests/support/graph.rs"]
mod graph;

use graph::{Graph, circle, rust_files};

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The crates under host-tools/ and where their sources are.
const CRATES: [(&str, &str); 4] = [
    ("bowl", "host-tools/src"),
    ("rig-client", "host-tools/rig-client/src"),
    ("virtual-rig", "host-tools/virtual-rig/src"),
    ("lab", "host-tools/lab/src"),
];

/// The top-level module a file belongs to (`chart/plot.rs` -> `chart`), `None` for the crate
/// root.
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next()?.as_os_str().to_string_lossy();
    let name = first.trim_end_matches(".rs").to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// The code of `text` without comments (line comments and doc comments), so intra-doc links
/// and prose do not count as imports.
fn code(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every module named right after `crate::` (and inside `use crate::{a, b::c}`).
fn imports(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    for (i, _) in code.match_indices("crate::") {
        // `bowl_test_cases::` and other names ending in `crate` are not this crate.
        if code[..i]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
        {
            continue;
        }
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap_or(group.len())];
            for item in group.split(',') {
                let name = ident(item.trim());
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        } else {
            let name = ident(rest);
            if !name.is_empty() {
                out.insert(name);
            }
        }
    }
    out
}

/// The arrows between the top-level modules of the crate whose sources are in `src`.
fn module_graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: BTreeSet<String> = files.iter().filter_map(|f| top_module(src, f)).collect();
    let mut graph = Graph::new();
    for file in &files {
        let Some(from) = top_module(src, file) else {
            continue;
        };
        let text = std::fs::read_to_string(file).unwrap();
        let to = graph.entry(from.clone()).or_default();
        for m in imports(&code(&text)) {
            if m != from && modules.contains(&m) {
                to.insert(m);
            }
        }
    }
    graph
}

#[test]
fn no_import_circle_inside_a_crate() {
    for (name, dir) in CRATES {
        let graph = module_graph(&root().join(dir));
        assert!(graph.len() > 1, "{name}: no modules found in {dir}");
        if let Some(c) = circle(&graph) {
            panic!("{name}: import circle {}", c.join(" -> "));
        }
    }
}

#[test]
fn the_circle_check_sees_a_circle() {
    let mut graph = BTreeMap::new();
    graph.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    graph.insert("b".to_string(), BTreeSet::from(["c".to_string()]));
    graph.insert("c".to_string(), BTreeSet::from(["a".to_string()]));
    assert_eq!(circle(&graph).unwrap(), ["a", "b", "c", "a"]);
    graph.get_mut("c").unwrap().clear();
    assert_eq!(circle(&graph), None);
    let seen = imports(&code(
        "use crate::{link, send::x};\n// crate::not_me\nlet y = crate::words::f();\nbowl_test_cases::z",
    ));
    assert_eq!(
        seen.into_iter().collect::<Vec<_>>(),
        ["link", "send", "words"]
    );
}

/// The package names a crate's Cargo.toml depends on (all its dependency tables).
fn dependencies(dir: &str) -> BTreeSet<String> {
    let text = std::fs::read_to_string(root().join(dir).join("../Cargo.toml")).unwrap();
    let manifest: toml::Table = toml::from_str(&text).unwrap();
    let mut tables: Vec<&toml::Table> = Vec::new();
    for key in ["dependencies", "dev-dependencies"] {
        if let Some(t) = manifest.get(key).and_then(|v| v.as_table()) {
            tables.push(t);
        }
    }
    if let Some(targets) = manifest.get("target").and_then(|v| v.as_table()) {
        for t in targets.values().filter_map(|v| v.as_table()) {
            for key in ["dependencies", "dev-dependencies"] {
                if let Some(t) = t.get(key).and_then(|v| v.as_table()) {
                    tables.push(t);
                }
            }
        }
    }
    tables.iter().flat_map(|t| t.keys().cloned()).collect()
}

/// Only the product's dependencies (not the dev ones).
fn product_dependencies(dir: &str) -> BTreeSet<String> {
    let text = std::fs::read_to_string(root().join(dir).join("../Cargo.toml")).unwrap();
    let manifest: toml::Table = toml::from_str(&text).unwrap();
    let mut out: BTreeSet<String> = manifest
        .get("dependencies")
        .and_then(|v| v.as_table())
        .map(|t| t.keys().cloned().collect())
        .unwrap_or_default();
    if let Some(targets) = manifest.get("target").and_then(|v| v.as_table()) {
        for t in targets.values().filter_map(|v| v.as_table()) {
            if let Some(d) = t.get("dependencies").and_then(|v| v.as_table()) {
                out.extend(d.keys().cloned());
            }
        }
    }
    out
}

#[test]
fn the_crates_depend_downwards_only() {
    let forbidden: [(&str, &[&str]); 3] = [
        ("rig-client", &["lab", "virtual-rig", "host-tools"]),
        ("virtual-rig", &["lab", "rig-client", "host-tools"]),
        ("lab", &["host-tools"]),
    ];
    for (name, dir) in CRATES {
        let deps = dependencies(dir);
        for (crate_name, never) in forbidden {
            if crate_name == name {
                for n in never {
                    assert!(!deps.contains(*n), "{name} depends on {n}");
                }
            }
        }
        assert!(
            !product_dependencies(dir).contains("bowl-test-cases"),
            "{name}: the product depends on the test crate"
        );
    }
}

#[test]
fn every_path_architecture_md_names_exists() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let mut missing = Vec::new();
    let mut checked = 0;
    // Paths are written in backticks from the repository's root: `host-tools/src/cmd/`,
    // `model-core/src/bowl.rs` (a name inside a row, such as `particle/`, is not checked).
    let tops = [
        "model-core/",
        "firmware/",
        "host-tools/",
        "emulator/",
        "rig-file/",
        "tests/",
        "docs/",
    ];
    for quoted in text.split('`').skip(1).step_by(2) {
        let looks_like_path = tops.iter().any(|t| quoted.starts_with(t))
            && !quoted.contains(' ')
            && !quoted.contains("://")
            && quoted
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "/._-".contains(c));
        if !looks_like_path {
            continue;
        }
        checked += 1;
        if !root().join(quoted).exists() {
            missing.push(quoted.to_string());
        }
    }
    assert!(
        checked > 20,
        "only {checked} paths found in ARCHITECTURE.md"
    );
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md names paths that do not exist: {missing:?}"
    );
}

/// The arrows ARCHITECTURE.md draws inside each crate ("Module imports inside each crate":
/// `` - `rig-client`: `link -> serial`; ... ``) are arrows of the crate as it is, between
/// modules it has (a module renamed or gone leaves its name in the prose otherwise).
#[test]
fn the_module_arrows_architecture_md_draws_exist() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let section = text
        .split_once("Module imports inside each crate")
        .expect("ARCHITECTURE.md: no \"Module imports inside each crate\" list")
        .1;
    let mut drawn = 0;
    let mut wrong = Vec::new();
    // The bullets: `- `crate`: ...` and their continuation lines, up to the first blank line.
    let mut graph = None;
    // (the rest of the heading's line, `A -> B`, explains the notation)
    for line in section.lines().skip(1).skip_while(|l| l.trim().is_empty()) {
        if line.trim().is_empty() {
            break;
        }
        if let Some(rest) = line.strip_prefix("- `") {
            let name = &rest[..rest.find('`').unwrap()];
            let (_, dir) = CRATES
                .iter()
                .find(|(n, _)| *n == name)
                .unwrap_or_else(|| panic!("ARCHITECTURE.md draws arrows of `{name}`, no crate"));
            graph = Some(module_graph(&root().join(dir)));
        }
        let graph = graph
            .as_ref()
            .expect("an arrow before the first crate's bullet");
        for quoted in line.split('`').skip(1).step_by(2) {
            let Some((from, to)) = quoted.split_once(" -> ") else {
                continue;
            };
            for to in to.split(", ") {
                drawn += 1;
                if !graph.get(from).is_some_and(|t| t.contains(to)) {
                    wrong.push(format!("{from} -> {to}"));
                }
            }
        }
    }
    assert!(drawn > 10, "only {drawn} arrows found in ARCHITECTURE.md");
    assert!(
        wrong.is_empty(),
        "ARCHITECTURE.md draws arrows the crates do not have: {wrong:?}"
    );
}

#[test]
fn no_source_file_over_500_lines() {
    let mut long = Vec::new();
    for (_, dir) in CRATES {
        let mut files = Vec::new();
        rust_files(&root().join(dir), &mut files);
        for f in files {
            let lines = std::fs::read_to_string(&f).unwrap().lines().count();
            if lines > 500 {
                long.push(format!("{} ({lines} lines)", f.display()));
            }
        }
    }
    assert!(long.is_empty(), "split by job: {long:?}");
}
