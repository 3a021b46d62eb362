//! Hand the linker (cortex-m-rt's `link.x`) the workspace's `memory.x`, and check the
//! board choice.
//!
//! `memory.x` is the chip's memory layout: every board of the image is an STM32F405RG, so
//! the layout is one file at the workspace root, not one per board folder (the linker
//! also looks in the working directory, the workspace root, first: a copy per board
//! would be shadowed by a root file anyway). A board on another chip would be another
//! image.
//!
//! The board is the one whose folder matches an enabled `board-<folder with dashes>`
//! feature (cargo sets `CARGO_FEATURE_BOARD_<FOLDER IN CAPITALS>`), else the default
//! board; two board features at once stop the build. A new board folder needs no change
//! here.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let boards = manifest.join("src").join("boards");
    let folders: Vec<String> = fs::read_dir(&boards)
        .expect("src/boards is readable")
        .filter_map(|entry| entry.ok())
        .filter(|entry| entry.path().is_dir())
        .filter_map(|entry| entry.file_name().into_string().ok())
        .collect();
    let selected: Vec<&String> = folders
        .iter()
        .filter(|folder| {
            env::var_os(format!("CARGO_FEATURE_BOARD_{}", folder.to_uppercase())).is_some()
        })
        .collect();
    if selected.len() > 1 {
        panic!("more than one board feature: {selected:?}");
    }
    let memory = manifest.join("../../memory.x");
    fs::copy(&memory, out.join("memory.x"))
        .unwrap_or_else(|e| panic!("copy {} into OUT_DIR: {e}", memory.display()));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rerun-if-changed={}", boards.display());
    println!("cargo:rerun-if-changed=build.rs");
    // defmt keeps only `error!` lines unless DEFMT_LOG says otherwise. The image's log
    // (phase changes, hold engage/release, aborts, link state) is `info!`/`debug!`: make
    // `debug` this package's default; an explicit DEFMT_LOG still wins.
    println!("cargo:rerun-if-env-changed=DEFMT_LOG");
    if env::var_os("DEFMT_LOG").is_none() {
        println!("cargo:rustc-env=DEFMT_LOG=debug");
    }
}
