//! The swash geometry against the published mixers.
//!
//! References (the lead cross-checks them against the sources):
//!
//! * Rotorflight, `src/main/flight/mixer.c`, `mixerUpdateSwash`: with SR, SP, SC its
//!   roll, pitch and collective inputs,
//!   - 120: `S1 = ½SC − SP`, `S2/S3 = ½SC ± 0.86602540·SR + 0.5·SP`
//!   - 135: `S1 = ½SC − SP`, `S2/S3 = ½SC ± 0.70710678·SR + 0.70710678·SP`
//!   - 140: `S1 = ½SC − SP`, `S2/S3 = ½SC ± 0.64278760·SR + 0.76604444·SP`.
//!
//!   Its servo 1 is our lead output (ψ = 0) and its SP, SR are −lon, −lat in our
//!   convention (S1 = −SP = +lon raises the front servo: nose up), so a Rotorflight row
//!   `roll·SR + pitch·SP` is our `lon·cos − lat·sin` with cos = −pitch, sin = roll.
//! * ArduPilot, `libraries/AP_Motors/AP_MotorsHeli_Swash.cpp`,
//!   `calculate_roll_pitch_collective_factors`: generic H3 `roll = cos(pos + 90° −
//!   phase)`, `pitch = cos(pos − phase)`, servo = `roll·R + pitch·P` (R right roll, P
//!   nose-up pitch: our lat and lon), so cos = pitch and sin = −roll; its fixed H3_120
//!   table is roll (0.866025, −0.866025, 0), pitch (0.5, 0.5, −1), servo 3 the rear
//!   elevator (positions −60°, 60°, 180°). H1: output 1 roll, output 2 pitch, output 3
//!   collective.

use super::*;

fn assert_factors(geometry: &SwashGeometry, expected: [(f32, f32); 3], tolerance: f32) {
    for (output, (got, want)) in geometry.factors().iter().zip(expected).enumerate() {
        assert!(
            (got.0 - want.0).abs() <= tolerance && (got.1 - want.1).abs() <= tolerance,
            "output {}: got {:?}, want {:?}",
            output + 1,
            got,
            want
        );
    }
}

/// Rotorflight's (roll, pitch) row of S1, S2, S3 to our (cos, sin): (−pitch, roll).
/// Its constants are kept as printed (eight digits, f64).
fn from_rotorflight(rows: [(f64, f64); 3]) -> [(f32, f32); 3] {
    rows.map(|(roll, pitch)| (-pitch as f32, roll as f32))
}

#[test]
fn the_default_geometry_is_the_ccpm_120_mixer_of_before() {
    // The exact constants of the former mixer: (cos ψ, sin ψ) at 0°, 120°, 240°.
    let before = [(1.0, 0.0), (-0.5, 0.866_025_4), (-0.5, -0.866_025_4)];
    assert_eq!(SwashGeometry::H3_120.factors(), before);
    assert_eq!(
        SwashGeometry::new(SwashType::H3_120, 0.0, 1),
        Ok(SwashGeometry::H3_120)
    );
}

#[test]
// Rotorflight's constants as it prints them, 0.70710678 included.
#[allow(clippy::approx_constant)]
fn ccpm_factors_match_rotorflight() {
    let cases = [
        (
            SwashType::H3_120,
            [(0.0, -1.0), (0.866_025_40, 0.5), (-0.866_025_40, 0.5)],
        ),
        (
            SwashType::H3_135,
            [
                (0.0, -1.0),
                (0.707_106_78, 0.707_106_78),
                (-0.707_106_78, 0.707_106_78),
            ],
        ),
        (
            SwashType::H3_140,
            [
                (0.0, -1.0),
                (0.642_787_60, 0.766_044_44),
                (-0.642_787_60, 0.766_044_44),
            ],
        ),
    ];
    for (kind, rows) in cases {
        let geometry = SwashGeometry::new(kind, 0.0, 1).unwrap();
        // Rotorflight prints eight digits; f32 carries about seven.
        assert_factors(&geometry, from_rotorflight(rows), 1e-7);
    }
}

/// ArduPilot's generic H3 factors for servo positions `positions_deg` and phase.
fn ardupilot_h3(positions_deg: [f64; 3], phase_deg: f64) -> [(f32, f32); 3] {
    positions_deg.map(|pos| {
        let roll = (pos + 90.0 - phase_deg).to_radians().cos();
        let pitch = (pos - phase_deg).to_radians().cos();
        (pitch as f32, -roll as f32)
    })
}

#[test]
fn ccpm_factors_match_ardupilot_generic_h3() {
    // Our plate with the lead servo at the rear is ours turned by φ = 180°: the lead
    // output sits at the rear and the outputs after it (clockwise) at −(180° − A) and
    // +(180° − A). With output 3 leading that is ArduPilot's numbering (servo 1 left,
    // servo 2 right, servo 3 elevator in the rear).
    for (kind, side) in [
        (SwashType::H3_120, 60.0),
        (SwashType::H3_135, 45.0),
        (SwashType::H3_140, 40.0),
    ] {
        let geometry = SwashGeometry::new(kind, 180.0, 3).unwrap();
        assert_factors(&geometry, ardupilot_h3([-side, side, 180.0], 0.0), 1e-6);
    }
    // A phase angle: ArduPilot subtracts it from every position.
    for phase in [-30.0f32, -7.5, 12.0, 30.0] {
        let geometry = SwashGeometry::new(SwashType::H3_120, phase, 1).unwrap();
        let expected = ardupilot_h3([0.0, 120.0, 240.0], f64::from(phase));
        assert_factors(&geometry, expected, 1e-6);
    }
}

#[test]
fn ardupilot_h3_120_table_is_our_plate_with_the_rear_servo_leading() {
    // AP_MotorsHeli_Swash H3_120: roll (0.866025, −0.866025, 0), pitch (0.5, 0.5, −1).
    let table = [(0.5, -0.866_025), (0.5, 0.866_025), (-1.0, 0.0)];
    let geometry = SwashGeometry::new(SwashType::H3_120, 180.0, 3).unwrap();
    assert_factors(&geometry, table, 1e-6);
}

#[test]
fn the_lead_servo_permutes_the_outputs() {
    let (c, s) = (-0.766_044_4, 0.642_787_6);
    let lead2 = SwashGeometry::new(SwashType::H3_140, 0.0, 2).unwrap();
    assert_eq!(lead2.factors(), [(c, -s), (1.0, 0.0), (c, s)]);
    let lead3 = SwashGeometry::new(SwashType::H3_140, 0.0, 3).unwrap();
    assert_eq!(lead3.factors(), [(c, s), (c, -s), (1.0, 0.0)]);
}

#[test]
fn a_phase_of_90_degrees_turns_fore_aft_into_lateral() {
    // h(ψ) = lon·cos(ψ − 90°) = lon·sin ψ: 0 at the front, +√3/2 at 120°, −√3/2 at
    // 240°, which is what −lat gives without a phase angle.
    let geometry = SwashGeometry::new(SwashType::H3_120, 90.0, 1).unwrap();
    let turned = geometry.heights(0.0, 1.0, 1.0, 0.0);
    let plain = SwashGeometry::H3_120.heights(-1.0, 0.0, 1.0, 0.0);
    for (a, b) in turned.iter().zip(plain) {
        assert!((a - b).abs() < 1e-6, "{turned:?} vs {plain:?}");
    }
}

#[test]
fn h1_passes_lateral_longitudinal_and_collective_through() {
    let h1 = SwashGeometry::new(SwashType::H1, 0.0, 1).unwrap();
    assert_eq!(h1.heights(0.4, 0.0, 0.5, 0.0), [0.2, 0.0, 0.0]);
    assert_eq!(h1.heights(0.0, -0.4, 0.5, 0.0), [0.0, -0.2, 0.0]);
    assert_eq!(h1.heights(0.0, 0.0, 0.5, 0.3), [0.0, 0.0, 0.3]);
    // A phase of 90°: lon' = lat, lat' = −lon.
    let turned = SwashGeometry::new(SwashType::H1, 90.0, 1).unwrap();
    let [a, b, c] = turned.heights(0.0, 1.0, 1.0, 0.0);
    assert!((a + 1.0).abs() < 1e-6 && b.abs() < 1e-6 && c == 0.0);
}

#[test]
fn bad_geometry_is_refused() {
    use SwashError::*;
    assert_eq!(
        SwashGeometry::new(SwashType::H3_120, f32::NAN, 1),
        Err(PhaseOutOfRange)
    );
    assert_eq!(
        SwashGeometry::new(SwashType::H3_120, 180.5, 1),
        Err(PhaseOutOfRange)
    );
    assert_eq!(
        SwashGeometry::new(SwashType::H3_120, 0.0, 0),
        Err(LeadOutOfRange)
    );
    assert_eq!(
        SwashGeometry::new(SwashType::H3_120, 0.0, 4),
        Err(LeadOutOfRange)
    );
}

#[test]
fn swash_type_codes_round_trip() {
    for kind in [
        SwashType::H1,
        SwashType::H3_120,
        SwashType::H3_135,
        SwashType::H3_140,
    ] {
        assert_eq!(SwashType::from_code(kind.code()), Some(kind));
    }
    assert_eq!(SwashType::from_code(90), None);
}

#[test]
fn the_ring_limits_the_cyclic_vector_and_keeps_its_direction() {
    assert_eq!(limit_to_ring(0.3, 0.4, 1.0), (0.3, 0.4));
    let (lat, lon) = limit_to_ring(1.0, 1.0, 1.0);
    assert!((lat - core::f32::consts::FRAC_1_SQRT_2).abs() < 1e-7 && lat == lon);
    let (lat, lon) = limit_to_ring(-0.6, 0.8, 0.5);
    assert!((lat + 0.3).abs() < 1e-7 && (lon - 0.4).abs() < 1e-7);
    // The default ring, 1.5, never touches commands within ±1.
    assert_eq!(limit_to_ring(-1.0, 1.0, 1.5), (-1.0, 1.0));
}

/// `unmix` inverts `heights` on every plate, phase and lead servo.
#[test]
fn unmix_returns_the_cyclic_and_collective_heights() {
    for kind in [
        SwashType::H3_120,
        SwashType::H3_135,
        SwashType::H3_140,
        SwashType::H1,
    ] {
        for phase_deg in [-30.0, 0.0, 12.5, 90.0] {
            for lead in 1..=3 {
                let geometry = SwashGeometry::new(kind, phase_deg, lead).unwrap();
                for (lat, lon, collective) in [(0.3, -0.2, 0.1), (-0.45, 0.0, -0.25)] {
                    let heights = geometry.heights(lat, lon, 1.0, collective);
                    let (l, o, c) = geometry.unmix(heights).unwrap();
                    let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
                    assert!(
                        close(l, lat) && close(o, lon) && close(c, collective),
                        "{kind:?} {phase_deg}° lead {lead}: {:?}",
                        (l, o, c)
                    );
                }
            }
        }
    }
}
