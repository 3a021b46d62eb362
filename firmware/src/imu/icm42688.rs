//! ICM-42688-P driver: blocking, generic over `embedded_hal::spi::SpiDevice` (SPI mode 0
//! or 3, up to 24 MHz) and `embedded_hal::delay::DelayNs`.
//!
//! Why not the `icm426xx` crate: it reads only through the FIFO in 20-bit mode, its
//! blocking interface is untested upstream (the async one is the tested path), and its
//! initialisation unwraps bus results, i.e. can panic, which this crate forbids. What
//! this board needs — configure once, then read the data registers after each data-ready
//! — is a few register accesses, written out here.
//!
//! # Register reads, not the FIFO
//!
//! Each data-ready, [`Icm42688::read`] fetches the 14-byte sensor block TEMP_DATA1 ..=
//! GYRO_DATA_Z0 in one SPI transaction (auto-increment). The chip latches the block for
//! the duration of a burst, so the six axes and the temperature come from one sample.
//! The FIFO is left off (FIFO_CONFIG reset value: bypass), so FIFO overflow does not
//! apply; a sample the application polls too late is overwritten by the next one, and a
//! poll that finds no new sample is counted by [`ImuMonitor`](super::ImuMonitor) as not
//! ready.
//!
//! # Initialisation ([`Icm42688::init`])
//!
//! 1. REG_BANK_SEL ← 0: a microcontroller reset leaves the chip in whichever bank it was
//!    in, and DEVICE_CONFIG exists only in bank 0.
//! 2. DEVICE_CONFIG ← SOFT_RESET_CONFIG, then wait [`SOFT_RESET_MS`] (1 ms, the
//!    datasheet's wait before the next register access). Every register is back at its
//!    reset value, the sensors are off, bank 0 is selected.
//! 3. WHO_AM_I must read 0x47, else [`ImuError::WrongId`].
//! 4. [`INIT_REGISTERS`], in order: INT1 push-pull, active high, pulsed (INT_CONFIG 0x03);
//!    INT_ASYNC_RESET cleared as the datasheet requires for the INT pins (INT_CONFIG1
//!    0x00); data-ready routed to INT1 (INT_SOURCE0 0x08), so the board may wait on the
//!    pin instead of polling; gyro ±2000 °/s at 1 kHz (GYRO_CONFIG0 0x06); accelerometer
//!    ±16 g at 1 kHz (ACCEL_CONFIG0 0x06); UI filters (GYRO_ACCEL_CONFIG0 0x41, below).
//! 5. PWR_MGMT0 ← 0x0F: gyro and accelerometer in low-noise mode, temperature on. The
//!    datasheet forbids register writes for 200 µs after a sensor leaves the off state,
//!    and the gyro needs about 30 ms from power-on to valid data (and must then stay on
//!    at least 45 ms). The driver waits [`GYRO_STARTUP_MS`] = 45 ms, which covers both,
//!    so the first sample after `init` is valid.
//! 6. The power and configuration registers are read back in one burst (PWR_MGMT0 ..=
//!    GYRO_ACCEL_CONFIG0); a difference is [`ImuError::ConfigMismatch`] (a broken MOSI
//!    line passes the WHO_AM_I check but not this one).
//! 7. INT_STATUS is read once, clearing RESET_DONE and any data-ready of the start-up,
//!    so the next data-ready announces a fresh sample.
//!
//! Full scale: ±2000 °/s covers the yaw rates a tail rotor can produce with margin, and
//! ±16 g keeps rotor vibration peaks off the rails (clipping would rectify vibration into
//! a false mean). The cost is resolution: 0.061 °/s and 0.49 mg per LSB, still below the
//! noise.
//!
//! UI filter bandwidths (low-noise mode, code → max(400 Hz, ODR)/n): gyro code 1, ODR/4 =
//! 250 Hz. The gyro feeds the rate loop and the identified frequency responses, so its
//! filter delay (under 1 ms) is kept small; the rotor harmonics (≈ 35 Hz 1/rev, 70 Hz
//! 2/rev, ≈ 160 Hz tail rotor on a 700-class model) lie below any anti-alias corner that
//! would keep that delay, and are for the estimator's notch filters. Accelerometer code
//! 4, ODR/10 = 100 Hz: it serves only as a slow attitude reference and for the boot
//! stillness check, so more smoothing (attenuating the tail-rotor line) costs nothing.
//! The filter orders (GYRO_CONFIG1, ACCEL_CONFIG1) stay at their reset values.
//!
//! # Scaling
//!
//! Gyro: `2000 °/s / 32768` per LSB, times π/180: [`GYRO_RAD_S_PER_LSB`] ≈ 1.0653e-3
//! rad/s. (The datasheet's nominal 16.4 LSB/(°/s) is 32768/2000 = 16.384 rounded; the
//! difference is inside its ±0.5 % sensitivity tolerance.) Accelerometer:
//! `16 g / 32768` per LSB with g = 9.80665 m/s²: [`ACCEL_M_S2_PER_LSB`] ≈ 4.7884e-3 m/s²
//! (2048 LSB/g). Temperature: `°C = raw / 132.48 + 25`. Sensor axes are then mapped to
//! body axes by the driver's [`Orientation`].

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{Error as _, Operation, SpiDevice};

use super::registers::*;
use super::{ImuError, ImuSample, Orientation, RawSample};

/// Gyro full scale configured by `init` \[°/s\].
pub const GYRO_FULL_SCALE_DPS: f32 = 2000.0;
/// Accelerometer full scale configured by `init` \[g\].
pub const ACCEL_FULL_SCALE_G: f32 = 16.0;
/// Standard gravity \[m/s²\].
pub const GRAVITY_M_S2: f32 = 9.806_65;
/// Gyro scale \[rad/s per LSB\]: 2000/32768 °/s per LSB in rad/s.
pub const GYRO_RAD_S_PER_LSB: f32 = GYRO_FULL_SCALE_DPS / 32768.0 * (core::f32::consts::PI / 180.0);
/// Accelerometer scale \[m/s² per LSB\]: 16 g / 32768.
pub const ACCEL_M_S2_PER_LSB: f32 = ACCEL_FULL_SCALE_G * GRAVITY_M_S2 / 32768.0;
/// Temperature sensitivity \[LSB/°C\].
pub const TEMP_LSB_PER_C: f32 = 132.48;
/// Temperature at raw 0 \[°C\].
pub const TEMP_OFFSET_C: f32 = 25.0;
/// Wait after a soft reset before the next register access \[ms\].
pub const SOFT_RESET_MS: u32 = 1;
/// Wait after turning the sensors on: ≥ 200 µs before further writes, ≈ 30 ms gyro
/// start-up, 45 ms minimum gyro on-time \[ms\].
pub const GYRO_STARTUP_MS: u32 = 45;

/// Configuration written by `init` between the WHO_AM_I check and power-on, in order.
pub const INIT_REGISTERS: [(u8, u8); 6] = [
    (
        INT_CONFIG,
        INT_CONFIG_INT1_PUSH_PULL | INT_CONFIG_INT1_ACTIVE_HIGH,
    ),
    (INT_CONFIG1, 0x00),
    (INT_SOURCE0, INT_SOURCE0_UI_DRDY_INT1_EN),
    (GYRO_CONFIG0, GYRO_FS_2000_DPS | ODR_1_KHZ),
    (ACCEL_CONFIG0, ACCEL_FS_16_G | ODR_1_KHZ),
    (
        GYRO_ACCEL_CONFIG0,
        (UI_FILT_BW_ODR_DIV_10 << ACCEL_UI_FILT_BW_SHIFT) | UI_FILT_BW_ODR_DIV_4,
    ),
];

/// ICM-42688-P on an SPI device (chip select handled by the `SpiDevice`).
#[derive(Debug)]
pub struct Icm42688<SPI> {
    spi: SPI,
    orientation: Orientation,
}

impl<SPI: SpiDevice> Icm42688<SPI> {
    /// Driver with the identity [`Orientation`]. Talks to the chip only in [`init`].
    ///
    /// [`init`]: Icm42688::init
    pub fn new(spi: SPI) -> Self {
        Self::with_orientation(spi, Orientation::IDENTITY)
    }

    /// Driver mapping chip axes to body axes with `orientation`.
    pub fn with_orientation(spi: SPI, orientation: Orientation) -> Self {
        Icm42688 { spi, orientation }
    }

    /// The chip-to-body axis mapping.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }

    /// Change the chip-to-body axis mapping.
    pub fn set_orientation(&mut self, orientation: Orientation) {
        self.orientation = orientation;
    }

    /// The SPI device (the host tests reach the emulator through it).
    pub fn spi_mut(&mut self) -> &mut SPI {
        &mut self.spi
    }

    /// Give the SPI device back.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// Reset and configure the chip (sequence in the module documentation). Blocks
    /// ≈ 46 ms in `delay`. On error the chip is in an unknown state; call again to retry.
    pub fn init(&mut self, delay: &mut impl DelayNs) -> Result<(), ImuError> {
        self.write_register(REG_BANK_SEL, 0)?;
        self.write_register(DEVICE_CONFIG, DEVICE_CONFIG_SOFT_RESET)?;
        delay.delay_ms(SOFT_RESET_MS);

        let id = self.who_am_i()?;
        if id != WHO_AM_I_VALUE {
            error!("ICM-42688-P: WHO_AM_I {=u8:#x}, expected 0x47", id);
            return Err(ImuError::WrongId(id));
        }

        for &(register, value) in INIT_REGISTERS.iter() {
            self.write_register(register, value)?;
        }
        self.write_register(PWR_MGMT0, PWR_MGMT0_SENSORS_LN)?;
        delay.delay_ms(GYRO_STARTUP_MS);

        // PWR_MGMT0, GYRO_CONFIG0, ACCEL_CONFIG0, GYRO_CONFIG1, GYRO_ACCEL_CONFIG0.
        let mut readback = [0u8; 5];
        self.read_registers(PWR_MGMT0, &mut readback)?;
        let [pwr, gyro0, accel0, _gyro1, filters] = readback;
        let expected = [
            (PWR_MGMT0, PWR_MGMT0_SENSORS_LN, pwr),
            (GYRO_CONFIG0, GYRO_FS_2000_DPS | ODR_1_KHZ, gyro0),
            (ACCEL_CONFIG0, ACCEL_FS_16_G | ODR_1_KHZ, accel0),
            (
                GYRO_ACCEL_CONFIG0,
                (UI_FILT_BW_ODR_DIV_10 << ACCEL_UI_FILT_BW_SHIFT) | UI_FILT_BW_ODR_DIV_4,
                filters,
            ),
        ];
        for (register, expected, found) in expected {
            if expected != found {
                error!(
                    "ICM-42688-P: register {=u8:#x} reads {=u8:#x}, wrote {=u8:#x}",
                    register, found, expected
                );
                return Err(ImuError::ConfigMismatch {
                    register,
                    expected,
                    found,
                });
            }
        }

        // Clear RESET_DONE and the start-up data-ready.
        self.read_register(INT_STATUS)?;
        info!("ICM-42688-P ready: 1 kHz, 2000 dps, 16 g");
        Ok(())
    }

    /// WHO_AM_I (0x47 for this chip).
    pub fn who_am_i(&mut self) -> Result<u8, ImuError> {
        self.read_register(WHO_AM_I)
    }

    /// Whether a new sample arrived since the last call (INT_STATUS.DATA_RDY_INT).
    /// Reading INT_STATUS clears all its bits.
    pub fn data_ready(&mut self) -> Result<bool, ImuError> {
        Ok(self.read_register(INT_STATUS)? & INT_STATUS_DATA_RDY != 0)
    }

    /// Read the sensor block (one 14-byte burst from TEMP_DATA1) and scale it to SI units
    /// in body axes.
    pub fn read(&mut self) -> Result<ImuSample, ImuError> {
        let mut block = [0u8; SENSOR_BLOCK_LEN];
        self.read_registers(TEMP_DATA1, &mut block)?;
        Ok(self.convert(decode_block(block)))
    }

    /// One poll at the sample rate: the sample if data is ready. When it is not, WHO_AM_I
    /// is checked, so a chip that went away (MISO reading zeros: no data-ready ever) is
    /// reported as [`ImuError::WrongId`] at once rather than as "not ready".
    pub fn poll(&mut self) -> Result<Option<ImuSample>, ImuError> {
        if self.data_ready()? {
            return self.read().map(Some);
        }
        let id = self.who_am_i()?;
        if id == WHO_AM_I_VALUE {
            Ok(None)
        } else {
            Err(ImuError::WrongId(id))
        }
    }

    /// Scale a raw sample to SI units and map it to body axes.
    pub fn convert(&self, raw: RawSample) -> ImuSample {
        let gyro = raw.gyro.map(|v| f32::from(v) * GYRO_RAD_S_PER_LSB);
        let accel = raw.accel.map(|v| f32::from(v) * ACCEL_M_S2_PER_LSB);
        ImuSample {
            gyro_rad_s: self.orientation.to_body(gyro),
            accel_m_s2: self.orientation.to_body(accel),
            temperature_c: f32::from(raw.temperature) / TEMP_LSB_PER_C + TEMP_OFFSET_C,
            raw,
        }
    }

    /// Read one register.
    pub fn read_register(&mut self, register: u8) -> Result<u8, ImuError> {
        let mut value = [0u8];
        self.read_registers(register, &mut value)?;
        let [value] = value;
        Ok(value)
    }

    /// Read `buffer.len()` consecutive registers from `first` in one transaction.
    pub fn read_registers(&mut self, first: u8, buffer: &mut [u8]) -> Result<(), ImuError> {
        self.spi
            .transaction(&mut [
                Operation::Write(&[first | SPI_READ]),
                Operation::Read(buffer),
            ])
            .map_err(|e| ImuError::Bus(e.kind()))
    }

    /// Write one register.
    pub fn write_register(&mut self, register: u8, value: u8) -> Result<(), ImuError> {
        self.spi
            .write(&[register & !SPI_READ, value])
            .map_err(|e| ImuError::Bus(e.kind()))
    }
}

/// Decode the 14-byte sensor block: temperature, accel x y z, gyro x y z, each a
/// big-endian `i16`.
pub(crate) fn decode_block(block: [u8; SENSOR_BLOCK_LEN]) -> RawSample {
    let [t1, t0, ax1, ax0, ay1, ay0, az1, az0, gx1, gx0, gy1, gy0, gz1, gz0] = block;
    let word = |high: u8, low: u8| i16::from_be_bytes([high, low]);
    RawSample {
        temperature: word(t1, t0),
        accel: [word(ax1, ax0), word(ay1, ay0), word(az1, az0)],
        gyro: [word(gx1, gx0), word(gy1, gy0), word(gz1, gz0)],
    }
}
