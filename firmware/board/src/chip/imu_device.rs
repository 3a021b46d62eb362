//! The IMU device the board stack reads: the ICM-42688-P on SPI1 ([`crate::chip::imu_spi`]), or,
//! in the bench image (feature `bench-imu`), the flight logic's register-level emulator
//! of the same chip standing still, so that QEMU, which has nothing on SPI1, can
//! calibrate, arm and fly the board application. The bench image is for tests only: the
//! attitude it reports is a still board's, whatever the aircraft does.

use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::dividers::DividerError;
use crate::chip::pins::BoardMap;

#[cfg(not(feature = "bench-imu"))]
mod device {
    use super::{pac, BoardMap, Boot, DividerError};
    use crate::chip::imu_spi::{self, ImuSpi};

    /// The chip on SPI1.
    pub type ImuDevice = ImuSpi;

    /// Configure SPI1 on `map`'s IMU pins.
    pub fn init(spi1: pac::SPI1, map: &BoardMap, boot: &Boot) -> Result<ImuDevice, DividerError> {
        let (spi, hz) = imu_spi::init(spi1, map.imu, boot)?;
        defmt::info!("IMU: ICM-42688-P on SPI1 at {=u32} Hz", hz);
        Ok(spi)
    }

    /// Before each poll: the chip samples on its own.
    pub fn before_poll(_device: &mut ImuDevice, _dt_us: u32) {}
}

#[cfg(feature = "bench-imu")]
mod device {
    use super::{pac, BoardMap, Boot, DividerError};
    use crate::chip::imu_spi;
    use sweephold_firmware::imu::emulator::{Icm42688Emulator, Imperfections};
    use sweephold_firmware::imu::GRAVITY_M_S2;

    /// The emulated chip.
    pub type ImuDevice = Icm42688Emulator;

    /// An emulated chip at rest, level, with a bench board's bias and noise, carried as
    /// `map`'s own chip is. SPI1 is set up as on the board image (chip select released),
    /// then left alone.
    pub fn init(spi1: pac::SPI1, map: &BoardMap, boot: &Boot) -> Result<ImuDevice, DividerError> {
        imu_spi::init(spi1, map.imu, boot)?;
        let mut device = Icm42688Emulator::new(Imperfections::BENCH);
        // The emulated chip sits on the board as the board's own chip does, so the image
        // reads it through the same mounting.
        device.set_mounting(map.imu_mounting.orientation());
        device.set_truth([0.0; 3], [0.0, 0.0, -GRAVITY_M_S2]);
        defmt::warn!("IMU: BENCH IMAGE, emulated ICM-42688-P at rest (never fly this image)");
        Ok(device)
    }

    /// Before each poll: let `dt_us` of emulated time pass, at most one sample period
    /// (1 ms), so the chip has one new sample; after an overrun the emulator does not
    /// catch up sample by sample (a slow, traced QEMU would never get out of it). Never
    /// inlined, so `docs/board_tick_instructions.py` can leave the emulation out.
    #[inline(never)]
    pub fn before_poll(device: &mut ImuDevice, dt_us: u32) {
        device.advance_ns(u64::from(dt_us.min(1000)) * 1000);
    }
}

pub use device::{before_poll, init, ImuDevice};
