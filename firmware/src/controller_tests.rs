//! Tests of the sequencer, the hold, the safety checks and the telemetry, run through the
//! public API and decoded with the protocol's own decoder.

use super::*;
use crate::excitation_scale::ExcitationScale;
use crate::slew::{CommandSlew, HoldSlew};
use proptest::prelude::*;
use sweephold_protocol::{Decoder, InputKind, PilotInput, WARN_RECORD_SHORT};

const DEG: f32 = core::f32::consts::PI / 180.0;
const PILOT: [f32; 4] = [0.05, -0.1, 0.02, 0.3];

/// Bo-105 lateral sweep shortened for tests: 10 s record (flagged short), 0.5 s fades,
/// 0.1 s trim capture.
/// The Bo-105 preset with a short record and the paper's hold thresholds (6° / 4° from
/// level), which the rule tests below are written in.
fn short_config() -> Config {
    let mut config = Config::bo105_default(Axis::Lat);
    config.test.hold_engage_rad = 6.0 * DEG;
    config.test.hold_release_rad = 4.0 * DEG;
    config.hold_reference = HoldReference::Level;
    config.test.sweep.t_rec_s = 10.0;
    config.test.sweep.fade_s = 0.5;
    config.trim_capture_s = 0.1;
    config
}

fn calm_input() -> SensorIn {
    SensorIn {
        seq: 0,
        meas: Measurements {
            theta: 0.04,
            az: -9.81,
            ..Measurements::default()
        },
        pilot: PilotInput {
            sticks: Controls::from_array(PILOT),
            test_switch: true,
        },
    }
}

/// A controller, the input it will get next, and every frame it emitted (decoded).
struct Rig {
    fc: FlightController,
    input: SensorIn,
    frames: Vec<Frame>,
    last_tick_frames: Vec<Frame>,
    decoder: Decoder,
}

impl Rig {
    fn new(config: Config) -> Self {
        Rig {
            fc: FlightController::new(config).expect("valid config"),
            input: calm_input(),
            frames: Vec::new(),
            last_tick_frames: Vec::new(),
            decoder: Decoder::new(),
        }
    }

    /// One tick with a fresh sensor sample.
    fn step(&mut self) -> Output {
        self.input.seq = self.input.seq.wrapping_add(1);
        self.step_same_seq()
    }

    /// One tick repeating the previous `seq` (a stale sensor sample).
    fn step_same_seq(&mut self) -> Output {
        let mut bytes = Vec::new();
        let output = self.fc.step(&self.input, &mut bytes);
        self.last_tick_frames = self
            .decoder
            .feed(&bytes)
            .map(|frame| frame.expect("every emitted frame decodes"))
            .collect();
        let Some(Frame::Sample(sample)) = self.last_tick_frames.last() else {
            panic!("the last frame of a tick must be its Sample");
        };
        assert_eq!(sample.command, output.command);
        self.frames.extend(self.last_tick_frames.iter().copied());
        output
    }

    fn sample(&self) -> Sample {
        match self.last_tick_frames.last() {
            Some(Frame::Sample(sample)) => *sample,
            _ => panic!("no sample"),
        }
    }

    /// The Sample of the tick before the last one.
    fn frames_sample_before_last(&self) -> Sample {
        let samples = self.frames.iter().filter_map(|f| match f {
            Frame::Sample(sample) => Some(*sample),
            _ => None,
        });
        match samples.collect::<Vec<_>>().as_slice() {
            [.., before, _] => *before,
            _ => panic!("fewer than two samples"),
        }
    }

    fn tick_events(&self) -> Vec<Event> {
        events(&self.last_tick_frames)
    }

    fn run_until(&mut self, phase: Phase) {
        for _ in 0..100_000 {
            if self.fc.phase() == phase {
                return;
            }
            self.step();
        }
        panic!("never reached {phase:?}");
    }

    /// Arm, capture trim and run a second into the sweep record.
    fn into_sweep(config: Config) -> Self {
        let mut rig = Rig::new(config);
        rig.run_until(Phase::Sweep);
        for _ in 0..200 {
            rig.step();
        }
        assert_eq!(rig.fc.phase(), Phase::Sweep);
        rig
    }
}

fn events(frames: &[Frame]) -> Vec<Event> {
    frames
        .iter()
        .filter_map(|frame| match frame {
            Frame::Event(event) => Some(*event),
            _ => None,
        })
        .collect()
}

fn phase_changes(frames: &[Frame]) -> Vec<(Phase, Phase)> {
    events(frames)
        .into_iter()
        .filter_map(|event| match event {
            Event::PhaseChange { from, to, .. } => Some((from, to)),
            _ => None,
        })
        .collect()
}

#[test]
fn a_whole_test_round_trips_through_the_decoder() {
    let mut rig = Rig::new(short_config());
    let mut outputs = Vec::new();
    while rig.fc.phase() != Phase::Done {
        outputs.push(rig.step());
        assert!(outputs.len() < 10_000);
    }
    use Phase::*;
    assert_eq!(
        phase_changes(&rig.frames),
        [
            (Idle, Armed),
            (Armed, TrimCapture),
            (TrimCapture, FadeIn),
            (FadeIn, Sweep),
            (Sweep, FadeOut),
            (FadeOut, Done)
        ]
    );
    // One Header, right before the Armed → TrimCapture change, with the short-record flag.
    let headers: Vec<usize> = (0..rig.frames.len())
        .filter(|&i| matches!(rig.frames[i], Frame::Header(_)))
        .collect();
    assert_eq!(headers.len(), 1);
    let Frame::Header(header) = rig.frames[headers[0]] else {
        unreachable!()
    };
    assert_eq!(header, rig.fc.header());
    assert_eq!(header.test.warnings, WARN_RECORD_SHORT);
    assert_eq!(header.rate_hz, 200);
    assert!(matches!(
        rig.frames[headers[0] + 1],
        Frame::Event(Event::PhaseChange {
            from: Armed,
            to: TrimCapture,
            ..
        })
    ));
    // One Sample per tick, consecutive, matching the returned outputs.
    let samples: Vec<Sample> = rig
        .frames
        .iter()
        .filter_map(|f| match f {
            Frame::Sample(s) => Some(*s),
            _ => None,
        })
        .collect();
    assert_eq!(samples.len(), outputs.len());
    for (i, (sample, output)) in samples.iter().zip(&outputs).enumerate() {
        assert_eq!(sample.tick, i as u32);
        assert_eq!(sample.command, output.command);
    }
    assert_eq!(rig.fc.tick(), outputs.len() as u32);
    let reply = outputs[7].actuator_out(7, 8);
    assert_eq!(
        (reply.tick, reply.seq, reply.command),
        (7, 8, samples[7].command)
    );
    // The trim is the pilot's sticks and the attitude.
    let trims: Vec<Event> = events(&rig.frames)
        .into_iter()
        .filter(|e| matches!(e, Event::TrimCaptured { .. }))
        .collect();
    assert_eq!(trims.len(), 1);
    let Event::TrimCaptured { sticks, theta, .. } = trims[0] else {
        unreachable!()
    };
    assert_eq!(sticks, Controls::from_array(PILOT));
    assert!((theta - 0.04).abs() < 1e-6);
    // Timeline: 20 trim ticks, 0.5 s fade, 10 s record, 0.5 s fade at 200 Hz.
    let count = |phase: Phase| samples.iter().filter(|s| s.phase == phase).count();
    assert_eq!(count(FadeIn), 100);
    assert_eq!(count(Sweep), 2000);
    assert_eq!(count(FadeOut), 100);
    // sweep_omega: ω_min … ω_max, increasing, in the record; 0 outside the excitation.
    let omegas: Vec<f32> = samples
        .iter()
        .filter(|s| s.phase == Sweep)
        .map(|s| s.sweep_omega)
        .collect();
    assert!((omegas[0] - 0.3).abs() < 1e-6);
    assert!((omegas[omegas.len() - 1] - 31.4).abs() / 31.4 < 0.01);
    assert!(omegas.windows(2).all(|w| w[1] > w[0]));
    assert!(samples
        .iter()
        .filter(|s| matches!(s.phase, Idle | Armed | TrimCapture | Done))
        .all(|s| s.sweep_omega == 0.0));
}

#[test]
fn commands_are_trim_plus_sweep_plus_noise_and_the_collective_is_untouched() {
    let mut rig = Rig::into_sweep(short_config());
    let mut noise_seen = [false; 3];
    for _ in 0..400 {
        rig.step();
        let s = rig.sample();
        assert_eq!(s.hold, [HoldState::Released; 3]);
        let [lat, lon, ped, col] = PILOT;
        assert!((s.command.lat - (lat + s.sweep.lat)).abs() < 1e-6);
        assert!((s.command.lon - (lon + s.noise.lon)).abs() < 1e-6);
        assert!((s.command.ped - (ped + s.noise.ped)).abs() < 1e-6);
        assert_eq!(s.command.col, col);
        assert_eq!((s.noise.lat, s.noise.col, s.sweep.col), (0.0, 0.0, 0.0));
        assert!(s.sweep.lat.abs() <= 0.05);
        noise_seen[1] |= s.noise.lon != 0.0;
        noise_seen[2] |= s.noise.ped != 0.0;
    }
    assert_eq!(noise_seen, [false, true, true]);
}

/// The largest tick-to-tick move of each command over the excitation, with the heading
/// 20° and the roll 8° off trim from the start (both holds engage) and the measured roll
/// rate flipping between ±0.5 rad/s every half second (the roll hold's damping term steps).
fn largest_steps(config: Config) -> [f32; 4] {
    let mut rig = Rig::into_sweep(config);
    let trim = rig.fc.trim();
    rig.input.meas.psi = trim.psi + 20.0 * DEG;
    rig.input.meas.phi = trim.phi + 8.0 * DEG;
    rig.input.meas.r = 1.0;
    let mut last = rig.sample().command.to_array();
    let mut largest = [0.0f32; 4];
    let mut tick = 0;
    while rig.fc.phase() != Phase::Done {
        tick += 1;
        rig.input.meas.p = if (tick / 100) % 2 == 0 { 0.5 } else { -0.5 };
        rig.step();
        assert_ne!(rig.fc.phase(), Phase::Aborted);
        let command = rig.sample().command.to_array();
        if rig.fc.phase() != Phase::Done {
            for ((big, now), before) in largest.iter_mut().zip(command).zip(last) {
                *big = big.max((now - before).abs());
            }
        }
        last = command;
    }
    largest
}

#[test]
fn a_slew_limit_bounds_every_step_of_the_commands_it_limits() {
    let mut config = short_config();
    config.hold_reference = HoldReference::Trim;
    config.test.primary = Axis::Col;
    config.test.sweep.amplitude = 0.5;
    let free = largest_steps(config);
    let step = 4.0 * config.dt_s();
    // Without a limit the holds (lat, ped) and the collective sweep move faster than 4 /s.
    assert!(
        free[0] > step && free[2] > step && free[3] > step,
        "{free:?}"
    );
    config.slew = CommandSlew {
        per_s: [4.0, f32::INFINITY, 4.0, 4.0],
    };
    let limited = largest_steps(config);
    for axis in [0, 2, 3] {
        assert!(limited[axis] <= step * (1.0 + 1e-5), "{limited:?}");
    }
    // The limit is per axis: the unlimited one is left as it was.
    assert_eq!(limited[1], free[1]);
}

#[test]
fn a_pedal_slew_limit_leaves_the_other_axes_bit_for_bit() {
    let mut config = short_config();
    config.hold_reference = HoldReference::Trim;
    let run = |config: Config| {
        let mut rig = Rig::into_sweep(config);
        let trim = rig.fc.trim();
        rig.input.meas.psi = trim.psi + 20.0 * DEG;
        (0..300)
            .map(|_| {
                rig.step();
                rig.sample()
            })
            .collect::<Vec<_>>()
    };
    let free = run(config);
    config.slew = CommandSlew::pedal(4.0);
    let limited = run(config);
    let step = 4.0 * config.dt_s();
    assert!(free
        .windows(2)
        .any(|w| (w[1].command.ped - w[0].command.ped).abs() > step));
    for (a, b) in free.iter().zip(&limited) {
        assert_eq!(
            (a.command.lat, a.command.lon, a.command.col),
            (b.command.lat, b.command.lon, b.command.col)
        );
    }
    assert!(limited
        .windows(2)
        .all(|w| (w[1].command.ped - w[0].command.ped).abs() <= step * (1.0 + 1e-5)));
    // The held pedal still gets where the hold drives it, at the limit's pace.
    assert!((limited[299].command.ped - free[299].command.ped).abs() < 1e-3);
}

/// A lon sweep under conditional attitude hold with the pitch attitude driven through the
/// engage and release angles every 40 ticks and a fast pitch rate for the hold's rate
/// damping to answer: every tick's Sample.
fn pitch_hold_run(hold_slew: HoldSlew) -> Vec<Sample> {
    let mut config = short_config();
    config.test.primary = Axis::Lon;
    config.hold_reference = HoldReference::Level;
    config.hold_slew = hold_slew;
    let mut rig = Rig::into_sweep(config);
    (0..400)
        .map(|k| {
            let m = &mut rig.input.meas;
            m.theta = if (k / 40) % 2 == 0 {
                8.0 * DEG
            } else {
                1.0 * DEG
            };
            m.q = 1.5 * libm::sinf(1.3 * k as f32);
            rig.step();
            rig.sample()
        })
        .collect()
}

#[test]
fn a_hold_slew_limit_bounds_the_holds_share_and_passes_the_sweep_and_noise() {
    let step = 4.0 * short_config().dt_s();
    // The pilot's sticks are the trim the capture takes.
    let trim = PILOT[1];
    let hold = |s: &Sample| s.command.lon - trim - s.sweep.lon - s.noise.lon;
    let free = pitch_hold_run(HoldSlew::NONE);
    let limited = pitch_hold_run(HoldSlew {
        per_s: [f32::INFINITY, 4.0, f32::INFINITY],
    });
    let engaged = |s: &Sample| s.hold[1] == HoldState::Engaged;
    assert!(free.iter().any(engaged) && free.iter().any(|s| !engaged(s)));
    // Without the limit the hold's rate damping moves its share faster than 4 /s.
    assert!(free
        .windows(2)
        .any(|w| (hold(&w[1]) - hold(&w[0])).abs() > step));
    let mut transitions = 0;
    for w in limited.windows(2) {
        // The hold's share moves by at most one step a tick, engagements and releases
        // included; the sweep and the noise come and go with the hold state at once.
        let moved = (hold(&w[1]) - hold(&w[0])).abs();
        assert!(moved <= step * (1.0 + 1e-4) + 1e-6, "{moved} > {step}");
        transitions += usize::from(w[0].hold[1] != w[1].hold[1]);
    }
    assert!(transitions >= 4, "{transitions}");
    // The sweep on the swept axis and every other axis are bit for bit those without
    // the limit.
    for (a, b) in free.iter().zip(&limited) {
        assert_eq!(
            (a.command.lat, a.command.ped, a.command.col, a.hold),
            (b.command.lat, b.command.ped, b.command.col, b.hold)
        );
        assert_eq!((a.sweep.lon, a.noise.lon), (b.sweep.lon, b.noise.lon));
    }
}

#[test]
fn hold_slew_limits_must_be_positive() {
    for bad in [0.0, -4.0, f32::NAN] {
        let mut config = short_config();
        config.hold_slew = HoldSlew {
            per_s: [f32::INFINITY, bad, f32::INFINITY],
        };
        assert_eq!(
            FlightController::new(config).err(),
            Some(ConfigError::SlewInvalid)
        );
    }
    assert_eq!(Config::bo105_default(Axis::Lat).hold_slew, HoldSlew::NONE);
    assert_eq!(
        Config::trex700l_default(Axis::Lat).hold_slew,
        crate::config::TREX700L_HOLD_SLEW
    );
}

#[test]
fn slew_limits_must_be_positive() {
    for bad in [0.0, -4.0, f32::NAN] {
        let mut config = short_config();
        config.slew = CommandSlew::pedal(bad);
        assert_eq!(
            FlightController::new(config).err(),
            Some(ConfigError::SlewInvalid)
        );
    }
    let mut config = short_config();
    config.slew = CommandSlew::pedal(f32::INFINITY);
    assert!(FlightController::new(config).is_ok());
    assert_eq!(Config::bo105_default(Axis::Lat).slew, CommandSlew::NONE);
}

#[test]
fn the_excitation_scale_multiplies_the_primary_sweep_and_each_axis_noise() {
    let run = |primary: Axis, scale: ExcitationScale| {
        let mut config = short_config();
        config.test.primary = primary;
        config.excitation_scale = scale;
        let mut rig = Rig::into_sweep(config);
        (0..400)
            .map(|_| {
                rig.step();
                rig.sample()
            })
            .collect::<Vec<_>>()
    };
    let scale = ExcitationScale {
        per_axis: [0.5, 0.25, 0.2, 1.0],
    };
    for primary in [Axis::Lat, Axis::Ped] {
        let unit = run(primary, ExcitationScale::UNIT);
        let scaled = run(primary, scale);
        let mut excited = [false; 3];
        for (a, b) in unit.iter().zip(&scaled) {
            assert_eq!(b.hold, [HoldState::Released; 3]);
            let parts = |s: &Sample| (s.sweep.to_array(), s.noise.to_array());
            let ((sweep_a, noise_a), (sweep_b, noise_b)) = (parts(a), parts(b));
            for axis in 0..3 {
                let k = scale.per_axis[axis];
                assert!((sweep_b[axis] - k * sweep_a[axis]).abs() <= 1e-6 * sweep_a[axis].abs());
                assert!((noise_b[axis] - k * noise_a[axis]).abs() <= 1e-6 * noise_a[axis].abs());
                excited[axis] |= sweep_a[axis] != 0.0 || noise_a[axis] != 0.0;
            }
            let command = b.command.to_array();
            for axis in 0..3 {
                let expected = PILOT[axis] + sweep_b[axis] + noise_b[axis];
                assert!((command[axis] - expected).abs() < 1e-6);
            }
        }
        assert_eq!(excited, [true; 3], "primary {primary:?}");
    }
}

#[test]
fn excitation_scales_must_lie_in_zero_to_one() {
    for bad in [0.0, 1.5, f32::NAN] {
        let mut config = short_config();
        config.excitation_scale.per_axis[2] = bad;
        assert_eq!(
            FlightController::new(config).err(),
            Some(ConfigError::ExcitationScaleInvalid)
        );
    }
    assert_eq!(
        Config::bo105_default(Axis::Lat).excitation_scale,
        ExcitationScale::UNIT
    );
}

#[test]
fn the_same_seed_gives_the_same_telemetry() {
    let run = || {
        let mut rig = Rig::new(short_config());
        for _ in 0..600 {
            rig.step();
        }
        rig.frames
    };
    assert_eq!(run(), run());
}

#[test]
fn a_release_without_fade_hands_the_axis_straight_back_to_the_sweep() {
    let mut config = short_config();
    config.gains.lat.release_time_s = 0.0;
    let mut rig = Rig::into_sweep(config);
    let trim_phi = rig.fc.trim().phi;
    rig.input.meas.phi = trim_phi + 7.0 * DEG;
    for _ in 0..50 {
        rig.step();
    }
    assert_eq!(rig.sample().hold[0], HoldState::Engaged);
    rig.input.meas.phi = trim_phi + 3.0 * DEG;
    rig.step();
    let s = rig.sample();
    assert_eq!(s.hold[0], HoldState::Released);
    assert!((s.command.lat - (PILOT[0] + s.sweep.lat)).abs() < 1e-6);
}

#[test]
fn conditional_hold_follows_the_three_rules_at_the_controller() {
    // Angles below are written as trim + deviation: measure from trim so they read as
    // the paper's thresholds whatever the rig's trim attitude; a short release fade so
    // the checks fit inside the short record.
    let mut config = short_config();
    config.hold_reference = HoldReference::Trim;
    config.gains.lat.release_time_s = 0.2;
    let mut rig = Rig::into_sweep(config);
    let trim_phi = rig.fc.trim().phi;
    let previous_command = rig.sample().command.lat;
    // Rule 1: above 6° the controller takes the axis, bumplessly.
    rig.input.meas.phi = trim_phi + 7.0 * DEG;
    rig.step();
    let s = rig.sample();
    assert_eq!(s.hold[0], HoldState::Engaged);
    assert!(rig.tick_events().contains(&Event::HoldEngaged {
        tick: s.tick,
        axis: Axis::Lat
    }));
    assert_eq!(s.sweep.lat, 0.0);
    assert!(
        (s.command.lat - previous_command).abs() < 1e-5,
        "bump {} -> {}",
        previous_command,
        s.command.lat
    );
    // The controller then takes over against the roll (φ stays 7°): after the bumpless
    // hand-over (τ_b = 0.3 s) the command is left of trim.
    for _ in 0..200 {
        rig.step();
    }
    assert!(rig.sample().command.lat < PILOT[0]);
    // Rule 2, falling: 5° is in the band, the prior form (held) is kept.
    rig.input.meas.phi = trim_phi + 5.0 * DEG;
    rig.step();
    assert_eq!(rig.sample().hold[0], HoldState::Engaged);
    assert!(rig.tick_events().is_empty());
    // Rule 3: below 4° the axis is released and carries the sweep again.
    rig.input.meas.phi = trim_phi + 3.0 * DEG;
    rig.step();
    let s = rig.sample();
    assert_eq!(s.hold[0], HoldState::Released);
    assert!(rig.tick_events().contains(&Event::HoldReleased {
        tick: s.tick,
        axis: Axis::Lat
    }));
    // Bumpless release: the sweep is back at once, the controller's last output fades
    // (τ_r), so the command does not jump...
    let held_command = rig.frames_sample_before_last().command.lat;
    assert!(
        (s.command.lat - held_command).abs() < 0.02,
        "release bump {held_command} -> {}",
        s.command.lat
    );
    // ...and after a few τ_r the axis carries exactly trim + sweep.
    rig.input.meas.phi = trim_phi + 1.0 * DEG;
    let fade_ticks = (6.0 * rig.fc.config().gains.lat.release_time_s * 200.0) as usize;
    for _ in 0..fade_ticks {
        rig.step();
    }
    let s = rig.sample();
    assert_eq!(s.hold[0], HoldState::Released);
    assert!((s.command.lat - (PILOT[0] + s.sweep.lat)).abs() < 0.01 * 0.3);
    // Rule 2, rising: 5° keeps the released form; negative angles work the same way.
    let mut sweep_seen = false;
    for angle in [5.0, -5.5, 5.9] {
        rig.input.meas.phi = trim_phi + angle * DEG;
        rig.step();
        assert_eq!(rig.sample().hold[0], HoldState::Released);
        sweep_seen |= rig.sample().sweep.lat != 0.0;
    }
    assert!(sweep_seen);
    rig.input.meas.phi = trim_phi - 6.5 * DEG;
    rig.step();
    assert_eq!(rig.sample().hold[0], HoldState::Engaged);
    // Pitch and heading error hold their axes the same way (heading wraps across ±π).
    rig.input.meas.theta = rig.fc.trim().theta + 8.0 * DEG;
    rig.input.meas.psi = rig.fc.trim().psi + 2.0 * core::f32::consts::PI - 7.0 * DEG;
    rig.step();
    assert_eq!(rig.sample().hold, [HoldState::Engaged; 3]);
}

#[test]
fn level_reference_applies_the_thresholds_to_the_attitude_itself() {
    // The rig trims at θ = 0.04 rad (2.3°). With the paper's Level reference, θ = 6.5°
    // (4.2° from trim) is past the 6° engage angle; measured from trim it is in the band.
    for (reference, engaged) in [(HoldReference::Level, true), (HoldReference::Trim, false)] {
        let mut config = short_config();
        config.hold_reference = reference;
        let mut rig = Rig::into_sweep(config);
        assert!((rig.fc.trim().theta - 0.04).abs() < 1e-3);
        rig.input.meas.theta = 6.5 * DEG;
        rig.step();
        let state = rig.sample().hold[1];
        assert_eq!(
            state == HoldState::Engaged,
            engaged,
            "{reference:?}: {state:?}"
        );
    }
}

#[test]
fn freeze_in_band_holds_the_last_command() {
    let mut config = short_config();
    config.test.freeze_in_band = true;
    config.hold_reference = HoldReference::Trim;
    let mut rig = Rig::into_sweep(config);
    let trim_theta = rig.fc.trim().theta;
    rig.input.meas.theta = trim_theta + 5.0 * DEG;
    rig.step();
    let frozen = rig.sample().command.lon;
    assert_eq!(rig.sample().hold[1], HoldState::Frozen);
    for _ in 0..50 {
        rig.step();
        assert_eq!(rig.sample().hold[1], HoldState::Frozen);
        assert_eq!(rig.sample().command.lon, frozen);
    }
    rig.input.meas.theta = trim_theta;
    rig.step();
    assert_eq!(rig.sample().hold[1], HoldState::Released);
}

#[test]
fn standard_and_off_axis_noise_modes_keep_the_controller_on() {
    for (mode, with_noise) in [
        (ExcitationMode::Standard, false),
        (ExcitationMode::OffAxisNoise, true),
    ] {
        let mut config = short_config();
        config.test.mode = mode;
        let mut rig = Rig::new(config);
        rig.run_until(Phase::FadeIn);
        let engaged = rig
            .tick_events()
            .iter()
            .filter(|e| matches!(e, Event::HoldEngaged { .. }))
            .count();
        assert_eq!(engaged, 3);
        let mut noise_seen = false;
        for _ in 0..300 {
            rig.step();
            let s = rig.sample();
            assert_eq!(s.hold, [HoldState::Engaged; 3]);
            noise_seen |= s.noise.lon != 0.0 || s.noise.ped != 0.0;
        }
        assert_eq!(noise_seen, with_noise, "{mode:?}");
        // Sweep on top of the controller on the primary axis.
        assert!(rig.sample().sweep.lat != 0.0);
    }
}

#[test]
fn doublet_runs_on_the_same_sequencer() {
    let mut config = short_config();
    config.test.input = InputKind::Doublet;
    config.test.pulse.width_s = 0.5;
    let mut rig = Rig::new(config);
    let mut pulse = Vec::new();
    while rig.fc.phase() != Phase::Done {
        rig.step();
        let s = rig.sample();
        if s.phase == Phase::Sweep {
            pulse.push(s.sweep.lat);
        }
        assert_eq!(s.sweep_omega, 0.0);
    }
    assert_eq!(pulse.len(), 200);
    assert!(pulse[..100].iter().all(|&v| v == 0.05));
    assert!(pulse[100..].iter().all(|&v| v == -0.05));
}

/// An adaptive sweep announces itself (input and protocol 1.3) in the Header, applies
/// the configured amplitude until it has measured a cycle, then shapes it: with a roll
/// that follows the input strongly the applied amplitude falls; it stays within its
/// bounds and the same inputs give the same telemetry. A fixed sweep announces 1.2.
#[test]
fn adaptive_sweep_is_announced_and_shapes_the_amplitude() {
    let mut config = short_config();
    config.test.sweep.omega_min = 3.0;
    assert_eq!(
        Rig::new(config).fc.header().protocol,
        ProtocolVersion { major: 1, minor: 2 }
    );
    config.test.input = InputKind::AdaptiveSweep;
    let run = || {
        let mut rig = Rig::new(config);
        assert_eq!(rig.fc.header().protocol, PROTOCOL_VERSION_FOR_TESTS);
        assert_eq!(rig.fc.header().test.input, InputKind::AdaptiveSweep);
        let mut applied = Vec::new();
        while rig.fc.phase() != Phase::Done {
            rig.step();
            let s = rig.sample();
            // The "aircraft": 200° of roll per unit stick, in phase.
            rig.input.meas.phi = rig.fc.trim().phi + 200.0 * DEG * s.sweep.lat;
            if s.phase == Phase::Sweep {
                applied.push(s.sweep.lat);
            }
            assert!(s.command.lat.abs() <= 1.0 && s.sweep.lat.abs() <= 0.1 + 1e-6);
        }
        (applied, rig.frames)
    };
    let (applied, frames) = run();
    let peak = |part: &[f32]| part.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    // ω_min = 3 rad/s: the first cycle (2 s) is flown at the configured amplitude.
    let (early, late) = applied.split_at(applied.len() / 2);
    assert!(peak(early) > 0.045, "early {}", peak(early));
    // 200°/stick: 2° (half the release angle) at 0.01 of stick.
    assert!(peak(late) < 0.02, "late {}", peak(late));
    assert_eq!(frames, run().1);
}

const PROTOCOL_VERSION_FOR_TESTS: ProtocolVersion = ProtocolVersion { major: 1, minor: 3 };

/// Drive into the sweep, apply `fault`, step once (or `ticks` times), and check the abort.
fn assert_aborts(reason: AbortReason, fault: impl FnOnce(&mut SensorIn)) -> Rig {
    let mut rig = Rig::into_sweep(short_config());
    // Hold engaged on roll first, so the abort must also release it.
    rig.input.meas.phi = rig.fc.trim().phi + 7.0 * DEG;
    rig.step();
    fault(&mut rig.input);
    let output = rig.step();
    let s = rig.sample();
    let events = rig.tick_events();
    assert!(
        events.contains(&Event::Abort {
            tick: s.tick,
            reason
        }),
        "{reason:?} not in {events:?}"
    );
    assert!(events.contains(&Event::HoldReleased {
        tick: s.tick,
        axis: Axis::Lat
    }));
    assert_eq!(rig.fc.phase(), Phase::Aborted);
    assert_eq!(s.phase, Phase::Aborted);
    assert_eq!(s.hold, [HoldState::Released; 3]);
    // Pilot pass-through in the same tick; a non-finite stick falls back to its last
    // finite value (PILOT, before the fault).
    let sticks = rig.input.pilot.sticks.to_array();
    for ((got, stick), before) in output.command.to_array().into_iter().zip(sticks).zip(PILOT) {
        let want = if stick.is_finite() { stick } else { before };
        assert_eq!(got, want);
    }
    rig
}

#[test]
fn abort_on_attitude_limit() {
    assert_aborts(AbortReason::AttitudeLimit, |input| {
        input.meas.theta = 21.0 * DEG
    });
}

#[test]
fn abort_on_rate_limit() {
    assert_aborts(AbortReason::RateLimit, |input| input.meas.q = -95.0 * DEG);
}

#[test]
fn abort_on_non_finite_sensor() {
    assert_aborts(AbortReason::SensorNotFinite, |input| {
        input.meas.w = f32::NAN
    });
    assert_aborts(AbortReason::SensorNotFinite, |input| {
        input.meas.p = f32::NEG_INFINITY
    });
    assert_aborts(AbortReason::SensorNotFinite, |input| {
        input.pilot.sticks.ped = f32::NAN
    });
}

#[test]
fn abort_on_stale_sensor_after_three_unchanged_ticks() {
    let mut rig = Rig::into_sweep(short_config());
    for _ in 0..3 {
        rig.step_same_seq();
        assert_eq!(rig.fc.phase(), Phase::Sweep);
    }
    rig.step_same_seq();
    let tick = rig.sample().tick;
    assert!(rig.tick_events().contains(&Event::Abort {
        tick,
        reason: AbortReason::SensorStale
    }));
    assert_eq!(rig.fc.phase(), Phase::Aborted);
    assert_eq!(rig.sample().command, Controls::from_array(PILOT));
}

#[test]
fn abort_on_pilot_override() {
    assert_aborts(AbortReason::PilotOverride, |input| {
        input.pilot.sticks.col = PILOT[3] + 0.11
    });
    // 9 % of travel is not an override.
    let mut rig = Rig::into_sweep(short_config());
    rig.input.pilot.sticks.lon = PILOT[1] - 0.09;
    rig.step();
    assert_eq!(rig.fc.phase(), Phase::Sweep);
}

#[test]
fn pilot_override_during_trim_capture_uses_the_running_average() {
    let mut rig = Rig::new(short_config());
    rig.run_until(Phase::TrimCapture);
    for _ in 0..5 {
        rig.step();
    }
    rig.input.pilot.sticks.lat = PILOT[0] + 0.2;
    rig.step();
    assert!(rig.tick_events().iter().any(|e| matches!(
        e,
        Event::Abort {
            reason: AbortReason::PilotOverride,
            ..
        }
    )));
}

#[test]
fn abort_on_switch_release_then_a_fresh_arm_is_needed() {
    let mut rig = assert_aborts(AbortReason::SwitchReleased, |input| {
        input.pilot.test_switch = false
    });
    // Switch off: back to Idle. Then on again: Armed.
    rig.input.meas = calm_input().meas;
    rig.step();
    assert_eq!(rig.fc.phase(), Phase::Idle);
    rig.input.pilot.test_switch = true;
    rig.step();
    assert_eq!(rig.fc.phase(), Phase::Armed);
    rig.step();
    assert_eq!(rig.fc.phase(), Phase::TrimCapture);
}

#[test]
fn after_an_abort_the_switch_must_be_cycled() {
    let mut rig = assert_aborts(AbortReason::AttitudeLimit, |input| {
        input.meas.phi = 25.0 * DEG
    });
    rig.input.meas = calm_input().meas;
    for _ in 0..50 {
        rig.step();
        assert_eq!(rig.fc.phase(), Phase::Aborted);
        assert_eq!(rig.sample().command, Controls::from_array(PILOT));
    }
}

#[test]
fn arming_needs_a_rising_edge_and_checks_safety_at_once() {
    let mut rig = Rig::new(short_config());
    rig.input.pilot.test_switch = false;
    rig.step();
    assert_eq!(rig.fc.phase(), Phase::Idle);
    // An unsafe attitude at arming aborts in the Armed tick, before any Header.
    rig.input.pilot.test_switch = true;
    rig.input.meas.phi = 30.0 * DEG;
    rig.step();
    assert_eq!(rig.fc.phase(), Phase::Aborted);
    assert!(!rig.frames.iter().any(|f| matches!(f, Frame::Header(_))));
}

#[test]
fn wrap_pi_stays_in_range() {
    use core::f32::consts::PI;
    assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-6);
    assert!((wrap_pi(-7.0 * PI / 2.0) - PI / 2.0).abs() < 1e-5);
    assert_eq!(wrap_pi(f32::NAN), 0.0);
    assert!(wrap_pi(1e30).abs() <= PI);
}

/// Any f32, biased towards the interesting ones: NaN, ±inf, huge, and flight-like.
fn any_value() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => -0.3f32..0.3,
        1 => proptest::num::f32::ANY,
        1 => prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY), Just(f32::MAX), Just(-1e30f32)],
    ]
}

fn any_sensor() -> impl Strategy<Value = (Vec<f32>, Vec<f32>, bool, bool)> {
    (
        proptest::collection::vec(any_value(), 12),
        proptest::collection::vec(any_value(), 4),
        prop::bool::weighted(0.95),
        prop::bool::weighted(0.9),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn step_never_panics_and_never_commands_outside_unit_range(
        ticks in proptest::collection::vec(any_sensor(), 1..120),
        mode in prop_oneof![
            Just(ExcitationMode::ConditionalAttitudeHold),
            Just(ExcitationMode::Standard),
            Just(ExcitationMode::OffAxisNoise)
        ],
        freeze in any::<bool>(),
        slewed in any::<bool>(),
    ) {
        let mut config = short_config();
        config.test.mode = mode;
        config.test.freeze_in_band = freeze;
        if slewed {
            config.slew = CommandSlew { per_s: [4.0, 2.0, 4.0, 1.0] };
            config.hold_slew = HoldSlew { per_s: [3.0, 3.0, 1.0] };
        }
        let mixer = config.mixer;
        let mut rig = Rig::into_sweep(config);
        for (meas, sticks, switch, fresh) in ticks {
            let m = &mut rig.input.meas;
            for (field, value) in [
                &mut m.p, &mut m.q, &mut m.r, &mut m.phi, &mut m.theta, &mut m.psi,
                &mut m.u, &mut m.v, &mut m.w, &mut m.ax, &mut m.ay, &mut m.az,
            ].into_iter().zip(meas) {
                *field = value;
            }
            let s = &mut rig.input.pilot.sticks;
            for (field, value) in [&mut s.lat, &mut s.lon, &mut s.ped, &mut s.col].into_iter().zip(sticks) {
                *field = value;
            }
            rig.input.pilot.test_switch = switch;
            let output = if fresh { rig.step() } else { rig.step_same_seq() };
            for value in output.command.to_array() {
                prop_assert!(value.is_finite() && (-1.0..=1.0).contains(&value), "{value}");
            }
            for (pulse, servo) in output.servo_us.iter().zip(mixer.swash.iter().chain([&mixer.tail])) {
                prop_assert!((servo.min_us..=servo.max_us).contains(pulse));
            }
        }
    }
}
