//! The flight logic's defmt log level. defmt keeps only `error!` lines unless DEFMT_LOG
//! says otherwise, and the level is fixed per crate when it compiles. The image's log
//! (phase changes, hold engage/release, aborts, link state) is `info!`/`debug!`: make
//! `debug` this package's default; an explicit DEFMT_LOG still wins. (The linker script
//! `memory.x` is the board crate's business: `firmware/board/build.rs`.)
use std::env;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=DEFMT_LOG");
    if env::var_os("DEFMT_LOG").is_none() {
        println!("cargo:rustc-env=DEFMT_LOG=debug");
    }
}
