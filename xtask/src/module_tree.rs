//! A crate's modules as the compiler finds them: from the crate root (`src/lib.rs`,
//! `src/main.rs`) through each `mod NAME;` declaration (`NAME.rs` or `NAME/mod.rs`, or its
//! `#[path]`), and each inline `mod NAME { … }`.
//!
//! Test code is left out: a `#[cfg(test)]` item (and so a `#[cfg(test)] mod` with its
//! files), and a module whose file is named `tests.rs` or lies in a `tests/` folder.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use regex::Regex;

use crate::rust_text::{blank_comments_and_strings, blank_range, blank_test_items, matching_brace};

/// A module path inside its crate (`["fit", "structure"]`; the root is empty).
pub type ModulePath = Vec<String>;

/// One non-test module.
#[derive(Debug)]
pub struct Module {
    /// The file it is written in.
    pub file: PathBuf,
    /// Its text, blanked ([`crate::rust_text`]) and with its inline child modules blanked
    /// too; byte offsets are the file's.
    pub text: String,
}

/// The modules of one crate root, by path.
pub type Tree = BTreeMap<ModulePath, Module>;

/// The trees of the crate roots under `src` (`lib.rs` and `main.rs`, those that exist).
pub fn crate_trees(src: &Path) -> std::io::Result<Vec<Tree>> {
    let mut trees = Vec::new();
    for root in ["lib.rs", "main.rs"] {
        let file = src.join(root);
        if file.is_file() {
            let mut tree = Tree::new();
            let text = fs::read_to_string(&file)?;
            let blanked = blank_test_items(&blank_comments_and_strings(&text));
            add(&mut tree, Vec::new(), &file, src, &text, blanked)?;
            trees.push(tree);
        }
    }
    Ok(trees)
}

/// Adds the module `path` written in `file` (whose own text is `blanked`, `original`
/// unblanked), whose children's files are in `child_dir`, and its children.
fn add(
    tree: &mut Tree,
    path: ModulePath,
    file: &Path,
    child_dir: &Path,
    original: &str,
    mut blanked: String,
) -> std::io::Result<()> {
    let declaration =
        Regex::new(r"\b(pub(\s*\([^)]*\))?\s+)?mod\s+(\w+)\s*([;{])").expect("valid regex");
    let path_attribute = Regex::new(r#"#\[path\s*=\s*"([^"]+)"\]"#).expect("valid regex");
    let mut from = 0;
    while let Some(m) = declaration.captures_at(&blanked, from) {
        let whole = m.get(0).expect("match");
        let name = m[3].to_string();
        let mut child = path.clone();
        child.push(name.clone());
        if &m[4] == "{" {
            let open = m.get(4).expect("brace").start();
            let close = matching_brace(&blanked, open).unwrap_or(blanked.len() - 1);
            // The inline module's text: its body alone, at the file's offsets.
            let mut body = blank_range(&blanked, 0, open + 1);
            body = blank_range(&body, close, body.len());
            blanked = blank_range(&blanked, whole.start(), close + 1);
            add(tree, child, file, &child_dir.join(&name), original, body)?;
            from = close + 1;
            continue;
        }
        from = whole.end();
        // `#[path = "…"]` among the attributes just before the declaration.
        let item_start = blanked[..whole.start()]
            .rfind([';', '}', '{'])
            .map_or(0, |p| p + 1);
        let attributes = &original[item_start..whole.start()];
        let child_file = match path_attribute.captures(attributes) {
            Some(a) => file.parent().unwrap_or(child_dir).join(&a[1]),
            None => {
                let flat = child_dir.join(format!("{name}.rs"));
                if flat.is_file() {
                    flat
                } else {
                    child_dir.join(&name).join("mod.rs")
                }
            }
        };
        let is_test = child_file.file_name().is_some_and(|n| n == "tests.rs")
            || child_file
                .strip_prefix(child_dir)
                .unwrap_or(&child_file)
                .components()
                .any(|c| c.as_os_str() == "tests");
        if is_test || !child_file.is_file() {
            continue;
        }
        let text = fs::read_to_string(&child_file)?;
        let child_blanked = blank_test_items(&blank_comments_and_strings(&text));
        let grandchildren = if child_file.file_name().is_some_and(|n| n == "mod.rs") {
            child_file.parent().unwrap_or(child_dir).to_path_buf()
        } else {
            child_file.with_extension("")
        };
        add(
            tree,
            child,
            &child_file,
            &grandchildren,
            &text,
            child_blanked,
        )?;
    }
    tree.insert(
        path,
        Module {
            file: file.to_path_buf(),
            text: blanked,
        },
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture;

    #[test]
    fn modules_are_found_from_the_root_without_tests() {
        let trees = crate_trees(&fixture("layers").join("clean/src")).unwrap();
        assert_eq!(trees.len(), 1);
        let paths: Vec<String> = trees[0].keys().map(|p| p.join("::")).collect();
        assert_eq!(
            paths,
            [
                "",
                "bottom",
                "leaf",
                "middle",
                "top",
                "top::driver",
                "top::driver::helper",
                "top::options"
            ]
        );
        let helper = &trees[0][&vec!["top".to_string(), "driver".into(), "helper".into()]];
        assert!(helper.file.ends_with("top/driver.rs"));
        assert!(helper.text.contains("use super::Thing;"));
        assert!(!helper.text.contains("drive("));
    }
}
