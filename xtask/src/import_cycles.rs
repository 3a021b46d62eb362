//! `cargo xtask import-cycles`: no two modules of a crate import each other, and the
//! folders that must not name a crate do not.
//!
//! A module is a file under `src/` (a `mod.rs` names its folder). Module A imports module
//! B when A's text names `crate::B...` (in a `use` or in a path) or, inside the same
//! parent, `super::B`. Tests (`tests.rs`, `*_tests.rs`, `test_support.rs`, and a
//! `#[cfg(test)] mod` with everything after it) are left out: a test may reach anywhere.
//! Edges are lifted to siblings (`a::x -> a::y::z` counts as `a::x -> a::y`); a circle is
//! a strongly connected set of two or more siblings. Port of the former
//! `docs/import_cycles.py`: same rules, same messages.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use regex::Regex;

use crate::report::Report;

/// The crates whose modules are checked, relative to the workspace root.
pub const CRATES: &[&str] = &[
    "shared",
    "firmware",
    "firmware/board",
    "host/rotorsim",
    "host/sysid",
    "host/cli",
    "host/truth",
    "xtask",
];

/// (folder, crates its non-test code must not name): the code of `sweephold identify`
/// runs on logs alone and names neither the simulator nor its truth.
pub const SEPARATED: &[(&str, &[&str])] = &[("host/cli/src/identify", &["rotorsim", "truth"])];

type Module = Vec<String>;

/// Checks the crates `crates` (folders under `root` holding a `src/`) and the
/// `separated` folders.
pub fn check(
    root: &Path,
    crates: &[&str],
    separated: &[(&str, &[&str])],
) -> std::io::Result<Report> {
    let mut report = Report::default();
    let mut found = 0;
    for krate in crates {
        let src = root.join(krate).join("src");
        if !src.is_dir() {
            continue;
        }
        for circle in cycles(&lift(&edges(&modules(&src)?))) {
            found += 1;
            let names: Vec<String> = circle
                .iter()
                .map(|m| {
                    if m.is_empty() {
                        "crate".to_string()
                    } else {
                        m.join("::")
                    }
                })
                .collect();
            report.line(format!("{krate}: {}", names.join(" <-> ")));
        }
    }
    let named = separated_named(root, separated)?;
    let any_named = !named.is_empty();
    for line in named {
        report.line(line);
    }
    if found > 0 {
        report.line(format!("{found} import circle(s)"));
    }
    report.failed = found > 0 || any_named;
    if !report.failed {
        report.line("no import circles; no folder names a crate it must not".to_string());
    }
    Ok(report)
}

fn is_test_file(name: &str) -> bool {
    name == "tests.rs" || name.ends_with("_tests.rs")
}

/// The `.rs` files under `dir`, sorted.
fn rust_files(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir)? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Each non-test module's text, without its tests and comments.
fn modules(src: &Path) -> std::io::Result<BTreeMap<Module, String>> {
    let mut mods = BTreeMap::new();
    for path in rust_files(src)? {
        let rel = path.strip_prefix(src).expect("under src");
        let name = rel.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        if is_test_file(name)
            || name == "test_support.rs"
            || rel.components().any(|c| c.as_os_str() == "bin")
        {
            continue;
        }
        let text = fs::read_to_string(&path)?;
        mods.insert(module_of(rel), strip_comments(&strip_tests(&text)));
    }
    Ok(mods)
}

fn module_of(rel: &Path) -> Module {
    let mut parts: Module = rel
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The text before the `#[cfg(test)] mod`: by this project's convention the test module
/// is a file's last item.
fn strip_tests(text: &str) -> String {
    let marker =
        Regex::new(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{").expect("valid regex");
    match marker.find(text) {
        Some(m) => text[..m.start()].to_string(),
        None => text.to_string(),
    }
}

fn strip_comments(text: &str) -> String {
    Regex::new(r"//[^\n]*")
        .expect("valid regex")
        .replace_all(text, "")
        .into_owned()
}

/// The longest known module prefix of `path`.
fn resolve(mods: &BTreeMap<Module, String>, path: &[String]) -> Option<Module> {
    (1..=path.len())
        .rev()
        .map(|n| path[..n].to_vec())
        .find(|p| mods.contains_key(p))
}

fn split_path(path: &str) -> Vec<String> {
    path.trim_matches(':')
        .split("::")
        .map(str::to_string)
        .collect()
}

fn edges(mods: &BTreeMap<Module, String>) -> BTreeMap<Module, BTreeSet<Module>> {
    let crate_path = Regex::new(r"\bcrate((?:::\w+)+)").expect("valid regex");
    let crate_group = Regex::new(r"\bcrate::\{([^}]*)\}").expect("valid regex");
    let super_path = Regex::new(r"\bsuper((?:::\w+)+)").expect("valid regex");
    let mut out = BTreeMap::new();
    for (m, text) in mods {
        let mut targets = BTreeSet::new();
        let mut add = |path: Vec<String>| {
            if let Some(target) = resolve(mods, &path) {
                if &target != m {
                    targets.insert(target);
                }
            }
        };
        for hit in crate_path.captures_iter(text) {
            add(split_path(&hit[1]));
        }
        for hit in crate_group.captures_iter(text) {
            for part in hit[1].split(',') {
                add(part.trim().split("::").map(str::to_string).collect());
            }
        }
        let parent = &m[..m.len().saturating_sub(1)];
        for hit in super_path.captures_iter(text) {
            let mut path = parent.to_vec();
            path.extend(split_path(&hit[1]));
            add(path);
        }
        out.insert(m.clone(), targets);
    }
    out
}

/// Collapses modules to siblings: an edge a.x -> a.y.z counts as a.x -> a.y; an edge
/// between a module and its own parent or child is no circle between siblings.
fn lift(graph: &BTreeMap<Module, BTreeSet<Module>>) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut lifted: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (a, targets) in graph {
        for b in targets {
            let common = a.iter().zip(b).take_while(|(x, y)| x == y).count();
            if common == a.len() || common == b.len() {
                continue;
            }
            let (sa, sb) = (a[..=common].to_vec(), b[..=common].to_vec());
            lifted.entry(sa).or_default().insert(sb.clone());
            lifted.entry(sb).or_default();
        }
    }
    lifted
}

/// Tarjan's strongly connected components of two or more modules, each sorted.
fn cycles(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct Tarjan<'g> {
        graph: &'g BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'g Module, usize>,
        low: BTreeMap<&'g Module, usize>,
        stack: Vec<&'g Module>,
        on_stack: BTreeSet<&'g Module>,
        out: Vec<Vec<Module>>,
    }
    impl<'g> Tarjan<'g> {
        fn visit(&mut self, v: &'g Module) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.graph.get(v).into_iter().flatten() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.on_stack.contains(w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                loop {
                    let w = self.stack.pop().expect("v is on the stack");
                    self.on_stack.remove(w);
                    component.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.out.push(component);
                }
            }
        }
    }
    let mut tarjan = Tarjan {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !tarjan.index.contains_key(v) {
            tarjan.visit(v);
        }
    }
    tarjan.out
}

/// `FILE: names `CRATE`, which it must not` for each file of a separated folder that
/// names a crate it must not.
fn separated_named(root: &Path, separated: &[(&str, &[&str])]) -> std::io::Result<Vec<String>> {
    let mut out = Vec::new();
    for (folder, banned) in separated {
        let dir = root.join(folder);
        if !dir.is_dir() {
            continue;
        }
        for path in rust_files(&dir)? {
            let name = path
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or_default();
            if is_test_file(name) {
                continue;
            }
            let text = strip_comments(&strip_tests(&fs::read_to_string(&path)?));
            for krate in *banned {
                let names = Regex::new(&format!(r"(\b|::){krate}\s*::|\buse\s+{krate}\b"))
                    .expect("valid regex");
                if names.is_match(&text) {
                    let shown = path.strip_prefix(root).unwrap_or(&path).display();
                    out.push(format!("{shown}: names `{krate}`, which it must not"));
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture;

    const BANNED: &[(&str, &[&str])] = &[("clean/src/logs", &["simulator"])];

    #[test]
    fn a_crate_without_circles_passes() {
        let report = check(&fixture("import_cycles"), &["clean"], BANNED).unwrap();
        assert!(!report.failed, "{:?}", report.lines);
        assert_eq!(
            report.lines,
            ["no import circles; no folder names a crate it must not"]
        );
    }

    #[test]
    fn circles_and_banned_names_are_listed() {
        let banned: &[(&str, &[&str])] = &[("circular/src/logs", &["simulator"])];
        let report = check(&fixture("import_cycles"), &["clean", "circular"], banned).unwrap();
        assert!(report.failed);
        assert_eq!(
            report.lines,
            [
                "circular: a <-> b",
                "circular: fly::link <-> fly::record",
                "circular/src/logs/read.rs: names `simulator`, which it must not",
                "2 import circle(s)",
            ]
        );
    }

    #[test]
    fn tests_and_comments_are_left_out() {
        let text = "use crate::a;\n// crate::b\n#[cfg(test)]\nmod tests {\n use crate::c;\n}\n";
        assert_eq!(strip_comments(&strip_tests(text)), "use crate::a;\n\n");
    }
}
