//! Put the selected board's `memory.x` (`src/boards/<board>/memory.x`) where the linker
//! (cortex-m-rt's `link.x`) finds it.
//!
//! The board is the one whose folder matches an enabled `board-<folder with dashes>`
//! feature (cargo sets `CARGO_FEATURE_BOARD_<FOLDER IN CAPITALS>`), else the default
//! board; two board features at once stop the build. A new board folder needs no change
//! here.
use std::{env, fs, path::PathBuf};

/// The board without a `board-*` feature.
const DEFAULT_BOARD: &str = "speedybee_f405_v4";

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let boards = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"))
        .join("src")
        .join("boards");
    let mut folders: Vec<String> = fs::read_dir(&boards)
        .expect("src/boards is readable")
        .filter_map(|entry| entry.ok())
        .filter(|entry| entry.path().is_dir())
        .filter_map(|entry| entry.file_name().into_string().ok())
        .collect();
    folders.sort();
    let selected: Vec<&String> = folders
        .iter()
        .filter(|folder| {
            env::var_os(format!("CARGO_FEATURE_BOARD_{}", folder.to_uppercase())).is_some()
        })
        .collect();
    let board = match selected.as_slice() {
        [] => DEFAULT_BOARD,
        [one] => one.as_str(),
        many => panic!("more than one board feature: {many:?}"),
    };
    let memory = boards.join(board).join("memory.x");
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
