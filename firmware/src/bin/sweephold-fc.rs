//! The STM32F4 flight-controller image. Built with `cargo fw`; on the host it is an empty
//! program so that `cargo build --workspace` works.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod board {
    use cortex_m_rt::entry;
    use defmt_rtt as _;

    #[entry]
    fn main() -> ! {
        defmt::info!("sweephold-fc boot");
        loop {
            cortex_m::asm::wfi();
        }
    }

    #[panic_handler]
    fn panic(_info: &core::panic::PanicInfo) -> ! {
        cortex_m::interrupt::disable();
        loop {
            cortex_m::asm::nop();
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("sweephold-fc is the flight-controller image: build it with `cargo fw`.");
    std::process::exit(2);
}
