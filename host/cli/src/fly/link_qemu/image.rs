//! The flight-controller image QEMU boots: where it is when `--elf` does not name it,
//! and the check that a file is one before QEMU is started.

use std::ffi::OsString;
use std::io::{ErrorKind, Read};
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail};

/// The image `cargo fw` builds, relative to a cargo target directory.
pub const IMAGE_IN_TARGET_DIR: &str = "thumbv7em-none-eabihf/firmware/sweephold-fc";

/// The environment variable naming the image when `--elf` is not given.
pub const IMAGE_ENV: &str = "SWEEPHOLD_FC_ELF";

/// ELF `e_machine` of 32-bit ARM.
const EM_ARM: u16 = 40;

/// Where the image is when `--elf` is not given: the file `$SWEEPHOLD_FC_ELF` names, if
/// that variable is set; else `target/thumbv7em-none-eabihf/firmware/sweephold-fc` in the
/// workspace this binary belongs to (the nearest folder above it whose `Cargo.toml` has a
/// `[workspace]` table: a binary of `<ws>/target/<profile>/`), under `$CARGO_TARGET_DIR`
/// when that is set, or under the current directory — the first that exists. If none
/// does, the error says where it looked and how to build the image.
pub fn default_image() -> anyhow::Result<PathBuf> {
    let exe = std::env::current_exe().ok();
    let cwd = std::env::current_dir().ok();
    find_image(
        std::env::var_os(IMAGE_ENV),
        std::env::var_os("CARGO_TARGET_DIR"),
        exe.as_deref(),
        cwd.as_deref(),
    )
}

/// [`default_image`] with its inputs given: the variable's value, `$CARGO_TARGET_DIR`, the
/// running binary and the current directory.
fn find_image(
    from_env: Option<OsString>,
    target_dir: Option<OsString>,
    exe: Option<&Path>,
    cwd: Option<&Path>,
) -> anyhow::Result<PathBuf> {
    if let Some(path) = from_env.filter(|value| !value.is_empty()) {
        let path = PathBuf::from(path);
        if path.is_file() {
            return Ok(path);
        }
        bail!(
            "{IMAGE_ENV}={}: no such file (point it at the image `cargo fw` builds, or unset it)",
            path.display()
        );
    }
    let mut candidates: Vec<PathBuf> = Vec::new();
    let workspace = exe.and_then(workspace_of);
    if let Some(workspace) = &workspace {
        candidates.push(workspace.join("target").join(IMAGE_IN_TARGET_DIR));
    }
    if let Some(dir) = target_dir.filter(|value| !value.is_empty()) {
        candidates.push(PathBuf::from(dir).join(IMAGE_IN_TARGET_DIR));
    }
    if let Some(cwd) = cwd {
        candidates.push(cwd.join("target").join(IMAGE_IN_TARGET_DIR));
    }
    candidates.dedup();
    if let Some(found) = candidates.iter().find(|path| path.is_file()) {
        return Ok(found.clone());
    }
    let build = match &workspace {
        Some(workspace) => format!("`cargo fw` in {}", workspace.display()),
        None => "`cargo fw` in the sweephold workspace".to_string(),
    };
    bail!(
        "no flight-controller image (looked for {}): build it with {build}, or pass --elf PATH \
         or set {IMAGE_ENV}",
        candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The workspace `exe` belongs to: the nearest folder above it whose `Cargo.toml` has a
/// `[workspace]` table.
fn workspace_of(exe: &Path) -> Option<PathBuf> {
    exe.ancestors()
        .skip(1)
        .find(|dir| {
            std::fs::read_to_string(dir.join("Cargo.toml"))
                .is_ok_and(|text| text.lines().any(|line| line.trim() == "[workspace]"))
        })
        .map(Path::to_path_buf)
}

/// Refuse `image` unless it is a 32-bit little-endian ARM ELF file — before QEMU is
/// started, which would otherwise load anything as raw memory and report a lockup.
pub fn check_image(image: &Path) -> anyhow::Result<()> {
    let mut file = match std::fs::File::open(image) {
        Ok(file) => file,
        Err(e) if e.kind() == ErrorKind::NotFound => bail!(
            "flight-controller image {} not found: build it with `cargo fw`",
            image.display()
        ),
        Err(e) => bail!(
            "cannot read flight-controller image {}: {e}",
            image.display()
        ),
    };
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        bail!(
            "flight-controller image {} is not a file: pass the ELF `cargo fw` builds (target/{})",
            image.display(),
            IMAGE_IN_TARGET_DIR
        );
    }
    // e_ident (16 bytes), e_type (2), e_machine (2).
    let mut header = [0u8; 20];
    let mut read = 0;
    while read < header.len() {
        match file.read(&mut header[read..]) {
            Ok(0) => break,
            Ok(n) => read += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => bail!(
                "cannot read flight-controller image {}: {e}",
                image.display()
            ),
        }
    }
    let refuse = |what: &str| {
        anyhow!(
            "{} is not a flight-controller image: {what}; pass the ELF `cargo fw` builds (target/{})",
            image.display(),
            IMAGE_IN_TARGET_DIR
        )
    };
    if read < 4 || header[..4] != *b"\x7fELF" {
        return Err(refuse("not an ELF file (no \\x7fELF magic)"));
    }
    if read < header.len() {
        return Err(refuse("an ELF file cut short"));
    }
    if header[4] != 1 || header[5] != 1 {
        return Err(refuse("an ELF file, but not 32-bit little-endian"));
    }
    let machine = u16::from_le_bytes([header[18], header[19]]);
    if machine != EM_ARM {
        return Err(refuse(&format!(
            "an ELF file for machine {machine}, not 32-bit ARM ({EM_ARM})"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch folder removed on drop.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir = std::env::temp_dir()
                .join(format!("sweephold-link-qemu-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }
        fn file(&self, relative: &str, bytes: &[u8]) -> PathBuf {
            let path = self.0.join(relative);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, bytes).unwrap();
            path
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// The first 20 bytes of an ELF header: class, data, machine.
    fn elf_header(class: u8, data: u8, machine: u16) -> Vec<u8> {
        let mut bytes = vec![0x7f, b'E', b'L', b'F', class, data, 1];
        bytes.resize(16, 0);
        bytes.extend_from_slice(&2u16.to_le_bytes()); // e_type: executable
        bytes.extend_from_slice(&machine.to_le_bytes());
        bytes.resize(64, 0);
        bytes
    }

    #[test]
    fn the_default_image_is_found_in_the_binarys_workspace() {
        let scratch = Scratch::new("default");
        let ws = scratch.0.join("ws");
        scratch.file(
            "ws/Cargo.toml",
            b"[package]\nname = \"x\"\n\n[workspace]\nmembers = []\n",
        );
        // A member's Cargo.toml below it has no [workspace]: the walk goes past it.
        scratch.file("ws/host/cli/Cargo.toml", b"[package]\nname = \"y\"\n");
        let exe = ws.join("target/release/sweephold");
        let elsewhere = scratch.0.join("elsewhere");
        std::fs::create_dir_all(&elsewhere).unwrap();

        // Not built yet: the error names where it looked and how to build it.
        let error = find_image(None, None, Some(&exe), Some(&elsewhere))
            .unwrap_err()
            .to_string();
        let in_ws = ws.join("target").join(IMAGE_IN_TARGET_DIR);
        assert!(error.contains(&in_ws.display().to_string()), "{error}");
        assert!(
            error.contains(&format!("`cargo fw` in {}", ws.display())),
            "{error}"
        );
        assert!(
            error.contains(IMAGE_ENV) && !error.contains('\n'),
            "{error}"
        );

        // Built: found from the binary, whatever the current directory.
        let image = scratch.file(
            &format!("ws/target/{IMAGE_IN_TARGET_DIR}"),
            &elf_header(1, 1, EM_ARM),
        );
        assert_eq!(
            find_image(None, None, Some(&exe), Some(&elsewhere)).unwrap(),
            image
        );
        // A test binary in target/debug/deps/ belongs to the same workspace.
        let test_exe = ws.join("target/debug/deps/qemu-0123");
        assert_eq!(
            find_image(None, None, Some(&test_exe), None).unwrap(),
            image
        );
        // A binary outside any workspace: the current directory's target/.
        let installed = scratch.0.join("bin/sweephold");
        assert_eq!(
            find_image(None, None, Some(&installed), Some(&ws)).unwrap(),
            image
        );
        let error = find_image(None, None, Some(&installed), Some(&elsewhere))
            .unwrap_err()
            .to_string();
        assert!(error.contains("in the sweephold workspace"), "{error}");

        // The variable wins, and a wrong one is an error naming it.
        let other = scratch.file("other.elf", &elf_header(1, 1, EM_ARM));
        assert_eq!(
            find_image(Some(other.clone().into()), None, Some(&exe), None).unwrap(),
            other
        );
        let error = find_image(Some("/nonexistent/fc.elf".into()), None, Some(&exe), None)
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("SWEEPHOLD_FC_ELF=/nonexistent/fc.elf: no such file"),
            "{error}"
        );
    }

    #[test]
    fn only_a_32_bit_arm_elf_is_booted() {
        let scratch = Scratch::new("elf");
        let arm = scratch.file("arm.elf", &elf_header(1, 1, EM_ARM));
        check_image(&arm).unwrap();
        for (name, bytes, reason) in [
            (
                "text.bin",
                b"hello, not an image".to_vec(),
                "not an ELF file",
            ),
            ("empty.bin", Vec::new(), "not an ELF file"),
            ("short.elf", b"\x7fELF\x01\x01".to_vec(), "cut short"),
            (
                "x86_64.elf",
                elf_header(2, 1, 62),
                "not 32-bit little-endian",
            ),
            (
                "x86.elf",
                elf_header(1, 1, 3),
                "machine 3, not 32-bit ARM (40)",
            ),
        ] {
            let path = scratch.file(name, &bytes);
            let error = check_image(&path).unwrap_err().to_string();
            assert!(
                error.starts_with(&format!(
                    "{} is not a flight-controller image",
                    path.display()
                )),
                "{error}"
            );
            assert!(error.contains(reason), "{name}: {error}");
            assert!(
                error.contains("cargo fw") && !error.contains('\n'),
                "{error}"
            );
        }
        let error = check_image(&scratch.0).unwrap_err().to_string();
        assert!(error.contains("is not a file"), "{error}");
        let error = check_image(&scratch.0.join("missing"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("not found: build it with `cargo fw`"),
            "{error}"
        );
    }
}
