//! SPI1 and the IMU's chip select as one `embedded_hal::spi::SpiDevice`: the bus the
//! ICM-42688-P driver of the flight logic talks through.
//!
//! Pins: the board map's [`ImuPins`] (SCK, MISO, MOSI in AF5; the chip select a GPIO,
//! active low). SPI mode 3 (CPOL 1, CPHA 1), 8-bit frames, MSB first, master with
//! software slave management, at the fastest clock not above [`MAX_CLOCK_HZ`].
//!
//! Each transaction asserts the chip select, runs its operations byte by byte
//! (full duplex: every byte written clocks one in), and releases it. Every wait on a
//! status flag is bounded ([`FLAG_POLLS`]): a bus that never answers gives
//! [`SpiError::Timeout`], never a hung loop, and the driver reports the IMU missing.
//!
//! Polled, not DMA: one IMU read is 14 bytes (under 6 µs at 21 MHz), cheaper than
//! setting up a DMA stream each millisecond. Under QEMU (`netduinoplus2`) SPI1 is
//! emulated with nothing on the bus: every byte reads 0x00, so WHO_AM_I does not match
//! and the image reports the IMU missing.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{self, ErrorKind, ErrorType, Operation, SpiDevice};
use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks::ClockGate;
use crate::chip::delay::BusyDelay;
use crate::chip::dividers::{self, DividerError};
use crate::chip::gpio::{Gpio, Pull};
use crate::chip::pins::{ImuPins, Pin};

/// Highest SPI clock the ICM-42688-P takes [Hz] (datasheet: 24 MHz).
pub const MAX_CLOCK_HZ: u32 = 24_000_000;

/// Status-register polls before a flag counts as never coming: a byte at the slowest
/// configured clock (8 MHz on the HSI tree) takes 1 µs, a poll a few cycles.
const FLAG_POLLS: u32 = 10_000;

/// A transfer that did not complete.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum SpiError {
    /// A status flag (TXE or RXNE) did not come within [`FLAG_POLLS`] polls.
    Timeout,
    /// The peripheral reported a receive overrun.
    Overrun,
}

impl spi::Error for SpiError {
    fn kind(&self) -> ErrorKind {
        match self {
            SpiError::Timeout => ErrorKind::Other,
            SpiError::Overrun => ErrorKind::Overrun,
        }
    }
}

/// SPI1 with the IMU's chip select. Owns SPI1 (thread mode only: the loop reads the IMU
/// there).
pub struct ImuSpi {
    spi1: pac::SPI1,
    gpio: &'static Gpio,
    chip_select: Pin,
    delay: BusyDelay,
}

/// Configure SPI1 and the board's IMU pins; the chip select is released (high) before
/// anything else. Returns the device and the SPI clock it runs at \[Hz\].
pub fn init(spi1: pac::SPI1, pins: ImuPins, boot: &Boot) -> Result<(ImuSpi, u32), DividerError> {
    let clocks = boot.clocks;
    let bits = dividers::spi_baud_bits(clocks.pclk2_hz, MAX_CLOCK_HZ)?;
    boot.output(pins.cs, true);
    boot.enable_clock(ClockGate::Spi1);
    for pin in [pins.sck, pins.miso, pins.mosi] {
        boot.alternate_function(pin, Pull::None);
    }
    spi1.cr1().reset();
    spi1.cr2().reset();
    spi1.cr1().write(|w| {
        w.cpha().second_edge();
        w.cpol().idle_high();
        w.mstr().master();
        w.br().set(bits);
        w.lsbfirst().msbfirst();
        w.ssm().enabled();
        w.ssi().slave_not_selected();
        w.dff().eight_bit();
        w.spe().enabled()
    });
    Ok((
        ImuSpi {
            spi1,
            gpio: boot.gpio,
            chip_select: pins.cs,
            delay: BusyDelay::new(clocks.hclk_hz),
        },
        clocks.pclk2_hz >> (bits + 1),
    ))
}

impl ImuSpi {
    /// Poll until `ready` holds, at most [`FLAG_POLLS`] times.
    fn wait_for(&self, ready: impl Fn(&pac::spi1::sr::R) -> bool) -> Result<(), SpiError> {
        let spi1 = &self.spi1;
        for _ in 0..FLAG_POLLS {
            let status = spi1.sr().read();
            if status.ovr().bit_is_set() {
                // Cleared by reading DR then SR (RM0090 §28.4.8).
                let _ = spi1.dr().read();
                let _ = spi1.sr().read();
                return Err(SpiError::Overrun);
            }
            if ready(&status) {
                return Ok(());
            }
        }
        Err(SpiError::Timeout)
    }

    /// Clock one byte out and one in.
    fn exchange(&self, byte: u8) -> Result<u8, SpiError> {
        let spi1 = &self.spi1;
        self.wait_for(|status| status.txe().bit_is_set())?;
        spi1.dr().write(|w| w.dr().set(u16::from(byte)));
        self.wait_for(|status| status.rxne().bit_is_set())?;
        Ok((spi1.dr().read().dr().bits() & 0xFF) as u8)
    }

    /// Wait until the last byte has left the shift register (BSY clear), so the chip
    /// select is not released in the middle of it.
    fn wait_idle(&self) -> Result<(), SpiError> {
        self.wait_for(|status| status.bsy().bit_is_clear())
    }
}

impl ErrorType for ImuSpi {
    type Error = SpiError;
}

impl SpiDevice for ImuSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), SpiError> {
        self.gpio.set(self.chip_select, false);
        // The operations borrow the bus through `spi`; the delay is a copy (a clock rate).
        let spi = &*self;
        let mut delay = spi.delay;
        let result = operations
            .iter_mut()
            .try_for_each(|operation| match operation {
                Operation::Read(buffer) => buffer.iter_mut().try_for_each(|byte| {
                    *byte = spi.exchange(0)?;
                    Ok(())
                }),
                Operation::Write(bytes) => bytes
                    .iter()
                    .try_for_each(|&byte| spi.exchange(byte).map(drop)),
                Operation::Transfer(read, write) => {
                    for i in 0..read.len().max(write.len()) {
                        let received = spi.exchange(write.get(i).copied().unwrap_or(0))?;
                        if let Some(slot) = read.get_mut(i) {
                            *slot = received;
                        }
                    }
                    Ok(())
                }
                Operation::TransferInPlace(buffer) => buffer.iter_mut().try_for_each(|byte| {
                    *byte = spi.exchange(*byte)?;
                    Ok(())
                }),
                Operation::DelayNs(ns) => {
                    delay.delay_ns(*ns);
                    Ok(())
                }
            });
        let idle = self.wait_idle();
        self.gpio.set(self.chip_select, true);
        result.and(idle)
    }
}
