//! `sweephold fly --fc qemu` speed: the board image in QEMU in lockstep with the simulator.
//! Target: each QEMU instance at least 20× faster than real time (≥ 4000 ticks/s at
//! 200 Hz).
//!
//! `cargo fw && cargo bench -p sweephold --bench fly_qemu` (release host; the image from
//! `cargo fw`, or `SWEEPHOLD_FC_ELF`). Flies the paper's two 90 s lateral sweep records
//! (two workers, one QEMU each) five times per transport and prints the medians; the
//! same campaign in-process gives the host's own share of the time. Skips with a message
//! when qemu-system-arm or the image is missing.

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use sweephold::fly::link::{FlightControllerLink, InProcessLink};
use sweephold::fly::link_qemu::{self, QemuLink, QemuTransport};
use sweephold::{Cli, Command};

/// Median wall time [s] of `runs` campaigns, and the flight seconds of one.
fn median_campaign(
    runs: usize,
    campaign: &[&str],
    make_link: &(dyn Fn() -> Box<dyn FlightControllerLink> + Sync),
) -> (f64, f64, usize) {
    let out = std::env::temp_dir().join(format!("sweephold-bench-qemu-{}", std::process::id()));
    let mut argv = vec![
        "sweephold",
        "fly",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    argv.extend(campaign);
    let Command::Fly(args) = Cli::parse_from(argv).command else {
        unreachable!()
    };
    let mut times = Vec::new();
    let (mut flown_s, mut records) = (0.0, 0);
    for _ in 0..runs {
        let start = Instant::now();
        let outcome = sweephold::fly::fly(&args, make_link).expect("campaign flies");
        times.push(start.elapsed().as_secs_f64());
        flown_s = outcome.summary.runs.iter().map(|r| r.duration_s).sum();
        records = outcome.summary.runs.len();
        assert!(outcome.summary.runs.iter().all(|r| !r.aborted));
    }
    std::fs::remove_dir_all(&out).ok();
    times.sort_by(f64::total_cmp);
    (times[runs / 2], flown_s, records)
}

fn main() {
    let image = match link_qemu::qemu_available().and_then(|()| {
        match std::env::var_os("SWEEPHOLD_FC_ELF") {
            Some(path) => Ok(PathBuf::from(path)),
            None => link_qemu::default_image(),
        }
    }) {
        Ok(image) => image,
        Err(why) => {
            println!("fly_qemu: skipped: {why}");
            return;
        }
    };
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(2);
    let campaign = ["--axes", "lat", "--seed", "3"];
    let (local_s, flown_s, records) =
        median_campaign(5, &campaign, &|| Box::new(InProcessLink::new()));
    println!("in-process: {records} records, {flown_s:.0} s of flight, median {local_s:.2} s wall");
    for (transport, runs, campaign) in [
        (QemuTransport::Semihosting, 5, &campaign[..]),
        // ~200 ticks/s: a 7 s doublet is enough to measure it.
        (
            QemuTransport::Usart,
            3,
            &["--axes", "lat", "--input", "doublet", "--seed", "3"][..],
        ),
    ] {
        let (wall_s, flown_s, records) = median_campaign(runs, campaign, &|| {
            Box::new(QemuLink::new(&image, transport, &[]))
        });
        // Records fly in parallel, one QEMU per worker: per instance, each flies
        // flown_s / min(workers, records) seconds of flight in wall_s.
        let parallel = workers.min(records) as f64;
        let ticks_per_s = flown_s * 200.0 / parallel / wall_s;
        println!(
            "{}: {records} records, {flown_s:.0} s of flight, median {wall_s:.2} s wall: \
             {ticks_per_s:.0} ticks/s per QEMU ({:.1}x real time), {:.2}x the 4000 ticks/s target",
            transport.link_name(),
            ticks_per_s / 200.0,
            ticks_per_s / 4000.0
        );
    }
}
