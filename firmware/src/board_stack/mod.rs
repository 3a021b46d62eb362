//! The board's sensor-to-servo stack: the IMU driver, its monitor and boot calibration,
//! the filter bank, the attitude estimator, the SBUS decoder, link monitor and channel
//! map, and the board application, wired together in one struct the board's runner
//! calls.
//!
//! ```text
//! boot()                      IMU init (reset, configure, power on)
//!
//! imu_sample(now)   1 kHz     poll ─▶ ImuMonitor (every poll)
//!                               │
//!                               ├─ calibrating: GyroCalibration (one sample per call);
//!                               │  when done: estimator with the level offsets, started
//!                               │  from the window's mean specific force
//!                               └─ running:  gyro − bias ─▶ FilterBank ─▶ Mahony
//!                                            (latest rates, specific force, estimate)
//!
//! control_tick(now, sbus, sink)   200 Hz
//!                             bytes ─▶ SbusDecoder ─▶ Receiver (link monitor)
//!                                                      ─▶ ChannelMap ─▶ RcInput
//!                             latest IMU values + status ─▶ ImuInput
//!                             TickInput ─▶ BoardApp::tick ─▶ TickOutput (telemetry into sink)
//! ```
//!
//! # Boot
//!
//! [`BoardStack::boot`] runs the driver's initialisation (it blocks ≈ 46 ms in the
//! delay). The calibration then takes the first [`CalibrationConfig::window_samples`]
//! still samples that [`BoardStack::imu_sample`] reads (1 s at 1 kHz): the aircraft must
//! stand still, rotor stopped, until [`BootState::Running`]. Until then the IMU status
//! the application sees is [`ImuStatus::Calibrating`], which blocks arming. A failed
//! initialisation ([`BootState::InitFailed`]: the chip does not answer or its
//! configuration does not read back) is reported as [`ImuFaultKind::Missing`]; call
//! `boot` again to retry. A calibration that finds no still window within its timeout
//! ([`BootState::CalibrationFailed`]) is reported as [`ImuFaultKind::NotReady`] until the
//! next `boot`: the board does not arm on an uncalibrated gyro.
//!
//! # The IMU path
//!
//! Every poll feeds the [`ImuMonitor`]; its latched fault is the IMU status from then on
//! (the application's IMU failsafe; it is cleared only by a new `boot`). A sample read
//! after calibration has the calibration's gyro bias subtracted, is filtered by the
//! [`FilterBank`] at the IMU rate (notches on the rotor harmonics, the low-pass before the
//! control tick's decimation) and updates the [`Mahony`] estimator, whose level offsets are
//! the calibration's. The control tick reads the latest values:
//!
//! * rates p, q, r: the estimator's bias-corrected rates in airframe axes (filtered gyro
//!   minus calibration bias minus the estimator's residual bias, rotated by the level
//!   offsets);
//! * specific force: the filtered accelerometer rotated into airframe axes the same way;
//! * φ, θ, ψ: the estimate (ψ relative: no magnetometer);
//! * `fresh`: at least one sample was read since the previous control tick.
//!
//! # The accelerometer during a test
//!
//! The estimator takes the specific force for the direction of gravity. On a helicopter
//! that holds only in unaccelerated flight: the rotor's thrust dominates the specific
//! force, so a banked aircraft accelerating sideways reads close to "level", and the
//! correction (at K_p = 0.5 rad/s) pulls the estimate towards the thrust's tilt with a
//! 2 s time constant. A sweep does exactly that for tens of seconds (its low band
//! excites periods of a minute), and the conditional attitude hold flies on the
//! estimate. While the sequencer flies the excitation (FadeIn, Sweep, FadeOut) the
//! estimator therefore propagates on the gyro alone ([`Mahony::propagate`]); the gyro
//! bias was measured at boot, so the drift over a record is that of the gyro's noise
//! and scale error, a small fraction of a degree. The correction resumes when the
//! excitation ends.
//!
//! # The receiver path
//!
//! The bytes the UART received since the previous tick are fed to the [`SbusDecoder`];
//! each frame it completes goes to the [`Receiver`] link monitor stamped with the tick's
//! time. The newest intact frame, if the link is valid at `now_us`, is mapped by the
//! [`ChannelMap`] and given to the application as [`Receiver::Valid`](AppReceiver::Valid);
//! otherwise the receiver is [`AppReceiver::Lost`] (no frame yet, failsafe flag, or no
//! intact frame for the link timeout).
//!
//! Nothing here allocates or panics; every value the application sees is computed from
//! integers read off the buses, so none is NaN, and the application turns whatever it is
//! given into finite, clamped outputs.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;

use crate::app::{
    AppConfig, AppConfigError, BoardApp, ImuFaultKind, ImuInput, ImuStatus,
    Receiver as AppReceiver, TickInput, TickOutput,
};
use crate::estimator::{EstimatorError, LevelOffset, Mahony, MahonyConfig, Quaternion, UpdateKind};
use crate::filters::{FilterBank, FilterBankConfig, FilterError};
use crate::imu::{
    Bias, CalibrationConfig, CalibrationStatus, GyroCalibration, Icm42688, ImuError, ImuFault,
    ImuMonitor, MonitorLimits, Orientation,
};
use crate::receiver::{ChannelMap, ChannelMapError, Receiver, SbusDecoder};
use crate::sink::FrameSink;
use sweephold_protocol::{Axis, Phase};

/// IMU sample rate the stack runs at \[Hz\]: the driver configures the chip for 1 kHz.
pub const IMU_RATE_HZ: f32 = 1000.0;

/// The board's estimator: [`MahonyConfig::helicopter`] at the IMU rate without the
/// in-flight bias integrator (K_i = 0). The gyro bias is measured at boot, rotor
/// stopped, and subtracted before the filters; the integrator would learn from the
/// specific force, which on a helicopter in manoeuvres is not the vertical (see the
/// module documentation), and a bias learnt wrongly in the hover before a test makes the
/// attitude drift through the test's excitation, where the estimator runs on the gyro
/// alone.
pub const BOARD_ESTIMATOR: MahonyConfig = MahonyConfig {
    ki: 0.0,
    ..MahonyConfig::helicopter(IMU_RATE_HZ)
};

/// Everything the stack needs besides its devices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StackConfig {
    /// The board application (sequencer, pilot mode, throttle, failsafes).
    pub app: AppConfig,
    /// How the IMU sits in the airframe.
    pub orientation: Orientation,
    /// IMU health limits.
    pub monitor: MonitorLimits,
    /// Boot calibration window and stillness limits.
    pub calibration: CalibrationConfig,
    /// IMU filter bank (must run at [`IMU_RATE_HZ`]).
    pub filters: FilterBankConfig,
    /// Attitude estimator (its level offset is replaced by the calibration's; its sample
    /// rate must be [`IMU_RATE_HZ`]).
    pub estimator: MahonyConfig,
    /// Receiver channel map.
    pub channel_map: ChannelMap,
    /// Receiver link timeout \[µs\].
    pub rc_timeout_us: u32,
}

impl StackConfig {
    /// TREX 700L: [`AppConfig::trex700l`], identity mounting, default monitor limits and
    /// calibration, [`FilterBankConfig::trex700l`], [`BOARD_ESTIMATOR`],
    /// [`ChannelMap::flybarless_default`], 100 ms link timeout.
    pub const fn trex700l(primary: Axis) -> Self {
        Self::with_app(AppConfig::trex700l(primary))
    }

    /// Bo-105 (simulator): [`AppConfig::bo105`] and otherwise the TREX 700L board's
    /// settings (the same IMU, filter bank and receiver).
    pub const fn bo105(primary: Axis) -> Self {
        Self::with_app(AppConfig::bo105(primary))
    }

    /// The board's standard settings around `app`.
    pub const fn with_app(app: AppConfig) -> Self {
        StackConfig {
            app,
            orientation: Orientation::IDENTITY,
            monitor: MonitorLimits::DEFAULT,
            calibration: CalibrationConfig::DEFAULT,
            filters: FilterBankConfig::trex700l(),
            estimator: BOARD_ESTIMATOR,
            channel_map: ChannelMap::flybarless_default(),
            rc_timeout_us: crate::receiver::sbus::LINK_TIMEOUT_US,
        }
    }
}

/// Why a configuration was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StackError {
    /// The board application refused its configuration.
    App(AppConfigError),
    /// The filter bank cannot be designed, or does not run at the IMU rate.
    Filters(FilterError),
    /// The estimator refused its settings.
    Estimator(EstimatorError),
    /// The channel map is invalid.
    ChannelMap(ChannelMapError),
    /// The calibration settings are invalid.
    Calibration,
    /// The filter bank or the estimator is set for another rate than [`IMU_RATE_HZ`].
    RateMismatch,
    /// A reconfiguration while the application is armed.
    Armed,
}

impl StackError {
    /// Human-readable explanation.
    pub const fn message(self) -> &'static str {
        match self {
            StackError::App(error) => error.message(),
            StackError::Filters(_) => "IMU filter bank cannot be designed",
            StackError::Estimator(_) => "attitude estimator settings invalid",
            StackError::ChannelMap(_) => "receiver channel map invalid",
            StackError::Calibration => "IMU calibration settings invalid",
            StackError::RateMismatch => "filter bank or estimator not set for the 1 kHz IMU rate",
            StackError::Armed => "reconfiguration refused: armed",
        }
    }
}

impl core::fmt::Display for StackError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

#[cfg(any(test, feature = "std"))]
impl std::error::Error for StackError {}

/// Where the boot stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BootState {
    /// [`BoardStack::boot`] has not run.
    NotBooted,
    /// The driver's initialisation failed (reported as [`ImuFaultKind::Missing`]).
    InitFailed(ImuError),
    /// The gyro calibration is collecting still samples.
    Calibrating,
    /// No still window within the calibration's timeout (reported as
    /// [`ImuFaultKind::NotReady`]).
    CalibrationFailed,
    /// Calibrated; the estimator runs.
    Running(Bias),
}

/// What one [`BoardStack::imu_sample`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ImuStep {
    /// Not booted, or the boot failed: the IMU was not polled.
    NotPolled,
    /// The poll failed (bus error or the chip gone).
    Error(ImuError),
    /// No new sample was ready.
    NotReady,
    /// The sample went to the calibration.
    Calibration(CalibrationStatus),
    /// The sample was filtered and updated the estimator.
    Estimated(UpdateKind),
}

/// The latest IMU values in airframe axes (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImuValues {
    /// Rates p, q, r \[rad/s\].
    pub rates: [f32; 3],
    /// Specific force \[m/s²\].
    pub specific_force: [f32; 3],
    /// φ, θ, ψ \[rad\].
    pub attitude: [f32; 3],
}

/// The stack. See the [module documentation](self).
#[derive(Debug)]
pub struct BoardStack<SPI, D> {
    config: StackConfig,
    imu: Icm42688<SPI>,
    delay: D,
    monitor: ImuMonitor,
    calibration: GyroCalibration,
    filters: FilterBank,
    estimator: Mahony,
    /// Level offsets of the estimator as a rotation (IMU to airframe axes).
    mount: Quaternion,
    boot: BootState,
    latest: ImuValues,
    /// Samples read since the last control tick.
    fresh_samples: u32,
    samples: u32,
    last_sample_us: Option<u32>,
    sbus: SbusDecoder,
    receiver: Receiver,
    app: BoardApp,
}

impl<SPI: SpiDevice, D: DelayNs> BoardStack<SPI, D> {
    /// The parts `config` builds, each checked, and the checks of the whole: the filter
    /// bank, the estimator and the application (for [`new`](Self::new) and
    /// [`reconfigure`](Self::reconfigure) alike).
    fn built_from(config: &StackConfig) -> Result<(FilterBank, Mahony, BoardApp), StackError> {
        let filters = FilterBank::new(config.filters).map_err(StackError::Filters)?;
        let estimator = Mahony::new(config.estimator).map_err(StackError::Estimator)?;
        if config.filters.sample_rate_hz != IMU_RATE_HZ
            || config.estimator.sample_rate_hz != IMU_RATE_HZ
        {
            return Err(StackError::RateMismatch);
        }
        if !config.calibration.is_valid() {
            return Err(StackError::Calibration);
        }
        config
            .channel_map
            .validate()
            .map_err(StackError::ChannelMap)?;
        let mut app = BoardApp::new(config.app).map_err(StackError::App)?;
        let announced = config.filters.measurement_filter();
        app.set_measurement_filter(Some(announced.map_err(StackError::Filters)?));
        Ok((filters, estimator, app))
    }

    /// Check `config` and build the stack on the IMU's SPI device and a delay. Nothing
    /// talks to the chip before [`boot`](Self::boot).
    pub fn new(spi: SPI, delay: D, config: StackConfig) -> Result<Self, StackError> {
        let (filters, estimator, app) = Self::built_from(&config)?;
        Ok(BoardStack {
            imu: Icm42688::with_orientation(spi, config.orientation),
            delay,
            monitor: ImuMonitor::new(config.monitor),
            calibration: GyroCalibration::new(config.calibration),
            filters,
            estimator,
            mount: Quaternion::IDENTITY,
            boot: BootState::NotBooted,
            latest: ImuValues::default(),
            fresh_samples: 0,
            samples: 0,
            last_sample_us: None,
            sbus: SbusDecoder::new(),
            receiver: Receiver::new(config.rc_timeout_us),
            app,
            config,
        })
    }

    /// Replace the configuration on the ground (the parameters changed): `Err` and
    /// nothing changed if `config` is refused or the application is armed. The
    /// application restarts Disarmed (tick 0, its arm switch to be cycled, the parameter
    /// flag kept), the filters and the receiver's timeout take the new settings, and a
    /// changed IMU mounting restarts the gyro calibration (bias and level were measured
    /// in the old axes). The IMU itself is not re-initialised.
    pub fn reconfigure(&mut self, config: StackConfig) -> Result<(), StackError> {
        if !self.app.host_link_allowed() {
            return Err(StackError::Armed);
        }
        let (filters, estimator, mut app) = Self::built_from(&config)?;
        app.set_params_valid(self.app.params_valid());
        let mounting_changed = config.orientation != self.config.orientation
            || config.calibration != self.config.calibration
            || config.estimator != self.config.estimator;
        self.app = app;
        self.filters = filters;
        self.receiver = Receiver::new(config.rc_timeout_us);
        self.monitor = ImuMonitor::new(config.monitor);
        self.imu.set_orientation(config.orientation);
        if mounting_changed {
            self.estimator = estimator;
            self.mount = Quaternion::IDENTITY;
            self.calibration = GyroCalibration::new(config.calibration);
            if matches!(
                self.boot,
                BootState::Running(_) | BootState::CalibrationFailed
            ) {
                self.boot = BootState::Calibrating;
            }
        }
        self.config = config;
        Ok(())
    }

    /// Initialise the IMU and start the calibration (see the module documentation).
    /// Clears the monitor's latched fault, the calibration and the estimator.
    pub fn boot(&mut self) -> Result<(), ImuError> {
        self.monitor.reset();
        self.calibration.reset();
        self.filters.reset();
        self.fresh_samples = 0;
        match self.imu.init(&mut self.delay) {
            Ok(()) => {
                self.boot = BootState::Calibrating;
                Ok(())
            }
            Err(error) => {
                self.boot = BootState::InitFailed(error);
                Err(error)
            }
        }
    }

    /// One poll of the IMU, at its 1 kHz rate (after its data-ready): monitor,
    /// calibration or filter and estimator. `now_us` is the board's free-running µs
    /// clock.
    pub fn imu_sample(&mut self, now_us: u32) -> ImuStep {
        if !matches!(self.boot, BootState::Calibrating | BootState::Running(_)) {
            return ImuStep::NotPolled;
        }
        let poll = self.imu.poll();
        self.monitor.feed(&poll);
        let sample = match poll {
            Err(error) => return ImuStep::Error(error),
            Ok(None) => return ImuStep::NotReady,
            Ok(Some(sample)) => sample,
        };
        self.samples = self.samples.saturating_add(1);
        self.last_sample_us = Some(now_us);
        match self.boot {
            BootState::Calibrating => {
                let status = self.calibration.feed(&sample);
                match status {
                    CalibrationStatus::Done(bias) => self.start_estimator(&bias),
                    CalibrationStatus::TimedOut => self.boot = BootState::CalibrationFailed,
                    CalibrationStatus::Collecting | CalibrationStatus::Moved(_) => {}
                }
                ImuStep::Calibration(status)
            }
            BootState::Running(bias) => {
                let gyro = bias.correct_gyro(sample.gyro_rad_s);
                let (gyro, accel) = self.filters.process_imu(gyro, sample.accel_m_s2);
                let kind = if is_excitation(self.app.flight_controller().phase()) {
                    self.estimator.propagate(gyro)
                } else {
                    self.estimator.update(gyro, accel)
                };
                let estimate = self.estimator.estimate();
                self.latest = ImuValues {
                    rates: [estimate.p, estimate.q, estimate.r],
                    specific_force: self.mount.rotate(accel),
                    attitude: [estimate.phi, estimate.theta, estimate.psi],
                };
                self.fresh_samples = self.fresh_samples.saturating_add(1);
                ImuStep::Estimated(kind)
            }
            _ => ImuStep::NotPolled,
        }
    }

    /// The calibration finished: estimator with its level offsets, started level from
    /// the window's mean specific force.
    fn start_estimator(&mut self, bias: &Bias) {
        let level_offset = LevelOffset {
            roll_rad: bias.roll_rad,
            pitch_rad: bias.pitch_rad,
        };
        let config = MahonyConfig {
            level_offset,
            ..self.config.estimator
        };
        // An offset beyond the estimator's limit (a board mounted askew) keeps the
        // configured one rather than failing the boot.
        let (estimator, offset) = match Mahony::new(config) {
            Ok(estimator) => (Some(estimator), level_offset),
            Err(_) => (
                Mahony::new(self.config.estimator).ok(),
                self.config.estimator.level_offset,
            ),
        };
        if let Some(estimator) = estimator {
            self.estimator = estimator;
        }
        self.estimator.reset();
        // In band by the calibration's own gravity check, or the filter starts level
        // and converges.
        let _ = self.estimator.initialise_from_accel(bias.accel_mean_m_s2);
        self.mount = Quaternion::from_euler(offset.roll_rad, offset.pitch_rad, 0.0);
        self.filters.reset();
        self.boot = BootState::Running(*bias);
        info!("board stack: IMU calibrated, estimator running");
    }

    /// One control tick: `sbus_bytes` are the receiver bytes that arrived since the
    /// previous tick; the application's telemetry goes into `sink`.
    pub fn control_tick<S: FrameSink>(
        &mut self,
        now_us: u32,
        sbus_bytes: &[u8],
        sink: &mut S,
    ) -> TickOutput {
        for &byte in sbus_bytes {
            if let Some(frame) = self.sbus.feed(byte) {
                self.receiver.on_frame(&frame, now_us);
            }
        }
        let rc = match self.receiver.frame(now_us) {
            Some(frame) => AppReceiver::Valid(self.config.channel_map.map(&frame)),
            None => AppReceiver::Lost,
        };
        let input = TickInput {
            imu: self.imu_input(),
            rc,
        };
        self.fresh_samples = 0;
        self.app.tick(&input, sink)
    }

    /// The IMU input of this tick.
    fn imu_input(&self) -> ImuInput {
        let status = match (self.boot, self.monitor.fault()) {
            (_, Some(fault)) => ImuStatus::Fault(fault_kind(fault)),
            (BootState::Running(_), None) => ImuStatus::Ok,
            (BootState::Calibrating, None) => ImuStatus::Calibrating,
            (BootState::NotBooted | BootState::CalibrationFailed, None) => {
                ImuStatus::Fault(ImuFaultKind::NotReady)
            }
            (BootState::InitFailed(_), None) => ImuStatus::Fault(ImuFaultKind::Missing),
        };
        let running = matches!(self.boot, BootState::Running(_));
        let v = &self.latest;
        let [p, q, r] = v.rates;
        let [ax, ay, az] = v.specific_force;
        let [phi, theta, psi] = v.attitude;
        ImuInput {
            status,
            fresh: self.fresh_samples > 0,
            p,
            q,
            r,
            ax,
            ay,
            az,
            phi,
            theta,
            psi,
            attitude_valid: running && [phi, theta, psi].iter().all(|a| a.is_finite()),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &StackConfig {
        &self.config
    }

    /// Where the boot stands.
    pub fn boot_state(&self) -> BootState {
        self.boot
    }

    /// The latest IMU values the control tick reads.
    pub fn imu_values(&self) -> ImuValues {
        self.latest
    }

    /// The IMU monitor's latched fault.
    pub fn imu_fault(&self) -> Option<ImuFault> {
        self.monitor.fault()
    }

    /// IMU samples read since creation.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The `now_us` of the last sample read.
    pub fn last_sample_us(&self) -> Option<u32> {
        self.last_sample_us
    }

    /// The estimator.
    pub fn estimator(&self) -> &Mahony {
        &self.estimator
    }

    /// The SBUS decoder (statistics).
    pub fn sbus(&self) -> &SbusDecoder {
        &self.sbus
    }

    /// The receiver link monitor.
    pub fn receiver(&self) -> &Receiver {
        &self.receiver
    }

    /// The board application (mode, sequencer, throttle).
    pub fn app(&self) -> &BoardApp {
        &self.app
    }

    /// Whether a valid parameter set is in use: the application's pre-arm check
    /// ([`BoardApp::set_params_valid`]).
    pub fn set_params_valid(&mut self, valid: bool) {
        self.app.set_params_valid(valid);
    }

    /// The IMU's SPI device (on the host: the emulator, to feed it the truth).
    pub fn imu_spi_mut(&mut self) -> &mut SPI {
        self.imu.spi_mut()
    }
}

/// Phases in which the sequencer flies the excitation.
fn is_excitation(phase: Phase) -> bool {
    matches!(phase, Phase::FadeIn | Phase::Sweep | Phase::FadeOut)
}

/// The monitor's fault as the application's fault kind.
const fn fault_kind(fault: ImuFault) -> ImuFaultKind {
    match fault {
        ImuFault::Missing => ImuFaultKind::Missing,
        ImuFault::Stuck => ImuFaultKind::Stuck,
        ImuFault::Saturated => ImuFaultKind::Saturated,
        ImuFault::NotReady => ImuFaultKind::NotReady,
    }
}

#[cfg(test)]
mod tests;
