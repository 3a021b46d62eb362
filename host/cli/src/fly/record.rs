//! Flying one record: the simulator and a flight-controller link in lockstep.

use rotorsim::{Helicopter, Sim, SimOptions, Trim};
use sweephold_firmware::{CollectiveSource, Config};
use sweephold_protocol::{
    Controls, Decoder, Event, Frame, HoldState, Measurements, Phase, PilotInput, Request, Sample,
    SensorIn,
};
use sysid::random::SplitMix64;

use super::gust_pulse::{GustPulse, GustResponse};
use super::link::FlightControllerLink;
use super::pilot_collective::{CollectiveStep, HeightHold};
use super::summary::{AfterTest, AttitudeDeg, FromTrimDeg, HoldFraction, MaxAbsDeg};

/// Disturbances and faults injected into one record.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Disturbances {
    /// Turbulence level handed to the simulator's gust model [m/s RMS].
    pub gust_level: f64,
    /// Per-tick probability that the sensor sample is not refreshed.
    pub sensor_dropout: f64,
    /// Per-tick probability of a sensor spike.
    pub sensor_spike: f64,
    /// Time \[s\] after arming at which the pilot moves the lateral stick 20 % off trim.
    pub pilot_override_at_s: Option<f64>,
    /// RMS of random pilot stick motion around trim, fraction of travel (0: hands still).
    pub pilot_stick_noise: f64,
    /// The pilot's collective stick step (`--collective-step`).
    pub collective_step: Option<CollectiveStep>,
    /// Seconds flown on after the test ended (Done or Aborted), the pilot's hands at trim
    /// (0: the record ends with the test).
    pub fly_on_s: f64,
    /// A discrete gust while flying on (`--gust-pulse`).
    pub gust_pulse: Option<GustPulse>,
}

/// What one record produced.
#[derive(Clone, Debug)]
pub struct FlownRecord {
    /// The telemetry exactly as the flight controller streamed it.
    pub dump: Vec<u8>,
    /// Good frames in the dump.
    pub frames: u64,
    /// Ticks flown (arming to the end).
    pub ticks: u64,
    /// Abort reason, if the firmware aborted.
    pub abort: Option<sweephold_protocol::AbortReason>,
    /// The flight controller streamed a Header: its test began.
    pub began: bool,
    /// The board application's first mode change (`pilot → rc_failsafe at tick 3520`),
    /// if any: what stopped a test that never began.
    pub first_mode_change: Option<String>,
    /// The check that refused the test request (`not_airborne`), if one did.
    pub test_refused: Option<String>,
    /// Peak attitude excursions over the excitation.
    pub max_abs_deg: MaxAbsDeg,
    /// Peak excursions from the captured trim over the excitation (None without a trim
    /// capture).
    pub max_from_trim_deg: Option<FromTrimDeg>,
    /// Share of excitation ticks with the hold engaged.
    pub hold_fraction: HoldFraction,
    /// The final sequencer phase (at the end of the test).
    pub final_phase: Phase,
    /// Largest |estimate − simulator| of φ and θ over the excitation (over the whole test
    /// if it had none): what the flight controller measured (the Samples' φ, θ) against
    /// the simulated aircraft's attitude.
    pub attitude_error_deg: AttitudeDeg,
    /// The flight after the test (`Disturbances::fly_on_s` > 0).
    pub after: Option<AfterTest>,
    /// The trim attitude φ, θ \[rad\] the flight controller captured (its first
    /// `TrimCaptured` event), if it captured one.
    pub trim_captured: Option<[f32; 2]>,
}

/// Whether `phase` is part of the excitation (fades included).
fn is_excitation(phase: Phase) -> bool {
    matches!(phase, Phase::FadeIn | Phase::Sweep | Phase::FadeOut)
}

/// Watches the telemetry as it streams, as a ground station would.
#[derive(Default)]
struct TelemetryMonitor {
    decoder: Decoder,
    phase: Option<Phase>,
    abort: Option<sweephold_protocol::AbortReason>,
    /// The first `TrimCaptured` event's attitude.
    trim_captured: Option<[f32; 2]>,
    start_psi: Option<f32>,
    max_abs: MaxAbsDeg,
    max_from_trim: Option<FromTrimDeg>,
    excitation_ticks: u64,
    engaged_ticks: [u64; 3],
    /// The last Sample seen.
    last: Option<Sample>,
    /// A Header was streamed: the test began.
    began: bool,
    /// The board application's first mode change, as `pilot → rc_failsafe at tick 3520`.
    first_mode_change: Option<String>,
    /// The check that refused the first test request.
    test_refused: Option<String>,
}

impl TelemetryMonitor {
    fn observe(&mut self, bytes: &[u8]) {
        let decoder = &mut self.decoder;
        for frame in decoder.feed(bytes).flatten() {
            match frame {
                Frame::Sample(sample) => {
                    Self::sample(
                        &sample,
                        &mut self.phase,
                        &mut self.start_psi,
                        &mut self.max_abs,
                        &mut self.excitation_ticks,
                        &mut self.engaged_ticks,
                    );
                    if let (Some([phi0, theta0]), true) =
                        (self.trim_captured, is_excitation(sample.phase))
                    {
                        let peak = self.max_from_trim.get_or_insert_with(FromTrimDeg::default);
                        let from = |value: f32, trim: f32| {
                            (f64::from(value) - f64::from(trim)).abs().to_degrees()
                        };
                        peak.phi = peak.phi.max(from(sample.meas.phi, phi0));
                        peak.theta = peak.theta.max(from(sample.meas.theta, theta0));
                    }
                    self.last = Some(sample);
                }
                Frame::Event(Event::Abort { reason, .. }) => self.abort = Some(reason),
                Frame::Header(_) => self.began = true,
                Frame::Event(Event::Refused {
                    request: Request::Test,
                    check,
                    ..
                }) => {
                    self.test_refused
                        .get_or_insert_with(|| check.name().to_string());
                }
                Frame::Event(Event::ModeChange { tick, from, to }) => {
                    self.first_mode_change.get_or_insert_with(|| {
                        format!("{} → {} at tick {tick}", from.name(), to.name())
                    });
                }
                Frame::Event(Event::TrimCaptured { phi, theta, .. }) => {
                    self.trim_captured.get_or_insert([phi, theta]);
                }
                _ => {}
            }
        }
    }

    fn sample(
        sample: &Sample,
        phase: &mut Option<Phase>,
        start_psi: &mut Option<f32>,
        max_abs: &mut MaxAbsDeg,
        excitation_ticks: &mut u64,
        engaged_ticks: &mut [u64; 3],
    ) {
        *phase = Some(sample.phase);
        if !is_excitation(sample.phase) {
            return;
        }
        let m = &sample.meas;
        let psi0 = *start_psi.get_or_insert(m.psi);
        let dpsi = rotorsim::sim::wrap_angle(f64::from(m.psi) - f64::from(psi0));
        max_abs.phi = max_abs.phi.max(f64::from(m.phi).abs().to_degrees());
        max_abs.theta = max_abs.theta.max(f64::from(m.theta).abs().to_degrees());
        max_abs.psi = max_abs.psi.max(dpsi.abs().to_degrees());
        *excitation_ticks += 1;
        for (count, hold) in engaged_ticks.iter_mut().zip(sample.hold) {
            *count += u64::from(hold == HoldState::Engaged);
        }
    }

    fn hold_fraction(&self) -> HoldFraction {
        let share = |n: u64| {
            if self.excitation_ticks == 0 {
                0.0
            } else {
                n as f64 / self.excitation_ticks as f64
            }
        };
        HoldFraction {
            lat: share(self.engaged_ticks[0]),
            lon: share(self.engaged_ticks[1]),
            ped: share(self.engaged_ticks[2]),
        }
    }
}

/// Largest |measured − true| φ and θ over ticks, kept separately for the excitation and
/// the whole test.
#[derive(Default)]
struct AttitudeErrors {
    excitation: Option<AttitudeDeg>,
    test: AttitudeDeg,
}

impl AttitudeErrors {
    fn add(&mut self, sample: &Sample, truth: [f64; 3]) {
        let error = |measured: f32, truth: f64| {
            rotorsim::sim::wrap_angle(f64::from(measured) - truth)
                .abs()
                .to_degrees()
        };
        let (phi, theta) = (
            error(sample.meas.phi, truth[0]),
            error(sample.meas.theta, truth[1]),
        );
        let grow = |max: &mut AttitudeDeg| {
            max.phi = max.phi.max(phi);
            max.theta = max.theta.max(theta);
        };
        grow(&mut self.test);
        if matches!(sample.phase, Phase::FadeIn | Phase::Sweep | Phase::FadeOut) {
            grow(self.excitation.get_or_insert_with(AttitudeDeg::default));
        }
    }

    fn result(&self) -> AttitudeDeg {
        self.excitation.unwrap_or(self.test)
    }
}

/// Ticks flown in Idle before the pilot flips the test switch.
const IDLE_TICKS: u64 = 10;

/// The simulated aircraft a record is flown on.
#[derive(Clone, Copy)]
pub struct Aircraft<'a> {
    /// Its parameters.
    pub heli: &'a Helicopter,
    /// The trim it starts from (hover).
    pub trim: &'a Trim,
    /// Sensors, actuators, integration step and seed.
    pub options: SimOptions,
}

/// Fly one record: start the simulator at trim, arm the flight controller, and run the
/// lockstep loop until the test is done or aborted (or `max_s` of flight time passed),
/// then `fly_on_s` more seconds with the pilot's hands at trim.
pub fn fly_record(
    link: &mut dyn FlightControllerLink,
    config: &Config,
    aircraft: Aircraft<'_>,
    disturbances: &Disturbances,
    max_s: f64,
    mut progress: impl FnMut(f64),
) -> anyhow::Result<FlownRecord> {
    let rate = f64::from(config.rate_hz);
    let dt = 1.0 / rate;
    let trim = aircraft.trim;
    let mut options = aircraft.options;
    options.gust_level = disturbances.gust_level;
    options.dropout_probability = disturbances.sensor_dropout;
    options.spike_probability = disturbances.sensor_spike;
    let mut sim = Sim::at_trim(aircraft.heli.clone(), trim, options);
    let trim_sticks = trim.controls.map(|c| c as f32);
    let mut pilot_rng = SplitMix64::new(u64::from(config.test.seed) ^ 0x9170_7D15_7A2B);
    // With the collective the pilot's during the test, the pilot holds height with it.
    let mut height_hold = match config.collective {
        CollectiveSource::Trim => None,
        CollectiveSource::Pilot => {
            let z_col = rotorsim::linearize(aircraft.heli, trim)
                .quasi_static
                .get("Zcol")
                .copied()
                .unwrap_or(0.0);
            HeightHold::new(z_col)
        }
    };

    link.begin_record(config)?;
    crate::interrupt::pause_point("fly");
    let mut dump = Vec::with_capacity((max_s * rate) as usize * 140);
    let mut monitor = TelemetryMonitor::default();
    let mut reading = sim.step(dt, trim.controls);
    let max_ticks = (max_s * rate).ceil() as u64;
    let fly_on_ticks = (disturbances.fly_on_s.max(0.0) * rate).round() as u64;
    let mut truth = sim.state().attitude();
    let mut errors = AttitudeErrors::default();
    // The tick count and final phase when the test ended, and the flight after it.
    let mut ended: Option<(u64, Phase)> = None;
    let mut after = AttitudeDeg::default();
    let mut gust = disturbances.gust_pulse.map(GustResponse::new);
    let mut ticks = 0;
    let ticks_per_second = u64::from(config.rate_hz).max(1);
    while ticks < max_ticks + fly_on_ticks {
        // A safe point every second of flight: a signal stops the record (and the run).
        if ticks % ticks_per_second == 0 {
            crate::interrupt::check()?;
        }
        let armed_s = ticks.saturating_sub(IDLE_TICKS) as f64 * dt;
        let mut sticks = trim_sticks;
        if ended.is_some() {
            // Flying on: the pilot's hands at trim.
        } else if disturbances.pilot_stick_noise > 0.0 {
            for s in &mut sticks {
                // One deviate per stick: the first of each Box–Muller pair.
                *s += (disturbances.pilot_stick_noise * pilot_rng.normal_pair().0) as f32;
            }
        }
        if let (Some(at), None) = (disturbances.pilot_override_at_s, ended) {
            if ticks >= IDLE_TICKS && armed_s >= at {
                sticks[0] += 0.2;
            }
        }
        if ended.is_none() {
            if let Some(hold) = height_hold.as_mut() {
                let height = -sim.state().0[rotorsim::model::DOWN];
                sticks[3] += hold.correction(height, dt) as f32;
            }
            if let Some(step) = disturbances.collective_step {
                if ticks as f64 * dt >= step.at_s {
                    sticks[3] += step.delta as f32;
                }
            }
        }
        let input = SensorIn {
            seq: reading.seq,
            meas: measurements(&reading),
            pilot: PilotInput {
                sticks: Controls::from_array(sticks),
                test_switch: ticks >= IDLE_TICKS,
            },
        };
        let start = dump.len();
        let out = link.exchange(&input, &mut dump)?;
        monitor.observe(&dump[start..]);
        if ended.is_none() {
            if let Some(sample) = &monitor.last {
                errors.add(sample, truth);
            }
        }
        if let (Some(gust), Some((end, _))) = (gust.as_mut(), ended) {
            let since_end = (ticks - end) as f64 * dt;
            sim.set_wind(gust.step(since_end, truth));
        }
        reading = sim.step(dt, link.controls_flown(&out));
        truth = sim.state().attitude();
        ticks += 1;
        if ticks % 200 == 0 {
            progress(ticks as f64 * dt);
        }
        match ended {
            Some((end, _)) => {
                after.phi = after.phi.max(truth[0].abs().to_degrees());
                after.theta = after.theta.max(truth[1].abs().to_degrees());
                if ticks >= end + fly_on_ticks {
                    break;
                }
            }
            None => {
                // The board application's own aborts (receiver, IMU) leave the sequencer
                // Idle within the tick: the Abort Event ends the test too.
                let over = matches!(monitor.phase, Some(Phase::Done | Phase::Aborted))
                    || monitor.abort.is_some();
                if ticks > IDLE_TICKS && over {
                    let phase = if monitor.abort.is_some() {
                        Phase::Aborted
                    } else {
                        monitor.phase.unwrap_or(Phase::Idle)
                    };
                    ended = Some((ticks, phase));
                    if fly_on_ticks == 0 {
                        break;
                    }
                } else if !monitor.began && monitor.test_refused.is_some() {
                    // The test switch stays on: no test starts without its cycling.
                    break;
                } else if ticks >= max_ticks {
                    break;
                }
            }
        }
    }
    monitor.decoder.finish();
    let (test_ticks, final_phase) = ended.unwrap_or((ticks, monitor.phase.unwrap_or(Phase::Idle)));
    let after = (fly_on_ticks > 0).then(|| AfterTest {
        mode: link.board_mode().unwrap_or("unknown").to_string(),
        duration_s: ticks.saturating_sub(test_ticks) as f64 * dt,
        max_abs_deg: after,
        gust_pulse: gust.and_then(|g| g.summary()),
    });
    Ok(FlownRecord {
        frames: monitor.decoder.stats().good_frames,
        ticks: test_ticks,
        abort: monitor.abort,
        began: monitor.began,
        first_mode_change: monitor.first_mode_change.clone(),
        test_refused: monitor.test_refused.clone(),
        trim_captured: monitor.trim_captured,
        max_abs_deg: monitor.max_abs,
        max_from_trim_deg: monitor.max_from_trim,
        hold_fraction: monitor.hold_fraction(),
        final_phase,
        attitude_error_deg: errors.result(),
        after,
        dump,
    })
}

/// The simulator's sensor reading as the firmware receives it.
pub fn measurements(r: &rotorsim::SensorReading) -> Measurements {
    Measurements {
        p: r.p as f32,
        q: r.q as f32,
        r: r.r as f32,
        phi: r.phi as f32,
        theta: r.theta as f32,
        psi: r.psi as f32,
        u: r.u as f32,
        v: r.v as f32,
        w: r.w as f32,
        ax: r.ax as f32,
        ay: r.ay as f32,
        az: r.az as f32,
    }
}
