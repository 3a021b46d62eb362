//! Test helpers: the closed-form Tischler sweep, exact-enough simulation of small linear
//! systems with input delays, Gaussian noise, and synthetic telemetry dumps.

use sweephold_protocol::{
    encode, Axis, Controls, ExcitationMode, FirmwareVersion, Frame, Header, HoldState, InputKind,
    Measurements, Phase, PulseSettings, Sample, SweepSettings, TestConfig, VehicleId,
    MAX_FRAME_LEN, PROTOCOL_VERSION,
};

use crate::random::SplitMix64;
use crate::records::{Channel, Record};

/// Tischler's exponential sweep, closed form:
/// θ(t) = ω_min t + (ω_max − ω_min)·C2·[(T/C1)(e^{C1 t/T} − 1) − t], C1 = 4,
/// C2 = 1/(e⁴ − 1); the signal is A·sin θ(t) on [0, T] and 0 outside.
#[derive(Clone, Copy, Debug)]
pub struct Sweep {
    pub omega_min: f64,
    pub omega_max: f64,
    pub duration: f64,
    pub amplitude: f64,
}

impl Sweep {
    const C1: f64 = 4.0;

    pub fn phase(&self, t: f64) -> f64 {
        let c2 = 1.0 / (Self::C1.exp() - 1.0);
        let t_rec = self.duration;
        self.omega_min * t
            + (self.omega_max - self.omega_min)
                * c2
                * ((t_rec / Self::C1) * ((Self::C1 * t / t_rec).exp() - 1.0) - t)
    }

    pub fn value(&self, t: f64) -> f64 {
        if (0.0..=self.duration).contains(&t) {
            self.amplitude * self.phase(t).sin()
        } else {
            0.0
        }
    }
}

/// SplitMix64 with Box–Muller ([`SplitMix64::normal_pair`]): reproducible Gaussian noise,
/// one deviate per call.
pub struct Noise {
    random: SplitMix64,
    spare: Option<f64>,
}

impl Noise {
    pub fn new(seed: u64) -> Noise {
        Noise {
            random: SplitMix64::new(seed),
            spare: None,
        }
    }

    /// A standard normal deviate.
    pub fn gaussian(&mut self) -> f64 {
        if let Some(v) = self.spare.take() {
            return v;
        }
        let (first, second) = self.random.normal_pair();
        self.spare = Some(second);
        first
    }
}

/// A SISO block `K·e^{−sτ}·N(s)/D(s)` in controllable canonical form, driven by an
/// input signal known in closed form (so the delay is exact).
#[derive(Clone, Debug)]
pub struct Block {
    /// Denominator coefficients d_0..d_{n−1} of s^n + d_{n−1}s^{n−1} + … + d_0.
    pub den: Vec<f64>,
    /// Numerator coefficients b_0..b_{n−1} (b_0 + b_1 s + …), degree < n.
    pub num: Vec<f64>,
    /// Input delay τ \[s\].
    pub delay: f64,
}

impl Block {
    /// K/(T s + 1)·e^{−sτ}.
    pub fn first_order(gain: f64, time_constant: f64, delay: f64) -> Block {
        Block {
            den: vec![1.0 / time_constant],
            num: vec![gain / time_constant],
            delay,
        }
    }

    /// K ωn²/(s² + 2ζωn s + ωn²)·e^{−sτ}.
    pub fn second_order(gain: f64, omega_n: f64, zeta: f64, delay: f64) -> Block {
        Block {
            den: vec![omega_n * omega_n, 2.0 * zeta * omega_n],
            num: vec![gain * omega_n * omega_n, 0.0],
            delay,
        }
    }

    /// H(iω) = e^{−iωτ}·N(iω)/D(iω).
    pub fn response(&self, omega: f64) -> num_complex::Complex64 {
        use num_complex::Complex64 as C;
        let s = C::new(0.0, omega);
        let order = self.den.len();
        let mut den = s.powu(order as u32);
        for (k, &d) in self.den.iter().enumerate() {
            den += d * s.powu(k as u32);
        }
        let mut num = C::new(0.0, 0.0);
        for (k, &b) in self.num.iter().enumerate() {
            num += b * s.powu(k as u32);
        }
        num / den * C::from_polar(1.0, -omega * self.delay)
    }

    /// ẋ for state x and input value u (controllable canonical form).
    fn derivative(&self, x: &[f64], u: f64, dx: &mut [f64]) {
        let n = x.len();
        dx[..n - 1].copy_from_slice(&x[1..]);
        dx[n - 1] = u - self.den.iter().zip(x).map(|(d, x)| d * x).sum::<f64>();
    }

    fn output(&self, x: &[f64]) -> f64 {
        self.num.iter().zip(x).map(|(b, x)| b * x).sum()
    }

    /// Simulate y(t_k), t_k = k/rate, k = 0..len−1, with RK4 at `substeps` steps per
    /// sample; `input` is evaluated at t − τ.
    pub fn simulate(
        &self,
        input: &dyn Fn(f64) -> f64,
        rate: f64,
        len: usize,
        substeps: usize,
    ) -> Vec<f64> {
        let n = self.den.len();
        let mut x = vec![0.0; n];
        let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
        );
        let h = 1.0 / (rate * substeps as f64);
        let u = |t: f64| input(t - self.delay);
        let mut y = Vec::with_capacity(len);
        for k in 0..len {
            y.push(self.output(&x));
            for s in 0..substeps {
                let t = k as f64 / rate + s as f64 * h;
                self.derivative(&x, u(t), &mut k1);
                for i in 0..n {
                    tmp[i] = x[i] + 0.5 * h * k1[i];
                }
                self.derivative(&tmp, u(t + 0.5 * h), &mut k2);
                for i in 0..n {
                    tmp[i] = x[i] + 0.5 * h * k2[i];
                }
                self.derivative(&tmp, u(t + 0.5 * h), &mut k3);
                for i in 0..n {
                    tmp[i] = x[i] + h * k3[i];
                }
                self.derivative(&tmp, u(t + h), &mut k4);
                for i in 0..n {
                    x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                }
            }
        }
        y
    }
}

/// Sample a closed-form signal at `rate` for `len` samples.
pub fn sample(signal: &dyn Fn(f64) -> f64, rate: f64, len: usize) -> Vec<f64> {
    (0..len).map(|k| signal(k as f64 / rate)).collect()
}

/// Add white Gaussian noise of standard deviation `ratio`·RMS(values).
pub fn add_noise(values: &mut [f64], ratio: f64, noise: &mut Noise) {
    let rms = crate::records::rms(values);
    for v in values.iter_mut() {
        *v += ratio * rms * noise.gaussian();
    }
}

/// A record with the given inputs (first one swept) and outputs.
pub fn record(
    rate: f64,
    band: [f64; 2],
    inputs: Vec<(&str, Vec<f64>)>,
    outputs: Vec<(&str, Vec<f64>)>,
) -> Record {
    Record {
        source: "synthetic".into(),
        sample_rate_hz: rate,
        primary: inputs[0].0.to_string(),
        primary_guessed: false,
        sweep_band: Some(band),
        inputs: inputs
            .into_iter()
            .map(|(n, v)| Channel::new(n, v))
            .collect(),
        outputs: outputs
            .into_iter()
            .map(|(n, v)| Channel::new(n, v))
            .collect(),
        references: Vec::new(),
        notes: vec![],
        trim_samples: 0,
        measurement_filter: None,
    }
}

/// What [`dump_bytes`] writes: idle samples, a Header, excitation samples, done samples.
#[derive(Clone, Debug)]
pub struct DumpSpec {
    pub rate_hz: u16,
    pub primary: Axis,
    pub input: InputKind,
    pub omega: [f32; 2],
    pub idle_samples: usize,
    pub sweep_samples: usize,
    /// Trim-capture samples before and done samples after the excitation.
    pub settle_samples: usize,
    pub with_header: bool,
    /// Leave out every n-th excitation Sample (lost frames).
    pub drop_every: Option<usize>,
    /// Per-sample commands and measurements of the excitation, if given; otherwise the
    /// primary command is a 1 Hz sine and `p` carries the tick number.
    pub signals: Option<(Vec<[f32; 4]>, Vec<Measurements>)>,
}

impl Default for DumpSpec {
    fn default() -> Self {
        DumpSpec {
            rate_hz: 100,
            primary: Axis::Lat,
            input: InputKind::Sweep,
            omega: [0.5, 20.0],
            idle_samples: 30,
            sweep_samples: 600,
            settle_samples: 0,
            with_header: true,
            drop_every: None,
            signals: None,
        }
    }
}

impl DumpSpec {
    pub fn first_sweep_tick(&self) -> u32 {
        1000 + (self.idle_samples + self.settle_samples) as u32
    }
}

fn header(spec: &DumpSpec) -> Header {
    Header {
        protocol: PROTOCOL_VERSION,
        firmware: FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        vehicle: VehicleId::Bo105,
        rate_hz: spec.rate_hz,
        test: TestConfig {
            mode: ExcitationMode::ConditionalAttitudeHold,
            primary: spec.primary,
            input: spec.input,
            sweep: SweepSettings {
                t_rec_s: spec.sweep_samples as f32 / f32::from(spec.rate_hz),
                amplitude: 0.05,
                omega_min: spec.omega[0],
                omega_max: spec.omega[1],
                fade_s: 0.0,
                start_hold_cycles: 0,
            },
            pulse: PulseSettings {
                amplitude: 0.05,
                width_s: 1.0,
            },
            noise_rms: 0.01,
            noise_cutoff_rad_s: 10.0,
            seed: 1,
            hold_engage_rad: 0.105,
            hold_release_rad: 0.07,
            freeze_in_band: false,
            warnings: 0,
        },
        selection: None,
    }
}

/// Encode a synthetic dump.
pub fn dump_bytes(spec: &DumpSpec) -> Vec<u8> {
    let mut out = Vec::new();
    let mut push = |frame: Frame| {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let n = encode(&frame, &mut buf).expect("frame fits");
        out.extend_from_slice(&buf[..n]);
    };
    let sample = |tick: u32, phase: Phase, command: [f32; 4], meas: Measurements| {
        Frame::Sample(Sample {
            tick,
            phase,
            primary: spec.primary,
            sweep_omega: 0.0,
            hold: [HoldState::Released; 3],
            command: Controls::from_array(command),
            // The injected excitation: the commands themselves, split 2:1 between
            // sweep and noise (the dump's references are 1.5 × the commands).
            sweep: Controls::from_array(command),
            noise: Controls::from_array(command.map(|c| 0.5 * c)),
            pilot: Controls::default(),
            meas,
        })
    };
    let mut tick = 1000u32;
    for _ in 0..spec.idle_samples {
        push(sample(tick, Phase::Idle, [0.0; 4], Measurements::default()));
        tick += 1;
    }
    if spec.with_header {
        push(Frame::Header(header(spec)));
    }
    let trim = |tick: u32| Measurements {
        p: tick as f32,
        ..Measurements::default()
    };
    for _ in 0..spec.settle_samples {
        push(sample(tick, Phase::TrimCapture, [0.0; 4], trim(tick)));
        tick += 1;
    }
    for k in 0..spec.sweep_samples {
        let (command, meas) = match &spec.signals {
            Some((commands, measurements)) => (commands[k], measurements[k]),
            None => {
                let mut command = [0.0f32; 4];
                command[spec.primary.index()] =
                    (std::f32::consts::TAU * k as f32 / f32::from(spec.rate_hz)).sin() * 0.05;
                let meas = Measurements {
                    p: tick as f32,
                    ..Measurements::default()
                };
                (command, meas)
            }
        };
        let phase = if k < spec.sweep_samples / 10 {
            Phase::FadeIn
        } else if k + spec.sweep_samples / 10 >= spec.sweep_samples {
            Phase::FadeOut
        } else {
            Phase::Sweep
        };
        let dropped = spec
            .drop_every
            .is_some_and(|n| k % n == n / 2 && k + 1 < spec.sweep_samples);
        if !dropped {
            push(sample(tick, phase, command, meas));
        }
        tick += 1;
    }
    for _ in 0..spec.settle_samples {
        push(sample(tick, Phase::Done, [0.0; 4], trim(tick)));
        tick += 1;
    }
    for _ in 0..20 {
        push(sample(tick, Phase::Idle, [0.0; 4], Measurements::default()));
        tick += 1;
    }
    out
}
