//! `sweephold fly`: the firmware's tick in lockstep with the simulator.

use clap::Parser;
use sweephold_tests::{fly, fly_args, Scratch};

/// The same seed gives byte-identical dumps; another seed does not.
#[test]
fn same_seed_same_bytes() {
    let (a, b, c) = (
        Scratch::new("seed-a"),
        Scratch::new("seed-b"),
        Scratch::new("seed-c"),
    );
    let run = |dir: &Scratch, seed: &str| {
        let out = dir.path().to_str().unwrap();
        fly(&fly_args(&[
            "--axes", "lat", "--t-rec", "10", "--seed", seed, "--out", out,
        ]))
    };
    let first = run(&a, "7");
    run(&b, "7");
    run(&c, "8");
    for dump in &first.dumps {
        let name = dump.file_name().unwrap();
        let bytes_a = std::fs::read(a.path().join(name)).unwrap();
        let bytes_b = std::fs::read(b.path().join(name)).unwrap();
        let bytes_c = std::fs::read(c.path().join(name)).unwrap();
        assert!(
            bytes_a.len() > 100_000,
            "a real record: {} bytes",
            bytes_a.len()
        );
        assert_eq!(
            bytes_a, bytes_b,
            "{name:?} differs between two runs of seed 7"
        );
        assert_ne!(bytes_a, bytes_c, "{name:?} is the same for seeds 7 and 8");
    }
    let summary_a = std::fs::read_to_string(a.path().join("summary.json")).unwrap();
    let summary_b = std::fs::read_to_string(b.path().join("summary.json")).unwrap();
    assert_eq!(summary_a, summary_b);
}

/// The pilot moving the stick aborts the test with `pilot_override`, at the time given.
#[test]
fn pilot_override_aborts() {
    let dir = Scratch::new("override");
    let out = dir.path().to_str().unwrap();
    let outcome = fly(&fly_args(&[
        "--axes",
        "lon",
        "--t-rec",
        "20",
        "--pilot-override",
        "4",
        "--out",
        out,
    ]));
    for run in &outcome.summary.runs {
        assert!(run.aborted, "{}", run.file);
        assert_eq!(run.abort_reason.as_deref(), Some("pilot_override"));
        // Arming after 10 idle ticks (0.05 s), override at 4 s after arming.
        assert!(
            (run.duration_s - 4.05).abs() < 0.02,
            "aborted at {} s",
            run.duration_s
        );
    }
}

/// A sensor that keeps dropping samples aborts the test as stale.
#[test]
fn sensor_dropout_aborts_as_stale() {
    let dir = Scratch::new("dropout");
    let out = dir.path().to_str().unwrap();
    let outcome = fly(&fly_args(&[
        "--axes",
        "lat",
        "--t-rec",
        "20",
        "--sensor-dropout",
        "0.6",
        "--out",
        out,
    ]));
    for run in &outcome.summary.runs {
        assert_eq!(
            run.abort_reason.as_deref(),
            Some("sensor_stale"),
            "{}",
            run.file
        );
    }
}

/// Spikes and gusts end in the documented behaviour — the hold, or an abort on a limit —
/// and never in an error of the tool.
#[test]
fn spikes_and_gusts_end_in_hold_or_a_limit_abort() {
    let dir = Scratch::new("spike");
    let out = dir.path().to_str().unwrap();
    let outcome = fly(&fly_args(&[
        "--axes",
        "lat,ped",
        "--t-rec",
        "20",
        "--sensor-spike",
        "0.01",
        "--gust",
        "1.0",
        "--out",
        out,
    ]));
    assert_eq!(outcome.summary.runs.len(), 4);
    for run in &outcome.summary.runs {
        match run.abort_reason.as_deref() {
            None => assert!(run.max_abs_deg.phi < 20.0 && run.max_abs_deg.theta < 20.0),
            Some(reason) => assert!(
                ["attitude_limit", "rate_limit"].contains(&reason),
                "{}: unexpected abort {reason}",
                run.file
            ),
        }
    }
}

/// Bad arguments are refused before anything is flown or written.
#[test]
fn bad_configuration_is_refused_up_front() {
    let dir = Scratch::new("refused");
    let out = dir.path().join("never");
    let out_arg = out.to_str().unwrap();
    // The command line refuses a rate outside 50–1000 Hz while it is read; a caller
    // that builds the arguments itself meets the firmware's own refusal.
    assert!(sweephold::Cli::try_parse_from(["sweephold", "fly", "--rate", "20"]).is_err());
    // (arguments, a rate set after parsing, a word the error must name)
    let cases: [(&[&str], Option<u16>, &str); 2] = [
        (&["--axes", "lat"], Some(20), "rate"),
        // The linearized plant has no wind input: a gust level is refused, not ignored.
        (
            &["--linearized-plant", "--gust", "1"],
            None,
            "--linearized-plant",
        ),
    ];
    for (arguments, rate_hz, named) in cases {
        let mut all = arguments.to_vec();
        all.extend(["--out", out_arg]);
        let mut args = fly_args(&all);
        if let Some(rate_hz) = rate_hz {
            args.rate_hz = rate_hz;
        }
        let error = sweephold::fly::fly(&args, &|| {
            Box::new(sweephold::fly::link::InProcessLink::new())
        })
        .err()
        .unwrap_or_else(|| panic!("{arguments:?} is refused"));
        assert!(error.to_string().contains(named), "{arguments:?}: {error}");
        assert!(!out.exists(), "{arguments:?}: nothing written");
    }
}

/// The paper's comparison on shortened (20 s) lateral records over three seeds: conditional
/// attitude hold flies without an abort within 10° of trim, and decorrelates the controls far
/// better than the standard feedback loop.
///
/// Measured (seeds 1–3, mean of the six lateral records, four-period coherence windows):
/// `cah` 0.21, `standard` 0.75, `noise` 0.28. The bounds below leave room for the spread
/// between seeds of such short records; at full length (90 s, seeds 1–6) `cah` reads
/// 0.18–0.24 and `standard` 0.84–0.85 (the mean over seeds is the figure judged: docs/results.md).
#[test]
fn conditional_hold_decorrelates_the_controls() {
    let mean_lat_lon = |mode: &str| -> f64 {
        let mut values = Vec::new();
        for seed in ["1", "2", "3"] {
            let dir = Scratch::new(&format!("relations-{mode}-{seed}"));
            let out = dir.path().to_str().unwrap();
            let outcome = fly(&fly_args(&[
                "--mode", mode, "--axes", "lat", "--t-rec", "20", "--seed", seed, "--out", out,
            ]));
            for run in &outcome.summary.runs {
                assert!(
                    !run.aborted,
                    "{mode} seed {seed} {}: {:?}",
                    run.file, run.abort_reason
                );
                if mode == "cah" {
                    // Within 10° of the trim the record captured (the presets measure the
                    // hold's thresholds from it).
                    let from_trim = run.max_from_trim_deg.as_ref().expect("a captured trim");
                    assert!(
                        from_trim.phi <= 10.0 && from_trim.theta <= 10.0,
                        "{}: |phi|, |theta| from trim {}, {}",
                        run.file,
                        from_trim.phi,
                        from_trim.theta
                    );
                }
                values.push(run.cross_coherence["lon"]);
            }
        }
        values.iter().sum::<f64>() / values.len() as f64
    };
    let cah = mean_lat_lon("cah");
    let standard = mean_lat_lon("standard");
    let noise = mean_lat_lon("noise");
    eprintln!(
        "lat-lon cross-control coherence: cah {cah:.3}, standard {standard:.3}, noise {noise:.3}"
    );
    assert!(cah <= 0.25, "cah {cah}");
    assert!(standard >= 0.65, "standard {standard}");
    assert!(standard - cah >= 0.4, "standard {standard} vs cah {cah}");
}
