//! Tests of the CSV reader.

use super::*;
use units::Unit;

fn columns() -> CsvColumns {
    CsvColumns {
        time: "t".into(),
        inputs: vec![
            ("lat".into(), "d_lat".into()),
            ("lon".into(), "d_lon".into()),
        ],
        outputs: vec![("p".into(), "p".into())],
        primary: None,
        primary_column: Some(PRIMARY_COLUMN.into()),
        phase_column: Some("phase".into()),
        sweep_band: Some([1.0, 10.0]),
        ..CsvColumns::default()
    }
}

#[test]
fn reads_named_columns_and_picks_the_swept_input() {
    let mut text = String::from("t, d_lat ,\"d_lon\",p,extra\n");
    for k in 0..50 {
        let t = k as f64 * 0.02;
        text += &format!("{t},{},{},{},x\n", (3.0 * t).sin(), 0.001 * t, 2.0 * t);
    }
    let record = parse_csv(&text, "log.csv", &columns()).unwrap();
    assert_eq!(record.len(), 50);
    assert!((record.sample_rate_hz - 50.0).abs() < 1e-9);
    assert_eq!(record.primary, "lat");
    assert!(record.primary_guessed);
    assert_eq!(record.input("lon").unwrap()[10], 0.001 * 0.2);
    assert_eq!(record.notes.len(), 1);
}

/// A lateral sweep as `decode` lays it out: idle rows, then excitation rows whose
/// `primary` is `lat`, while the longitudinal stick moves more than the lateral one.
fn decoded_lateral_sweep(primary_of_row: impl Fn(usize) -> &'static str) -> String {
    let mut text = String::from("t,phase,primary,cmd_lat,cmd_lon,p\n");
    for k in 0..60 {
        let t = k as f64 * 0.02;
        let phase = if k < 10 { "idle" } else { "sweep" };
        let (lat, lon) = (0.01 * (3.0 * t).sin(), 0.2 * (1.3 * t).cos());
        text += &format!("{t},{phase},{},{lat},{lon},{}\n", primary_of_row(k), lat);
    }
    text
}

fn decode_columns() -> CsvColumns {
    CsvColumns {
        inputs: vec![
            ("lat".into(), "cmd_lat".into()),
            ("lon".into(), "cmd_lon".into()),
        ],
        ..columns()
    }
}

#[test]
fn the_swept_axis_comes_from_the_option_then_the_primary_column_then_activity() {
    let text = decoded_lateral_sweep(|_| "lat");
    // The primary column names `lat`, though `lon` is the most active.
    let record = parse_csv(&text, "d.csv", &decode_columns()).unwrap();
    assert_eq!(record.primary, "lat");
    assert!(!record.primary_guessed && record.notes.is_empty());
    // Without the column the most active input is taken.
    let no_column = CsvColumns {
        primary_column: None,
        ..decode_columns()
    };
    let record = parse_csv(&text, "d.csv", &no_column).unwrap();
    assert_eq!(record.primary, "lon");
    assert!(record.primary_guessed);
    // A named swept input overrides the column.
    let named = CsvColumns {
        primary: Some("lon".into()),
        ..decode_columns()
    };
    let record = parse_csv(&text, "d.csv", &named).unwrap();
    assert_eq!(
        (record.primary.as_str(), record.primary_guessed),
        ("lon", false)
    );
    // Inputs renamed: the column's `lat` still finds the input read from `cmd_lat`.
    let renamed = CsvColumns {
        inputs: vec![
            ("roll".into(), "cmd_lat".into()),
            ("pitch".into(), "cmd_lon".into()),
        ],
        ..decode_columns()
    };
    assert_eq!(parse_csv(&text, "d.csv", &renamed).unwrap().primary, "roll");
    // Idle rows may name another axis: only the kept rows must agree.
    let idle_other = decoded_lateral_sweep(|k| if k < 10 { "ped" } else { "lat" });
    assert_eq!(
        parse_csv(&idle_other, "d.csv", &decode_columns())
            .unwrap()
            .primary,
        "lat"
    );
}

#[test]
fn a_primary_column_that_changes_or_names_no_input_is_refused() {
    let text = decoded_lateral_sweep(|k| if k < 40 { "lat" } else { "lon" });
    let err = parse_csv(&text, "d.csv", &decode_columns()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "d.csv:42: column `primary` names `lon` here but `lat` on lines 12–41: one swept axis per file (rows in the fade-in, sweep and fade-out phases); split the file or name the swept input (--swept)"
    );
    // Naming the swept input sets the column aside.
    let named = CsvColumns {
        primary: Some("lat".into()),
        ..decode_columns()
    };
    assert_eq!(parse_csv(&text, "d.csv", &named).unwrap().primary, "lat");
    let text = decoded_lateral_sweep(|_| "col");
    let err = parse_csv(&text, "d.csv", &decode_columns()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "d.csv: column `primary` names `col`, which is not among the inputs (lat, lon); name the swept input (--swept)"
    );
    let unknown = CsvColumns {
        primary: Some("ped".into()),
        ..decode_columns()
    };
    let err = parse_csv(&text, "d.csv", &unknown).unwrap_err();
    assert_eq!(
        err.to_string(),
        "d.csv: swept input `ped` is not among the inputs (lat, lon)"
    );
}

#[test]
fn keeps_only_excitation_rows_when_there_is_a_phase_column() {
    let mut text = String::from("t,phase,d_lat,d_lon,p\n");
    for k in 0..30 {
        let phase = ["idle", "fade_in", "sweep", "fade_out", "done"][k / 6];
        text += &format!("{},{phase},{k},0,1\n", k as f64 * 0.1);
    }
    let record = parse_csv(&text, "d.csv", &columns()).unwrap();
    assert_eq!(record.len(), 18);
    assert_eq!(record.input("lat").unwrap()[0], 6.0);
}

#[test]
fn clear_errors() {
    let err = parse_csv("t,d_lat,p\n0,1,2\n", "a.csv", &columns()).unwrap_err();
    assert!(err.to_string().contains("no column `d_lon`"), "{err}");
    let err = parse_csv("t,d_lat,d_lon,p\n0,1,2,3\n0.1,1,x,3\n", "b.csv", &columns()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "b.csv:3: `x` in column `d_lon` is not a number (write a missing value as an empty field or nan)"
    );
    let err = parse_csv("", "e.csv", &columns()).unwrap_err();
    assert!(err.to_string().contains("empty"), "{err}");
    let err = parse_csv("1,2,3\n", "f.csv", &columns()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "f.csv:1: no column `t`: the file has no header row (its first row is all numbers); give columns by position, 1–3 (e.g. --time 1 --inputs NAME=2 --outputs NAME=3)"
    );
    let units = CsvColumns {
        units: vec![("gx".into(), Unit::DegPerS)],
        ..columns()
    };
    let err = parse_csv("t,d_lat,d_lon,p\n0,1,2,3\n", "g.csv", &units).unwrap_err();
    assert_eq!(
        err.to_string(),
        "g.csv: unit given for `gx`, which is neither an input (lat, lon) nor an output (p)"
    );
}

/// Three columns, no header, as a logger writes them: time, input, roll rate in deg/s.
fn headerless(rows: usize, time: impl Fn(usize) -> String) -> String {
    (0..rows)
        .map(|k| {
            let t = k as f64 * 0.01;
            format!(
                "{},{},{}\n",
                time(k),
                (7.0 * t).sin(),
                57.3 * (7.0 * t).cos()
            )
        })
        .collect()
}

fn positional() -> CsvColumns {
    CsvColumns {
        time: "1".into(),
        inputs: vec![("lat".into(), "2".into())],
        outputs: vec![("p".into(), "3".into())],
        ..CsvColumns::default()
    }
}

#[test]
fn columns_by_position_and_units_converted() {
    let text = headerless(100, |k| format!("{}", k as f64 * 0.01));
    let deg = CsvColumns {
        units: vec![("p".into(), Unit::DegPerS)],
        ..positional()
    };
    let record = parse_csv(&text, "x.csv", &deg).unwrap();
    assert_eq!(record.len(), 100);
    // A first row with a missing value is a data row, not a header.
    let gap_first = format!("0,,1\n{}", text.split_once('\n').unwrap().1);
    let gap_record = parse_csv(&gap_first, "x.csv", &deg).unwrap();
    assert_eq!(gap_record.len(), 99);
    assert!(
        gap_record.notes.iter().any(|n| n.contains("line(s) 1)")),
        "{:?}",
        gap_record.notes
    );
    assert!((record.sample_rate_hz - 100.0).abs() < 1e-9);
    assert!((record.output("p").unwrap()[0] - 57.3f64.to_radians()).abs() < 1e-12);
    assert_eq!(
        record.notes,
        ["x.csv: swept input taken to be `lat` (the most active)"]
    );
    // Without the unit the rate is used as written, with a note that it looks like deg/s.
    let record = parse_csv(&text, "x.csv", &positional()).unwrap();
    assert_eq!(record.output("p").unwrap()[0], 57.3);
    assert!(
        record.notes[0].contains("`p` peaks at 57.3") && record.notes[0].contains("p=deg/s"),
        "{:?}",
        record.notes
    );
    // A header name that is a number is a name, not a position.
    let text = format!("t,3,2\n{text}");
    let by_name = CsvColumns {
        time: "t".into(),
        ..positional()
    };
    let record = parse_csv(&text, "y.csv", &by_name).unwrap();
    assert_eq!(record.input("lat").unwrap()[1], 57.3 * 0.07f64.cos());
}

#[test]
fn time_in_ms_or_us_is_told_by_its_step_or_given() {
    let seconds = parse_csv(
        &headerless(100, |k| format!("{}", k as f64 * 0.01)),
        "s.csv",
        &positional(),
    )
    .unwrap();
    for (scale, unit) in [(1e3, "ms"), (1e6, "µs")] {
        let text = headerless(100, |k| format!("{}", k as f64 * 10.0 * scale / 1e3));
        let record = parse_csv(&text, "t.csv", &positional()).unwrap();
        assert!((record.sample_rate_hz - 100.0).abs() < 1e-9, "{unit}");
        assert_eq!(record.outputs, seconds.outputs);
        assert!(
            record.notes[0].contains(&format!("read in {unit}")),
            "{:?}",
            record.notes
        );
        let given = CsvColumns {
            time_unit: TimeUnit::parse(unit),
            ..positional()
        };
        let record = parse_csv(&text, "t.csv", &given).unwrap();
        assert!(!record.notes.iter().any(|n| n.contains("read in")));
    }
}

#[test]
fn a_window_keeps_its_rows() {
    let text = headerless(1000, |k| format!("{}", k as f64 * 0.01));
    let window = CsvColumns {
        window_s: Some([2.0, 5.0]),
        ..positional()
    };
    let record = parse_csv(&text, "w.csv", &window).unwrap();
    assert_eq!(record.len(), 301);
    assert_eq!(record.input("lat").unwrap()[0], 14.0f64.sin());
    let outside = CsvColumns {
        window_s: Some([20.0, 30.0]),
        ..positional()
    };
    let err = parse_csv(&text, "w.csv", &outside).unwrap_err();
    assert_eq!(
        err.to_string(),
        "w.csv: window 20–30 s keeps 0 row(s): the time column runs 0–9.99 s"
    );
}

#[test]
fn a_row_with_a_missing_value_is_a_filled_gap() {
    let mut text = String::from("t,d_lat,d_lon,p\n");
    for k in 0..60 {
        let t = k as f64 * 0.02;
        let p = match k {
            20 => "nan".to_string(),
            21 => String::new(),
            _ => format!("{}", 2.0 * t),
        };
        text += &format!("{t},{},{},{p}\n", (3.0 * t).sin(), 0.01 * t);
    }
    let record = parse_csv(&text, "m.csv", &columns()).unwrap();
    assert_eq!(record.len(), 60);
    assert!((record.output("p").unwrap()[21] - 2.0 * 0.42).abs() < 1e-9);
    let notes = record.notes.join("\n");
    assert!(
        notes.contains("2 row(s) with an empty or non-finite field left out as missing samples (line(s) 22, 23)")
            && notes.contains("1 gap(s) of up to 2 missing samples filled"),
        "{notes}"
    );
}

#[test]
fn a_reference_column_becomes_the_inputs_reference() {
    let mut text = String::from("t,lat,sweep,p\n");
    for k in 0..50 {
        let t = k as f64 * 0.02;
        text += &format!("{t},{},{},{}\n", (3.0 * t).sin(), 0.5 * (3.0 * t).sin(), t);
    }
    let with_reference = CsvColumns {
        time: "t".into(),
        inputs: vec![("lat".into(), "lat".into())],
        outputs: vec![("p".into(), "p".into())],
        references: vec![("lat".into(), "sweep".into())],
        ..CsvColumns::default()
    };
    let record = parse_csv(&text, "r.csv", &with_reference).unwrap();
    assert!((record.reference("lat").unwrap()[10] - 0.5 * 0.6f64.sin()).abs() < 1e-12);
    let wrong = CsvColumns {
        references: vec![("lon".into(), "sweep".into())],
        ..with_reference
    };
    let err = parse_csv(&text, "r.csv", &wrong).unwrap_err();
    assert_eq!(
        err.to_string(),
        "r.csv: reference `lon` is not named after an input (lat)"
    );
}

#[test]
fn a_long_gap_splits_the_file() {
    let text: String = headerless(1000, |k| format!("{}", k as f64 * 0.01))
        .lines()
        .enumerate()
        .filter(|(k, _)| !(400..450).contains(k))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let records = parse_csv_records(&text, "g.csv", &positional()).unwrap();
    assert_eq!(records.len(), 2);
    assert_eq!((records[0].len(), records[1].len()), (400, 550));
    assert_eq!(records[1].source, "g.csv (part 2 of 2, from 4.500 s)");
    let err = parse_csv(&text, "g.csv", &positional()).unwrap_err();
    assert!(err.to_string().contains("2 records"), "{err}");
}
