//! `sweephold decode`: telemetry dumps → CSV or JSON lines, streaming; flight logs (PX4 ULog,
//! ArduPilot DataFlash) go to [`crate::logs`].

use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use sweephold_protocol::{
    tick_step, DecodeStats, Decoder, Event, Frame, FrameError, Header, MeasurementFilter,
    RefusedCheck, TickStep,
};

use sysid::records::{test_line, TestProgress};

use crate::output::{refuse_inputs_as_outputs, AtomicFile, StdoutWriter};
use crate::table::{axis_name, phase_name, RowWriter};

/// Output format of `decode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Comma-separated, one header row then one row per Sample.
    Csv,
    /// One JSON object per line: `{"type":"sample",...}` per Sample and
    /// `{"type":"event",...}` / `{"type":"header",...}` in stream order.
    Jsonl,
}

/// Arguments of `sweephold decode`.
#[derive(Args, Debug)]
#[command(
    after_help = "Columns are listed in docs/formats.md. A summary goes to \
stderr: good frames, corrupt frames skipped, tick gaps, tick steps back (a Sample whose tick \
is not after the previous one's), duration, vehicle, protocol version, then one line per test \
(a dump holds one test per Header: number, axis, input, mode, duration, and how it ended: \
completed, aborted, partial when the file ends during the excitation, or not started); with \
CSV output the events are listed there too. Every Sample of every test is written. With -o FILE the file appears only when decoding \
succeeded (an earlier FILE stays as it was otherwise); a FILE that is one of the dumps is \
refused.\n\nExit status: 0 when at least one good frame was read; 1 on a missing or \
unreadable file or a folder, an output that is an input, a dump of another protocol major \
version, no valid frame at all, a standard output that cannot be written, or SIGINT/SIGTERM \
(decoding stops between chunks; FILE stays as it was); 130 on a second signal (ended at once, \
the temporary file removed).\n\nA flight log (PX4 ULog `.ulg`, ArduPilot DataFlash `.bin`; \
recognised by its first bytes, decoded alone) gives the list of its topics, one row each: \
topic (`NAME[k]` for ULog instance k > 0), messages, median rate [Hz], first and last time \
[s], field names; with --topic NAME, that topic's messages, one row each (time_s, then \
every field as the log holds it). The summary on stderr names what could not be read \
(a cut-off last message, skipped bytes), with byte offsets."
)]
pub struct DecodeArgs {
    /// Telemetry dumps (raw frame streams as the flight controller sends them), or one
    /// flight log (PX4 ULog, ArduPilot DataFlash; recognised by its first bytes).
    #[arg(required = true, value_name = "DUMP|LOG")]
    pub dumps: Vec<PathBuf>,
    /// Flight logs: write this topic's messages (`NAME`, or `NAME[k]` for ULog instance
    /// k) instead of the list of topics.
    #[arg(long, value_name = "NAME")]
    pub topic: Option<String>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// Write the rows here instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// What decoding one dump found.
#[derive(Debug, Default, Clone)]
pub struct DumpSummary {
    /// Decoder totals.
    pub stats: DecodeStats,
    /// The first Header, if any.
    pub header: Option<Header>,
    /// Samples written.
    pub samples: u64,
    /// Ticks of the first and last Sample.
    pub tick_span: Option<(u32, u32)>,
    /// Ticks elapsed from the first Sample to the last, counted over the steps that move
    /// forward (`sweephold_protocol::tick_step`): a step back or a repeat adds nothing, a
    /// wrap of the counter at 2³² counts as the step forward it is.
    pub forward_ticks: u64,
    /// Events in stream order.
    pub events: Vec<Event>,
    /// One per Header: the test it starts, its Samples and how far it got.
    pub tests: Vec<DecodedTest>,
}

/// A test of a dump as decoding sees it (the same rule as `frf`'s:
/// [`sysid::records::TestProgress`]).
#[derive(Debug, Clone)]
pub struct DecodedTest {
    /// Its Header.
    pub header: Header,
    /// Samples up to the next Header.
    pub samples: usize,
    /// The phases and Events seen.
    pub progress: TestProgress,
}

impl DumpSummary {
    /// Seconds from the first to the last Sample over the ticks that moved forward
    /// ([`Self::forward_ticks`]), when the rate is known.
    pub fn duration_s(&self) -> Option<f64> {
        self.tick_span?;
        let rate = f64::from(self.header?.rate_hz);
        (rate > 0.0).then(|| self.forward_ticks as f64 / rate)
    }
}

/// Read size of the streaming loop; memory stays flat whatever the dump size.
const CHUNK: usize = 256 * 1024;

/// Decode one dump from `input`, writing rows to `rows`. Stops with an error on a Header
/// of another protocol major version (after flushing what was written).
pub fn decode_stream<R: Read, W: Write>(
    mut input: R,
    rows: &mut RowWriter<W>,
) -> anyhow::Result<DumpSummary> {
    let mut decoder = Decoder::new();
    let mut summary = DumpSummary::default();
    let mut chunk = vec![0u8; CHUNK];
    let mut first = true;
    loop {
        // A safe point between chunks: a signal stops the decoding, and the output file
        // (an `AtomicFile`) is dropped, its temporary file removed.
        crate::interrupt::check()?;
        if !std::mem::take(&mut first) {
            crate::interrupt::pause_point("decode");
        }
        let n = match input.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e).context("read failed"),
        };
        for result in decoder.feed(&chunk[..n]) {
            match result {
                Ok(frame) => handle_frame(frame, rows, &mut summary)?,
                Err(mismatch @ FrameError::VersionMismatch { .. }) => bail!("{mismatch}"),
                Err(_) => {} // counted by the decoder; keep going
            }
        }
    }
    decoder.finish();
    summary.stats = decoder.stats();
    Ok(summary)
}

fn handle_frame<W: Write>(
    frame: Frame,
    rows: &mut RowWriter<W>,
    summary: &mut DumpSummary,
) -> anyhow::Result<()> {
    match frame {
        Frame::Sample(sample) => {
            let first = match summary.tick_span {
                Some((first, last)) => {
                    if let TickStep::Forward(step) = tick_step(last, sample.tick) {
                        summary.forward_ticks += u64::from(step);
                    }
                    first
                }
                None => sample.tick,
            };
            summary.tick_span = Some((first, sample.tick));
            let time = summary
                .header
                .filter(|h| h.rate_hz > 0)
                .map(|h| summary.forward_ticks as f64 / f64::from(h.rate_hz));
            rows.sample(&sample, time)?;
            summary.samples += 1;
            if let Some(test) = summary.tests.last_mut() {
                test.samples += 1;
                test.progress.see(sample.phase);
            }
        }
        Frame::Event(event) => {
            rows.json_line(&event_json(&event).to_string())?;
            if let Some(test) = summary.tests.last_mut() {
                test.progress.see_event(&event);
            }
            summary.events.push(event);
        }
        Frame::Header(header) => {
            rows.json_line(&header_json(&header).to_string())?;
            if summary.header.is_none() {
                summary.header = Some(header);
            }
            summary.tests.push(DecodedTest {
                header,
                samples: 0,
                progress: TestProgress::default(),
            });
        }
        Frame::MeasurementFilter(filter) => {
            rows.json_line(&measurement_filter_json(&filter).to_string())?;
        }
        // In-the-loop, parameter and servo-test traffic is not telemetry; a dump of a
        // serial link may hold it.
        Frame::SensorIn(_)
        | Frame::ActuatorOut(_)
        | Frame::Configure(_)
        | Frame::ConfigureResult(_)
        | Frame::ParamRequest(_)
        | Frame::ParamReply(_)
        | Frame::ServoTest(_)
        | Frame::ServoTestReply(_) => {}
    }
    Ok(())
}

/// A Header as a JSON object; a board application's (protocol 1.7) with its test list
/// `entry` and `engagement` number.
pub fn header_json(h: &Header) -> serde_json::Value {
    let mut json = serde_json::json!({
        "type": "header",
        "protocol": h.protocol.to_string(),
        "firmware": h.firmware.to_string(),
        "vehicle": h.vehicle.name(),
        "rate_hz": h.rate_hz,
        "test": serde_json::to_value(h.test).unwrap_or(serde_json::Value::Null),
    });
    if let (Some(selection), Some(object)) = (h.selection, json.as_object_mut()) {
        object.insert("entry".into(), selection.entry.into());
        object.insert("engagement".into(), selection.engagement.into());
    }
    json
}

/// A MeasurementFilter frame as a JSON object: the rate and each biquad section's
/// `[b0, b1, b2, a1, a2]`.
pub fn measurement_filter_json(filter: &MeasurementFilter) -> serde_json::Value {
    serde_json::json!({
        "type": "measurement_filter",
        "sample_rate_hz": filter.sample_rate_hz,
        "sections": filter.sections,
    })
}

/// An Event as a JSON object.
pub fn event_json(event: &Event) -> serde_json::Value {
    use serde_json::json;
    match *event {
        Event::PhaseChange { tick, from, to } => {
            json!({"type": "event", "event": "phase_change", "tick": tick, "from": phase_name(from), "to": phase_name(to)})
        }
        Event::HoldEngaged { tick, axis } => {
            json!({"type": "event", "event": "hold_engaged", "tick": tick, "axis": axis_name(axis)})
        }
        Event::HoldReleased { tick, axis } => {
            json!({"type": "event", "event": "hold_released", "tick": tick, "axis": axis_name(axis)})
        }
        Event::TrimCaptured {
            tick,
            sticks,
            phi,
            theta,
            psi,
        } => json!({
            "type": "event", "event": "trim_captured", "tick": tick,
            "sticks": {"lat": sticks.lat, "lon": sticks.lon, "ped": sticks.ped, "col": sticks.col},
            "phi": phi, "theta": theta, "psi": psi,
        }),
        Event::Abort { tick, reason } => {
            json!({"type": "event", "event": "abort", "tick": tick, "reason": reason.name()})
        }
        Event::ModeChange { tick, from, to } => {
            json!({"type": "event", "event": "mode_change", "tick": tick, "from": from.name(), "to": to.name()})
        }
        Event::ImuHealthChange { tick, health } => {
            json!({"type": "event", "event": "imu_health", "tick": tick, "health": health.name()})
        }
        Event::Refused {
            tick,
            request,
            check,
        } => {
            let imu = match check {
                RefusedCheck::Imu(health) => serde_json::Value::from(health.name()),
                _ => serde_json::Value::Null,
            };
            json!({"type": "event", "event": "refused", "tick": tick, "request": request.name(), "check": check.name(), "imu": imu})
        }
        Event::HostLinkIgnored { tick, frame } => {
            json!({"type": "event", "event": "host_link_ignored", "tick": tick, "frame": frame.name()})
        }
        Event::ParamStore { tick, status } => {
            json!({"type": "event", "event": "param_store", "tick": tick, "status": status.name()})
        }
    }
}

/// A one-line human description of an event.
pub fn event_text(event: &Event) -> String {
    match *event {
        Event::PhaseChange { tick, from, to } => {
            format!("tick {tick}: phase {} -> {}", phase_name(from), phase_name(to))
        }
        Event::HoldEngaged { tick, axis } => format!("tick {tick}: hold engaged on {}", axis_name(axis)),
        Event::HoldReleased { tick, axis } => format!("tick {tick}: hold released on {}", axis_name(axis)),
        Event::TrimCaptured { tick, sticks, phi, theta, .. } => format!(
            "tick {tick}: trim captured (lat {:.4}, lon {:.4}, ped {:.4}, col {:.4}; phi {:.2} deg, theta {:.2} deg)",
            sticks.lat,
            sticks.lon,
            sticks.ped,
            sticks.col,
            phi.to_degrees(),
            theta.to_degrees()
        ),
        Event::Abort { tick, reason } => format!("tick {tick}: ABORT ({})", reason.name()),
        Event::ModeChange { tick, from, to } => {
            format!("tick {tick}: mode {} -> {}", from.name(), to.name())
        }
        Event::ImuHealthChange { tick, health } => format!("tick {tick}: IMU {}", health.name()),
        Event::Refused {
            tick,
            request,
            check,
        } => match check {
            RefusedCheck::Imu(health) => {
                format!("tick {tick}: {} refused: IMU {}", request.name(), health.name())
            }
            _ => format!("tick {tick}: {} refused: {}", request.name(), check.name()),
        },
        Event::HostLinkIgnored { tick, frame } => {
            format!("tick {tick}: host {} ignored while armed", frame.name())
        }
        Event::ParamStore { tick, status } => {
            format!("tick {tick}: parameter store {}", status.name())
        }
    }
}

/// Where the rows go: standard output, or a file that appears only when complete.
enum Sink {
    Stdout(StdoutWriter),
    File(AtomicFile),
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Sink::Stdout(out) => out.write(buf),
            Sink::File(file) => file.write(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self {
            Sink::Stdout(out) => out.flush(),
            Sink::File(file) => file.flush(),
        }
    }
}

fn open(path: &Path) -> anyhow::Result<File> {
    if path.is_dir() {
        bail!("cannot open {}: it is a folder, not a dump", path.display());
    }
    File::open(path).with_context(|| format!("cannot open {}", path.display()))
}

/// Run `sweephold decode`.
pub fn run(args: &DecodeArgs) -> anyhow::Result<()> {
    if let Some(log) = args
        .dumps
        .iter()
        .find(|p| crate::logs::log_format(p).is_some())
    {
        if args.dumps.len() > 1 {
            bail!(
                "{}: a flight log is decoded alone, not with other files",
                log.display()
            );
        }
        if let Some(path) = &args.output {
            refuse_inputs_as_outputs(&[log.as_path()], &[("--output", path)])?;
        }
        let jsonl = args.format == Format::Jsonl;
        return crate::logs::decode(
            log,
            args.topic.as_deref(),
            jsonl,
            args.output.as_deref(),
            args.quiet,
        );
    }
    if args.topic.is_some() {
        bail!("--topic reads flight logs (PX4 ULog, ArduPilot DataFlash), not telemetry dumps");
    }
    // Open every input before writing anything, so a typo loses no output.
    let inputs = args
        .dumps
        .iter()
        .map(|p| open(p).map(|f| (p, f)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let input_paths: Vec<&Path> = args.dumps.iter().map(PathBuf::as_path).collect();
    if let Some(path) = &args.output {
        refuse_inputs_as_outputs(&input_paths, &[("--output", path)])?;
    }
    // The output file appears only when decoding succeeded (see `crate::output`).
    let sink = match &args.output {
        Some(path) => Sink::File(AtomicFile::create(path)?),
        None => Sink::Stdout(StdoutWriter::lock()),
    };
    let sink = BufWriter::with_capacity(CHUNK, sink);
    let mut rows = match args.format {
        Format::Csv => RowWriter::csv(sink),
        Format::Jsonl => RowWriter::jsonl(sink),
    };
    rows.header()?;
    let mut empty = Vec::new();
    let mut any_good = false;
    for (path, file) in inputs {
        let summary =
            decode_stream(file, &mut rows).with_context(|| format!("{}", path.display()))?;
        let st = summary.stats;
        if st.good_frames == 0 {
            empty.push(format!(
                "{} ({} bytes, {} corrupt frames)",
                path.display(),
                st.bytes,
                st.corrupt_frames
            ));
            continue;
        }
        any_good = true;
        if !args.quiet {
            print_summary(path, &summary, args.format == Format::Csv);
        }
    }
    if !any_good {
        bail!("no valid frame in {}", empty.join(", "));
    }
    let sink = rows
        .into_inner()
        .and_then(|buffered| buffered.into_inner().map_err(|e| e.into_error()))
        .context("cannot write output")?;
    if let Sink::File(file) = sink {
        file.commit()?;
    }
    if !args.quiet {
        for dump in &empty {
            crate::note!("warning: no valid frame in {dump}");
        }
    }
    Ok(())
}

fn print_summary(path: &Path, s: &DumpSummary, list_events: bool) {
    let st = &s.stats;
    let (vehicle, protocol, firmware, rate) = match &s.header {
        Some(h) => (
            h.vehicle.name().to_string(),
            h.protocol.to_string(),
            h.firmware.to_string(),
            format!("{} Hz", h.rate_hz),
        ),
        None => (
            "unknown (no header)".into(),
            "unknown".into(),
            "unknown".into(),
            "unknown".into(),
        ),
    };
    let duration = s
        .duration_s()
        .map_or("unknown".to_string(), |d| format!("{d:.3} s"));
    crate::note!("{}:", path.display());
    crate::note!(
        "  {} bytes, {} good frames ({} samples, {} events), {} corrupt frames skipped, {} tick gaps, {} tick steps back",
        st.bytes,
        st.good_frames,
        s.samples,
        s.events.len(),
        st.corrupt_frames,
        st.tick_gaps,
        st.tick_steps_back
    );
    crate::note!(
        "  duration {duration}, vehicle {vehicle}, rate {rate}, protocol {protocol}, firmware {firmware}"
    );
    for (index, test) in s.tests.iter().enumerate() {
        let end = test.progress.end();
        crate::note!(
            "  {}",
            test_line(index + 1, &test.header, test.samples, end)
        );
    }
    if list_events {
        for event in &s.events {
            crate::note!("  {}", event_text(event));
        }
    }
}
