//! No import circles in model-core: the `crate::<module>` imports between its top-level modules
//! and the `super::<module>` imports between the modules of `wire/`, read from the source tree,
//! are each one of the allowed directions listed below, and the allowed directions form no
//! circle. A new import is a decision: add its direction here, and the test says whether it
//! closes a circle.

#[path = "../../tests/support/graph.rs"]
mod graph;

use graph::{Graph, circle, rust_files};

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Which top-level module may import which (`a` imports from each of its list). Read down:
/// the simulator sits on the binding, the binding on the controller, the particle model and
/// the wire; the wire on nothing.
const TOP_LEVEL: &[(&str, &[&str])] = &[
    ("real", &[]),
    ("bowl", &["real"]),
    ("wire", &[]),
    ("control", &["bowl", "real"]),
    ("ode", &["real"]),
    ("particle", &["ode", "real"]),
    ("choose", &["ode", "particle", "real"]),
    ("binding", &["control", "particle", "wire", "real"]),
    (
        "sim",
        &["binding", "bowl", "control", "particle", "wire", "real"],
    ),
];

/// Which module of `wire/` may import which (`wire` itself: the constants its `mod.rs`
/// defines; its `pub use` re-exports are for the users of `wire`, not for its own modules).
const WIRE: &[(&str, &[&str])] = &[
    ("wire", &[]),
    ("crc", &[]),
    ("types", &[]),
    ("words", &["types"]),
    ("params", &["types"]),
    ("commands", &["params", "types"]),
    // commands/parse.rs: the commands' field parsing and range checks, a part of `commands`.
    ("parse", &["commands", "params", "types"]),
    ("frame", &["commands", "params", "types"]),
    (
        "encode",
        &["commands", "crc", "frame", "params", "types", "wire"],
    ),
    (
        "decode",
        &["commands", "crc", "frame", "params", "types", "wire"],
    ),
    ("stream", &["decode", "frame", "wire"]),
    ("typed", &["commands", "params", "types"]),
    // A line typed at a plain console, read by the frame's own parser.
    ("console", &["commands", "decode", "types", "wire"]),
    (
        "device",
        &[
            "commands", "console", "decode", "encode", "frame", "params", "stream", "types", "wire",
        ],
    ),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The code of a file without its comments (doc links name modules too).
fn code(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The identifiers right after each `prefix` (`crate::`, `super::`), and the first segment of
/// each item when a `{...}` group follows.
fn imported(code: &str, prefix: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for (i, _) in code.match_indices(prefix) {
        // `super::super::` and `self::super::` are not used in wire/; a longer path is its own.
        if i > 0 && code[..i].ends_with("::") {
            continue;
        }
        let rest = &code[i + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut item_start = true;
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    c if item_start && !c.is_whitespace() => {
                        out.push(ident(&group[j..]));
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            out.push(ident(rest));
        }
    }
    out
}

fn top_level_of(path: &Path) -> Option<String> {
    let rel = path.strip_prefix(src()).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (name != "lib").then(|| name.to_string())
}

/// `crate::<module>` imports between top-level modules (`crate::Real` is `real`'s).
fn top_level_graph() -> Graph {
    let modules: BTreeSet<&str> = TOP_LEVEL.iter().map(|(m, _)| *m).collect();
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut graph = Graph::new();
    for file in files {
        let Some(from) = top_level_of(&file) else {
            continue;
        };
        assert!(
            modules.contains(from.as_str()),
            "{from} is a new top-level module: give it a row in TOP_LEVEL"
        );
        for to in imported(&code(&file), "crate::") {
            let to = if to == "Real" { "real".to_string() } else { to };
            if modules.contains(to.as_str()) && to != from {
                graph.entry(from.clone()).or_default().insert(to);
            }
        }
    }
    graph
}

/// `super::<module>` imports between the modules of `wire/`; a `super::` name that is no module
/// must be one of the constants `wire/mod.rs` defines itself (a re-exported name would hide
/// which module it comes from).
fn wire_graph() -> Graph {
    let dir = src().join("wire");
    let modules: BTreeSet<&str> = WIRE.iter().map(|(m, _)| *m).collect();
    let facade = code(&dir.join("mod.rs"));
    let own: BTreeSet<String> = facade
        .lines()
        .filter_map(|l| {
            let l = l.trim();
            let rest = l
                .strip_prefix("pub const fn ")
                .or_else(|| l.strip_prefix("pub const "))
                .or_else(|| l.strip_prefix("pub fn "))?;
            Some(
                rest.chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect(),
            )
        })
        .collect();
    let mut graph = Graph::new();
    let mut files = Vec::new();
    rust_files(&dir, &mut files);
    for file in files {
        let from = file.file_stem().unwrap().to_str().unwrap().to_string();
        if from == "mod" {
            continue;
        }
        assert!(
            modules.contains(from.as_str()),
            "wire/{from}.rs is a new module: give it a row in WIRE"
        );
        let code = code(&file);
        // A module's own tests (`mod tests { use super::*; }`) import their module.
        let code = code.split("mod tests {").next().unwrap();
        for to in imported(code, "super::") {
            let to = if modules.contains(to.as_str()) {
                to
            } else {
                assert!(
                    own.contains(&to),
                    "wire/{from}.rs imports `super::{to}`: import it from the module that \
                     defines it (`super::types::{to}`, ...)"
                );
                "wire".to_string()
            };
            if to != from {
                graph.entry(from.clone()).or_default().insert(to);
            }
        }
        for to in imported(code, "crate::wire::") {
            if modules.contains(to.as_str()) && to != from {
                graph.entry(from.clone()).or_default().insert(to);
            }
        }
    }
    graph
}

fn allowed(table: &[(&str, &[&str])]) -> Graph {
    table
        .iter()
        .map(|(m, tos)| (m.to_string(), tos.iter().map(|t| t.to_string()).collect()))
        .collect()
}

/// Every import in `found` is allowed (or listed in `exempt`), and the allowed ones form no
/// circle.
fn check(name: &str, found: &Graph, allowed: &Graph, exempt: &[(&str, &str)]) {
    for (from, tos) in found {
        for to in tos {
            let ok = allowed.get(from).is_some_and(|a| a.contains(to))
                || exempt.contains(&(from.as_str(), to.as_str()));
            assert!(
                ok,
                "{name}: `{from}` imports `{to}`, a direction not listed: list it if it keeps \
                 the graph free of circles, else move what is shared down"
            );
        }
    }
    assert_eq!(
        circle(allowed),
        None,
        "{name}: the allowed directions close a circle"
    );
    let mut without = found.clone();
    for (from, to) in exempt {
        if let Some(tos) = without.get_mut(*from) {
            tos.remove(*to);
        }
    }
    assert_eq!(circle(&without), None, "{name}: the imports close a circle");
}

#[test]
fn model_core_top_level_modules_import_one_way() {
    let found = top_level_graph();
    eprintln!("model-core imports: {found:?}");
    check("model-core", &found, &allowed(TOP_LEVEL), &[]);
    // The binding the firmware links never reaches the simulator.
    assert!(!found["binding"].contains("sim"));
}

#[test]
fn wire_modules_import_one_way() {
    let found = wire_graph();
    eprintln!("wire imports: {found:?}");
    check("wire", &found, &allowed(WIRE), &[]);
    // The parameter table and the plain types do not import each other.
    assert!(!found.get("types").is_some_and(|t| t.contains("params")));
}

#[test]
fn a_circle_is_found() {
    let graph = allowed(&[("a", &["b"]), ("b", &["c"]), ("c", &["a"])]);
    assert!(circle(&graph).is_some());
    assert_eq!(circle(&allowed(WIRE)), None);
    let words = imported(
        "use super::{a::X, b, c::{D, E}};\nuse crate::sim::Plant;",
        "super::",
    );
    assert_eq!(words, ["a", "b", "c"]);
}
