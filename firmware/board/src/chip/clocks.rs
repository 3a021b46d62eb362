//! Clock tree: HSE + PLL to 168 MHz when the crystal starts, HSI 16 MHz otherwise.
//!
//! One image boots on the board and in QEMU: every ready flag is polled with a bounded
//! number of reads. If the HSE or the PLL never reports ready (a dead crystal, or QEMU,
//! whose `netduinoplus2` has no RCC model at all), the core stays on the 16 MHz HSI it
//! started on and the reason is recorded in [`Clocks::source`]. Every divider in the image
//! (tick timer, servo PWM, baud rate) is computed from the [`Clocks`] returned here.
//!
//! Clock tree with the board's crystal (RM0090 §6.2, Fig. 21), HSE = the board map's
//! [`Crystal`] (8 MHz on every board of the list; PLLM = HSE / 2 MHz):
//!
//! ```text
//! f_VCO_in = HSE / PLLM = 2 MHz          (1–2 MHz; 2 MHz gives the lowest PLL jitter)
//! f_VCO    = f_VCO_in · PLLN = 336 MHz   (PLLN = 168; 100–432 MHz)
//! SYSCLK   = f_VCO / PLLP = 168 MHz      (PLLP = 2)
//! f_48     = f_VCO / PLLQ = 48 MHz       (PLLQ = 7; USB/SDIO)
//! HCLK     = SYSCLK / 1 = 168 MHz
//! PCLK1    = HCLK / 4 = 42 MHz           (APB1 ≤ 42 MHz)  → TIM2..5 clock 2·PCLK1 = 84 MHz
//! PCLK2    = HCLK / 2 = 84 MHz           (APB2 ≤ 84 MHz)  → USART1 kernel clock
//! ```
//!
//! The timer clock rule (RM0090 §6.2): a timer on an APB bus whose prescaler is 1 runs at
//! PCLK, otherwise at 2·PCLK.

use stm32f4::stm32f405 as pac;

use crate::chip::pins::Crystal;

/// The internal RC oscillator every STM32F4 starts on [Hz].
pub const HSI_HZ: u32 = 16_000_000;

/// Target system clock with the PLL [Hz].
pub const PLL_SYSCLK_HZ: u32 = 168_000_000;

/// Reads of a ready flag before giving up. The HSE needs up to ~2 ms to start
/// (datasheet t_SU(HSE)); one poll costs at least 4 cycles at 16 MHz, so 100 000 polls
/// wait ≥ 25 ms, ten times the worst start-up, and cost QEMU about a millisecond.
const READY_POLLS: u32 = 100_000;

/// Timer clock of QEMU 7.2's STM32F405 model [Hz]: its TIM2..TIM5 count at a fixed
/// 1 GHz whatever the (absent) RCC says. Used only when the RCC reads back all zeros.
pub const EMULATED_TIMER_HZ: u32 = 1_000_000_000;

// RCC_PLLCFGR fields (RM0090 §7.3.2): VCO 336 MHz, SYSCLK /2, 48 MHz /7 (PLLM, the
// VCO input divider, is the crystal's: `Crystal::pll_m`).
const PLLN: u16 = 168;
const PLLQ: u8 = 7;

/// Where the system clock comes from, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum ClockSource {
    /// HSE crystal through the PLL: the configuration of [`PLL_SYSCLK_HZ`].
    HsePll,
    /// HSI 16 MHz: the HSE did not report ready within the poll budget.
    HsiHseTimeout,
    /// HSI 16 MHz: the HSE started but the PLL did not lock.
    HsiPllTimeout,
    /// HSI 16 MHz: the flash did not confirm the wait states 168 MHz needs.
    HsiFlashLatency,
    /// HSI 16 MHz: the clock switch to the PLL was not confirmed.
    HsiSwitchTimeout,
    /// The RCC reads back all zeros, which no STM32F4 does (HSIRDY is set out of reset):
    /// an emulator without an RCC model (QEMU). The core clock is nominally HSI, and the
    /// timers count at [`EMULATED_TIMER_HZ`].
    NoRcc,
}

/// The frequencies every divider of the image is computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Clocks {
    /// Core clock (HCLK = SYSCLK here) [Hz].
    pub hclk_hz: u32,
    /// APB1 bus clock [Hz].
    pub pclk1_hz: u32,
    /// APB2 bus clock (USART1) [Hz].
    pub pclk2_hz: u32,
    /// Kernel clock of the APB1 timers TIM2..TIM5 [Hz].
    pub apb1_timer_hz: u32,
    /// Kernel clock of the APB2 timers (TIM8) [Hz].
    pub apb2_timer_hz: u32,
    /// How the clock tree came up.
    pub source: ClockSource,
}

impl Clocks {
    /// The reset clock tree: everything on HSI, all prescalers 1.
    const fn hsi(source: ClockSource) -> Clocks {
        Clocks {
            hclk_hz: HSI_HZ,
            pclk1_hz: HSI_HZ,
            pclk2_hz: HSI_HZ,
            apb1_timer_hz: HSI_HZ,
            apb2_timer_hz: HSI_HZ,
            source,
        }
    }

    /// The PLL clock tree of the module documentation.
    const fn pll() -> Clocks {
        let pclk1 = PLL_SYSCLK_HZ / 4;
        Clocks {
            hclk_hz: PLL_SYSCLK_HZ,
            pclk1_hz: pclk1,
            pclk2_hz: PLL_SYSCLK_HZ / 2,
            // APB1 prescaler ≠ 1 → timers at 2·PCLK1.
            apb1_timer_hz: 2 * pclk1,
            // APB2 prescaler ≠ 1 → timers at 2·PCLK2.
            apb2_timer_hz: PLL_SYSCLK_HZ,
            source: ClockSource::HsePll,
        }
    }
}

/// Poll until `ready()` or the budget runs out; `true` when ready.
fn wait_for(mut ready: impl FnMut() -> bool) -> bool {
    (0..READY_POLLS).any(|_| ready())
}

/// The RCC after the clock set-up: what switches the peripherals' clocks on.
pub struct ClockGates {
    rcc: pac::RCC,
}

/// Bring up the clock tree (see the module documentation) with the board's `crystal` and
/// report what it is. Takes the RCC for good and the flash interface for its wait
/// states; the RCC comes back as the [`ClockGates`] the drivers' set-up uses, the flash
/// interface for the parameter store's driver (`chip::flash`, which uses only KEYR, CR
/// and SR; the wait states in ACR stay as set here).
pub fn init(
    rcc: pac::RCC,
    flash: pac::FLASH,
    crystal: Crystal,
) -> (Clocks, ClockGates, pac::FLASH) {
    let clocks = configure(&rcc, &flash, crystal);
    (clocks, ClockGates { rcc }, flash)
}

fn configure(rcc: &pac::RCC, flash: &pac::FLASH, crystal: Crystal) -> Clocks {
    let pllm = crystal.pll_m();
    if rcc.cr().read().hsirdy().bit_is_clear() {
        // Out of reset a real STM32F4 runs on HSI with HSION and HSIRDY set.
        return Clocks {
            apb1_timer_hz: EMULATED_TIMER_HZ,
            ..Clocks::hsi(ClockSource::NoRcc)
        };
    }

    rcc.cr().modify(|_, w| w.hseon().set_bit());
    if !wait_for(|| rcc.cr().read().hserdy().bit_is_set()) {
        rcc.cr().modify(|_, w| w.hseon().clear_bit());
        return Clocks::hsi(ClockSource::HsiHseTimeout);
    }

    // The PLL may only be configured while it is off (it is, out of reset). Reserved
    // bits keep their reset values.
    rcc.pllcfgr().modify(|_, w| {
        // SAFETY: PLLM = HSE / 2 MHz, 2..=13 for the crystals `Crystal::hz` accepts
        // (2..=63 allowed), PLLN = 168 (50..=432), PLLQ = 7 (2..=15): values RM0090
        // §7.3.2 allows, giving the frequencies of the module documentation.
        unsafe {
            w.pllm().bits(pllm);
            w.plln().bits(PLLN);
            w.pllq().bits(PLLQ);
        }
        w.pllp().div2();
        w.pllsrc().hse()
    });
    rcc.cr().modify(|_, w| w.pllon().set_bit());
    if !wait_for(|| rcc.cr().read().pllrdy().bit_is_set()) {
        rcc.cr()
            .modify(|_, w| w.pllon().clear_bit().hseon().clear_bit());
        return Clocks::hsi(ClockSource::HsiPllTimeout);
    }

    // Wait states before the clock goes up (5 at 168 MHz and 2.7–3.6 V, RM0090 Table
    // 10); read back so the new latency is in effect.
    flash.acr().write(|w| {
        w.latency().ws5();
        w.prften().set_bit();
        w.icen().set_bit();
        w.dcen().set_bit()
    });
    if !wait_for(|| flash.acr().read().latency().is_ws5()) {
        rcc.cr()
            .modify(|_, w| w.pllon().clear_bit().hseon().clear_bit());
        return Clocks::hsi(ClockSource::HsiFlashLatency);
    }

    // Bus prescalers first (AHB /1, APB1 /4, APB2 /2), then the switch.
    rcc.cfgr().write(|w| {
        w.hpre().div1();
        w.ppre1().div4();
        w.ppre2().div2();
        w.sw().hsi()
    });
    rcc.cfgr().modify(|_, w| w.sw().pll());
    if !wait_for(|| rcc.cfgr().read().sws().is_pll()) {
        rcc.cfgr().write(|w| w.sw().hsi());
        rcc.cr()
            .modify(|_, w| w.pllon().clear_bit().hseon().clear_bit());
        return Clocks::hsi(ClockSource::HsiSwitchTimeout);
    }
    Clocks::pll()
}

/// A peripheral's clock-enable bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClockGate {
    /// TIM1 (APB2ENR.TIM1EN).
    Tim1,
    /// GPIO port A (AHB1ENR.GPIOAEN).
    GpioA,
    /// GPIO port B (AHB1ENR.GPIOBEN).
    GpioB,
    /// GPIO port C (AHB1ENR.GPIOCEN).
    GpioC,
    /// TIM2 (APB1ENR.TIM2EN).
    Tim2,
    /// TIM3 (APB1ENR.TIM3EN).
    Tim3,
    /// TIM4 (APB1ENR.TIM4EN).
    Tim4,
    /// TIM5 (APB1ENR.TIM5EN).
    Tim5,
    /// TIM8 (APB2ENR.TIM8EN).
    Tim8,
    /// USART1 (APB2ENR.USART1EN).
    Usart1,
    /// USART2 (APB1ENR.USART2EN): the SBUS receiver.
    Usart2,
    /// USART3 (APB1ENR.USART3EN).
    Usart3,
    /// SPI1 (APB2ENR.SPI1EN): the IMU.
    Spi1,
}

impl ClockGates {
    /// Turn `gate`'s clock on, then read the register back: RM0090 §7.3 asks for two bus
    /// cycles between the enable and the first access to the peripheral.
    pub fn enable(&self, gate: ClockGate) {
        let rcc = &self.rcc;
        match gate {
            ClockGate::Tim1 => rcc.apb2enr().modify(|_, w| w.tim1en().set_bit()),
            ClockGate::GpioA => rcc.ahb1enr().modify(|_, w| w.gpioaen().set_bit()),
            ClockGate::GpioB => rcc.ahb1enr().modify(|_, w| w.gpioben().set_bit()),
            ClockGate::GpioC => rcc.ahb1enr().modify(|_, w| w.gpiocen().set_bit()),
            ClockGate::Tim2 => rcc.apb1enr().modify(|_, w| w.tim2en().set_bit()),
            ClockGate::Tim3 => rcc.apb1enr().modify(|_, w| w.tim3en().set_bit()),
            ClockGate::Tim4 => rcc.apb1enr().modify(|_, w| w.tim4en().set_bit()),
            ClockGate::Tim5 => rcc.apb1enr().modify(|_, w| w.tim5en().set_bit()),
            ClockGate::Tim8 => rcc.apb2enr().modify(|_, w| w.tim8en().set_bit()),
            ClockGate::Usart1 => rcc.apb2enr().modify(|_, w| w.usart1en().set_bit()),
            ClockGate::Usart2 => rcc.apb1enr().modify(|_, w| w.usart2en().set_bit()),
            ClockGate::Usart3 => rcc.apb1enr().modify(|_, w| w.usart3en().set_bit()),
            ClockGate::Spi1 => rcc.apb2enr().modify(|_, w| w.spi1en().set_bit()),
        };
        let _ = rcc.ahb1enr().read();
        let _ = rcc.apb1enr().read();
        let _ = rcc.apb2enr().read();
    }
}
