use super::staged::RUN_MARKER;
use super::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sweephold-output-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn an_input_named_as_output_is_refused_by_path_link_or_hard_link() {
    let dir = scratch("same");
    let input = dir.join("a.bin");
    fs::write(&input, b"telemetry").unwrap();
    let relative = dir.join("sub/../a.bin");
    fs::create_dir_all(dir.join("sub")).unwrap();
    let hard = dir.join("hard.bin");
    fs::hard_link(&input, &hard).unwrap();
    for output in [&input, &relative, &hard] {
        let error = refuse_inputs_as_outputs(&[&input], &[("-o", output)]).unwrap_err();
        assert!(
            error.to_string().contains("is one of the inputs"),
            "{error}"
        );
    }
    #[cfg(unix)]
    {
        let link = dir.join("link.bin");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        assert!(refuse_inputs_as_outputs(&[&input], &[("-o", &link)]).is_err());
    }
    let other = dir.join("new/out.csv");
    refuse_inputs_as_outputs(&[&input], &[("-o", &other)]).unwrap();
    assert_eq!(fs::read(&input).unwrap(), b"telemetry");
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_atomic_file_replaces_only_on_commit() {
    let dir = scratch("atomic");
    let path = dir.join("frf.json");
    fs::write(&path, b"earlier").unwrap();
    {
        let mut file = AtomicFile::create(&path).unwrap();
        file.write_all(b"half").unwrap();
        // dropped: no commit
    }
    assert_eq!(fs::read(&path).unwrap(), b"earlier");
    write_atomic(&path, b"new").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"new");
    #[cfg(unix)]
    {
        // As File::create would make it: readable by others unless the umask says no.
        use std::os::unix::fs::PermissionsExt;
        let plain = dir.join("plain");
        fs::File::create(&plain).unwrap();
        let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&path), mode(&plain));
        fs::remove_file(&plain).unwrap();
    }
    // No temporary file is left behind.
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
    assert!(write_atomic(&dir, b"x").is_err());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_device_is_written_in_place_and_a_link_keeps_pointing_at_its_target() {
    // Classified only: a rename over /dev/null would replace the device with a file.
    assert_eq!(
        Destination::of(Path::new("/dev/null"), Links::Follow).unwrap(),
        Destination::InPlace
    );
    let dir = scratch("link");
    let target = dir.join("target.json");
    fs::write(&target, b"old").unwrap();
    #[cfg(unix)]
    {
        let link = dir.join("link.json");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&target).unwrap(), b"new");
        // Inside an output folder the link itself is replaced; its target is kept.
        write_file_in_folder(&link, b"plot").unwrap();
        assert!(fs::symlink_metadata(&link).unwrap().is_file());
        assert_eq!(fs::read(&link).unwrap(), b"plot");
        assert_eq!(fs::read(&target).unwrap(), b"new");
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_staged_folder_replaces_the_previous_run_only_when_complete() {
    let dir = scratch("staged");
    let out = dir.join("run");
    // First run completes.
    let stage = StagedFolder::begin(&out).unwrap();
    fs::write(stage.path().join(RUN_MARKER), b"one").unwrap();
    fs::write(stage.path().join("stale.bin"), b"old").unwrap();
    stage.complete().unwrap();
    assert_eq!(fs::read(out.join(RUN_MARKER)).unwrap(), b"one");
    // Second run fails: the first stays, the failed one is kept beside it.
    let stage = StagedFolder::begin(&out).unwrap();
    fs::write(stage.path().join(RUN_MARKER), b"two").unwrap();
    let failed = stage.fail().unwrap();
    assert_eq!(fs::read(out.join(RUN_MARKER)).unwrap(), b"one");
    assert_eq!(fs::read(failed.join(RUN_MARKER)).unwrap(), b"two");
    // Third run completes: its folder replaces the first whole (no stale file).
    let stage = StagedFolder::begin(&out).unwrap();
    fs::write(stage.path().join(RUN_MARKER), b"three").unwrap();
    stage.complete().unwrap();
    assert_eq!(fs::read(out.join(RUN_MARKER)).unwrap(), b"three");
    assert!(!out.join("stale.bin").exists());
    assert!(!dir.join("run.partial").exists() && !dir.join("run.previous").exists());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_folder_of_other_files_is_not_replaced() {
    let dir = scratch("foreign");
    let out = dir.join("home");
    fs::create_dir_all(&out).unwrap();
    fs::write(out.join("thesis.tex"), b"precious").unwrap();
    let error = StagedFolder::begin(&out).err().unwrap();
    assert!(error.to_string().contains("not a sweephold run"), "{error}");
    assert_eq!(fs::read(out.join("thesis.tex")).unwrap(), b"precious");
    fs::write(dir.join("file"), b"x").unwrap();
    assert!(StagedFolder::begin(&dir.join("file")).is_err());
    fs::remove_dir_all(&dir).unwrap();
}
