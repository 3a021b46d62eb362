//! Inertial measurement: the ICM-42688-P driver, its health monitor, boot calibration and
//! (host only) a register-level emulator of the chip.
//!
//! * [`Icm42688`] — blocking driver over `embedded_hal::spi::SpiDevice`: configures the
//!   chip (±2000 °/s, ±16 g, 1 kHz, low-noise mode) and reads one [`ImuSample`] in SI
//!   units and body axes per data-ready.
//! * [`ImuMonitor`] — fed with every poll, reports the first [`ImuFault`]
//!   (missing, stuck, saturated, not ready).
//! * [`rotation`] — the mounting as one of the 24 axis-aligned rotations, and the
//!   pre-arm check that the board stands within 25° of level.
//! * [`calibration`] — gyro bias and level offsets from a still window at boot, one
//!   sample at a time.
//! * `emulator` (with `std` or in tests) — the chip as an `SpiDevice`, fed with the
//!   simulator's truth, with bias, noise, scale error, rotor vibration, quantisation,
//!   saturation and injectable faults.
//!
//! # Axes and units
//!
//! Body axes: x forward, y right, z down (right-handed). Gyro: body rates p, q, r about
//! x, y, z in rad/s. Accelerometer: *specific force* (acceleration minus gravity) in
//! m/s², so an aircraft at rest and level reads `a ≈ (0, 0, −g)`.
//!
//! The chip's own axes are fixed to its package (x, y in the package plane, z out of the
//! top face, right-handed). [`Orientation`] maps them onto body axes as a signed
//! permutation; the default is the identity, which is the chip mounted *top face down*
//! with its x forward. A chip mounted top face up with x forward reads +g on its z at
//! rest and needs [`Orientation::TOP_UP_X_FORWARD`] (body = (x, −y, −z)).

pub mod calibration;
#[cfg(any(test, feature = "std", feature = "imu-emulator"))]
pub mod emulator;
mod icm42688;
pub mod registers;
pub mod rotation;
#[cfg(test)]
mod rotation_tests;
#[cfg(test)]
mod tests;

pub use calibration::{
    Bias, CalibrationConfig, CalibrationStatus, GyroCalibration, Motion, Restart,
};
pub use icm42688::{
    Icm42688, ACCEL_FULL_SCALE_G, ACCEL_M_S2_PER_LSB, GRAVITY_M_S2, GYRO_FULL_SCALE_DPS,
    GYRO_RAD_S_PER_LSB, GYRO_STARTUP_MS, INIT_REGISTERS, SOFT_RESET_MS, TEMP_LSB_PER_C,
    TEMP_OFFSET_C,
};
pub use rotation::{check_level, ImuRotation, LevelError};

use embedded_hal::spi::ErrorKind;

/// One sensor sample as read from the data registers: big-endian words decoded, sensor
/// axes, no scaling.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RawSample {
    /// TEMP_DATA1:TEMP_DATA0.
    pub temperature: i16,
    /// ACCEL_DATA_X/Y/Z, sensor axes.
    pub accel: [i16; 3],
    /// GYRO_DATA_X/Y/Z, sensor axes.
    pub gyro: [i16; 3],
}

impl RawSample {
    /// Whether any of the six axes sits at either end of its range (±32767, or −32768,
    /// which the chip also uses for "no data").
    pub fn any_axis_saturated(&self) -> bool {
        self.accel
            .iter()
            .chain(self.gyro.iter())
            .any(|&v| v == i16::MAX || v <= -i16::MAX)
    }

    /// The six motion axes (accel x, y, z, gyro x, y, z), the data the stuck check
    /// compares.
    pub fn motion(&self) -> [i16; 6] {
        let [ax, ay, az] = self.accel;
        let [gx, gy, gz] = self.gyro;
        [ax, ay, az, gx, gy, gz]
    }
}

/// One IMU sample in SI units and body axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImuSample {
    /// Body rates p, q, r \[rad/s\].
    pub gyro_rad_s: [f32; 3],
    /// Specific force along body x, y, z \[m/s²\] (≈ (0, 0, −g) at rest, level).
    pub accel_m_s2: [f32; 3],
    /// Die temperature \[°C\].
    pub temperature_c: f32,
    /// The register values the SI values were scaled from (sensor axes).
    pub raw: RawSample,
}

/// One signed sensor axis: which chip axis a body axis reads, and with which sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SignedAxis {
    /// Chip +x.
    PosX,
    /// Chip −x.
    NegX,
    /// Chip +y.
    PosY,
    /// Chip −y.
    NegY,
    /// Chip +z.
    PosZ,
    /// Chip −z.
    NegZ,
}

impl SignedAxis {
    /// Index of the chip axis (x 0, y 1, z 2).
    pub const fn index(self) -> usize {
        match self {
            SignedAxis::PosX | SignedAxis::NegX => 0,
            SignedAxis::PosY | SignedAxis::NegY => 1,
            SignedAxis::PosZ | SignedAxis::NegZ => 2,
        }
    }

    /// +1 or −1.
    pub const fn sign(self) -> i8 {
        match self {
            SignedAxis::PosX | SignedAxis::PosY | SignedAxis::PosZ => 1,
            SignedAxis::NegX | SignedAxis::NegY | SignedAxis::NegZ => -1,
        }
    }

    /// This axis with its sign multiplied by `sign` (+1 keeps it, −1 reverses it).
    const fn signed(self, sign: i8) -> SignedAxis {
        match (self.index(), self.sign() * sign) {
            (0, 1) => SignedAxis::PosX,
            (0, _) => SignedAxis::NegX,
            (1, 1) => SignedAxis::PosY,
            (1, _) => SignedAxis::NegY,
            (_, 1) => SignedAxis::PosZ,
            _ => SignedAxis::NegZ,
        }
    }

    /// The signed component of `v` this axis selects.
    fn pick(self, v: [f32; 3]) -> f32 {
        let [x, y, z] = v;
        match self {
            SignedAxis::PosX => x,
            SignedAxis::NegX => -x,
            SignedAxis::PosY => y,
            SignedAxis::NegY => -y,
            SignedAxis::PosZ => z,
            SignedAxis::NegZ => -z,
        }
    }

    /// The axis as an integer unit vector in chip axes.
    fn unit(self) -> [i8; 3] {
        let s = self.sign();
        match self.index() {
            0 => [s, 0, 0],
            1 => [0, s, 0],
            _ => [0, 0, s],
        }
    }
}

/// Board orientation: for each body axis (x forward, y right, z down), the signed chip
/// axis it reads, `body[i] = sign_i · chip[axis_i]`.
///
/// Only proper rotations are accepted (a permutation of x, y, z whose signed unit
/// vectors have determinant +1): both frames are right-handed, and a reflection would
/// flip the sense of the gyro's rotation while leaving the accelerometer's vector
/// consistent, which no mounting can do. The same map serves both sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Orientation {
    axes: [SignedAxis; 3],
}

impl Default for Orientation {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Orientation {
    /// Chip axes are body axes: chip top face down, chip x forward.
    pub const IDENTITY: Orientation = Orientation {
        axes: [SignedAxis::PosX, SignedAxis::PosY, SignedAxis::PosZ],
    };

    /// Chip top face up, chip x forward (a 180° roll of the identity):
    /// body = (x, −y, −z).
    pub const TOP_UP_X_FORWARD: Orientation = Orientation {
        axes: [SignedAxis::PosX, SignedAxis::NegY, SignedAxis::NegZ],
    };

    /// The mapping `body[i] = axes[i]` when it is a proper rotation, `None` otherwise
    /// (a chip axis used twice, or a reflection).
    pub fn new(axes: [SignedAxis; 3]) -> Option<Self> {
        let [a, b, c] = axes.map(SignedAxis::unit);
        // Determinant of the rows a, b, c: a · (b × c). ±1 for a signed permutation,
        // 0 when an axis repeats.
        let [a0, a1, a2] = a.map(i32::from);
        let [b0, b1, b2] = b.map(i32::from);
        let [c0, c1, c2] = c.map(i32::from);
        let det = a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
        (det == 1).then_some(Orientation { axes })
    }

    /// The signed chip axis read by each body axis.
    pub const fn axes(&self) -> [SignedAxis; 3] {
        self.axes
    }

    /// `self` after `inner`: the map from `inner`'s input axes to `self`'s output axes
    /// (`to_body` of the result equals `self.to_body(inner.to_body(v))`). The image uses
    /// it to put the aircraft's mounting of the board (`IMU_ROT`) after the board's own
    /// mounting of its chip. A product of proper rotations is proper.
    pub fn after(self, inner: Orientation) -> Orientation {
        let [x, y, z] = inner.axes;
        let through_inner = |outer: SignedAxis| {
            let read = match outer.index() {
                0 => x,
                1 => y,
                _ => z,
            };
            read.signed(outer.sign())
        };
        Orientation {
            axes: self.axes.map(through_inner),
        }
    }

    /// Chip-axis vector to body axes.
    pub fn to_body(&self, chip: [f32; 3]) -> [f32; 3] {
        self.axes.map(|axis| axis.pick(chip))
    }

    /// Body-axis vector to chip axes (the inverse map, `chip[axis_i] = sign_i · body[i]`).
    pub fn to_chip(&self, body: [f32; 3]) -> [f32; 3] {
        let mut chip = [0.0; 3];
        for (axis, value) in self.axes.iter().zip(body) {
            if let Some(slot) = chip.get_mut(axis.index()) {
                *slot = f32::from(axis.sign()) * value;
            }
        }
        chip
    }
}

/// A failed driver operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImuError {
    /// The SPI device returned an error.
    Bus(ErrorKind),
    /// WHO_AM_I read this instead of 0x47: no chip, another chip, or MISO stuck.
    WrongId(u8),
    /// A configuration register read back differently from what `init` wrote.
    ConfigMismatch {
        /// Register address.
        register: u8,
        /// Value written.
        expected: u8,
        /// Value read back.
        found: u8,
    },
}

impl ImuError {
    /// The health fault this error means: every driver error is [`ImuFault::Missing`]
    /// (the chip cannot be talked to or is not the expected one).
    pub const fn fault(&self) -> ImuFault {
        ImuFault::Missing
    }
}

/// IMU health fault, as reported by [`ImuMonitor`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImuFault {
    /// SPI error, wrong WHO_AM_I or a configuration that does not read back.
    Missing,
    /// The six motion axes read identical raw values on `stuck_reads` consecutive reads.
    Stuck,
    /// An axis sat at ± full scale on `saturated_reads` consecutive reads.
    Saturated,
    /// No data-ready on `not_ready_polls` consecutive polls at the sample rate.
    NotReady,
}

/// Thresholds of [`ImuMonitor`], in reads or polls at the sample rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MonitorLimits {
    /// Identical 6-axis raw data on this many consecutive reads is [`ImuFault::Stuck`].
    pub stuck_reads: u16,
    /// Any axis at ± full scale on this many consecutive reads is
    /// [`ImuFault::Saturated`].
    pub saturated_reads: u16,
    /// This many consecutive polls without data-ready is [`ImuFault::NotReady`].
    pub not_ready_polls: u16,
}

impl MonitorLimits {
    /// Defaults for 1 kHz polling: stuck 20 reads (20 ms), saturated 10 reads (10 ms),
    /// not ready 5 polls (5 ms).
    ///
    /// Stuck: at rest the noise is about 0.7 LSB rms per gyro axis and 1.4 LSB per
    /// accelerometer axis (2.8 m°/s/√Hz and 70 µg/√Hz at the configured bandwidths), so two
    /// consecutive reads agree on all six axes with a probability of the order of 10⁻³
    /// even allowing for filter correlation; 19 repeats in a row (≈ 10⁻⁵⁷) do not happen to
    /// a working chip, and in flight the vibration makes them less likely still.
    ///
    /// Saturated: shorter than the stuck limit, so a chip whose output is pinned at full
    /// scale (identical reads too) is reported as saturated. A vibration peak clipped on
    /// each rotor cycle makes short runs (a fraction of the 14 ms half period at 35 Hz)
    /// and does not trip it; 10 ms without a break at ±2000 °/s or ±16 g does, and data
    /// clipped that long are no longer a measurement.
    ///
    /// Not ready: the poll and the chip run on different clocks, so a poll occasionally
    /// finds no new sample; five in a row is a chip that stopped sampling (a brown-out
    /// resets it with its sensors off).
    pub const DEFAULT: MonitorLimits = MonitorLimits {
        stuck_reads: 20,
        saturated_reads: 10,
        not_ready_polls: 5,
    };
}

impl Default for MonitorLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// IMU health monitor: fed with every poll result, reports the first fault and keeps
/// reporting it (latched) until [`ImuMonitor::reset`].
///
/// Detection latencies with [`MonitorLimits::DEFAULT`], counted in polls at 1 kHz:
/// Missing on the first failed poll; NotReady on the 5th consecutive poll without data;
/// Saturated on the 10th consecutive saturated read; Stuck on the 20th consecutive read
/// with identical data (19 repeats of the first). A zero limit acts as one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImuMonitor {
    limits: MonitorLimits,
    last_motion: Option<[i16; 6]>,
    identical_reads: u16,
    saturated_reads: u16,
    not_ready_polls: u16,
    fault: Option<ImuFault>,
}

impl Default for ImuMonitor {
    fn default() -> Self {
        Self::new(MonitorLimits::DEFAULT)
    }
}

impl ImuMonitor {
    /// Monitor with the given limits, no fault.
    pub const fn new(limits: MonitorLimits) -> Self {
        ImuMonitor {
            limits,
            last_motion: None,
            identical_reads: 0,
            saturated_reads: 0,
            not_ready_polls: 0,
            fault: None,
        }
    }

    /// The limits in use.
    pub const fn limits(&self) -> MonitorLimits {
        self.limits
    }

    /// The latched fault, if any.
    pub const fn fault(&self) -> Option<ImuFault> {
        self.fault
    }

    /// Clear the fault and every counter.
    pub fn reset(&mut self) {
        *self = Self::new(self.limits);
    }

    /// Feed one poll result ([`Icm42688::poll`]): a sample, no data ready, or an error.
    /// Returns the latched fault.
    pub fn feed(&mut self, poll: &Result<Option<ImuSample>, ImuError>) -> Option<ImuFault> {
        match poll {
            Ok(Some(sample)) => self.feed_sample(&sample.raw),
            Ok(None) => self.feed_not_ready(),
            Err(error) => self.feed_error(error),
        }
    }

    /// Feed one read of the data registers (made after data-ready).
    pub fn feed_sample(&mut self, raw: &RawSample) -> Option<ImuFault> {
        self.not_ready_polls = 0;
        let motion = raw.motion();
        self.identical_reads = if self.last_motion == Some(motion) {
            self.identical_reads.saturating_add(1)
        } else {
            1
        };
        self.last_motion = Some(motion);
        self.saturated_reads = if raw.any_axis_saturated() {
            self.saturated_reads.saturating_add(1)
        } else {
            0
        };
        // Saturated before stuck: pinned full-scale output is also identical output.
        if self.saturated_reads >= self.limits.saturated_reads.max(1) {
            self.latch(ImuFault::Saturated);
        }
        if self.identical_reads >= self.limits.stuck_reads.max(1) {
            self.latch(ImuFault::Stuck);
        }
        self.fault
    }

    /// Feed one poll that found no data ready.
    pub fn feed_not_ready(&mut self) -> Option<ImuFault> {
        self.not_ready_polls = self.not_ready_polls.saturating_add(1);
        if self.not_ready_polls >= self.limits.not_ready_polls.max(1) {
            self.latch(ImuFault::NotReady);
        }
        self.fault
    }

    /// Feed one failed poll: [`ImuFault::Missing`] at once.
    pub fn feed_error(&mut self, error: &ImuError) -> Option<ImuFault> {
        self.latch(error.fault());
        self.fault
    }

    fn latch(&mut self, fault: ImuFault) {
        if self.fault.is_none() {
            warn!("IMU fault: {=u8}", fault as u8);
            self.fault = Some(fault);
        }
    }
}
