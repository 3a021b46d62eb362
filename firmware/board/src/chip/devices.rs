//! The boot's peripheral set-up: the PAC's peripherals (and the core's) are taken here,
//! once, and each instance is handed to the driver that owns it from then on, with the
//! board map's pins. Servos first: their failsafe pulses and the throttle cut are on the
//! pins before anything else runs.

use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks;
use crate::chip::dividers;
use crate::chip::flash::{F405Flash, Registers};
use crate::chip::gpio::{Gpio, GpioOutput};
use crate::chip::imu_device::{self, ImuDevice};
use crate::chip::logport;
use crate::chip::nvic::Nvic;
use crate::chip::pins::BoardMap;
use crate::chip::sbus_uart::{self, SbusRx};
use crate::chip::servo::{self, OutputTimers, ServoChannel, Servos};
use crate::chip::usart::{self, UsartRx, UsartTx};
use crate::chip::watchdog::Watchdog;
use sweephold_firmware::app::cues::StatusLed;

/// The drivers of a board, set up, and what the loop still starts itself.
pub struct Devices {
    /// Clocks, clock gates, ports and NVIC, for the tick timer's start.
    pub boot: Boot,
    /// The four servos in wire order.
    pub servos: Servos<ServoChannel>,
    /// The ESC's throttle output.
    pub esc: ServoChannel,
    /// The host link's transmit half.
    pub tx: UsartTx,
    /// The host link's receive half.
    pub rx: UsartRx,
    /// The SBUS receiver's bytes.
    pub sbus: SbusRx,
    /// The IMU.
    pub imu: ImuDevice,
    /// The independent watchdog (not started).
    pub watchdog: Watchdog,
    /// The flash, for the parameter store.
    pub flash: F405Flash<Registers>,
    /// The loop tick's timer, started by the loop once its flight logic is ready.
    pub tim5: pac::TIM5,
    /// The status LED, off, when the board has one.
    pub led: Option<StatusLed<GpioOutput>>,
}

/// Take the peripherals and set up every driver on `map`'s pins; a driver that cannot
/// be set up (a divider out of range) stops the boot with a panic, which puts the
/// outputs in their safe state and resets.
pub fn bring_up(map: &BoardMap) -> Devices {
    let (Some(p), Some(core)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        defmt::panic!("peripherals taken twice")
    };
    let (clocks, gates, flash) = clocks::init(p.RCC, p.FLASH, map.crystal);
    defmt::info!("clocks {}", clocks);
    let Some(gpio) = cortex_m::singleton!(: Gpio = Gpio::new(p.GPIOA, p.GPIOB, p.GPIOC)) else {
        defmt::panic!("GPIO taken twice")
    };
    let mut boot = Boot {
        clocks,
        gates,
        gpio,
        nvic: Nvic::new(core.NVIC),
    };

    let Some(timers) = cortex_m::singleton!(: OutputTimers =
        OutputTimers::new(p.TIM1, p.TIM2, p.TIM3, p.TIM4, p.TIM8))
    else {
        defmt::panic!("output timers taken twice")
    };
    let (servos, esc) = match servo::init(timers, map, &boot) {
        Ok(outputs) => outputs,
        Err(error) => defmt::panic!("servo timer: {}", error),
    };
    let (tx, rx) = match usart::init(p.USART1, (map.link_tx, map.link_rx), &mut boot) {
        Ok(halves) => halves,
        Err(error) => defmt::panic!("USART1: {}", error),
    };
    defmt::info!(
        "USART1 {=u32} Bd, BRR {=u32:#x}, rate error {=u32} ppm",
        usart::BAUD,
        tx.brr(),
        dividers::baud_error_ppm(clocks.pclk2_hz, usart::BAUD, tx.brr())
    );
    if let Err(error) = logport::init(p.USART3, map.log_tx, &mut boot) {
        defmt::panic!("USART3 (log): {}", error);
    }
    let sbus = match sbus_uart::init(p.USART2, map.sbus_rx, &mut boot) {
        Ok(sbus) => sbus,
        Err(error) => defmt::panic!("USART2 (SBUS): {}", error),
    };
    let imu = match imu_device::init(p.SPI1, map, &boot) {
        Ok(imu) => imu,
        Err(error) => defmt::panic!("SPI1 (IMU): {}", error),
    };
    let led = map.led.map(|led| {
        // Off until the first control tick: the level that does not light it.
        let output = GpioOutput::new(boot.gpio, &boot.gates, led.pin, led.active_low);
        StatusLed::new(output, led.active_low)
    });
    Devices {
        boot,
        led,
        servos,
        esc,
        tx,
        rx,
        sbus,
        imu,
        watchdog: Watchdog::new(p.IWDG),
        flash: F405Flash::new(Registers::new(flash)),
        tim5: p.TIM5,
    }
}
