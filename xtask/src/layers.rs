//! `cargo xtask layers`: inside a crate, imports go down, never up.
//!
//! Two rules, on every path a non-test module names (in a `use` or in its code) that
//! starts with `crate::`, `super::` or `self::`:
//!
//! 1. **No import from an ancestor.** A module never imports an item through the file of
//!    one of its ancestors (`super::X`, `super::super::X`, `crate::fit::X` inside
//!    `fit::…`): a child depending on its parent would make the parent more than the sum
//!    of its children. It imports the item from the module that defines it
//!    (`super::options::FitOptions`, not `super::FitOptions` re-exported by `fit`); an
//!    item defined in the parent's own file moves into a module of its own.
//! 2. **The crate's layer order.** A crate with a stated order of its top-level modules
//!    ([`CRATES`], the order its root's doc states) may import, from each top-level
//!    module, only the modules of the layers below it.
//!
//! The modules are found as the compiler finds them ([`crate::module_tree`]); test code
//! (`#[cfg(test)]` items, `tests.rs` files and `tests/` folders) is exempt: a test may
//! reach anywhere. Every crate of [`CRATES`] is checked; only the enforced ones fail the
//! check, the others' findings are listed for the record.

use std::collections::BTreeSet;
use std::path::Path;

use regex::Regex;

use crate::module_tree::{crate_trees, ModulePath, Tree};
use crate::report::Report;
use crate::rust_text::{blank_range, line_of, use_declarations};

/// One crate the check reads: its folder, whether its findings fail the check, and the
/// order of its top-level modules, highest layer first: `a > b, c > d` lets `a` import
/// `b`, `c` and `d`, and `b` and `c` import `d` (not each other); empty for none stated.
#[derive(Debug, Clone, Copy)]
pub struct CrateRule {
    /// The crate's folder, relative to the workspace root.
    pub folder: &'static str,
    /// Whether a finding fails the check (otherwise it is listed only).
    pub enforced: bool,
    /// The layer order of its top-level modules.
    pub layers: &'static str,
}

const fn rule(folder: &'static str, enforced: bool, layers: &'static str) -> CrateRule {
    CrateRule {
        folder,
        enforced,
        layers,
    }
}

/// The crates checked, one line each (the sysid order is the one `host/sysid/src/lib.rs`
/// states).
#[rustfmt::skip]
pub const CRATES: &[CrateRule] = &[
    rule("host/sysid", true, "models, steady > fit > frf > document, records, random"),
    rule("shared", true, ""),
    rule("firmware", false, ""),
    rule("firmware/board", false, ""),
    rule("host/aircraft", false, ""),
    rule("host/rotorsim", true, ""),
    rule("host/truth", false, ""),
    rule("host/control", true, ""),
    rule("host/cli", false, ""),
    rule("xtask", true, ""),
];

/// Checks the crates `crates` (folders under `root` holding a `src/`).
pub fn check(root: &Path, crates: &[CrateRule]) -> std::io::Result<Report> {
    let mut report = Report::default();
    let mut enforced_findings = 0;
    let mut listed = Vec::new();
    for krate in crates {
        let src = root.join(krate.folder).join("src");
        if !src.is_dir() {
            continue;
        }
        let layers = parse_layers(krate.layers);
        let mut findings = BTreeSet::new();
        for tree in crate_trees(&src)? {
            findings.extend(tree_findings(&tree, &layers, root));
        }
        let findings: Vec<String> = findings
            .into_iter()
            .map(|(file, line, message)| format!("{file}:{line}: {message}"))
            .collect();
        if findings.is_empty() {
            continue;
        }
        if krate.enforced {
            enforced_findings += findings.len();
            report.lines.extend(findings);
        } else {
            listed.push(format!(
                "{}: {} finding(s), listed, not enforced",
                krate.folder,
                findings.len()
            ));
            report
                .lines
                .extend(findings.into_iter().map(|f| format!("(listed) {f}")));
        }
    }
    report.lines.extend(listed);
    report.failed = enforced_findings > 0;
    let enforced: Vec<&str> = crates
        .iter()
        .filter(|c| c.enforced)
        .map(|c| c.folder)
        .collect();
    report.line(if report.failed {
        format!("{enforced_findings} upward or out-of-order import(s) in the enforced crates")
    } else {
        format!(
            "no upward import and none against the layer order in {}",
            enforced.join(", ")
        )
    });
    Ok(report)
}

/// `a > b, c > d` as layers, highest first.
fn parse_layers(order: &str) -> Vec<Vec<String>> {
    order
        .split('>')
        .map(|layer| {
            layer
                .split(',')
                .map(|m| m.trim().to_string())
                .filter(|m| !m.is_empty())
                .collect::<Vec<_>>()
        })
        .filter(|layer| !layer.is_empty())
        .collect()
}

/// A path a module names, with the byte offset where it is written.
struct Named {
    at: usize,
    segments: Vec<String>,
}

/// Every `crate::`, `super::` and `self::` path module text names: the paths of its `use`
/// declarations, and those written in its code.
fn named_paths(text: &str) -> Vec<Named> {
    let mut out = Vec::new();
    let mut code = text.to_string();
    for declaration in use_declarations(text) {
        for path in declaration.paths {
            out.push(Named {
                at: declaration.start,
                segments: path.segments,
            });
        }
        code = blank_range(&code, declaration.start, declaration.end);
    }
    // Visibilities name ancestors without importing from them.
    let visibility = Regex::new(r"\bpub\s*\([^)]*\)").expect("valid regex");
    for m in visibility.find_iter(&code.clone()) {
        code = blank_range(&code, m.start(), m.end());
    }
    let path =
        Regex::new(r"(^|[^\w$:])((?:crate|super|self)(?:::\w+)+)(\s*!)?").expect("valid regex");
    for hit in path.captures_iter(&code) {
        let m = hit.get(2).expect("group");
        // A macro (`crate::note!`) exported with `#[macro_export]` lives at the crate
        // root wherever it is written: its path says nothing of the module layout.
        if hit.get(3).is_some() {
            continue;
        }
        out.push(Named {
            at: m.start(),
            segments: m.as_str().split("::").map(str::to_string).collect(),
        });
    }
    out
}

/// Where `segments`, named in `module`, leads: the module it reaches and the item named
/// in it (`None` for a module itself). `None` for a path outside the crate.
fn resolve(
    tree: &Tree,
    module: &ModulePath,
    segments: &[String],
) -> Option<(ModulePath, Option<String>)> {
    let (mut base, rest) = match segments.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &segments[1..]),
        Some("self") => (module.clone(), &segments[1..]),
        Some("super") => {
            let ups = segments.iter().take_while(|s| *s == "super").count();
            let base = module[..module.len().checked_sub(ups)?].to_vec();
            (base, &segments[ups..])
        }
        Some(first) => {
            // A path relative to the module itself (`use child::X`), else an outside crate.
            let mut child = module.clone();
            child.push(first.to_string());
            if !tree.contains_key(&child) {
                return None;
            }
            (module.clone(), segments)
        }
        None => return None,
    };
    for segment in rest {
        let mut child = base.clone();
        child.push(segment.clone());
        if !tree.contains_key(&child) {
            return Some((base, Some(segment.clone())));
        }
        base = child;
    }
    Some((base, None))
}

/// The module that defines `name` re-exported by `module` (following re-exports), or
/// `module` itself when its own file defines it.
fn defining_module(tree: &Tree, module: &ModulePath, name: &str, depth: usize) -> ModulePath {
    let Some(text) = tree.get(module).map(|m| &m.text) else {
        return module.clone();
    };
    if depth > 8 {
        return module.clone();
    }
    for declaration in use_declarations(text).into_iter().filter(|d| d.public) {
        for path in declaration.paths {
            if path.name != name {
                continue;
            }
            return match resolve(tree, module, &path.segments) {
                Some((source, Some(item))) => defining_module(tree, &source, &item, depth + 1),
                Some((source, None)) => source,
                None => module.clone(),
            };
        }
    }
    module.clone()
}

fn shown(module: &[String]) -> String {
    if module.is_empty() {
        "crate".to_string()
    } else {
        module.join("::")
    }
}

fn layer_of(layers: &[Vec<String>], top: &str) -> Option<usize> {
    layers
        .iter()
        .position(|layer| layer.iter().any(|m| m == top))
}

/// A finding: file (relative to the workspace root), line, what is wrong.
type Finding = (String, usize, String);

/// The findings of one crate root's modules.
fn tree_findings(tree: &Tree, layers: &[Vec<String>], root: &Path) -> Vec<Finding> {
    let order = layers
        .iter()
        .map(|l| l.join(", "))
        .collect::<Vec<_>>()
        .join(" > ");
    // Macros by `macro_rules!` name, for `use crate::note;` (see `named_paths`).
    let macro_rules = Regex::new(r"\bmacro_rules!\s*(\w+)").expect("valid regex");
    let macros: BTreeSet<String> = tree
        .values()
        .flat_map(|m| macro_rules.captures_iter(&m.text).map(|c| c[1].to_string()))
        .collect();
    let mut out = Vec::new();
    for (module, source) in tree {
        if module.is_empty() {
            continue;
        }
        let file = source.file.strip_prefix(root).unwrap_or(&source.file);
        let file = file.display().to_string();
        for named in named_paths(&source.text) {
            let Some((target, item)) = resolve(tree, module, &named.segments) else {
                continue;
            };
            if item.as_deref().is_some_and(|name| macros.contains(name)) {
                continue;
            }
            // An inline module (`mod helper { … }`) may use the file it is written in.
            if tree.get(&target).is_some_and(|t| t.file == source.file) {
                continue;
            }
            let line = line_of(&source.text, named.at);
            let mut push = |message: String| out.push((file.clone(), line, message));
            let written = named.segments.join("::");
            let upward = target.len() < module.len() && module.starts_with(&target);
            if upward {
                let ancestor = shown(&target);
                push(match item.as_deref() {
                    None => format!("`{written}` names its ancestor `{ancestor}`"),
                    Some("*") => {
                        format!("`{written}` imports everything of its ancestor `{ancestor}`")
                    }
                    Some(item) => {
                        let defining = defining_module(tree, &target, item, 0);
                        if defining == target {
                            format!(
                                "`{written}` imports `{item}` from its ancestor `{ancestor}`, which defines it: move it into a module of its own"
                            )
                        } else {
                            format!(
                                "`{written}` imports `{item}` through its ancestor `{ancestor}`: import it from `{}`, which defines it",
                                shown(&defining)
                            )
                        }
                    }
                });
                continue;
            }
            if layers.is_empty() {
                continue;
            }
            let (Some(from), Some(to)) = (module.first(), target.first()) else {
                continue;
            };
            if from == to {
                continue;
            }
            match (layer_of(layers, from), layer_of(layers, to)) {
                (Some(a), Some(b)) if a < b => {}
                (Some(_), Some(_)) => push(format!(
                    "`{from}` imports `{written}`, but `{to}` is not below it in the layer order ({order})"
                )),
                (a, _) => push(format!(
                    "`{}` is not in the layer order ({order})",
                    if a.is_none() { from } else { to }
                )),
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture;

    const ORDER: &str = "top > middle > bottom, leaf";

    #[test]
    fn a_tree_of_downward_imports_passes() {
        let report = check(&fixture("layers"), &[rule("clean", true, ORDER)]).unwrap();
        assert!(!report.failed, "{:?}", report.lines);
        assert_eq!(
            report.lines,
            ["no upward import and none against the layer order in clean"]
        );
    }

    #[test]
    fn imports_from_an_ancestor_are_listed() {
        let report = check(&fixture("layers"), &[rule("upward", true, "")]).unwrap();
        assert!(report.failed);
        assert_eq!(
            report.lines,
            [
                "upward/src/fit/cost.rs:2: `super::Options` imports `Options` from its ancestor `fit`, which defines it: move it into a module of its own",
                "upward/src/fit/cost.rs:3: `super::Grid` imports `Grid` through its ancestor `fit`: import it from `fit::grid`, which defines it",
                "upward/src/fit/cost.rs:7: `crate::fit::Options` imports `Options` from its ancestor `fit`, which defines it: move it into a module of its own",
                "upward/src/fit/structure/parse.rs:1: `super::super::Options` imports `Options` from its ancestor `fit`, which defines it: move it into a module of its own",
                "upward/src/fit/structure/parse.rs:2: `super::*` imports everything of its ancestor `fit::structure`",
                "upward/src/fit/structure/parse.rs:5: `super::Kind` imports `Kind` from its ancestor `fit::structure`, which defines it: move it into a module of its own",
                "6 upward or out-of-order import(s) in the enforced crates",
            ]
        );
    }

    #[test]
    fn imports_against_the_layer_order_are_listed() {
        let report = check(&fixture("layers"), &[rule("against", true, ORDER)]).unwrap();
        assert!(report.failed);
        assert_eq!(
            report.lines,
            [
                "against/src/bottom.rs:1: `bottom` imports `crate::leaf::Seed`, but `leaf` is not below it in the layer order (top > middle > bottom, leaf)",
                "against/src/middle.rs:2: `middle` imports `crate::top::run`, but `top` is not below it in the layer order (top > middle > bottom, leaf)",
                "against/src/stray.rs:1: `stray` is not in the layer order (top > middle > bottom, leaf)",
                "3 upward or out-of-order import(s) in the enforced crates",
            ]
        );
    }

    #[test]
    fn findings_of_a_crate_not_enforced_are_listed_without_failing() {
        let report = check(
            &fixture("layers"),
            &[rule("clean", true, ORDER), rule("upward", false, "")],
        )
        .unwrap();
        assert!(!report.failed, "{:?}", report.lines);
        assert!(report.lines[0].starts_with("(listed) upward/src/fit/cost.rs:2: "));
        assert_eq!(
            report.lines[6..],
            [
                "upward: 6 finding(s), listed, not enforced",
                "no upward import and none against the layer order in clean",
            ]
        );
    }

    #[test]
    fn layers_are_read_highest_first() {
        assert_eq!(
            parse_layers("a > b, c > d"),
            [vec!["a"], vec!["b", "c"], vec!["d"]]
        );
        assert!(parse_layers("").is_empty());
    }
}
