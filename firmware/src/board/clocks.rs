//! Clock tree: HSE + PLL to 168 MHz when the crystal starts, HSI 16 MHz otherwise.
//!
//! One image boots on the board and in QEMU: every ready flag is polled with a bounded
//! number of reads. If the HSE or the PLL never reports ready (a dead crystal, or QEMU,
//! whose `netduinoplus2` has no RCC model at all), the core stays on the 16 MHz HSI it
//! started on and the reason is recorded in [`Clocks::source`]. Every divider in the image
//! (tick timer, servo PWM, baud rate) is computed from the [`Clocks`] returned here.
//!
//! Board clock tree with the crystal (RM0090 §6.2, Fig. 21), HSE = [`HSE_HZ`]:
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

use super::regs::{flash, rcc, Reg};

/// Frequency of the board's crystal [Hz]. 8 MHz is what STM32F405 flight-controller
/// boards and the STM32F4 Discovery carry; change it (it must be a multiple of 2 MHz)
/// for another crystal.
pub const HSE_HZ: u32 = 8_000_000;

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

// RCC_CR bits.
const CR_HSIRDY: u32 = 1 << 1;
const CR_HSEON: u32 = 1 << 16;
const CR_HSERDY: u32 = 1 << 17;
const CR_PLLON: u32 = 1 << 24;
const CR_PLLRDY: u32 = 1 << 25;

// RCC_PLLCFGR fields: PLLM[5:0], PLLN[14:6], PLLP[17:16], PLLSRC[22], PLLQ[27:24].
const PLLCFGR_FIELDS: u32 = 0x3F | (0x1FF << 6) | (0b11 << 16) | (1 << 22) | (0xF << 24);
const PLLCFGR_SRC_HSE: u32 = 1 << 22;
const PLLM: u32 = HSE_HZ / 2_000_000;
const PLLN: u32 = 168;
const PLLP: u32 = 2;
const PLLQ: u32 = 7;

// RCC_CFGR fields: SW[1:0], SWS[3:2], HPRE[7:4], PPRE1[12:10], PPRE2[15:13].
const CFGR_SW_HSI: u32 = 0b00;
const CFGR_SW_PLL: u32 = 0b10;
const CFGR_PPRE_DIV2: u32 = 0b100;
const CFGR_PPRE_DIV4: u32 = 0b101;

// FLASH_ACR: 5 wait states at 168 MHz and 2.7–3.6 V (RM0090 Table 10), prefetch, caches.
const ACR_LATENCY_5WS: u32 = 5;
const ACR_PRFTEN: u32 = 1 << 8;
const ACR_ICEN: u32 = 1 << 9;
const ACR_DCEN: u32 = 1 << 10;

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

/// Bring up the clock tree (see the module documentation) and report what it is.
pub fn init() -> Clocks {
    if rcc::CR.read() & CR_HSIRDY == 0 {
        // Out of reset a real STM32F4 runs on HSI with HSION and HSIRDY set.
        return Clocks {
            apb1_timer_hz: EMULATED_TIMER_HZ,
            ..Clocks::hsi(ClockSource::NoRcc)
        };
    }

    rcc::CR.set_bits(CR_HSEON);
    if !wait_for(|| rcc::CR.read() & CR_HSERDY != 0) {
        rcc::CR.clear_bits(CR_HSEON);
        return Clocks::hsi(ClockSource::HsiHseTimeout);
    }

    // The PLL may only be configured while it is off (it is, out of reset). Reserved
    // bits keep their reset values.
    rcc::PLLCFGR.modify(|value| {
        (value & !PLLCFGR_FIELDS)
            | PLLM
            | (PLLN << 6)
            | ((PLLP / 2 - 1) << 16)
            | PLLCFGR_SRC_HSE
            | (PLLQ << 24)
    });
    rcc::CR.set_bits(CR_PLLON);
    if !wait_for(|| rcc::CR.read() & CR_PLLRDY != 0) {
        rcc::CR.clear_bits(CR_PLLON | CR_HSEON);
        return Clocks::hsi(ClockSource::HsiPllTimeout);
    }

    // Wait states before the clock goes up; read back so the new latency is in effect.
    flash::ACR.write(ACR_LATENCY_5WS | ACR_PRFTEN | ACR_ICEN | ACR_DCEN);
    if !wait_for(|| flash::ACR.read() & 0xF == ACR_LATENCY_5WS) {
        rcc::CR.clear_bits(CR_PLLON | CR_HSEON);
        return Clocks::hsi(ClockSource::HsiFlashLatency);
    }

    // Bus prescalers first (AHB /1, APB1 /4, APB2 /2), then the switch.
    rcc::CFGR.write((CFGR_PPRE_DIV4 << 10) | (CFGR_PPRE_DIV2 << 13) | CFGR_SW_HSI);
    rcc::CFGR.write_field(0, 2, CFGR_SW_PLL);
    if !wait_for(|| (rcc::CFGR.read() >> 2) & 0b11 == CFGR_SW_PLL) {
        rcc::CFGR.write(CFGR_SW_HSI);
        rcc::CR.clear_bits(CR_PLLON | CR_HSEON);
        return Clocks::hsi(ClockSource::HsiSwitchTimeout);
    }
    Clocks::pll()
}

/// A peripheral's clock-enable bit.
#[derive(Clone, Copy)]
pub struct ClockGate {
    register: Reg,
    bit: u32,
}

impl ClockGate {
    const fn at(register: Reg, bit: u32) -> ClockGate {
        ClockGate { register, bit }
    }

    /// GPIO port A (AHB1ENR.GPIOAEN).
    pub const GPIOA: ClockGate = ClockGate::at(rcc::AHB1ENR, 1 << 0);
    /// GPIO port B (AHB1ENR.GPIOBEN).
    pub const GPIOB: ClockGate = ClockGate::at(rcc::AHB1ENR, 1 << 1);
    /// GPIO port C (AHB1ENR.GPIOCEN).
    pub const GPIOC: ClockGate = ClockGate::at(rcc::AHB1ENR, 1 << 2);
    /// TIM2 (APB1ENR.TIM2EN).
    pub const TIM2: ClockGate = ClockGate::at(rcc::APB1ENR, 1 << 0);
    /// TIM3 (APB1ENR.TIM3EN).
    pub const TIM3: ClockGate = ClockGate::at(rcc::APB1ENR, 1 << 1);
    /// TIM4 (APB1ENR.TIM4EN).
    pub const TIM4: ClockGate = ClockGate::at(rcc::APB1ENR, 1 << 2);
    /// TIM5 (APB1ENR.TIM5EN).
    pub const TIM5: ClockGate = ClockGate::at(rcc::APB1ENR, 1 << 3);
    /// TIM8 (APB2ENR.TIM8EN).
    pub const TIM8: ClockGate = ClockGate::at(rcc::APB2ENR, 1 << 1);
    /// USART1 (APB2ENR.USART1EN).
    pub const USART1: ClockGate = ClockGate::at(rcc::APB2ENR, 1 << 4);

    /// Turn the clock on, then read the register back: RM0090 §7.3 asks for two bus
    /// cycles between the enable and the first access to the peripheral.
    pub fn enable(self) {
        self.register.set_bits(self.bit);
        let _ = self.register.read();
    }
}
