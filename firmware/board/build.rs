//! Put the workspace's `memory.x` where the linker (cortex-m-rt's `link.x`) finds it.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let memory = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"))
        .join("../..")
        .join("memory.x");
    fs::copy(&memory, out.join("memory.x")).expect("copy ../../memory.x into OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rerun-if-changed=build.rs");
    // defmt keeps only `error!` lines unless DEFMT_LOG says otherwise. The image's log
    // (phase changes, hold engage/release, aborts, link state) is `info!`/`debug!`: make
    // `debug` this package's default; an explicit DEFMT_LOG still wins.
    println!("cargo:rerun-if-env-changed=DEFMT_LOG");
    if env::var_os("DEFMT_LOG").is_none() {
        println!("cargo:rustc-env=DEFMT_LOG=debug");
    }
}
