//! Rust source read as text, for the source checks: comments, strings and test items
//! blanked out, and `use` declarations expanded into the paths they import.
//!
//! Blanking replaces every byte but newlines with a space, so that a byte offset (and so
//! a line number) in the blanked text is the same as in the file. Hand-written rather than
//! on `syn`: the checks need the paths only, and a file that does not parse must still be
//! checked (the task runner depends on none of the project's crates and builds nothing).

use regex::Regex;

/// `text` with its comments, string literals and character literals blanked.
pub fn blank_comments_and_strings(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = bytes.to_vec();
    let blank = |out: &mut [u8], from: usize, to: usize| {
        for b in &mut out[from..to.min(bytes.len())] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    };
    let ident = |i: usize| i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
    let mut i = 0;
    while i < bytes.len() {
        let rest = &bytes[i..];
        let end = if rest.starts_with(b"//") {
            i + rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len())
        } else if rest.starts_with(b"/*") {
            block_comment_end(bytes, i)
        } else if rest[0] == b'"' {
            string_end(bytes, i + 1)
        } else if let Some(start) = raw_string_start(bytes, i).filter(|_| !ident(i)) {
            raw_string_end(bytes, start)
        } else if rest[0] == b'\'' {
            char_literal_end(text, i).unwrap_or(i)
        } else {
            i
        };
        if end > i {
            blank(&mut out, i, end);
            i = end;
        } else {
            i += 1;
        }
    }
    String::from_utf8(out).expect("only ASCII bytes were replaced, by spaces")
}

fn block_comment_end(bytes: &[u8], start: usize) -> usize {
    let (mut depth, mut i) = (0usize, start);
    while i + 1 < bytes.len() {
        match &bytes[i..i + 2] {
            b"/*" => {
                depth += 1;
                i += 2;
            }
            b"*/" => {
                depth -= 1;
                i += 2;
                if depth == 0 {
                    return i;
                }
            }
            _ => i += 1,
        }
    }
    bytes.len()
}

/// The end of a string whose contents start at `i` (after the opening quote).
fn string_end(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    bytes.len()
}

/// For `r"`, `r#"`, `br"`…: the offset of the `r`.
fn raw_string_start(bytes: &[u8], i: usize) -> Option<usize> {
    let r = if bytes[i] == b'b' { i + 1 } else { i };
    if bytes.get(r) != Some(&b'r') {
        return None;
    }
    let hashes = bytes[r + 1..].iter().take_while(|&&b| b == b'#').count();
    (bytes.get(r + 1 + hashes) == Some(&b'"')).then_some(r)
}

fn raw_string_end(bytes: &[u8], r: usize) -> usize {
    let hashes = bytes[r + 1..].iter().take_while(|&&b| b == b'#').count();
    let mut closing = vec![b'"'];
    closing.extend(std::iter::repeat_n(b'#', hashes));
    let body = r + 2 + hashes;
    bytes[body..]
        .windows(closing.len())
        .position(|w| w == closing.as_slice())
        .map_or(bytes.len(), |p| body + p + closing.len())
}

/// The end of the character literal at `i`, or `None` for a lifetime.
fn char_literal_end(text: &str, i: usize) -> Option<usize> {
    let rest = &text[i + 1..];
    if rest.starts_with('\\') {
        // `'\''`, `'\n'`, `'\u{..}'`: the escaped character, then the closing quote.
        return rest.get(2..)?.find('\'').map(|p| i + 1 + 2 + p + 1);
    }
    let c = rest.chars().next()?;
    rest[c.len_utf8()..]
        .starts_with('\'')
        .then(|| i + 1 + c.len_utf8() + 1)
}

/// The offset of the brace matching the `{` at `open`, in blanked text.
pub fn matching_brace(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (i, b) in text.bytes().enumerate().skip(open) {
        match b {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(i);
                }
            }
            _ => {}
        }
    }
    None
}

/// Blanked `text` (see [`blank_comments_and_strings`]) with every `#[cfg(test)]` item
/// blanked too: a test may reach anywhere.
pub fn blank_test_items(text: &str) -> String {
    let marker = Regex::new(r"#\[cfg\(test\)\]").expect("valid regex");
    let attribute = Regex::new(r"^\s*#\[[^\]]*\]").expect("valid regex");
    let use_item = Regex::new(r"^\s*(pub(\s*\([^)]*\))?\s+)?use\b").expect("valid regex");
    let mut out = text.to_string();
    while let Some(m) = marker.find(&out) {
        let mut item = m.end();
        while let Some(a) = attribute.find(&out[item..]) {
            item += a.end();
        }
        let rest = &out[item..];
        let semicolon = rest.find(';').map(|p| item + p);
        let brace = rest.find('{').map(|p| item + p);
        let end = match (semicolon, brace) {
            (Some(s), _) if use_item.is_match(rest) => s + 1,
            (Some(s), Some(b)) if s < b => s + 1,
            (_, Some(b)) => matching_brace(&out, b).map_or(out.len(), |e| e + 1),
            (Some(s), None) => s + 1,
            (None, None) => out.len(),
        };
        out = blank_range(&out, m.start(), end);
    }
    out
}

/// `text` with the bytes `from..to` blanked (newlines kept).
pub fn blank_range(text: &str, from: usize, to: usize) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for b in &mut bytes[from..to] {
        if *b != b'\n' {
            *b = b' ';
        }
    }
    String::from_utf8(bytes).expect("only bytes of a blanked (ASCII) range were replaced")
}

/// The 1-based line of byte offset `at`.
pub fn line_of(text: &str, at: usize) -> usize {
    text.as_bytes()[..at]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// One path a `use` declaration imports: `use a::{b::C as D, e::*}` imports `a::b::C`
/// (named `D`) and `a::e::*`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UsePath {
    /// The path's segments; `self` in a group is dropped (`a::{self}` is `a`), a glob's
    /// last segment is `*`.
    pub segments: Vec<String>,
    /// The name the path is known by in the importing module (its alias or last segment).
    pub name: String,
}

/// A `use` declaration of blanked text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UseDeclaration {
    /// Byte offsets of the declaration (from `pub`/`use` to its `;`).
    pub start: usize,
    /// One past its `;`.
    pub end: usize,
    /// Whether it re-exports (`pub use`, `pub(crate) use`…).
    pub public: bool,
    /// The paths it imports.
    pub paths: Vec<UsePath>,
}

/// Every `use` declaration of blanked `text`, in order (inside function bodies too).
pub fn use_declarations(text: &str) -> Vec<UseDeclaration> {
    let keyword = Regex::new(r"\b(pub(\s*\([^)]*\))?\s+)?use\s").expect("valid regex");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(m) = keyword.find_at(text, from) {
        let Some(semicolon) = text[m.end()..].find(';').map(|p| m.end() + p) else {
            break;
        };
        let tokens = tokens(&text[m.end()..semicolon]);
        let mut paths = Vec::new();
        tree(&tokens, &mut 0, &[], &mut paths);
        out.push(UseDeclaration {
            start: m.start(),
            end: semicolon + 1,
            public: m.as_str().starts_with("pub"),
            paths,
        });
        from = semicolon + 1;
    }
    out
}

fn tokens(text: &str) -> Vec<String> {
    let token = Regex::new(r"::|[{},*]|[A-Za-z_][A-Za-z0-9_]*").expect("valid regex");
    token
        .find_iter(text)
        .map(|t| t.as_str().to_string())
        .collect()
}

/// One use tree at `tokens[*at..]` under `prefix`, its paths pushed onto `out`.
fn tree(tokens: &[String], at: &mut usize, prefix: &[String], out: &mut Vec<UsePath>) {
    let mut path = prefix.to_vec();
    if tokens.get(*at).map(String::as_str) == Some("::") {
        *at += 1; // a leading `::` (an outside crate)
    }
    loop {
        match tokens.get(*at).map(String::as_str) {
            Some("{") => {
                *at += 1;
                while !matches!(tokens.get(*at).map(String::as_str), Some("}") | None) {
                    tree(tokens, at, &path, out);
                    if tokens.get(*at).map(String::as_str) == Some(",") {
                        *at += 1;
                    }
                }
                *at += 1;
                return;
            }
            Some("*") => {
                *at += 1;
                path.push("*".to_string());
                out.push(UsePath {
                    segments: path,
                    name: "*".to_string(),
                });
                return;
            }
            Some(segment) if segment != "}" && segment != "," => {
                if segment != "self" || path.is_empty() {
                    path.push(segment.to_string());
                }
                *at += 1;
                if tokens.get(*at).map(String::as_str) == Some("::") {
                    *at += 1;
                    continue;
                }
                let mut name = path.last().cloned().unwrap_or_default();
                if tokens.get(*at).map(String::as_str) == Some("as") {
                    name = tokens.get(*at + 1).cloned().unwrap_or_default();
                    *at += 2;
                }
                out.push(UsePath {
                    segments: path,
                    name,
                });
                return;
            }
            _ => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_strings_and_chars_are_blanked_in_place() {
        let text =
            "let s = \"super::a\"; // super::b\nlet c = '\"'; /* x /* y */ */ f::<'a>(r#\"q\"#);\n";
        let blanked = blank_comments_and_strings(text);
        assert_eq!(blanked.len(), text.len());
        assert_eq!(
            blanked,
            "let s =           ;            \nlet c =    ;                 f::<'a>(      );\n"
        );
    }

    #[test]
    fn test_items_are_blanked() {
        let text = "use a::b;\n#[cfg(test)]\nuse c::{d, e};\n#[cfg(test)]\n#[path = \"x\"]\nmod t;\n#[cfg(test)]\nmod tests {\n    use super::*;\n}\nfn f() {}\n";
        let blanked = blank_test_items(&blank_comments_and_strings(text));
        assert!(blanked.starts_with("use a::b;\n"), "{blanked}");
        assert!(blanked.ends_with("\nfn f() {}\n"), "{blanked}");
        assert!(!blanked.contains("use c"), "{blanked}");
        assert!(!blanked.contains("mod"), "{blanked}");
        assert_eq!(line_of(&blanked, blanked.find("fn f").unwrap()), 11);
    }

    #[test]
    fn use_trees_are_expanded() {
        let text = "pub use super::{cost::{self, Grid as G}, e::*};\nuse crate::fit;\nfn f() { use std::fmt; }";
        let uses = use_declarations(text);
        let paths: Vec<(String, &str, bool)> = uses
            .iter()
            .flat_map(|u| {
                u.paths
                    .iter()
                    .map(move |p| (p.segments.join("::"), p.name.as_str(), u.public))
            })
            .collect();
        assert_eq!(
            paths,
            [
                ("super::cost".to_string(), "cost", true),
                ("super::cost::Grid".to_string(), "G", true),
                ("super::e::*".to_string(), "*", true),
                ("crate::fit".to_string(), "fit", false),
                ("std::fmt".to_string(), "fmt", false),
            ]
        );
    }
}
