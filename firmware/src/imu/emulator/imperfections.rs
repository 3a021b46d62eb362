//! The emulated chip's imperfections: bias, noise, scale errors and the rotor's vibration
//! lines ([`Imperfections`]), with the bench's and a running 700-class rotor's presets.

/// One vibration line: a sinusoid of the same frequency on every axis, zero phase at
/// t = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vibration {
    /// Frequency \[Hz\].
    pub frequency_hz: f32,
    /// Gyro amplitude per chip axis \[rad/s\].
    pub gyro_rad_s: [f32; 3],
    /// Accelerometer amplitude per chip axis \[m/s²\].
    pub accel_m_s2: [f32; 3],
}

impl Vibration {
    /// No vibration.
    pub const OFF: Vibration = Vibration {
        frequency_hz: 0.0,
        gyro_rad_s: [0.0; 3],
        accel_m_s2: [0.0; 3],
    };
}

/// Main-rotor speed of a 700-class model \[rpm\] (the vibration lines below derive from
/// it).
pub const TREX700L_HEADSPEED_RPM: f32 = 2100.0;
/// Tail-rotor to main-rotor speed ratio of a 700-class model.
pub const TREX700L_TAIL_RATIO: f32 = 4.5;

/// Sensor imperfections, chip axes. Every one can be set to zero ([`Imperfections::IDEAL`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Imperfections {
    /// Constant gyro bias \[rad/s\].
    pub gyro_bias_rad_s: [f32; 3],
    /// Constant accelerometer bias \[m/s²\] (indistinguishable from a tilt at rest).
    pub accel_bias_m_s2: [f32; 3],
    /// Gyro white noise, standard deviation per sample \[rad/s\].
    pub gyro_noise_rad_s: f32,
    /// Accelerometer white noise, standard deviation per sample \[m/s²\].
    pub accel_noise_m_s2: f32,
    /// Gyro scale-factor error (0.003 = reads 0.3 % high).
    pub gyro_scale_error: [f32; 3],
    /// Accelerometer scale-factor error.
    pub accel_scale_error: [f32; 3],
    /// Vibration lines (rotor harmonics); [`Vibration::OFF`] for none.
    pub vibration: [Vibration; 3],
    /// Noise generator seed.
    pub seed: u64,
}

const DEG: f32 = core::f32::consts::PI / 180.0;

impl Imperfections {
    /// None: the output is the quantised, saturated truth.
    pub const IDEAL: Imperfections = Imperfections {
        gyro_bias_rad_s: [0.0; 3],
        accel_bias_m_s2: [0.0; 3],
        gyro_noise_rad_s: 0.0,
        accel_noise_m_s2: 0.0,
        gyro_scale_error: [0.0; 3],
        accel_scale_error: [0.0; 3],
        vibration: [Vibration::OFF; 3],
        seed: 0x5EED,
    };

    /// A chip on a board at rest, rotor stopped (the [`Default`]):
    /// gyro bias (0.3, −0.2, 0.1) °/s, inside the datasheet's ±0.5 °/s zero-rate offset;
    /// no accelerometer bias; noise at the datasheet densities over the configured
    /// bandwidths: gyro 2.8 m°/s/√Hz · √250 Hz ≈ 0.044 °/s = 7.7·10⁻⁴ rad/s,
    /// accelerometer 70 µg/√Hz · √100 Hz = 0.7 mg ≈ 6.9·10⁻³ m/s²; scale errors of
    /// (+0.3, −0.2, +0.1) % (gyro) and (+0.2, −0.1, +0.3) % (accelerometer), inside the
    /// ±0.5 % sensitivity tolerance; no vibration.
    pub const BENCH: Imperfections = Imperfections {
        gyro_bias_rad_s: [0.3 * DEG, -0.2 * DEG, 0.1 * DEG],
        accel_bias_m_s2: [0.0; 3],
        gyro_noise_rad_s: 7.7e-4,
        accel_noise_m_s2: 6.9e-3,
        gyro_scale_error: [0.003, -0.002, 0.001],
        accel_scale_error: [0.002, -0.001, 0.003],
        vibration: [Vibration::OFF; 3],
        seed: 0x5EED,
    };

    /// [`Imperfections::BENCH`] plus the rotor lines of a 700-class model at 2100 rpm:
    /// main rotor 1/rev 35 Hz and 2/rev 70 Hz, tail rotor 4.5 × 35 = 157.5 Hz
    /// ([`Imperfections::rotor_running`]).
    pub const TREX700L_ROTOR_RUNNING: Imperfections = Imperfections::rotor_running(
        TREX700L_HEADSPEED_RPM / 60.0,
        TREX700L_TAIL_RATIO * TREX700L_HEADSPEED_RPM / 60.0,
    );

    /// [`Imperfections::BENCH`] plus a two-bladed rotor's lines: the main rotor's 1/rev
    /// at `main_rotor_hz` and 2/rev, the tail rotor at `tail_rotor_hz`. The amplitudes
    /// are illustrative, not measured: 1/rev 0.02 rad/s roll/pitch, 0.5 m/s² in-plane,
    /// 1 m/s² vertical; 2/rev 0.01 rad/s and 1.5 m/s² vertical; tail rotor 0.03 rad/s
    /// in yaw and 1.5 m/s² lateral.
    pub const fn rotor_running(main_rotor_hz: f32, tail_rotor_hz: f32) -> Imperfections {
        Imperfections {
            vibration: [
                Vibration {
                    frequency_hz: main_rotor_hz,
                    gyro_rad_s: [0.02, 0.02, 0.005],
                    accel_m_s2: [0.5, 0.5, 1.0],
                },
                Vibration {
                    frequency_hz: 2.0 * main_rotor_hz,
                    gyro_rad_s: [0.01, 0.01, 0.005],
                    accel_m_s2: [0.3, 0.3, 1.5],
                },
                Vibration {
                    frequency_hz: tail_rotor_hz,
                    gyro_rad_s: [0.005, 0.005, 0.03],
                    accel_m_s2: [1.0, 1.5, 0.5],
                },
            ],
            ..Imperfections::BENCH
        }
    }
}

impl Default for Imperfections {
    fn default() -> Self {
        Self::BENCH
    }
}
