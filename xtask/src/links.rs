//! `cargo xtask links`: the relative links of README.md and docs/**/*.md resolve.
//!
//! Every `[text](path#anchor)` must name an existing file inside the repository, and every
//! `#anchor` a heading of its target. URLs (`scheme:`) are not checked; fenced code blocks
//! are skipped. Port of the former `docs/check_links.py`: same rules, same messages.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Component, Path, PathBuf};

use regex::Regex;

use crate::report::Report;

/// Checks README.md and every `.md` under `docs/` of the tree at `root`.
pub fn check(root: &Path) -> std::io::Result<Report> {
    let root = root.canonicalize()?;
    let mut files = vec![root.join("README.md")];
    let mut docs = Vec::new();
    markdown_files(&root.join("docs"), &mut docs)?;
    docs.sort();
    files.extend(docs);

    let link = Regex::new(r"\]\(([^)\s]+)\)").expect("valid regex");
    let scheme = Regex::new(r"^[a-z]+:").expect("valid regex");
    let mut report = Report::default();
    let mut dead = 0;
    for file in &files {
        let text = without_code_blocks(&fs::read_to_string(file)?);
        let shown = file
            .strip_prefix(&root)
            .unwrap_or(file)
            .display()
            .to_string();
        for hit in link.captures_iter(&text) {
            let target = &hit[1];
            if scheme.is_match(target) {
                continue; // URLs are not checked
            }
            let (path, anchor) = target.split_once('#').unwrap_or((target, ""));
            let dest = if path.is_empty() {
                file.clone()
            } else {
                resolve(&file.parent().expect("a file has a folder").join(path))
            };
            let why = if !dest.starts_with(&root) {
                Some("outside the project")
            } else if !dest.exists() {
                Some("no such file")
            } else if !anchor.is_empty() && (dest.is_dir() || !anchors(&dest)?.contains(anchor)) {
                Some("no such heading")
            } else {
                None
            };
            if let Some(why) = why {
                report.line(format!("{shown}: {target} ({why})"));
                dead += 1;
            }
        }
    }
    report.line(format!("{} files, {dead} dead links", files.len()));
    report.failed = dead > 0;
    Ok(report)
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    if !dir.is_dir() {
        return Ok(());
    }
    for entry in fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            markdown_files(&path, out)?;
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
    Ok(())
}

/// The text without its fenced code blocks: a link shown as code is not a link.
fn without_code_blocks(text: &str) -> String {
    Regex::new(r"(?s)```.*?```")
        .expect("valid regex")
        .replace_all(text, "")
        .into_owned()
}

/// Like Python's `Path.resolve()`: links followed where the path exists, `..` folded
/// lexically where it does not.
fn resolve(path: &Path) -> PathBuf {
    if let Ok(real) = path.canonicalize() {
        return real;
    }
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// GitHub's anchors of a Markdown file's headings.
fn anchors(path: &Path) -> std::io::Result<BTreeSet<String>> {
    let text = without_code_blocks(&fs::read_to_string(path)?);
    let heading = Regex::new(r"(?m)^#+\s+(.*)$").expect("valid regex");
    Ok(heading.captures_iter(&text).map(|c| slug(&c[1])).collect())
}

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | ' '))
        .collect::<String>()
        .replace(' ', "-")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture;

    #[test]
    fn slug_follows_github() {
        assert_eq!(
            slug("Data flow: from one sample to the report"),
            "data-flow-from-one-sample-to-the-report"
        );
        assert_eq!(slug("  `cargo xtask` & CI "), "cargo-xtask--ci");
    }

    #[test]
    fn clean_tree_passes() {
        let report = check(&fixture("links/clean")).unwrap();
        assert!(!report.failed, "{:?}", report.lines);
        assert_eq!(report.lines, ["3 files, 0 dead links"]);
    }

    #[test]
    fn dead_links_are_named_with_their_reason() {
        let report = check(&fixture("links/dead")).unwrap();
        assert!(report.failed);
        assert_eq!(
            report.lines,
            [
                "README.md: docs/missing.md (no such file)",
                "README.md: ../../outside.md (outside the project)",
                "README.md: docs/guide.md#no-such-part (no such heading)",
                "docs/guide.md: #also-missing (no such heading)",
                "docs/guide.md: ./#part (no such heading)",
                "2 files, 5 dead links",
            ]
        );
    }
}
