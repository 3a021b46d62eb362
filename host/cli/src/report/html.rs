//! The page around the figures: one self-contained HTML document (inline CSS, no script,
//! nothing fetched), at most 1280 px wide, and its tables.

use std::fmt::Write as _;

pub use crate::plot::draw::escape;
use crate::plot::PlotError;

/// The page's style: a centred column at most 1280 px wide (no sideways scroll at that
/// width), figures scaled to the column, wide tables scrolling inside their own box.
const STYLE: &str = "\
*{box-sizing:border-box}\
body{margin:0;font-family:system-ui,sans-serif;color:#222;background:#fff}\
main{max-width:1280px;margin:0 auto;padding:16px 24px}\
h1{font-size:1.6em;margin:.4em 0}h2{font-size:1.25em;margin:1.6em 0 .4em;border-bottom:1px solid #ccc}\
p.note{color:#555;font-size:.92em;max-width:60em}\
figure{margin:8px 0 18px;max-width:100%}figcaption{font-size:.9em;color:#444}\
svg{display:block;max-width:100%;height:auto}\
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(min(560px,100%),1fr));gap:8px 20px}\
.table{max-width:100%;overflow-x:auto}\
table{border-collapse:collapse;font-size:.9em;margin:6px 0}\
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right;white-space:nowrap}\
th{background:#f2f2f2}td.name,th.name{text-align:left}\
td.flag{background:#fde2d6}td.flag:last-child{text-align:left}td.good{background:#dff3e4}td.bad{background:#fbd3d3}\
";

/// A whole page.
pub fn page(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<main>\n{body}</main>\n</body>\n</html>\n",
        escape(title)
    )
}

/// A `<section>` with an id (the check and the tests find the plot sections by it).
pub fn section(id: &str, heading: &str, content: &str) -> String {
    format!(
        "<section id=\"{}\">\n<h2>{}</h2>\n{content}</section>\n",
        escape(id),
        escape(heading)
    )
}

/// A figure (an inline `<svg>`) with a caption; a drawing that failed is said in its place.
pub fn figure(svg: Result<String, PlotError>, caption: &str) -> String {
    match svg {
        Ok(svg) => format!(
            "<figure>{svg}<figcaption>{}</figcaption></figure>\n",
            escape(caption)
        ),
        Err(error) => note(&format!("{caption}: {error}")),
    }
}

/// A paragraph of explanatory text.
pub fn note(text: &str) -> String {
    format!("<p class=\"note\">{}</p>\n", escape(text))
}

/// How a table cell is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// Plain.
    Plain,
    /// Left-aligned name.
    Name,
    /// Meets its guideline.
    Good,
    /// Misses its guideline.
    Bad,
    /// An accuracy flag.
    Flag,
}

/// One table cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// Text.
    pub text: String,
    /// Highlight.
    pub mark: Mark,
}

impl Cell {
    /// A plain cell.
    pub fn plain(text: impl Into<String>) -> Self {
        Cell {
            text: text.into(),
            mark: Mark::Plain,
        }
    }

    /// A left-aligned name cell.
    pub fn name(text: impl Into<String>) -> Self {
        Cell {
            text: text.into(),
            mark: Mark::Name,
        }
    }

    /// A cell marked good or bad by `ok`.
    pub fn judged(text: impl Into<String>, ok: bool) -> Self {
        Cell {
            text: text.into(),
            mark: if ok { Mark::Good } else { Mark::Bad },
        }
    }

    /// A cell with `mark`.
    pub fn marked(text: impl Into<String>, mark: Mark) -> Self {
        Cell {
            text: text.into(),
            mark,
        }
    }
}

/// A table (first header left-aligned, like the name column).
pub fn table(headers: &[&str], rows: &[Vec<Cell>]) -> String {
    let mut out = String::from("<div class=\"table\"><table>\n<tr>");
    for (i, header) in headers.iter().enumerate() {
        let class = if i == 0 { " class=\"name\"" } else { "" };
        let _ = write!(out, "<th{class}>{}</th>", escape(header));
    }
    out.push_str("</tr>\n");
    for row in rows {
        out.push_str("<tr>");
        for cell in row {
            let class = match cell.mark {
                Mark::Plain => "",
                Mark::Name => " class=\"name\"",
                Mark::Good => " class=\"good\"",
                Mark::Bad => " class=\"bad\"",
                Mark::Flag => " class=\"flag\"",
            };
            let _ = write!(out, "<td{class}>{}</td>", escape(&cell.text));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</table></div>\n");
    out
}

/// `value` with `digits` decimals, or `-`.
pub fn number(value: Option<f64>, digits: usize) -> String {
    match value {
        Some(v) if v.is_finite() => format!("{v:.digits$}"),
        Some(_) => "inf".to_string(),
        None => "-".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_is_self_contained_and_escaped() {
        let body = section(
            "s",
            "A < B",
            &table(
                &["name", "x"],
                &[vec![Cell::name("p&q"), Cell::judged("1", true)]],
            ),
        );
        let html = page("t", &body);
        assert!(html.contains("max-width:1280px"));
        assert!(
            !html.contains("<script") && !html.contains("http://") && !html.contains("https://")
        );
        assert!(
            html.contains("A &lt; B")
                && html.contains("p&amp;q")
                && html.contains("class=\"good\"")
        );
        assert_eq!(number(Some(1.234), 1), "1.2");
        assert_eq!(number(None, 1), "-");
    }
}
