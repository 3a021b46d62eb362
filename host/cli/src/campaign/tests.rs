use std::ffi::OsString;

use super::*;

#[test]
fn the_trim_balance_default_is_per_vehicle_and_an_explicit_one_wins() {
    use CampaignTrimBalance as C;
    let (bo105, trex) = (Vehicle::shipped("bo105"), Vehicle::shipped("trex700l"));
    assert_eq!(C::Default.for_vehicle(&bo105), TrimBalanceArg::Hold);
    assert_eq!(C::Default.for_vehicle(&trex), TrimBalanceArg::Joint);
    for vehicle in [&bo105, &trex] {
        assert_eq!(C::Hold.for_vehicle(vehicle), TrimBalanceArg::Hold);
        assert_eq!(C::Joint.for_vehicle(vehicle), TrimBalanceArg::Joint);
    }
    let parsed: CampaignArgs = verb_args("campaign", Vec::<OsString>::new()).unwrap();
    assert_eq!(
        (parsed.trim_points, parsed.trim_balance),
        (TrimPointsArg::On, C::Default)
    );
}

#[test]
fn a_failed_stage_keeps_the_previous_campaign_and_its_own_files() {
    let dir = std::env::temp_dir().join(format!("sweephold-stage-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("campaign");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join(files::SUMMARY), "previous").unwrap();
    std::fs::write(out.join(files::REPORT), "previous report").unwrap();
    let args = CampaignArgs {
        vehicle: Vehicle::shipped("bo105"),
        out: out.clone(),
        seed: 7,
        quick: true,
        trim_points: TrimPointsArg::On,
        trim_balance: CampaignTrimBalance::Default,
        amplitude: AmplitudeArg::Fixed,
        fc: CampaignLink::InProcess,
        strict: false,
        quiet: true,
        priors: None,
    };
    let mut run = Campaign::new(&args);
    run.stage(Stage::Setup, Campaign::set_up).unwrap();
    std::fs::write(run.dir().join(files::FRF), "this run's").unwrap();
    let error = run
        .stage(Stage::Frf, |_| -> anyhow::Result<((), String)> {
            Err(anyhow!("no coherent pair"))
        })
        .unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("`frf` failed: no coherent pair"),
        "{message}"
    );
    assert!(message.contains("campaign.failed"), "{message}");
    assert_eq!(
        std::fs::read_to_string(out.join(files::SUMMARY)).unwrap(),
        "previous"
    );
    assert_eq!(
        std::fs::read_to_string(out.join(files::REPORT)).unwrap(),
        "previous report"
    );
    assert!(!out.join(files::FRF).exists());
    let failed = dir.join("campaign.failed");
    assert_eq!(
        std::fs::read_to_string(failed.join(files::FRF)).unwrap(),
        "this run's"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(failed.join(files::SUMMARY)).unwrap())
            .unwrap();
    assert_eq!(summary["error"]["stage"], "frf");
    assert_eq!(summary["seed"], 7);
    assert!(!dir.join("campaign.partial").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The stages run the verbs on their defaults: these are what the campaign's files
/// were made with (a default that changes changes the campaign's output).
#[test]
fn the_verbs_defaults_are_the_campaigns_settings() {
    let frf: crate::frf::FrfArgs = verb_args("frf", ["lat-1.bin".into()]).unwrap();
    assert_eq!(frf.options(), sysid::frf::FrfOptions::default());
    let fit: crate::fit::FitArgs = verb_args(
        "fit",
        ["--frf", "frf.json", "--model", "bo105-6dof", "--seed", "7"].map(OsString::from),
    )
    .unwrap();
    let expected = sysid::fit::FitOptions {
        seed: 7,
        ..sysid::fit::FitOptions::default()
    };
    assert_eq!(fit.options(None), expected);
    let verify: crate::verify::VerifyArgs = verb_args(
        "verify",
        ["--model", "model9.json", "lat-1.bin"].map(OsString::from),
    )
    .unwrap();
    assert_eq!(verify.segment, None);
    assert_eq!(verify.bias.mode(), sysid::fit::verify::BiasMode::Trim);
    let error = verb_args::<crate::frf::FrfArgs>("frf", Vec::new()).unwrap_err();
    assert!(
        error.to_string().starts_with("`frf` arguments: "),
        "{error}"
    );
}

/// The headline gives each mode's largest excursion from its captured trim beside the
/// absolute attitude, and leaves it out for a mode that captured none.
#[test]
fn the_headline_shows_the_excursion_from_trim() {
    use crate::artifacts::summary::{ModeSummary, PeakAttitudeDeg};
    let mode = |from_trim: Option<PeakAttitudeDeg>| ModeSummary {
        cross_coherence_lat_lon: Some(0.2),
        max_abs_deg: PeakAttitudeDeg {
            phi: 14.0,
            theta: 9.5,
        },
        max_from_trim_deg: from_trim,
        aborts: 0,
        records: 6,
        folder: "fly-cah".into(),
    };
    let summary = CampaignSummary {
        vehicle: "trex700l".into(),
        link: "in-process".into(),
        seed: 1,
        verification_seed: 2,
        t_rec_s: 90.0,
        quick: false,
        modes: Modes {
            cah: Some(mode(Some(PeakAttitudeDeg {
                phi: 9.24,
                theta: 9.76,
            }))),
            standard: Some(mode(None)),
            noise: None,
        },
        fit: None,
        verify: None,
        timings_s: BTreeMap::new(),
        error: None,
    };
    let text = headline(&summary);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert!(
        lines[0].starts_with("cah ")
            && lines[0]
                .contains("max |phi| 14.0°, |theta| 9.5° (from trim 9.2°, 9.8°), 0 abort(s)"),
        "{text}"
    );
    assert!(
        lines[1].contains("|theta| 9.5°, 0 abort(s)") && !lines[1].contains("from trim"),
        "{text}"
    );
}
