//! Register-level emulator of the ICM-42688-P, for the host: an
//! `embedded_hal::spi::SpiDevice` that the driver talks to as it would to the chip, fed
//! by the simulator with the true body rates and specific force.
//!
//! # Registers and SPI
//!
//! Five banks of 128 registers. Each SPI transaction is one chip-select frame: its first
//! byte is the address (bit 7 set: read), every following byte reads or writes the next
//! address (auto-increment, wrapping at 0x7F); a write transaction's MISO bytes are 0x00.
//! REG_BANK_SEL (0x76) selects the bank in every bank. Bank 0 behaves as the chip does
//! for what the driver uses; the other banks are plain memory.
//!
//! * Power-on and soft reset (DEVICE_CONFIG bit 0, or [`Icm42688Emulator::soft_reset`])
//!   load [`RESET_VALUES`] (every other register 0x00), select bank 0, turn the sensors
//!   off and set INT_STATUS.RESET_DONE.
//! * Read-only registers (sensor data, INT_STATUS, FIFO count and data, WHO_AM_I) ignore
//!   writes. INT_STATUS clears on read.
//! * PWR_MGMT0: the gyro samples in low-noise mode (11), the accelerometer in low-power
//!   or low-noise mode (1x), the temperature sensor unless TEMP_DIS. A sensor that is off
//!   reads −32768 (0x8000), the chip's "no data" value.
//! * GYRO_CONFIG0 / ACCEL_CONFIG0: the full-scale selections set the LSB used to encode
//!   each sample; the gyro ODR (the accelerometer's when the gyro is off) sets the sample
//!   clock. Sampling starts one period after the sensors are turned on. Start-up
//!   transients, the UI filters and the FIFO are not modelled: each sample is the truth at
//!   its instant plus the imperfections below.
//! * Each sample writes the data registers and sets INT_STATUS.DATA_RDY.
//!
//! # Imperfections ([`Imperfections`])
//!
//! In chip axes (the truth is mapped from body axes by the emulator's mounting
//! [`Orientation`]), per axis `i`, at the sample instant `t`:
//!
//! ```text
//! measured_i = (1 + scale_error_i)·truth_i + bias_i
//!              + Σ_h amplitude_h,i · sin(2π f_h t) + σ·n_i
//! raw_i      = clamp(round(measured_i / LSB), −32767, 32767)
//! ```
//!
//! `n_i` is unit-variance noise from a [`Pcg32`] seeded with `seed` (Irwin–Hall, bounded
//! by ±2√3): six draws per sample, gyro x y z then accelerometer x y z, whatever the
//! configuration, so one seed gives the same bytes every run. Quantisation is the
//! rounding to the LSB of the selected full scale, saturation the clamp.
//!
//! # Faults ([`Fault`]), switchable at any time
//!
//! * `Stuck`: the data registers keep their last values; data-ready still comes.
//! * `Saturate`: all six axes read +32767.
//! * `Missing`: the chip does not answer: MISO is 0x00 on every byte (WHO_AM_I reads
//!   0x00, data-ready never shows) and writes are lost.
//! * `BusError`: every transaction fails with an SPI error.

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};

use super::registers::*;
use super::{Orientation, GRAVITY_M_S2};
use crate::noise::Pcg32;

mod imperfections;
pub use imperfections::{Imperfections, Vibration, TREX700L_HEADSPEED_RPM, TREX700L_TAIL_RATIO};

/// Bank-0 reset values the emulator loads (every register not listed resets to 0x00).
pub const RESET_VALUES: [(u8, u8); 20] = [
    (TEMP_DATA1, 0x80),
    (ACCEL_DATA_X1, 0x80),
    (ACCEL_DATA_Y1, 0x80),
    (ACCEL_DATA_Z1, 0x80),
    (GYRO_DATA_X1, 0x80),
    (GYRO_DATA_Y1, 0x80),
    (GYRO_DATA_Z1, 0x80),
    (INT_STATUS, INT_STATUS_RESET_DONE),
    (INTF_CONFIG0, 0x30),
    (INTF_CONFIG1, 0x91),
    (PWR_MGMT0, 0x00),
    (GYRO_CONFIG0, 0x06),
    (ACCEL_CONFIG0, 0x06),
    (GYRO_CONFIG1, 0x16),
    (GYRO_ACCEL_CONFIG0, 0x11),
    (ACCEL_CONFIG1, 0x0D),
    (INT_CONFIG1, 0x10),
    (INT_SOURCE0, 0x10),
    (WHO_AM_I, WHO_AM_I_VALUE),
    (REG_BANK_SEL, 0x00),
];

/// Number of register banks.
pub const BANKS: usize = 5;

/// FIFO_COUNTH, FIFO_COUNTL, FIFO_DATA: read-only, unused by the driver.
const FIFO_READ_ONLY: core::ops::RangeInclusive<u8> = 0x2E..=0x30;

/// Injected fault.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Fault {
    /// Working chip.
    #[default]
    None,
    /// Data registers frozen at their last values; data-ready continues.
    Stuck,
    /// All six axes at positive full scale.
    Saturate,
    /// No chip on the bus: MISO reads 0x00, writes are lost.
    Missing,
    /// Every SPI transaction returns an error.
    BusError,
}

/// Where the next SPI byte goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Frame {
    Address,
    Read(u8),
    Write(u8),
}

/// The emulated chip.
#[derive(Clone, Debug)]
pub struct Icm42688Emulator {
    banks: [[u8; 128]; BANKS],
    bank: u8,
    frame: Frame,
    imperfections: Imperfections,
    mounting: Orientation,
    rng: Pcg32,
    fault: Fault,
    gyro_truth_rad_s: [f32; 3],
    specific_force_truth_m_s2: [f32; 3],
    temperature_c: f32,
    time_ns: u64,
    next_sample_ns: u64,
    samples: u64,
    transactions: u64,
}

impl Default for Icm42688Emulator {
    fn default() -> Self {
        Self::new(Imperfections::default())
    }
}

impl Icm42688Emulator {
    /// A chip just powered on: reset values, sensors off, truth at rest and level
    /// (0 rad/s, specific force (0, 0, −g) in body axes), 25 °C, identity mounting.
    pub fn new(imperfections: Imperfections) -> Self {
        let mut emulator = Icm42688Emulator {
            banks: [[0; 128]; BANKS],
            bank: 0,
            frame: Frame::Address,
            imperfections,
            mounting: Orientation::IDENTITY,
            rng: Pcg32::with_stream(imperfections.seed, Pcg32::DEFAULT_STREAM),
            fault: Fault::None,
            gyro_truth_rad_s: [0.0; 3],
            specific_force_truth_m_s2: [0.0, 0.0, -GRAVITY_M_S2],
            temperature_c: 25.0,
            time_ns: 0,
            next_sample_ns: 0,
            samples: 0,
            transactions: 0,
        };
        emulator.soft_reset();
        emulator
    }

    /// Soft reset (also what a power cycle or brown-out does): [`RESET_VALUES`] in bank
    /// 0, other banks cleared, bank 0 selected, sensors off. Truth, time, noise generator
    /// and injected fault are the outside world's and stay.
    pub fn soft_reset(&mut self) {
        self.banks = [[0; 128]; BANKS];
        for &(address, value) in RESET_VALUES.iter() {
            if let Some(slot) = self.bank0_mut(address) {
                *slot = value;
            }
        }
        self.bank = 0;
    }

    /// The imperfections in use.
    pub fn imperfections(&self) -> &Imperfections {
        &self.imperfections
    }

    /// Replace the imperfections and reseed the noise generator with their seed.
    pub fn set_imperfections(&mut self, imperfections: Imperfections) {
        self.imperfections = imperfections;
        self.rng = Pcg32::with_stream(imperfections.seed, Pcg32::DEFAULT_STREAM);
    }

    /// How the chip sits in the airframe: `body = mounting.to_body(chip)`.
    pub fn set_mounting(&mut self, mounting: Orientation) {
        self.mounting = mounting;
    }

    /// The true body rates \[rad/s\] and specific force \[m/s²\] (body axes, x forward,
    /// y right, z down) that the next samples measure.
    pub fn set_truth(&mut self, gyro_rad_s: [f32; 3], specific_force_m_s2: [f32; 3]) {
        self.gyro_truth_rad_s = gyro_rad_s;
        self.specific_force_truth_m_s2 = specific_force_m_s2;
    }

    /// The true die temperature \[°C\].
    pub fn set_temperature(&mut self, temperature_c: f32) {
        self.temperature_c = temperature_c;
    }

    /// Inject a fault (or [`Fault::None`] to heal).
    pub fn set_fault(&mut self, fault: Fault) {
        self.fault = fault;
    }

    /// The injected fault.
    pub fn fault(&self) -> Fault {
        self.fault
    }

    /// A register's value, without a read's side effects.
    pub fn register(&self, bank: u8, address: u8) -> u8 {
        if address == REG_BANK_SEL {
            return self.bank;
        }
        self.banks
            .get(usize::from(bank))
            .and_then(|registers| registers.get(usize::from(address)))
            .copied()
            .unwrap_or(0)
    }

    /// The selected bank.
    pub fn bank(&self) -> u8 {
        self.bank
    }

    /// Emulated time \[s\].
    pub fn time_s(&self) -> f64 {
        self.time_ns as f64 * 1e-9
    }

    /// Samples produced since creation.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// SPI transactions served since creation (failed ones included).
    pub fn transactions(&self) -> u64 {
        self.transactions
    }

    /// Sample period from the ODR of the sampling sensor \[ns\]; `None` when both are off
    /// or the ODR code is reserved.
    pub fn sample_period_ns(&self) -> Option<u64> {
        let (gyro_on, accel_on, _) = self.sensors_on();
        let config = if gyro_on {
            self.reg0(GYRO_CONFIG0)
        } else if accel_on {
            self.reg0(ACCEL_CONFIG0)
        } else {
            return None;
        };
        odr_period_ns(config & ODR_MASK)
    }

    /// Let `dt_s` seconds pass (non-finite or negative: none), producing the samples that
    /// fall due. Returns how many.
    pub fn advance(&mut self, dt_s: f32) -> u32 {
        let dt_ns = f64::from(dt_s) * 1e9;
        if !(dt_ns.is_finite() && dt_ns > 0.0) {
            return 0;
        }
        self.advance_ns(libm::round(dt_ns) as u64)
    }

    /// Let `dt_ns` nanoseconds pass, producing the samples that fall due. Returns how
    /// many.
    pub fn advance_ns(&mut self, dt_ns: u64) -> u32 {
        let end = self.time_ns.saturating_add(dt_ns);
        let mut produced = 0u32;
        while let Some(period) = self.sample_period_ns() {
            if self.next_sample_ns > end {
                break;
            }
            self.time_ns = self.next_sample_ns;
            self.produce_sample();
            self.next_sample_ns = self.next_sample_ns.saturating_add(period);
            produced = produced.saturating_add(1);
        }
        self.time_ns = end;
        produced
    }

    /// Produce one sample now, whatever the sample clock: returns false (and does
    /// nothing) when both sensors are off.
    pub fn produce_sample(&mut self) -> bool {
        let (gyro_on, accel_on, temperature_on) = self.sensors_on();
        if !(gyro_on || accel_on) {
            return false;
        }
        self.samples = self.samples.saturating_add(1);
        let t = self.time_s();
        let imp = self.imperfections;
        // Six draws every sample, fixed order: gyro x y z, accel x y z.
        let gyro_noise: [f32; 3] = core::array::from_fn(|_| self.rng.next_gaussian());
        let accel_noise: [f32; 3] = core::array::from_fn(|_| self.rng.next_gaussian());

        let gyro_truth = self.mounting.to_chip(self.gyro_truth_rad_s);
        let accel_truth = self.mounting.to_chip(self.specific_force_truth_m_s2);
        let gyro_lsb = self.gyro_lsb_rad_s();
        let accel_lsb = self.accel_lsb_m_s2();
        let gyro: [i16; 3] = core::array::from_fn(|i| {
            let vibration = imp
                .vibration
                .iter()
                .map(|v| at(v.gyro_rad_s, i) * sine(v.frequency_hz, t))
                .sum::<f64>();
            let measured = (1.0 + at(imp.gyro_scale_error, i)) * at(gyro_truth, i)
                + at(imp.gyro_bias_rad_s, i)
                + vibration
                + f64::from(imp.gyro_noise_rad_s) * at(gyro_noise, i);
            quantise(measured, gyro_lsb)
        });
        let accel: [i16; 3] = core::array::from_fn(|i| {
            let vibration = imp
                .vibration
                .iter()
                .map(|v| at(v.accel_m_s2, i) * sine(v.frequency_hz, t))
                .sum::<f64>();
            let measured = (1.0 + at(imp.accel_scale_error, i)) * at(accel_truth, i)
                + at(imp.accel_bias_m_s2, i)
                + vibration
                + f64::from(imp.accel_noise_m_s2) * at(accel_noise, i);
            quantise(measured, accel_lsb)
        });
        let temperature = if temperature_on {
            quantise(
                f64::from(self.temperature_c) - f64::from(super::TEMP_OFFSET_C),
                1.0 / f64::from(super::TEMP_LSB_PER_C),
            )
        } else {
            DATA_INVALID
        };

        let (gyro, accel) = match self.fault {
            Fault::Saturate => ([i16::MAX; 3], [i16::MAX; 3]),
            _ => (
                if gyro_on { gyro } else { [DATA_INVALID; 3] },
                if accel_on { accel } else { [DATA_INVALID; 3] },
            ),
        };
        if self.fault != Fault::Stuck {
            let [ax, ay, az] = accel;
            let [gx, gy, gz] = gyro;
            let words = [temperature, ax, ay, az, gx, gy, gz];
            for (pair, word) in (TEMP_DATA1..=GYRO_DATA_Z0).step_by(2).zip(words) {
                let [high, low] = word.to_be_bytes();
                if let Some(slot) = self.bank0_mut(pair) {
                    *slot = high;
                }
                if let Some(slot) = self.bank0_mut(pair.wrapping_add(1)) {
                    *slot = low;
                }
            }
        }
        if let Some(status) = self.bank0_mut(INT_STATUS) {
            *status |= INT_STATUS_DATA_RDY;
        }
        true
    }

    /// Gyro LSB \[rad/s\] for GYRO_FS_SEL: 2000 °/s / 2^code over 32768.
    fn gyro_lsb_rad_s(&self) -> f64 {
        let code = self.reg0(GYRO_CONFIG0) >> FS_SEL_SHIFT;
        let full_scale_dps = 2000.0 / f64::from(1u16 << code);
        full_scale_dps / 32768.0 * core::f64::consts::PI / 180.0
    }

    /// Accelerometer LSB \[m/s²\] for ACCEL_FS_SEL: 16 g / 2^code over 32768 (reserved
    /// codes 4–7 read as ±16 g).
    fn accel_lsb_m_s2(&self) -> f64 {
        let code = self.reg0(ACCEL_CONFIG0) >> FS_SEL_SHIFT;
        let code = if code > 3 { 0 } else { code };
        let full_scale_g = 16.0 / f64::from(1u16 << code);
        full_scale_g * f64::from(GRAVITY_M_S2) / 32768.0
    }

    /// (gyro sampling, accelerometer sampling, temperature sampling).
    fn sensors_on(&self) -> (bool, bool, bool) {
        let power = self.reg0(PWR_MGMT0);
        let gyro = power & PWR_MGMT0_GYRO_MODE_MASK == PWR_MGMT0_GYRO_LN;
        let accel = power & PWR_MGMT0_ACCEL_MODE_MASK >= 0b10;
        let temperature = (gyro || accel) && power & PWR_MGMT0_TEMP_DIS == 0;
        (gyro, accel, temperature)
    }

    fn reg0(&self, address: u8) -> u8 {
        self.banks
            .first()
            .and_then(|bank| bank.get(usize::from(address)))
            .copied()
            .unwrap_or(0)
    }

    fn bank0_mut(&mut self, address: u8) -> Option<&mut u8> {
        self.banks
            .first_mut()
            .and_then(|bank| bank.get_mut(usize::from(address)))
    }

    /// One byte of a frame: MOSI in, MISO out.
    fn clock(&mut self, mosi: u8) -> u8 {
        if self.fault == Fault::Missing {
            return 0x00;
        }
        match self.frame {
            Frame::Address => {
                let address = mosi & !SPI_READ;
                self.frame = if mosi & SPI_READ != 0 {
                    Frame::Read(address)
                } else {
                    Frame::Write(address)
                };
                0x00
            }
            Frame::Read(address) => {
                self.frame = Frame::Read(next_address(address));
                self.read_register(address)
            }
            Frame::Write(address) => {
                self.frame = Frame::Write(next_address(address));
                self.write_register(address, mosi);
                0x00
            }
        }
    }

    fn read_register(&mut self, address: u8) -> u8 {
        let value = self.register(self.bank, address);
        if self.bank == 0 && address == INT_STATUS {
            if let Some(status) = self.bank0_mut(INT_STATUS) {
                *status = 0;
            }
        }
        value
    }

    fn write_register(&mut self, address: u8, value: u8) {
        if address == REG_BANK_SEL {
            self.bank = value & 0x07;
            return;
        }
        if self.bank != 0 {
            if let Some(slot) = self
                .banks
                .get_mut(usize::from(self.bank))
                .and_then(|bank| bank.get_mut(usize::from(address)))
            {
                *slot = value;
            }
            return;
        }
        let read_only = (TEMP_DATA1..=INT_STATUS).contains(&address)
            || FIFO_READ_ONLY.contains(&address)
            || address == WHO_AM_I;
        if read_only {
            return;
        }
        if address == DEVICE_CONFIG && value & DEVICE_CONFIG_SOFT_RESET != 0 {
            self.soft_reset();
            return;
        }
        let was_sampling = self.sample_period_ns().is_some();
        if let Some(slot) = self.bank0_mut(address) {
            *slot = value;
        }
        if !was_sampling {
            if let Some(period) = self.sample_period_ns() {
                self.next_sample_ns = self.time_ns.saturating_add(period);
            }
        }
    }
}

impl ErrorType for Icm42688Emulator {
    type Error = ErrorKind;
}

impl SpiDevice for Icm42688Emulator {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        self.transactions = self.transactions.saturating_add(1);
        if self.fault == Fault::BusError {
            return Err(ErrorKind::Other);
        }
        self.frame = Frame::Address;
        for operation in operations.iter_mut() {
            match operation {
                Operation::Read(buffer) => {
                    for byte in buffer.iter_mut() {
                        *byte = self.clock(0x00);
                    }
                }
                Operation::Write(buffer) => {
                    for &byte in buffer.iter() {
                        self.clock(byte);
                    }
                }
                Operation::Transfer(read, write) => {
                    for i in 0..read.len().max(write.len()) {
                        let miso = self.clock(write.get(i).copied().unwrap_or(0x00));
                        if let Some(slot) = read.get_mut(i) {
                            *slot = miso;
                        }
                    }
                }
                Operation::TransferInPlace(buffer) => {
                    for byte in buffer.iter_mut() {
                        *byte = self.clock(*byte);
                    }
                }
                Operation::DelayNs(_) => {}
            }
        }
        self.frame = Frame::Address;
        Ok(())
    }
}

/// Period of an ODR code \[ns\]; `None` for the reserved code 0.
fn odr_period_ns(code: u8) -> Option<u64> {
    Some(match code {
        1 => 31_250,       // 32 kHz
        2 => 62_500,       // 16 kHz
        3 => 125_000,      // 8 kHz
        4 => 250_000,      // 4 kHz
        5 => 500_000,      // 2 kHz
        6 => 1_000_000,    // 1 kHz
        7 => 5_000_000,    // 200 Hz
        8 => 10_000_000,   // 100 Hz
        9 => 20_000_000,   // 50 Hz
        10 => 40_000_000,  // 25 Hz
        11 => 80_000_000,  // 12.5 Hz
        12 => 160_000_000, // 6.25 Hz
        13 => 320_000_000, // 3.125 Hz
        14 => 640_000_000, // 1.5625 Hz
        15 => 2_000_000,   // 500 Hz
        _ => return None,
    })
}

/// The address after `address`, wrapping within the 7-bit space.
fn next_address(address: u8) -> u8 {
    address.wrapping_add(1) & !SPI_READ
}

/// Component `i` of `v` in `f64` (0 past the end).
fn at(v: [f32; 3], i: usize) -> f64 {
    v.get(i).copied().map_or(0.0, f64::from)
}

/// sin(2π f t).
fn sine(frequency_hz: f32, t: f64) -> f64 {
    libm::sin(2.0 * core::f64::consts::PI * f64::from(frequency_hz) * t)
}

/// `value / lsb` rounded to the nearest count and clamped to ±32767 (−32768 stays the
/// "no data" value); NaN reads 0.
fn quantise(value: f64, lsb: f64) -> i16 {
    let counts = libm::round(value / lsb);
    if counts.is_nan() {
        0
    } else {
        counts.clamp(-f64::from(i16::MAX), f64::from(i16::MAX)) as i16
    }
}
