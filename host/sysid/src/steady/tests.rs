use sweephold_protocol::{Axis, Controls, HoldState, Measurements, Phase, Sample};

use super::*;
use crate::fit::trim::TrimPoints;
use crate::random::SplitMix64;

const RATE_HZ: f64 = 50.0;

/// A Sample at `tick` in `phase` with rates, attitude (φ, θ, ψ), pilot sticks and commands.
fn sample(
    tick: u32,
    phase: Phase,
    rates: [f64; 3],
    attitude: [f64; 3],
    sticks: [f64; 4],
) -> Sample {
    let c = Controls::from_array(sticks.map(|v| v as f32));
    Sample {
        tick,
        phase,
        primary: Axis::Lat,
        sweep_omega: 0.0,
        hold: [HoldState::Released; 3],
        command: c,
        sweep: Controls::default(),
        noise: Controls::default(),
        pilot: c,
        meas: Measurements {
            p: rates[0] as f32,
            q: rates[1] as f32,
            r: rates[2] as f32,
            phi: attitude[0] as f32,
            theta: attitude[1] as f32,
            psi: attitude[2] as f32,
            ..Measurements::default()
        },
    }
}

/// A synthetic flight at 50 Hz: 8 s of hover, a 4 s roll manoeuvre, 8 s forward at
/// 1 m/s (θ −0.03 rad, lon stick −0.04), 3 s of a third condition (too short), then 8 s
/// of a test's sweep held as still as the hover (not the pilot's flight). Gyro noise
/// 0.02 rad/s, attitude noise 0.002 rad, GNSS at 10 Hz with 0.1 m/s noise.
fn flight() -> (Vec<Sample>, Vec<GnssFix>) {
    let mut rng = SplitMix64::new(7);
    let mut samples = Vec::new();
    let mut fixes = Vec::new();
    let stretches: [(f64, Phase, &str); 5] = [
        (8.0, Phase::Idle, "hover"),
        (4.0, Phase::Idle, "manoeuvre"),
        (8.0, Phase::Idle, "forward"),
        (3.0, Phase::Idle, "short"),
        (8.0, Phase::Sweep, "test"),
    ];
    let mut tick = 100_u32;
    for (seconds, phase, what) in stretches {
        for k in 0..(seconds * RATE_HZ) as usize {
            let t = k as f64 / RATE_HZ;
            let (mut rates, mut attitude, sticks, velocity) = match what {
                "manoeuvre" => {
                    let w = 2.0 * std::f64::consts::PI;
                    (
                        [0.5 * (w * t).sin(), 0.0, 0.0],
                        [0.08 * (1.0 - (w * t).cos()), 0.0, 0.0],
                        [0.2 * (w * t).sin(), 0.0, 0.0, 0.3],
                        [0.0, 0.4 * t, 0.0],
                    )
                }
                "forward" => (
                    [0.0; 3],
                    [0.0, -0.03, 0.0],
                    [0.0, -0.04, 0.0, 0.31],
                    [1.0, 0.0, 0.0],
                ),
                "short" => (
                    [0.0; 3],
                    [0.03, 0.0, 0.0],
                    [0.03, 0.0, 0.0, 0.3],
                    [0.0, 1.0, 0.0],
                ),
                _ => ([0.0; 3], [0.0; 3], [0.0, 0.0, 0.0, 0.3], [0.0; 3]),
            };
            for v in &mut rates {
                *v += 0.02 * rng.normal_pair().0;
            }
            for v in &mut attitude[..2] {
                *v += 0.002 * rng.normal_pair().0;
            }
            samples.push(sample(tick, phase, rates, attitude, sticks));
            if tick.is_multiple_of(5) {
                let mut noisy = velocity;
                for v in &mut noisy {
                    *v += 0.1 * rng.normal_pair().0;
                }
                fixes.push(GnssFix {
                    tick,
                    velocity_ned: noisy,
                    heading: 0.0,
                });
            }
            tick += 1;
        }
    }
    (samples, fixes)
}

#[test]
fn the_segment_finder_finds_the_steady_stretches_and_rejects_the_manoeuvre() {
    let (samples, fixes) = flight();
    let segments = find_steady_segments(&samples, &fixes, RATE_HZ, &STEADINESS_RULE);
    assert_eq!(segments.len(), 2, "{segments:#?}");
    let [hover, forward] = [&segments[0], &segments[1]];
    // Inside their stretches: hover ticks 100–499, forward 700–1099.
    assert!(
        hover.ticks[0] >= 100 && hover.ticks[1] <= 499,
        "{:?}",
        hover.ticks
    );
    assert!(
        forward.ticks[0] >= 700 && forward.ticks[1] <= 1099,
        "{:?}",
        forward.ticks
    );
    assert!(hover.blocks >= 7 && forward.blocks >= 7);
    assert_eq!(forward.point.label, "steady 2");
    // 80 fixes of 0.1 m/s noise: a standard error near 0.011 m/s; 5 of them is 0.056.
    let u_se = forward.standard_error[0];
    assert!(u_se > 0.003 && u_se < 0.03, "u_se {u_se}");
    let [u, v, w, ..] = forward.point.states;
    for (got, want) in [(u, 1.0), (v, 0.0), (w, 0.0)] {
        assert!((got - want).abs() < 0.06, "{got} vs {want}");
    }
    assert!((forward.point.states[7] + 0.03).abs() < 0.002);
    assert!((forward.point.controls[1] + 0.04).abs() < 1e-6);
    assert!(hover.point.states[0].abs() < 0.06);
}

#[test]
fn a_manoeuvre_alone_gives_no_segment() {
    let (samples, fixes) = flight();
    let manoeuvre: Vec<Sample> = samples
        .into_iter()
        .filter(|s| (500..700).contains(&s.tick))
        .collect();
    assert!(find_steady_segments(&manoeuvre, &fixes, RATE_HZ, &STEADINESS_RULE).is_empty());
}

#[test]
fn the_trim_point_file_reads_as_trim_points() {
    let (samples, fixes) = flight();
    let segments = find_steady_segments(&samples, &fixes, RATE_HZ, &STEADINESS_RULE);
    let csv = steady_trim_points_csv(&segments);
    assert!(csv.starts_with("label,u,v,w,p,q,r,phi,theta,lat,lon,ped,col,u_se,"));
    let points = TrimPoints::parse_csv(&csv).unwrap();
    assert_eq!(points.points.len(), 2);
    assert_eq!(points.points[1], segments[1].point);
}

#[test]
fn the_velocity_turns_into_the_body_axes() {
    // Heading east, flying east at 1 m/s: forward. Pitched nose-down 0.1 rad: part of it
    // along the body's z.
    let [u, v, w] = segments::ned_to_body([0.0, 1.0, 0.0], 0.0, -0.1, std::f64::consts::FRAC_PI_2);
    assert!((u - 0.1_f64.cos()).abs() < 1e-12 && v.abs() < 1e-12);
    assert!((w + 0.1_f64.sin()).abs() < 1e-12, "{w}");
}

#[test]
fn gnss_files_round_trip_and_errors_name_their_line() {
    let fixes = vec![
        GnssFix {
            tick: 10,
            velocity_ned: [1.0, -0.5, 0.25],
            heading: 0.5,
        },
        GnssFix {
            tick: 30,
            velocity_ned: [0.0, 0.0, 0.0],
            heading: -3.0,
        },
    ];
    assert_eq!(parse_gnss_csv(&gnss_csv(&fixes)).unwrap(), fixes);
    let cases = [
        ("", "line 1: no header line"),
        (
            "t,vn,ve,vd,heading\n",
            "line 1: the header must be `tick,vn,ve,vd,heading`, not `t,vn,ve,vd,heading`",
        ),
        ("tick,vn,ve,vd,heading\n", "line 1: no fix after the header"),
        (
            "tick,vn,ve,vd,heading\n1,0,0\n",
            "line 2: 3 fields, the header has 5",
        ),
        (
            "tick,vn,ve,vd,heading\n-1,0,0,0,0\n",
            "line 2: `tick` is not a tick count: `-1`",
        ),
        (
            "tick,vn,ve,vd,heading\n1,0,NaN,0,0\n",
            "line 2: `ve` is not a finite number: `NaN`",
        ),
        (
            "tick,vn,ve,vd,heading\n1,200,0,0,0\n",
            "line 2: a speed of 200.0 m/s is not plausible (at most 150 m/s)",
        ),
        (
            "tick,vn,ve,vd,heading\n1,0,0,0,4\n",
            "line 2: `heading` = 4 lies outside ±π rad",
        ),
        (
            "tick,vn,ve,vd,heading\n# a comment\n5,0,0,0,0\n5,0,0,0,0\n",
            "line 4: tick 5 is not after the previous fix's 5",
        ),
    ];
    for (text, message) in cases {
        assert_eq!(
            parse_gnss_csv(text).unwrap_err().to_string(),
            message,
            "{text:?}"
        );
    }
}
