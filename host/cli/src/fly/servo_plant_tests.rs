use super::*;
use aircraft::{ServoOutput, Swash, SwashKind};
use sweephold_firmware::mixer::mix;

/// Commands across the envelope the mixer passes unclamped with standard servos
/// (|col| + |cyclic| ≤ about 1: heights within ±0.5 of the centre at 400 µs each... the
/// 1100–1940 µs limits clamp beyond 1.05 up, 1.05 down).
fn commands() -> Vec<[f32; 4]> {
    let mut out = Vec::new();
    for &lat in &[-0.6, -0.25, 0.0, 0.3, 0.55] {
        for &lon in &[-0.5, 0.0, 0.2, 0.45] {
            for &(ped, col) in &[(0.0, 0.0), (-0.7, 0.3), (0.8, -0.4)] {
                out.push([lat, lon, ped, col]);
            }
        }
    }
    out
}

fn swash(kind: SwashKind, phase_deg: f64, lead: u8, reversed: [bool; 3]) -> Swash {
    let mut swash = Swash {
        kind,
        phase: phase_deg.to_radians(),
        lead,
        ..Swash::default()
    };
    for (servo, reversed) in swash.servos.iter_mut().zip(reversed) {
        servo.reversed = reversed;
    }
    swash
}

#[test]
fn the_inverse_returns_the_firmware_mixers_command_for_every_swash_type() {
    let narrow_tail = ServoOutput {
        reversed: true,
        centre_us: 760.0,
        throw_us: 200.0,
        min_us: 550.0,
        max_us: 970.0,
    };
    let mut worst: f64 = 0.0;
    for kind in [
        SwashKind::H1,
        SwashKind::H3_120,
        SwashKind::H3_135,
        SwashKind::H3_140,
    ] {
        for phase in [0.0, 30.0, -45.0] {
            for lead in 1..=3 {
                for reversed in [[false; 3], [false, true, false], [true, false, true]] {
                    let mut aircraft = swash(kind, phase, lead, reversed);
                    aircraft.tail = narrow_tail;
                    let board = board_mixer(&aircraft);
                    let geometry = ServoGeometry::new(&aircraft);
                    for command in commands() {
                        let pulses = mix(&board, &Controls::from_array(command));
                        let back = geometry.controls(pulses);
                        for (got, sent) in back.iter().zip(command) {
                            let error = (got - f64::from(sent)).abs();
                            worst = worst.max(error);
                            // One µs of rounding per servo: 1/400 of a height unit,
                            // 1/200 of a stick; the inverse adds at most a factor 2.
                            assert!(
                                error < 0.011,
                                "{kind:?} phase {phase} lead {lead} {reversed:?}: {command:?} -> {pulses:?} -> {back:?}"
                            );
                        }
                    }
                }
            }
        }
    }
    // The round trip is not exact (µs pulses), but close.
    assert!(worst > 0.0 && worst < 0.011, "{worst}");
}

#[test]
fn a_board_mixing_for_another_plate_or_direction_tilts_the_plate_otherwise() {
    let aircraft = swash(SwashKind::H3_140, 0.0, 1, [false, true, false]);
    let geometry = ServoGeometry::new(&aircraft);
    let command = Controls::from_array([0.4, 0.0, 0.0, 0.2]);
    let right = geometry.controls(mix(&board_mixer(&aircraft), &command));
    assert!(
        (right[0] - 0.4).abs() < 0.011 && right[1].abs() < 0.011,
        "{right:?}"
    );
    // The board mixes 120° on the 140° plate: pure lat comes out 1.32× too strong
    // (sin 120° / sin 140°) and nothing else.
    let wrong_type = swash(SwashKind::H3_120, 0.0, 1, [false, true, false]);
    let got = geometry.controls(mix(&board_mixer(&wrong_type), &command));
    assert!((got[0] - 0.4 * 0.866 / 0.643).abs() < 0.02, "{got:?}");
    // Servo 2 not reversed on the board: pure collective tilts the plate.
    let wrong_direction = swash(SwashKind::H3_140, 0.0, 1, [false; 3]);
    let collective = Controls::from_array([0.0, 0.0, 0.0, 0.4]);
    let got = geometry.controls(mix(&board_mixer(&wrong_direction), &collective));
    assert!(got[0].abs() + got[1].abs() > 0.3, "{got:?}");
    let right = geometry.controls(mix(&board_mixer(&aircraft), &collective));
    assert!(right[0].abs() + right[1].abs() < 0.011, "{right:?}");
}

#[test]
fn the_presets_geometry_is_the_firmware_default_mixer() {
    assert_eq!(
        board_mixer(&Swash::default()),
        sweephold_firmware::mixer::MixerConfig::trex700l()
    );
    let geometry = ServoGeometry::new(&Swash::default());
    assert_eq!(geometry.controls([1520; 4]), [0.0; 4]);
    assert_eq!(
        board_frame_rates(&Swash::default()),
        [sweephold_firmware::params::typed::DEFAULT_FRAME_HZ; 2]
    );
}

#[test]
fn servos_take_a_new_pulse_only_when_a_frame_starts() {
    // 333 Hz frames (3003 µs): every 5 ms tick's pulse reaches the servos.
    let mut hold = FrameHold::new(333, 333, [1520; 4]);
    for k in 0..400u64 {
        let pulse = 1500 + (k % 7) as u16;
        assert_eq!(
            hold.tick(k * 5000, 5000, [pulse; 4]),
            [pulse; 4],
            "tick {k}"
        );
    }
    // 50 Hz frames (20 ms): one tick in four; the others hold the last.
    let mut hold = FrameHold::new(50, 333, [1520; 4]);
    let mut reached = 0;
    for k in 0..400u64 {
        let pulse = 1500 + k as u16;
        let held = hold.tick(k * 5000, 5000, [pulse; 4]);
        assert_eq!(held[3], pulse, "the tail at 333 Hz, tick {k}");
        if held[0] == pulse {
            reached += 1;
        } else {
            assert!(held[0] < pulse && held[0] + 4 > pulse, "tick {k}: {held:?}");
        }
    }
    assert_eq!(reached, 100);
}
