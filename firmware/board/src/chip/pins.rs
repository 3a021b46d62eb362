//! What a board's pin map is made of: pins in their alternate functions, PWM outputs on
//! timer channels, and the whole map ([`BoardMap`]) that each folder under
//! [`crate::boards`] fills in. The drivers of this chip layer take their pins from a
//! [`BoardMap`] and name none themselves.
//!
//! A map is checked when the image is built ([`BoardMap::check`]: crystal, frame rates,
//! every output's timer started) and by the unit tests of `crate::boards` (no pin used
//! twice, alternate functions that match the peripherals, output groups on timers of
//! their own).

// The map names the whole board: its name and the SWD pins it must never touch are read
// by the tests only, and on the host (tests) the
// drivers that read the rest are not built.
#![allow(dead_code)]

use sweephold_firmware::imu::ImuRotation;

/// A GPIO port of the pins a board map may use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Port {
    /// GPIOA.
    A,
    /// GPIOB.
    B,
    /// GPIOC.
    C,
}

/// One pin in one of its alternate functions (STM32F405 datasheet, Table 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pin {
    /// Port.
    pub port: Port,
    /// Pin number in the port, 0..=15.
    pub number: u8,
    /// Alternate function number, 0..=15 (0 for a plain GPIO).
    pub af: u8,
}

/// Pin `number` of `port` in alternate function `af`.
pub const fn pin(port: Port, number: u8, af: u8) -> Pin {
    Pin { port, number, af }
}

/// The timers that may drive PWM outputs: the four-channel timers the drivers know.
/// TIM5 is not among them: it is the loop tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputTimer {
    /// TIM1 (APB2, advanced, 16-bit).
    Tim1,
    /// TIM2 (APB1, 32-bit).
    Tim2,
    /// TIM3 (APB1, 16-bit).
    Tim3,
    /// TIM4 (APB1, 16-bit).
    Tim4,
    /// TIM8 (APB2, advanced, 16-bit).
    Tim8,
}

impl OutputTimer {
    /// The alternate function of this timer's channels on a pin (datasheet Table 9:
    /// TIM1/2 AF1, TIM3..5 AF2, TIM8..11 AF3).
    pub const fn af(self) -> u8 {
        match self {
            OutputTimer::Tim1 | OutputTimer::Tim2 => 1,
            OutputTimer::Tim3 | OutputTimer::Tim4 => 2,
            OutputTimer::Tim8 => 3,
        }
    }

    /// `self == other`, usable in a constant.
    const fn same(self, other: OutputTimer) -> bool {
        self as u8 == other as u8
    }
}

/// One PWM output pad: its pin and its timer channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Output {
    /// The pin, in its timer alternate function.
    pub pin: Pin,
    /// The timer.
    pub timer: OutputTimer,
    /// The compare channel, 1..=4 (never a complementary `CHxN` output).
    pub channel: u8,
}

/// An output timer and the PWM frame rate of every output on it [Hz]. Frame rates are
/// per timer, so per group of outputs sharing one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimerRate {
    /// The timer.
    pub timer: OutputTimer,
    /// Its frame rate [Hz].
    pub frame_hz: u32,
}

/// The status LED: its pin (a GPIO output) and which level lights it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Led {
    /// The pin.
    pub pin: Pin,
    /// The LED lights when the pin is low (wired from the supply through the LED to the
    /// pin).
    pub active_low: bool,
}

/// The IMU's SPI1 pins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImuPins {
    /// SPI1 clock (AF5).
    pub sck: Pin,
    /// SPI1 data from the IMU (AF5).
    pub miso: Pin,
    /// SPI1 data to the IMU (AF5).
    pub mosi: Pin,
    /// Chip select (GPIO output, active low).
    pub cs: Pin,
    /// Data-ready interrupt (GPIO input; the image polls instead, the pin is reserved).
    pub int: Pin,
}

/// The board's crystal (HSE) [Hz]: a multiple of 2 MHz from 4 to 26 MHz (the HSE
/// range of the STM32F405), so that the PLL's input divider gives the 2 MHz VCO input
/// of `crate::chip::clocks`. Checked when the constant is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crystal(u32);

impl Crystal {
    /// A crystal of `hz`; stops the build for one the clock tree cannot use.
    pub const fn hz(hz: u32) -> Crystal {
        assert!(
            hz >= 4_000_000 && hz <= 26_000_000 && hz.is_multiple_of(2_000_000),
            "the crystal must be a multiple of 2 MHz from 4 to 26 MHz"
        );
        Crystal(hz)
    }

    /// The PLL input divider PLLM that makes the 2 MHz VCO input: 2..=13.
    pub const fn pll_m(self) -> u8 {
        (self.0 / 2_000_000) as u8
    }
}

/// Everything the drivers need to know of one board: which pin and timer does what, and
/// its crystal. The peripheral instances are the same on every board the image supports
/// (USART1 host link, USART2 SBUS, USART3 log, SPI1 IMU, TIM5 tick): a board that wires
/// them elsewhere needs a driver change, not only a map.
#[derive(Clone, Copy, Debug)]
pub struct BoardMap {
    /// The board's name, as its maker sells it.
    pub name: &'static str,
    /// The crystal.
    pub crystal: Crystal,
    /// The servo outputs in wire order (`ActuatorOut::servo_us`): swash 1, 2, 3, tail.
    pub servos: [Output; 4],
    /// The ESC's throttle output.
    pub esc: Output,
    /// Every timer of `servos` and `esc` with its frame rate, in the order they are
    /// started.
    pub output_timers: &'static [TimerRate],
    /// Host link USART1 TX (AF7).
    pub link_tx: Pin,
    /// Host link USART1 RX (AF7).
    pub link_rx: Pin,
    /// SBUS receiver input, USART2 RX (AF7), behind the board's inverter.
    pub sbus_rx: Pin,
    /// Onboard logger output, USART3 TX (AF7).
    pub log_tx: Pin,
    /// The IMU on SPI1.
    pub imu: ImuPins,
    /// How the board carries its IMU chip: the rotation from the chip's axes to the
    /// board's (x towards the board's forward arrow, y right, z down through its bottom
    /// face), from the board's published definitions. The parameter `IMU_ROT` is the
    /// aircraft's mounting of the board, applied after this one.
    pub imu_mounting: ImuRotation,
    /// Status LED (GPIO output), when the board has one off the SWD pins: the pilot
    /// cues (`sweephold_firmware::app::cues`).
    pub led: Option<Led>,
    /// The SWD pins: never reconfigured by the image.
    pub swd: [Pin; 2],
}

/// Shortest pulse ever put on a pin [µs]: the parameter table's shortest servo pulse,
/// so a 760 µs tail servo's range (about 560–960 µs) reaches the pin; each servo's own
/// `*_MIN`/`*_MAX` limit it in the mixer before this last clamp.
pub const MIN_PULSE_US: u16 = 500;
/// Longest pulse ever put on a pin [µs].
pub const MAX_PULSE_US: u16 = 2100;
/// Highest frame rate whose period still holds the longest pulse plus a 100 µs gap [Hz].
pub const MAX_FRAME_HZ: u32 = 1_000_000 / (MAX_PULSE_US as u32 + 100);

impl BoardMap {
    /// The frame rate of `timer`'s outputs [Hz]; 0 for a timer the map does not start.
    pub const fn frame_hz(&self, timer: OutputTimer) -> u32 {
        let mut i = 0;
        while i < self.output_timers.len() {
            if self.output_timers[i].timer.same(timer) {
                return self.output_timers[i].frame_hz;
            }
            i += 1;
        }
        0
    }

    /// The servos and the ESC, in that order.
    pub const fn outputs(&self) -> [Output; 5] {
        let s = self.servos;
        [s[0], s[1], s[2], s[3], self.esc]
    }

    /// Stop the build unless every output sits on a started timer with a usable frame
    /// rate (its period longer than the longest pulse, [`MAX_FRAME_HZ`]) on a channel
    /// 1..=4, in its timer's alternate function. Each board evaluates it in a constant.
    pub const fn check(&self) {
        let outputs = self.outputs();
        let mut i = 0;
        while i < outputs.len() {
            let hz = self.frame_hz(outputs[i].timer);
            assert!(hz > 0, "an output's timer is not in output_timers");
            assert!(hz <= MAX_FRAME_HZ, "frame rate above MAX_FRAME_HZ");
            assert!(
                outputs[i].channel >= 1 && outputs[i].channel <= 4,
                "channel out of range"
            );
            assert!(
                outputs[i].pin.af == outputs[i].timer.af(),
                "an output's pin is not in its timer's alternate function"
            );
            i += 1;
        }
    }
}
