//! Trim points as a user meets them: `sim trim-points` writes the simulator's steady
//! flights in the documented CSV, `fit --trim-points` refuses a bad file with a one-line
//! error naming it and the line, and no input file is modified.

use std::path::PathBuf;
use std::process::{Command, Output};

use sysid::fit::trim::TrimPoints;

struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("sweephold-trim-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

fn sweephold(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .args(args)
        .output()
        .expect("run sweephold")
}

#[test]
fn sim_trim_points_writes_the_steady_flights_in_the_documented_csv() {
    let out = sweephold(&["sim", "trim-points", "--vehicle", "bo105"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let points = TrimPoints::parse_csv(&text).unwrap();
    let labels: Vec<&str> = points.points.iter().map(|p| p.label.as_str()).collect();
    assert_eq!(
        labels,
        [
            "hover",
            "forward",
            "aft",
            "right",
            "left",
            "descent",
            "climb",
            "turn right",
            "turn left"
        ]
    );
    let [hover, forward, _, right, _, descent, climb, turn, _] = &points.points[..] else {
        panic!("nine points");
    };
    // The body velocities are the flights' (1 m/s, 0.5 m/s down, 0.1 rad/s turn) turned by
    // the trim attitude of a few degrees.
    assert!((forward.states[0] - 1.0).abs() < 0.01, "{forward:?}");
    assert!((right.states[1] - 1.0).abs() < 0.01, "{right:?}");
    assert!((descent.states[2] - 0.5).abs() < 0.01, "{descent:?}");
    assert!((turn.states[5] - 0.1).abs() < 0.001, "{turn:?}");
    // Physics: a climb takes more collective than hover, a descent less; flying forward
    // takes forward (negative) longitudinal stick.
    assert!(climb.controls[3] > hover.controls[3] && descent.controls[3] < hover.controls[3]);
    assert!(forward.controls[1] < hover.controls[1]);

    // --out writes the same bytes.
    let dir = TempDir::new("out");
    let path = dir.0.join("trim-points.csv");
    let written = sweephold(&["sim", "trim-points", "--out", path.to_str().unwrap()]);
    assert!(written.status.success());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
}

#[test]
fn a_bad_trim_point_file_is_refused_in_one_line_and_left_alone() {
    let dir = TempDir::new("bad");
    let frf = dir.file("frf.json", b"{}");
    let header = "label,u,v,w,p,q,r,phi,theta,lat,lon,ped,col\n";
    let cases: [(&str, String, &str); 3] = [
        (
            "missing.csv",
            "u,v,w\n".to_string(),
            "line 1: missing column `p`",
        ),
        (
            "nan.csv",
            format!("{header}hover,0,0,0,0,0,0,0,0,0,0,0,0\nfwd,1,0,0,0,0,0,0,0,0,NaN,0,0\n"),
            "line 3: `lon` is not a finite number: `NaN`",
        ),
        (
            "one.csv",
            format!("{header}hover,0,0,0,0,0,0,0,0,0,0,0,0\n"),
            "1 trim point(s): at least two are needed",
        ),
    ];
    for (name, text, message) in cases {
        let path = dir.file(name, text.as_bytes());
        let out = sweephold(&[
            "fit",
            "--frf",
            frf.to_str().unwrap(),
            "--model",
            "bo105-6dof",
            "--trim-points",
            path.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{name}: {stderr}");
        assert!(
            stderr.contains(name) && stderr.contains(message),
            "{name}: {stderr}"
        );
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            text,
            "{name} modified"
        );
    }
}
