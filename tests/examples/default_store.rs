//! Write the bytes of the board's parameter store sectors (STM32F405 sectors 10 and 11,
//! 256 KiB from 0x080C_0000) holding the TREX 700L defaults, as the firmware library's
//! own `ParamStore` saves them, to the file named on the command line. A QEMU run of the
//! bench image that must arm preloads them:
//! `-device loader,file=FILE,addr=0x080c0000,force-raw=on`
//! (`docs/board_tick_instructions.py`; the QEMU tests make the same bytes themselves).
//!
//! `cargo run -p sweephold-tests --example default_store -- target/default-store.bin`

use sweephold_firmware::params::ram_flash::saved_region;
use sweephold_firmware::params::ParamTable;
use sweephold_protocol::VehicleId;

fn main() {
    let Some(path) = std::env::args_os().nth(1) else {
        eprintln!("error: usage: default_store OUT_FILE");
        std::process::exit(2);
    };
    // The F405 driver's word (4 B) and sector (128 KiB); the store's region as flash
    // offsets (memory.x).
    let table = ParamTable::defaults(VehicleId::Trex700l);
    let bytes = match saved_region::<4, { 128 * 1024 }>(&table, 0xC_0000..0x10_0000) {
        Ok(bytes) => bytes,
        Err(error) => {
            eprintln!("error: the store did not save: {error:?}");
            std::process::exit(1);
        }
    };
    if let Err(error) = std::fs::write(&path, bytes) {
        eprintln!("error: cannot write {}: {error}", path.to_string_lossy());
        std::process::exit(1);
    }
}
