//! The CI steps that run cargo and the outside tools, each printing when it starts.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use crate::report::Report;

/// A step's failure: the one line `cargo xtask` prints after `error: `.
pub type StepResult = Result<(), String>;

/// The workspace root and where cargo builds, shared by every step.
pub struct Workspace {
    /// The workspace root (the folder above `xtask/`).
    pub root: PathBuf,
    /// Cargo's target dir: `CARGO_TARGET_DIR` or `target/` in the root.
    pub target: PathBuf,
    started: Instant,
    /// Seconds between the run's start (`SWEEPHOLD_CI_START`, Unix seconds, set by
    /// `.ci/run`) and this process's start, so that the step times read on one clock.
    offset_s: u64,
}

impl Workspace {
    /// The workspace this binary was built from.
    pub fn new() -> Self {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"))
            .parent()
            .expect("xtask/ is inside the workspace")
            .to_path_buf();
        let target = std::env::var_os("CARGO_TARGET_DIR")
            .map(PathBuf::from)
            .map(|t| root.join(t))
            .unwrap_or_else(|| root.join("target"));
        let now = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let offset_s = std::env::var("SWEEPHOLD_CI_START")
            .ok()
            .and_then(|s| s.parse::<u64>().ok())
            .map(|start| now.saturating_sub(start))
            .unwrap_or(0);
        Workspace {
            root,
            target,
            started: Instant::now(),
            offset_s,
        }
    }

    /// Prints a step's start like `.ci/run` did: seconds since the run began, so that a
    /// slow step shows in the log.
    pub fn step(&self, title: &str) {
        println!("\n=== [{:4}s] {title}", self.seconds());
    }

    /// Seconds since the run began.
    pub fn seconds(&self) -> u64 {
        self.offset_s + self.started.elapsed().as_secs()
    }

    /// A command run in the workspace root.
    pub fn command(&self, program: &str, args: &[&str]) -> Command {
        let mut command = Command::new(program);
        command.args(args).current_dir(&self.root);
        command
    }

    /// `cargo ARGS` in the workspace root.
    pub fn cargo(&self, args: &[&str]) -> Command {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
        self.command(&cargo, args)
    }

    /// The flight-controller image `cargo fw` builds.
    pub fn fc_elf(&self) -> PathBuf {
        self.target
            .join("thumbv7em-none-eabihf/firmware/sweephold-fc")
    }

    /// The bench image (feature bench-imu), built in its own target dir.
    pub fn bench_elf(&self) -> PathBuf {
        self.target
            .join("fw-bench/thumbv7em-none-eabihf/firmware/sweephold-fc")
    }

    /// The host tool of the test build (`cargo test --workspace` builds it for the CLI's
    /// integration tests).
    pub fn host_tool(&self) -> PathBuf {
        self.target.join("debug/sweephold")
    }
}

/// Runs a command to its end; its failure names it.
pub fn run(command: &mut Command) -> StepResult {
    let shown = format!("{command:?}");
    let status = command
        .status()
        .map_err(|e| format!("cannot start {shown}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{shown} failed ({status})"))
    }
}

/// Prints a source check's lines; fails when the check did.
pub fn print_report(name: &str, report: std::io::Result<Report>) -> StepResult {
    let report = report.map_err(|e| format!("{name}: {e}"))?;
    for line in &report.lines {
        println!("{line}");
    }
    if report.failed {
        Err(format!("{name} failed"))
    } else {
        Ok(())
    }
}

/// The flash and RAM budgets of an image: the boards' STM32F405 has 1 MiB flash and
/// 192 KiB SRAM; the image keeps to a quarter of the flash and half of the RAM. It fits
/// far tighter limits today (148 KiB text, 16 KiB static RAM): those are checked too, so
/// growth shows before it matters. The tight flash limit was 144 KiB until table version 7:
/// the pilot mode's eight gain parameters and their typed view took the SpeedyBee image
/// from 147 428 B (28 B under it) to 148 236 B, and the gains belong in the table (tuned
/// per aircraft and pushed, not compiled in); 148 KiB keeps some 3 KiB of warning room.
pub fn check_budgets(ws: &Workspace, elf: &Path) -> StepResult {
    let output = ws
        .command("size", &[])
        .arg(elf)
        .output()
        .map_err(|e| format!("cannot run size (apt-get install binutils): {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "size {} failed: {}",
            elf.display(),
            String::from_utf8_lossy(&output.stderr).trim()
        ));
    }
    let table = String::from_utf8_lossy(&output.stdout);
    print!("{table}");
    let (flash, ram) = flash_and_ram(&table)?;
    println!(
        "flash text+data {flash} B (limit 262144, tight 151552), static RAM data+bss {ram} B (limit 98304, tight 16384)"
    );
    match over_budget(flash, ram) {
        Some(why) => Err(format!("{}: {why}", elf.display())),
        None => Ok(()),
    }
}

/// Flash (text + data) and static RAM (data + bss) in bytes, from `size`'s table.
fn flash_and_ram(table: &str) -> Result<(u64, u64), String> {
    let sizes: Vec<u64> = table
        .lines()
        .last()
        .unwrap_or_default()
        .split_whitespace()
        .take(3)
        .map(|n| {
            n.parse()
                .map_err(|_| format!("cannot read size's output: {table}"))
        })
        .collect::<Result<_, _>>()?;
    match sizes[..] {
        [text, data, bss] => Ok((text + data, data + bss)),
        _ => Err(format!("cannot read size's output: {table}")),
    }
}

/// The first budget an image breaks, if any.
fn over_budget(flash: u64, ram: u64) -> Option<&'static str> {
    let budgets = [
        (flash, 262_144, "image flash over 256 KiB"),
        (ram, 98_304, "static RAM over 96 KiB"),
        (flash, 151_552, "image flash over the tight 148 KiB"),
        (ram, 16_384, "static RAM over the tight 16 KiB"),
    ];
    budgets
        .iter()
        .find(|(used, limit, _)| used > limit)
        .map(|&(_, _, why)| why)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn size_table_gives_flash_and_ram() {
        let table = "   text\t   data\t    bss\t    dec\t    hex\tfilename\n 140000\t    880\t   6744\t 147624\t  240a8\tsweephold-fc\n";
        assert_eq!(flash_and_ram(table), Ok((140_880, 7_624)));
        assert!(flash_and_ram("size: nothing\n").is_err());
    }

    #[test]
    fn budgets_name_the_first_one_broken() {
        assert_eq!(over_budget(140_880, 7_624), None);
        assert_eq!(
            over_budget(151_553, 7_624),
            Some("image flash over the tight 148 KiB")
        );
        assert_eq!(
            over_budget(140_880, 16_385),
            Some("static RAM over the tight 16 KiB")
        );
        assert_eq!(
            over_budget(300_000, 100_000),
            Some("image flash over 256 KiB")
        );
        assert_eq!(
            over_budget(100_000, 100_000),
            Some("static RAM over 96 KiB")
        );
    }
}
