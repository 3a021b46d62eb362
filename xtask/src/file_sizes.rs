//! `cargo xtask file-sizes`: no non-test Rust source file over its size limit.
//!
//! The limit is 600 lines for every crate ([`RULES`]: the first matching rule wins, so a
//! folder may be given its own). With a fixed limit, that one limit applies to every file.
//!
//! A file is a test file when it is named `tests.rs`, `*_tests.rs` or `test_support.rs`,
//! or lives in a `tests/`, `benches/` or `fuzz/` folder. Build output (`target/`,
//! `target-*/`) and `.git/` are skipped. Port of the former `docs/file_sizes.py`: same
//! rules, same messages.

use std::fs;
use std::path::Path;

use crate::report::Report;

/// (path prefix, limit in lines): the first match wins; the last rule matches every path.
pub const RULES: &[(&str, usize)] = &[("", 600)];

/// Checks every `.rs` file under `root` against `fixed` or, without it, [`RULES`].
pub fn check(root: &Path, fixed: Option<usize>) -> std::io::Result<Report> {
    let mut over = Vec::new();
    walk(root, root, fixed, &mut over)?;
    over.sort_by(|a, b| b.cmp(a));
    let mut report = Report::default();
    for (lines, path, limit) in &over {
        report.line(format!("{path}: {lines} lines (limit {limit})"));
    }
    report.failed = !over.is_empty();
    if !report.failed {
        report.line(match fixed {
            Some(limit) => format!("no non-test source file over {limit} lines"),
            None => match RULES {
                [("", limit)] => format!("no non-test source file over {limit} lines"),
                rules => {
                    let rules: Vec<String> = rules
                        .iter()
                        .map(|(prefix, limit)| {
                            let place = if prefix.is_empty() {
                                "elsewhere"
                            } else {
                                prefix
                            };
                            format!("{place} {limit}")
                        })
                        .collect();
                    format!(
                        "no non-test source file over its limit ({})",
                        rules.join(", ")
                    )
                }
            },
        });
    }
    Ok(report)
}

fn walk(
    root: &Path,
    dir: &Path,
    fixed: Option<usize>,
    over: &mut Vec<(usize, String, usize)>,
) -> std::io::Result<()> {
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if entry.file_type()?.is_dir() {
            if name != "target" && name != ".git" && !name.starts_with("target-") {
                walk(root, &path, fixed, over)?;
            }
            continue;
        }
        if !name.ends_with(".rs") {
            continue;
        }
        let rel = path
            .strip_prefix(root)
            .expect("under root")
            .to_string_lossy()
            .replace('\\', "/");
        if is_test(&rel) {
            continue;
        }
        let lines = line_count(&fs::read(&path)?);
        let limit = fixed.unwrap_or_else(|| limit_of(&rel));
        if lines > limit {
            over.push((lines, rel, limit));
        }
    }
    Ok(())
}

/// Lines as a text editor counts them: a last line without its newline counts too.
fn line_count(bytes: &[u8]) -> usize {
    let newlines = bytes.iter().filter(|&&b| b == b'\n').count();
    newlines + usize::from(bytes.last().is_some_and(|&b| b != b'\n'))
}

fn is_test(rel: &str) -> bool {
    let mut parts = rel.split('/');
    let name = rel.rsplit('/').next().unwrap_or(rel);
    matches!(name, "tests.rs" | "test_support.rs")
        || name.ends_with("_tests.rs")
        || parts.any(|p| matches!(p, "tests" | "benches" | "fuzz"))
}

fn limit_of(rel: &str) -> usize {
    RULES
        .iter()
        .find(|(prefix, _)| rel.starts_with(prefix))
        .map(|&(_, limit)| limit)
        .expect("the last rule matches every path")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture;

    #[test]
    fn limits_follow_the_first_matching_rule() {
        assert_eq!(limit_of("host/cli/src/fly/mod.rs"), 600);
        assert_eq!(limit_of("host/cli/src/fly/link.rs"), 600);
        assert_eq!(limit_of("firmware/src/app/mod.rs"), 600);
        assert_eq!(limit_of("shared/src/lib.rs"), 600);
        assert_eq!(limit_of("xtask/src/main.rs"), 600);
    }

    #[test]
    fn test_files_are_recognised() {
        assert!(is_test("host/sysid/src/fit/tests.rs"));
        assert!(is_test("host/cli/src/dump_tests.rs"));
        assert!(is_test("host/cli/src/test_support.rs"));
        assert!(is_test("host/cli/tests/cli/main.rs"));
        assert!(is_test("fuzz/fuzz_targets/decode.rs"));
        assert!(!is_test("host/cli/src/testing.rs"));
    }

    #[test]
    fn lines_count_a_last_line_without_newline() {
        assert_eq!(line_count(b""), 0);
        assert_eq!(line_count(b"a\nb\n"), 2);
        assert_eq!(line_count(b"a\nb"), 2);
    }

    #[test]
    fn files_over_a_fixed_limit_are_listed_longest_first() {
        let report = check(&fixture("file_sizes"), Some(3)).unwrap();
        assert!(report.failed);
        assert_eq!(
            report.lines,
            [
                "src/long.rs: 5 lines (limit 3)",
                "src/four.rs: 4 lines (limit 3)"
            ]
        );
    }

    #[test]
    fn tests_and_build_output_are_skipped() {
        let report = check(&fixture("file_sizes"), Some(5)).unwrap();
        assert!(!report.failed, "{:?}", report.lines);
        assert_eq!(report.lines, ["no non-test source file over 5 lines"]);
    }
}
