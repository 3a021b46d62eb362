//! Deterministic synthetic telemetry for benchmarks and tests (feature `synthetic`).
//!
//! The values are smooth functions of the tick with full-precision mantissas, so their
//! encoded size matches real telemetry (postcard writes every f32 as 4 bytes anyway).

use crate::frames::*;

/// A plausible Sample of a lateral sweep at `tick` (200 Hz).
pub fn sample(tick: u32) -> Sample {
    let t = tick as f32 / 200.0;
    let s = |k: f32| libm_free_sin(t * k);
    let c = |a: f32| Controls {
        lat: 0.05 * s(a),
        lon: 0.01 * s(a + 1.3),
        ped: 0.01 * s(a + 2.1),
        col: 0.43,
    };
    Sample {
        tick,
        phase: Phase::Sweep,
        primary: Axis::Lat,
        sweep_omega: 0.3 + 0.001 * tick as f32,
        hold: [HoldState::Released, HoldState::Released, HoldState::Engaged],
        command: c(1.0),
        sweep: c(1.7),
        noise: c(2.3),
        pilot: c(0.1),
        meas: Measurements {
            p: 0.1 * s(3.1),
            q: 0.05 * s(2.9),
            r: 0.02 * s(1.9),
            phi: 0.03 * s(0.7),
            theta: 0.04 + 0.01 * s(0.5),
            psi: 0.2 * s(0.05),
            u: 0.3 * s(0.3),
            v: 0.2 * s(0.4),
            w: 0.1 * s(0.6),
            ax: 0.2 * s(4.1),
            ay: 0.3 * s(3.7),
            az: -9.81 + 0.2 * s(5.3),
        },
    }
}

/// A Header of a default Bo-105 lateral sweep.
pub fn header() -> Header {
    Header {
        protocol: PROTOCOL_VERSION,
        firmware: FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        vehicle: VehicleId::Bo105,
        rate_hz: 200,
        test: TestConfig {
            mode: ExcitationMode::ConditionalAttitudeHold,
            primary: Axis::Lat,
            input: InputKind::Sweep,
            sweep: SweepSettings {
                t_rec_s: 90.0,
                amplitude: 0.05,
                omega_min: 0.3,
                omega_max: 31.4,
                fade_s: 2.0,
                start_hold_cycles: 0,
            },
            pulse: PulseSettings {
                amplitude: 0.05,
                width_s: 1.0,
            },
            noise_rms: 0.01,
            noise_cutoff_rad_s: 31.4,
            seed: 1,
            hold_engage_rad: 0.104_719_76,
            hold_release_rad: 0.069_813_17,
            freeze_in_band: false,
            warnings: 0,
        },
        selection: None,
    }
}

/// A sine good to a few 1e-4 (Bhaskara-free Taylor on a reduced argument): enough for
/// synthetic data, and it keeps this crate free of a libm dependency.
fn libm_free_sin(x: f32) -> f32 {
    let two_pi = core::f32::consts::TAU;
    let mut r = x - two_pi * (x / two_pi) as i32 as f32;
    if r > core::f32::consts::PI {
        r -= two_pi;
    }
    let r2 = r * r;
    r * (1.0 - r2 / 6.0 * (1.0 - r2 / 20.0 * (1.0 - r2 / 42.0 * (1.0 - r2 / 72.0))))
}
