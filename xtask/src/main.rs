//! `cargo xtask`: every check CI runs, one subcommand each, and `ci` for all of them in
//! CI's order (`.ci/run` installs what a fresh machine needs, then calls `cargo xtask ci`).
//!
//! A workspace member binary run through the cargo alias `xtask` (`.cargo/config.toml`),
//! the pattern of defmt's xtask: the checks are Rust, so CI needs no Python for them.
//!
//! **Its room and what it may import.** The project's checks and CI steps, nothing of
//! the product. It depends on none of the project's crates (it reads the sources as text
//! and runs cargo as a subprocess, so a crate that does not build cannot stop a check)
//! and on two well-kept crates: clap for the subcommands and their help, regex for the
//! source checks ported from Python with the same expressions.

mod file_sizes;
mod import_cycles;
mod layers;
mod links;
mod module_tree;
mod report;
mod rust_text;
mod steps;

use clap::{Parser, Subcommand};

use steps::{check_budgets, print_report, run, StepResult, Workspace};

/// sweephold's task runner: each subcommand runs one check CI runs; `ci` runs them all.
#[derive(Parser)]
#[command(name = "cargo xtask", version)]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand, Clone, Copy, PartialEq, Eq, Debug)]
enum Task {
    /// Formatting: `cargo fmt --all -- --check`.
    Fmt,
    /// Docs: every relative link of README.md and docs/ names a file inside the project
    /// and, with `#anchor`, one of its headings.
    Links,
    /// No two modules of a crate import each other; `sweephold identify`'s code names
    /// neither the simulator nor its truth.
    ImportCycles,
    /// Inside a crate, imports go down: no module imports from an ancestor's file (it
    /// imports from the module that defines the item), and each crate with a stated
    /// order of its top-level modules keeps it (sysid: `models, steady > fit > frf > document,
    /// records, random`). Other crates' findings are listed, not enforced.
    Layers,
    /// No non-test source file over its size limit (600 lines, every crate).
    FileSizes {
        /// One limit for every file instead of the rules.
        limit: Option<usize>,
    },
    /// Clippy on the host workspace, all targets, warnings are errors.
    Clippy,
    /// Clippy on the firmware for thumbv7em-none-eabihf: the default board, the bench IMU
    /// and the Matek F405-TE board.
    FwClippy,
    /// `cargo doc` of the workspace's crates, warnings are errors.
    Doc,
    /// The README's test command: `cargo test --workspace`.
    Test,
    /// The two boards' images and the bench image, with the flash/RAM budget check.
    Images,
    /// The QEMU tests (in the loop byte for byte, IMU, SBUS, arming) and the QEMU boot
    /// check of the image (netduinoplus2); builds the images and the test build if missing.
    Qemu,
    /// A quick campaign and its HTML report checked in headless Chromium.
    Report,
    /// Every check above, in CI's order, printing each step's start time.
    Ci,
}

impl Task {
    /// CI's order: the cheap source checks first, then lints, docs, tests, images, QEMU.
    const CI: [Task; 12] = [
        Task::Fmt,
        Task::Links,
        Task::ImportCycles,
        Task::Layers,
        Task::FileSizes { limit: None },
        Task::Clippy,
        Task::FwClippy,
        Task::Doc,
        Task::Test,
        Task::Images,
        Task::Qemu,
        Task::Report,
    ];

    fn title(self) -> &'static str {
        match self {
            Task::Fmt => "cargo fmt --check",
            Task::Links => "docs: no dead link, nothing outside the project",
            Task::ImportCycles => "no import circle between the modules of a crate",
            Task::Layers => "no upward import inside a crate, its layer order kept",
            Task::FileSizes { .. } => "no non-test source file over 600 lines",
            Task::Clippy => "clippy (host workspace)",
            Task::FwClippy => "clippy (firmware, thumbv7em-none-eabihf)",
            Task::Doc => "cargo doc (warnings are errors)",
            Task::Test => "tests (the README's test command)",
            Task::Images => "images: the two boards' and the bench image, with their budgets",
            Task::Qemu => "QEMU: the QEMU tests and the boot check (netduinoplus2)",
            Task::Report => "campaign --quick and its report in headless Chromium",
            Task::Ci => "ci",
        }
    }

    fn run(self, ws: &Workspace) -> StepResult {
        match self {
            Task::Fmt => run(&mut ws.cargo(&["fmt", "--all", "--", "--check"])),
            Task::Links => print_report("links", links::check(&ws.root)),
            Task::ImportCycles => print_report(
                "import-cycles",
                import_cycles::check(&ws.root, import_cycles::CRATES, import_cycles::SEPARATED),
            ),
            Task::Layers => print_report("layers", layers::check(&ws.root, layers::CRATES)),
            Task::FileSizes { limit } => {
                print_report("file-sizes", file_sizes::check(&ws.root, limit))
            }
            Task::Clippy => run(&mut ws.cargo(&[
                "clippy",
                "--workspace",
                "--all-targets",
                "--",
                "-D",
                "warnings",
            ])),
            Task::FwClippy => fw_clippy(ws),
            Task::Doc => {
                let mut doc = ws.cargo(&["doc", "--workspace", "--no-deps"]);
                doc.env("RUSTDOCFLAGS", "-D warnings");
                run(&mut doc)
            }
            Task::Test => run(&mut ws.cargo(&["test", "--workspace"])),
            Task::Images => images(ws),
            Task::Qemu => qemu(ws),
            Task::Report => campaign_report(ws),
            Task::Ci => {
                for task in Task::CI {
                    ws.step(task.title());
                    let started = ws.seconds();
                    task.run(ws)?;
                    println!("--- {} s", ws.seconds() - started);
                }
                ws.step("done");
                run(ws.command("du", &["-sh"]).arg(&ws.target))
            }
        }
    }
}

fn fw_clippy(ws: &Workspace) -> StepResult {
    run(&mut ws.cargo(&["fw-clippy", "--", "-D", "warnings"]))?;
    // Same target dir: only the board crate and the flight logic are checked again.
    for board in [
        "sweephold-board/bench-imu",
        "sweephold-board/board-matek-f405-te",
    ] {
        run(&mut ws.cargo(&["fw-clippy", "--features", board, "--", "-D", "warnings"]))?;
    }
    Ok(())
}

fn images(ws: &Workspace) -> StepResult {
    let elf = ws.fc_elf();
    println!("second board's image (Matek F405-TE, feature board-matek-f405-te)");
    // Same target dir: only the board crate is rebuilt for the feature. Kept aside, since
    // the default image below takes its place.
    run(&mut ws.cargo(&["fw", "--features", "board-matek-f405-te"]))?;
    let matek = ws.target.join("sweephold-fc-matek-f405-te");
    std::fs::copy(&elf, &matek).map_err(|e| format!("cannot copy {} aside: {e}", elf.display()))?;
    check_budgets(ws, &matek)?;
    println!("firmware image (SpeedyBee F405 V4)");
    run(&mut ws.cargo(&["fw"]))?;
    check_budgets(ws, &elf)?;
    println!(
        "bench image (feature bench-imu: the emulated IMU at rest, for the QEMU arming tests)"
    );
    bench_image(ws)?;
    run(ws.command("size", &[]).arg(ws.bench_elf()))
}

fn bench_image(ws: &Workspace) -> StepResult {
    let dir = ws.target.join("fw-bench");
    let mut build = ws.cargo(&["fw", "--features", "bench-imu", "--target-dir"]);
    build.arg(dir);
    run(&mut build)
}

/// The test build, of which the QEMU steps use the host tool: nothing to do after
/// `cargo xtask test`. The same package set as the README's command, so that cargo
/// resolves the same features and rebuilds nothing.
fn test_build(ws: &Workspace) -> StepResult {
    run(&mut ws.cargo(&["test", "--workspace", "--no-run"]))
}

fn qemu(ws: &Workspace) -> StepResult {
    // Nothing to build after `cargo xtask images` and `test`.
    run(&mut ws.cargo(&["fw"]))?;
    bench_image(ws)?;
    test_build(ws)?;
    println!("QEMU: in the loop byte for byte, the IMU, SBUS and arming (tests/qemu.rs, for real)");
    // `--workspace`: the features of the test build, which `-p sweephold-tests` alone
    // would change (and so rebuild the CLI and its dependencies).
    let mut tests = ws.cargo(&["test", "--workspace", "--test", "qemu", "--", "--nocapture"]);
    tests
        .env("SWEEPHOLD_REQUIRE_QEMU", "1")
        .env("SWEEPHOLD_FC_ELF", ws.fc_elf())
        .env("SWEEPHOLD_FC_BENCH_ELF", ws.bench_elf());
    run(&mut tests)?;
    println!("QEMU boot check (netduinoplus2)");
    let mut boot = ws.command("bash", &[".ci/qemu-boot-check.sh"]);
    boot.arg(ws.fc_elf()).arg(ws.host_tool());
    run(&mut boot)?;
    // The check decodes into /dev/null: it must still be the device afterwards.
    use std::os::unix::fs::FileTypeExt;
    match std::fs::metadata("/dev/null") {
        Ok(meta) if meta.file_type().is_char_device() => Ok(()),
        _ => Err("/dev/null is no longer a character device".to_string()),
    }
}

fn campaign_report(ws: &Workspace) -> StepResult {
    test_build(ws)?;
    let out = ws.target.join("ci-campaign");
    let mut campaign = ws.command(
        &ws.host_tool().to_string_lossy(),
        &["campaign", "--quick", "--quiet", "--out"],
    );
    campaign.arg(&out);
    run(&mut campaign)?;
    let mut check = ws.command("bash", &[".ci/report-check.sh"]);
    check.arg(out.join("report.html"));
    run(&mut check)
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let ws = Workspace::new();
    match cli.task.run(&ws) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            std::process::ExitCode::FAILURE
        }
    }
}
