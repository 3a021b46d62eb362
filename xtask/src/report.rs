//! What a source check found: the lines it prints and whether it failed.

/// The output of one source check (links, import circles, file sizes).
#[derive(Debug, Default)]
pub struct Report {
    /// The lines to print, in order: findings first, then the summary.
    pub lines: Vec<String>,
    /// True when the check found something that fails CI.
    pub failed: bool,
}

impl Report {
    /// Adds a line to print.
    pub fn line(&mut self, line: String) {
        self.lines.push(line);
    }
}

/// A fixture tree of the xtask crate's tests (`xtask/tests/fixtures/NAME`).
#[cfg(test)]
pub fn fixture(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}
