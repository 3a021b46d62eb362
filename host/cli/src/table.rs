//! The flat row a [`Sample`] becomes in CSV and JSON-lines output: one column list, two
//! writers, so the two formats cannot drift apart.

use std::io::{self, Write};

use sweephold_protocol::{Axis, HoldState, Phase, Sample};

/// Column names, in order. Units: rad, rad/s, m/s, m/s², s; commands in fractions of
/// full stick travel.
pub const COLUMNS: [&str; 35] = [
    "tick",
    "time_s",
    "phase",
    "primary",
    "sweep_omega",
    "hold_lat",
    "hold_lon",
    "hold_ped",
    "cmd_lat",
    "cmd_lon",
    "cmd_ped",
    "cmd_col",
    "sweep_lat",
    "sweep_lon",
    "sweep_ped",
    "sweep_col",
    "noise_lat",
    "noise_lon",
    "noise_ped",
    "noise_col",
    "pilot_lat",
    "pilot_lon",
    "pilot_ped",
    "pilot_col",
    "p",
    "q",
    "r",
    "phi",
    "theta",
    "psi",
    "u",
    "v",
    "w",
    "ax",
    "ay",
];

/// The last column, kept apart so `COLUMNS` reads as the table above.
pub const LAST_COLUMN: &str = "az";

/// One cell of a row.
#[derive(Clone, Copy, Debug)]
pub enum Cell {
    /// An integer.
    Int(u32),
    /// A measured or commanded value.
    Real(f32),
    /// Seconds since the first Sample of the dump; absent before a Header gave the rate.
    Time(Option<f64>),
    /// A name (phase, axis, hold state).
    Name(&'static str),
}

/// Snake-case name of a sequencer phase.
pub fn phase_name(phase: Phase) -> &'static str {
    match phase {
        Phase::Idle => "idle",
        Phase::Armed => "armed",
        Phase::TrimCapture => "trim_capture",
        Phase::FadeIn => "fade_in",
        Phase::Sweep => "sweep",
        Phase::FadeOut => "fade_out",
        Phase::Done => "done",
        Phase::Aborted => "aborted",
    }
}

/// Snake-case name of a hold state.
pub fn hold_name(hold: HoldState) -> &'static str {
    match hold {
        HoldState::Released => "released",
        HoldState::Engaged => "engaged",
        HoldState::Frozen => "frozen",
    }
}

/// Name of an axis.
pub fn axis_name(axis: Axis) -> &'static str {
    axis.name()
}

/// The cells of one Sample, in [`COLUMNS`] order followed by [`LAST_COLUMN`].
pub fn cells(sample: &Sample, time_s: Option<f64>) -> [Cell; 36] {
    use Cell::{Int, Name, Real};
    let s = sample;
    let m = &s.meas;
    [
        Int(s.tick),
        Cell::Time(time_s),
        Name(phase_name(s.phase)),
        Name(axis_name(s.primary)),
        Real(s.sweep_omega),
        Name(hold_name(s.hold[0])),
        Name(hold_name(s.hold[1])),
        Name(hold_name(s.hold[2])),
        Real(s.command.lat),
        Real(s.command.lon),
        Real(s.command.ped),
        Real(s.command.col),
        Real(s.sweep.lat),
        Real(s.sweep.lon),
        Real(s.sweep.ped),
        Real(s.sweep.col),
        Real(s.noise.lat),
        Real(s.noise.lon),
        Real(s.noise.ped),
        Real(s.noise.col),
        Real(s.pilot.lat),
        Real(s.pilot.lon),
        Real(s.pilot.ped),
        Real(s.pilot.col),
        Real(m.p),
        Real(m.q),
        Real(m.r),
        Real(m.phi),
        Real(m.theta),
        Real(m.psi),
        Real(m.u),
        Real(m.v),
        Real(m.w),
        Real(m.ax),
        Real(m.ay),
        Real(m.az),
    ]
}

/// All column names, [`COLUMNS`] then [`LAST_COLUMN`].
pub fn column_names() -> impl Iterator<Item = &'static str> {
    COLUMNS.iter().copied().chain(std::iter::once(LAST_COLUMN))
}

/// Write a cell's value as text: shortest round-trip decimals (ryu), `nan`/`inf` spelled
/// out for CSV, `null` for JSON where a value is not finite or absent.
fn write_cell(out: &mut Vec<u8>, cell: Cell, json: bool, floats: &mut ryu::Buffer) {
    match cell {
        Cell::Int(i) => {
            let mut digits = itoa_u32(i);
            out.extend_from_slice(digits.as_bytes_mut());
        }
        Cell::Real(x) if x.is_finite() => out.extend_from_slice(floats.format_finite(x).as_bytes()),
        Cell::Real(x) => out.extend_from_slice(match (json, x.is_nan(), x > 0.0) {
            (true, _, _) => b"null",
            (false, true, _) => b"nan",
            (false, false, true) => b"inf",
            (false, false, false) => b"-inf",
        }),
        Cell::Time(Some(t)) => out.extend_from_slice(floats.format(t).as_bytes()),
        Cell::Time(None) => {
            if json {
                out.extend_from_slice(b"null")
            }
        }
        Cell::Name(name) => {
            if json {
                out.push(b'"');
                out.extend_from_slice(name.as_bytes());
                out.push(b'"');
            } else {
                out.extend_from_slice(name.as_bytes());
            }
        }
    }
}

/// Decimal digits of a u32 without allocation.
struct Digits {
    buf: [u8; 10],
    start: usize,
}

impl Digits {
    fn as_bytes_mut(&mut self) -> &[u8] {
        &self.buf[self.start..]
    }
}

fn itoa_u32(mut value: u32) -> Digits {
    let mut buf = [0u8; 10];
    let mut start = buf.len();
    loop {
        start -= 1;
        buf[start] = b'0' + (value % 10) as u8;
        value /= 10;
        if value == 0 {
            break;
        }
    }
    Digits { buf, start }
}

/// Writes Sample rows as CSV or JSON lines, reusing one line buffer.
pub struct RowWriter<W: Write> {
    out: W,
    json: bool,
    line: Vec<u8>,
    floats: ryu::Buffer,
}

impl<W: Write> RowWriter<W> {
    /// A CSV writer (header row written by [`RowWriter::header`]).
    pub fn csv(out: W) -> Self {
        Self {
            out,
            json: false,
            line: Vec::with_capacity(512),
            floats: ryu::Buffer::new(),
        }
    }

    /// A JSON-lines writer: one object per Sample.
    pub fn jsonl(out: W) -> Self {
        Self {
            out,
            json: true,
            line: Vec::with_capacity(1024),
            floats: ryu::Buffer::new(),
        }
    }

    /// Write the CSV header row (nothing for JSON lines).
    pub fn header(&mut self) -> io::Result<()> {
        if self.json {
            return Ok(());
        }
        let names: Vec<&str> = column_names().collect();
        writeln!(self.out, "{}", names.join(","))
    }

    /// Write one Sample.
    pub fn sample(&mut self, sample: &Sample, time_s: Option<f64>) -> io::Result<()> {
        self.line.clear();
        let row = cells(sample, time_s);
        if self.json {
            self.line.extend_from_slice(b"{\"type\":\"sample\"");
            for (name, cell) in column_names().zip(row) {
                self.line.extend_from_slice(b",\"");
                self.line.extend_from_slice(name.as_bytes());
                self.line.extend_from_slice(b"\":");
                write_cell(&mut self.line, cell, true, &mut self.floats);
            }
            self.line.push(b'}');
        } else {
            for (i, cell) in row.into_iter().enumerate() {
                if i > 0 {
                    self.line.push(b',');
                }
                write_cell(&mut self.line, cell, false, &mut self.floats);
            }
        }
        self.line.push(b'\n');
        self.out.write_all(&self.line)
    }

    /// Write a raw JSON line (events, in JSON-lines output only).
    pub fn json_line(&mut self, line: &str) -> io::Result<()> {
        if self.json {
            self.out.write_all(line.as_bytes())?;
            self.out.write_all(b"\n")?;
        }
        Ok(())
    }

    /// Flush and return the inner writer.
    pub fn into_inner(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_print_in_decimal() {
        for v in [0u32, 7, 10, 99, 1_000_000, u32::MAX] {
            assert_eq!(
                std::str::from_utf8(itoa_u32(v).as_bytes_mut()).unwrap(),
                v.to_string()
            );
        }
    }

    #[test]
    fn every_column_has_a_cell() {
        assert_eq!(column_names().count(), 36);
        let names: std::collections::HashSet<_> = column_names().collect();
        assert_eq!(names.len(), 36, "column names are unique");
    }
}
