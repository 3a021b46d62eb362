//! SPI1 and the IMU's chip select as one `embedded_hal::spi::SpiDevice`: the bus the
//! ICM-42688-P driver of the flight logic talks through.
//!
//! Pins PA5 SCK, PA6 MISO, PA7 MOSI (AF5) and PA4 chip select (GPIO, active low), from
//! the pin map. SPI mode 3 (CPOL 1, CPHA 1), 8-bit frames, MSB first, master with
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

use crate::clocks::{ClockGate, Clocks};
use crate::delay::BusyDelay;
use crate::dividers::{self, DividerError};
use crate::gpio::{self, Pull};
use crate::pins;

/// Highest SPI clock the ICM-42688-P takes [Hz] (datasheet: 24 MHz).
pub const MAX_CLOCK_HZ: u32 = 24_000_000;

/// Status-register polls before a flag counts as never coming: a byte at the slowest
/// configured clock (8 MHz on the HSI tree) takes 1 µs, a poll a few cycles.
const FLAG_POLLS: u32 = 10_000;

/// SPI1's registers.
fn spi1() -> &'static pac::spi1::RegisterBlock {
    // SAFETY: SPI1's register block is always mapped. This module is its only user, from
    // thread mode only (the loop reads the IMU there), so no access interleaves.
    unsafe { &*pac::SPI1::ptr() }
}

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

/// SPI1 with the IMU's chip select.
pub struct ImuSpi {
    delay: BusyDelay,
}

/// Configure SPI1 and its pins; the chip select is released (high) before anything
/// else. Returns the device and the SPI clock it runs at \[Hz\].
pub fn init(clocks: &Clocks) -> Result<(ImuSpi, u32), DividerError> {
    let bits = dividers::spi_baud_bits(clocks.pclk2_hz, MAX_CLOCK_HZ)?;
    gpio::output(pins::IMU_CS, true);
    ClockGate::Spi1.enable();
    for pin in [pins::IMU_SCK, pins::IMU_MISO, pins::IMU_MOSI] {
        gpio::alternate_function(pin, Pull::None);
    }
    let spi1 = spi1();
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
            delay: BusyDelay::new(clocks.hclk_hz),
        },
        clocks.pclk2_hz >> (bits + 1),
    ))
}

/// Poll until `ready` holds, at most [`FLAG_POLLS`] times.
fn wait_for(ready: impl Fn(&pac::spi1::sr::R) -> bool) -> Result<(), SpiError> {
    let spi1 = spi1();
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
fn exchange(byte: u8) -> Result<u8, SpiError> {
    let spi1 = spi1();
    wait_for(|status| status.txe().bit_is_set())?;
    spi1.dr().write(|w| w.dr().set(u16::from(byte)));
    wait_for(|status| status.rxne().bit_is_set())?;
    Ok((spi1.dr().read().dr().bits() & 0xFF) as u8)
}

/// Wait until the last byte has left the shift register (BSY clear), so the chip
/// select is not released in the middle of it.
fn wait_idle() -> Result<(), SpiError> {
    wait_for(|status| status.bsy().bit_is_clear())
}

impl ErrorType for ImuSpi {
    type Error = SpiError;
}

impl SpiDevice for ImuSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), SpiError> {
        gpio::set(pins::IMU_CS, false);
        let result = operations
            .iter_mut()
            .try_for_each(|operation| match operation {
                Operation::Read(buffer) => buffer.iter_mut().try_for_each(|byte| {
                    *byte = exchange(0)?;
                    Ok(())
                }),
                Operation::Write(bytes) => {
                    bytes.iter().try_for_each(|&byte| exchange(byte).map(drop))
                }
                Operation::Transfer(read, write) => {
                    for i in 0..read.len().max(write.len()) {
                        let received = exchange(write.get(i).copied().unwrap_or(0))?;
                        if let Some(slot) = read.get_mut(i) {
                            *slot = received;
                        }
                    }
                    Ok(())
                }
                Operation::TransferInPlace(buffer) => buffer.iter_mut().try_for_each(|byte| {
                    *byte = exchange(*byte)?;
                    Ok(())
                }),
                Operation::DelayNs(ns) => {
                    self.delay.delay_ns(*ns);
                    Ok(())
                }
            });
        let idle = wait_idle();
        gpio::set(pins::IMU_CS, true);
        result.and(idle)
    }
}
