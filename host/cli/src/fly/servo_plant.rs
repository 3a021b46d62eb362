//! The aircraft's servos under `--fc board-sim`: the pulses the board outputs, turned
//! back into the simulator's controls through the aircraft's real servo geometry (its
//! `[swash]` table), and held between servo frames.
//!
//! # Pulse to control
//!
//! Each servo's pulse gives its height, `h = ±(pulse − centre)/throw` (minus when the
//! servo is reversed). A three-servo plate of angle A has its servos at azimuths 0, +A
//! and −A clockwise from the lead servo, and a servo at azimuth ψ stands at
//!
//! ```text
//! h(ψ) = C + lon'·cos(ψ − φ) − lat'·sin(ψ − φ)
//! ```
//!
//! (φ the phase angle, C the collective height, lon', lat' the cyclic heights; the
//! convention of the firmware's `swash` module, after ArduPilot and Rotorflight). Three
//! servos, three unknowns: the 3×3 system is inverted once, in f64, from the azimuths
//! computed here — not from the firmware's mixing factors, so a board whose mixer does
//! not match the aircraft flies a plate tilted other than it meant. An H1 head takes lat'
//! from servo 1, lon' from servo 2 and C from servo 3, turned back by φ. The tail servo's
//! height is the pedal height.
//!
//! The simulator's controls are stick fractions, and the aircraft's `[controls]` gearing is
//! stated at the board's default mixer scales: swash height 0.5 per unit collective and
//! per unit cyclic, tail height 1 per unit pedal. So `col = C/0.5`, `lat = lat'/0.5`,
//! `lon = lon'/0.5`, `ped = h_tail`. A board with the default scales and the aircraft's
//! geometry thus returns its command, to the µs rounding of its pulses and its servo
//! limits.
//!
//! # Frames
//!
//! A servo takes a new pulse only when a frame starts: the board's output timer starts a
//! frame every `1/rate` (swash and tail have their own rate), and the pulse a control tick
//! writes reaches the servo if a frame starts before the next tick writes another. At
//! 333 Hz (a frame every 3.0 ms) every 200 Hz tick's pulse reaches the servos; at 50 Hz
//! (20 ms) one tick in four, the servo holding it meanwhile. The simulator flies each
//! tick's step with the pulses the servos hold during it.

use aircraft::{ServoOutput, Swash, SwashKind};
use sweephold_protocol::Controls;

/// Swash height per unit collective and per unit cyclic command of the board's default
/// mixer (`MixerConfig::trex700l`), at which the aircraft's gearing is stated.
pub const SWASH_HEIGHT_PER_STICK: f64 = 0.5;
/// Tail height per unit pedal of the board's default mixer.
pub const TAIL_HEIGHT_PER_STICK: f64 = 1.0;

/// Pulses to controls through one aircraft's geometry.
#[derive(Clone, Debug)]
pub struct ServoGeometry {
    swash: Swash,
    /// For a CCPM plate: (C, lon', lat') = inverse · (h₁, h₂, h₃).
    inverse: [[f64; 3]; 3],
}

impl ServoGeometry {
    /// The geometry of `swash`.
    pub fn new(swash: &Swash) -> Self {
        let angle = match swash.kind {
            SwashKind::H1 => 0.0_f64,
            SwashKind::H3_120 => 120.0,
            SwashKind::H3_135 => 135.0,
            SwashKind::H3_140 => 140.0,
        }
        .to_radians();
        // Azimuth of each output: the lead output at 0, the next clockwise at +A, the
        // third at −A.
        let mut rows = [[0.0; 3]; 3];
        for (position, azimuth) in [0.0, angle, -angle].into_iter().enumerate() {
            let output = (usize::from(swash.lead) + 2 + position) % 3;
            let relative = azimuth - swash.phase;
            rows[output] = [1.0, relative.cos(), -relative.sin()];
        }
        ServoGeometry {
            swash: *swash,
            inverse: invert(rows),
        }
    }

    /// The controls \[stick fractions\] the aircraft's rotor gets from `pulses` (swash
    /// outputs 1–3, tail) \[µs\].
    pub fn controls(&self, pulses: [u16; 4]) -> [f64; 4] {
        let height = |servo: &ServoOutput, pulse: u16| {
            let sign = if servo.reversed { -1.0 } else { 1.0 };
            sign * (f64::from(pulse) - servo.centre_us) / servo.throw_us
        };
        let [s1, s2, s3] = self.swash.servos;
        let [p1, p2, p3, tail] = pulses;
        let h = [height(&s1, p1), height(&s2, p2), height(&s3, p3)];
        let (collective, lon_h, lat_h) = match self.swash.kind {
            SwashKind::H1 => {
                // h₁ = lat·cosφ − lon·sinφ, h₂ = lon·cosφ + lat·sinφ: turn back by φ.
                let (c, s) = (self.swash.phase.cos(), self.swash.phase.sin());
                let (lat_t, lon_t) = (h[0], h[1]);
                (h[2], lon_t * c - lat_t * s, lat_t * c + lon_t * s)
            }
            _ => {
                let m = &self.inverse;
                let row = |r: &[f64; 3]| r[0] * h[0] + r[1] * h[1] + r[2] * h[2];
                (row(&m[0]), row(&m[1]), row(&m[2]))
            }
        };
        [
            lat_h / SWASH_HEIGHT_PER_STICK,
            lon_h / SWASH_HEIGHT_PER_STICK,
            height(&self.swash.tail, tail) / TAIL_HEIGHT_PER_STICK,
            collective / SWASH_HEIGHT_PER_STICK,
        ]
    }

    /// The controls as the protocol's type (f32).
    pub fn controls_f32(&self, pulses: [u16; 4]) -> Controls {
        Controls::from_array(self.controls(pulses).map(|v| v as f32))
    }
}

/// The inverse of a 3×3 matrix (the plate's rows are independent for every angle and
/// phase: the azimuths 0, ±A with 0 < A < 180° are distinct).
fn invert(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let [[a, b, c], [d, e, f], [g, h, i]] = m;
    let det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    [
        [
            (e * i - f * h) / det,
            (c * h - b * i) / det,
            (b * f - c * e) / det,
        ],
        [
            (f * g - d * i) / det,
            (a * i - c * g) / det,
            (c * d - a * f) / det,
        ],
        [
            (d * h - e * g) / det,
            (b * g - a * h) / det,
            (a * e - b * d) / det,
        ],
    ]
}

/// The pulses the servos hold: a servo group takes the board's newest pulse when one of
/// its frames starts within the tick.
#[derive(Clone, Debug)]
pub struct FrameHold {
    /// Frame period of the swash and the tail output \[µs\].
    period_us: [u64; 2],
    /// When each group's next frame starts \[µs of board time\].
    next_frame_us: [u64; 2],
    /// What the servos hold.
    held: [u16; 4],
}

impl FrameHold {
    /// Frames at `swash_hz` and `tail_hz`, the servos at `initial` until the first frame.
    pub fn new(swash_hz: u16, tail_hz: u16, initial: [u16; 4]) -> Self {
        let period = |hz: u16| (1_000_000 / u64::from(hz.max(1))).max(1);
        FrameHold {
            period_us: [period(swash_hz), period(tail_hz)],
            next_frame_us: [0, 0],
            held: initial,
        }
    }

    /// The board writes `pulses` at `now_us`; the tick lasts `tick_us`. Returns what the
    /// servos hold over the tick.
    pub fn tick(&mut self, now_us: u64, tick_us: u64, pulses: [u16; 4]) -> [u16; 4] {
        let end = now_us + tick_us;
        for group in 0..2 {
            // Frames that started before this tick's write carried the old pulse.
            while self.next_frame_us[group] < now_us {
                self.next_frame_us[group] += self.period_us[group];
            }
            if self.next_frame_us[group] < end {
                let outputs = if group == 0 { 0..3 } else { 3..4 };
                for k in outputs {
                    self.held[k] = pulses[k];
                }
                while self.next_frame_us[group] < end {
                    self.next_frame_us[group] += self.period_us[group];
                }
            }
        }
        self.held
    }
}

#[cfg(test)]
#[path = "servo_plant_tests.rs"]
mod tests;

/// The mixer of a board set up for `swash`: its geometry and servos, the default scales
/// (what `sweephold fc params push` writes for the aircraft file).
pub fn board_mixer(swash: &Swash) -> sweephold_firmware::mixer::MixerConfig {
    use sweephold_firmware::mixer::{MixerConfig, ServoConfig};
    use sweephold_firmware::swash::{SwashGeometry, SwashType};
    let servo = |s: &ServoOutput| ServoConfig {
        centre_us: s.centre_us as u16,
        throw_us: s.throw_us as f32,
        min_us: s.min_us as u16,
        max_us: s.max_us as u16,
        reversed: s.reversed,
    };
    let kind = SwashType::from_code(swash.kind.code()).unwrap_or(SwashType::H3_120);
    let phase_deg = swash.phase.to_degrees() as f32;
    let geometry = if kind == SwashType::H3_120 && phase_deg == 0.0 && swash.lead == 1 {
        SwashGeometry::H3_120
    } else {
        // The aircraft crate checked the phase (±180°) and the lead servo (1–3).
        SwashGeometry::new(kind, phase_deg, swash.lead).unwrap_or(SwashGeometry::H3_120)
    };
    MixerConfig {
        swash: swash.servos.each_ref().map(servo),
        geometry,
        tail: servo(&swash.tail),
        ..MixerConfig::trex700l()
    }
}

/// The frame rates \[Hz\] of a board set up for `swash`: its own, else the board's default.
pub fn board_frame_rates(swash: &Swash) -> [u16; 2] {
    let default = sweephold_firmware::params::typed::DEFAULT_FRAME_HZ;
    [swash.frame_rate, swash.tail_frame_rate].map(|rate| rate.map_or(default, |hz| hz as u16))
}

/// The main and tail rotor speeds \[rpm\] of `aircraft`, when both lie within the ranges
/// of the board's `HEAD_RPM` and `TAIL_RPM`: the vibration notches a board set up for it
/// gets (`sweephold fc params push`), and the rotor lines `--fc board-sim`'s emulated IMU
/// senses. `None` for a full-size rotor (the Bo-105's 424 rpm).
pub fn board_rotor_rpm(aircraft: &aircraft::Aircraft) -> Option<[f32; 2]> {
    use sweephold_firmware::params::ParamId;
    let rpm = |rad_s: f64| (rad_s * 60.0 / std::f64::consts::TAU) as f32;
    let speeds = [
        rpm(aircraft.main_rotor.head_speed.value),
        rpm(aircraft.tail_rotor.speed.value),
    ];
    let within = |id: ParamId, value: f32| {
        let def = id.def();
        value.is_finite() && (def.min..=def.max).contains(&value)
    };
    (within(ParamId::HeadRpm, speeds[0]) && within(ParamId::TailRpm, speeds[1])).then_some(speeds)
}
