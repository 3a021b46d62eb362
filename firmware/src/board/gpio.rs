//! Pin muxing: the pins the image uses, switched to their alternate functions.

use super::regs::GpioPort;

/// Pull resistor of an input.
#[derive(Clone, Copy)]
pub enum Pull {
    /// Floating.
    None,
    /// Pull-up (idle-high UART line).
    Up,
}

/// Put `pin` of `port` in alternate-function mode `af` (RM0090 §8.3.7, Table 9 of the
/// STM32F405 datasheet for the AF numbers), fast output speed.
pub fn alternate_function(port: GpioPort, pin: u32, af: u32, pull: Pull) {
    const MODE_ALTERNATE: u32 = 0b10;
    const SPEED_FAST: u32 = 0b10;
    port.moder.write_field(2 * pin, 2, MODE_ALTERNATE);
    port.ospeedr.write_field(2 * pin, 2, SPEED_FAST);
    let pull_bits = match pull {
        Pull::None => 0b00,
        Pull::Up => 0b01,
    };
    port.pupdr.write_field(2 * pin, 2, pull_bits);
    if pin < 8 {
        port.afrl.write_field(4 * pin, 4, af);
    } else {
        port.afrh.write_field(4 * (pin - 8), 4, af);
    }
}
