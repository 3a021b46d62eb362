//! The STM32F405 drivers every board of the image shares, on the `stm32f4` PAC: clocks,
//! pin muxing, the servo and ESC timers, the three USARTs (host link, SBUS, log), the
//! IMU's SPI, the loop tick, the watchdog and the NVIC. Which pin and timer channel does
//! what comes from a board's [`pins::BoardMap`]; no driver names a pin.
//!
//! **Peripherals are taken once.** [`devices::bring_up`] takes the PAC's `Peripherals`
//! (and the core's) a single time and hands each driver the instances it owns. A driver
//! whose interrupt handler touches its registers too keeps its instance in a
//! [`shared::IrqShared`] reached inside a critical section. The only stolen instances are
//! the output timers in the panic and fault path ([`servo::force_failsafe_anywhere`]).
//!
//! **What it may import.** The PAC, `cortex-m`, the flight logic's device traits
//! (`embedded-hal`, `embedded-io`, the IMU emulator of the bench image), the wire
//! protocol's encoder, and `crate::ring`; nothing of `crate::image` or `crate::boards`.

#[cfg(target_os = "none")]
pub mod boot;
#[cfg(target_os = "none")]
pub mod clocks;
#[cfg(target_os = "none")]
pub mod delay;
#[cfg(target_os = "none")]
pub mod devices;
#[cfg(any(target_os = "none", test))]
pub mod dividers;
#[cfg(any(target_os = "none", test))]
pub mod flash;
#[cfg(target_os = "none")]
pub mod gpio;
#[cfg(target_os = "none")]
pub mod imu_device;
#[cfg(target_os = "none")]
pub mod imu_spi;
#[cfg(target_os = "none")]
pub mod logport;
#[cfg(target_os = "none")]
pub mod nvic;
pub mod pins;
#[cfg(target_os = "none")]
pub mod sbus_uart;
#[cfg(target_os = "none")]
pub mod servo;
#[cfg(target_os = "none")]
pub mod shared;
#[cfg(target_os = "none")]
pub mod ticker;
#[cfg(target_os = "none")]
pub mod usart;
#[cfg(target_os = "none")]
pub mod watchdog;
