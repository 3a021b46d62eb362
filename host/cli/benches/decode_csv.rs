//! `sweephold decode --format csv` throughput and peak memory.
//!
//! `cargo bench -p sweephold --bench decode_csv`. Targets: ≥ 50 MB/s of dump on one core;
//! peak resident memory < 50 MB while decoding a 200 MB dump.
//!
//! Throughput: median of several in-process passes of the same code the binary runs
//! (`decode::decode_stream` into a CSV `RowWriter`) over a ~64 MB dump, output discarded.
//! Memory: the real binary decodes a 200 MB dump to /dev/null while its peak resident set
//! (VmHWM in /proc) is sampled.

use std::io::{self, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use sweephold::decode::decode_stream;
use sweephold::table::RowWriter;
use sweephold_protocol::{codec, synthetic, Frame};

fn dump(bytes: usize) -> Vec<u8> {
    let mut stream = Vec::with_capacity(bytes + 1024);
    stream.extend_from_slice(&codec::encode_to_vec(&Frame::Header(synthetic::header())).unwrap());
    let mut tick = 0;
    while stream.len() < bytes {
        stream.extend_from_slice(
            &codec::encode_to_vec(&Frame::Sample(synthetic::sample(tick))).unwrap(),
        );
        tick += 1;
    }
    stream
}

fn throughput() {
    let stream = dump(64 << 20);
    let mut rates = Vec::new();
    for _ in 0..7 {
        let start = Instant::now();
        let mut rows = RowWriter::csv(io::BufWriter::with_capacity(256 * 1024, io::sink()));
        rows.header().unwrap();
        let summary = decode_stream(stream.as_slice(), &mut rows).unwrap();
        rows.into_inner().unwrap().flush().unwrap();
        let secs = start.elapsed().as_secs_f64();
        assert!(summary.samples > 400_000);
        rates.push(stream.len() as f64 / secs / 1e6);
    }
    rates.sort_by(f64::total_cmp);
    let median = rates[rates.len() / 2];
    println!(
        "decode --format csv: {:.1} MB dump, median {:.0} MB/s, {:.1}x the 50 MB/s target",
        stream.len() as f64 / 1e6,
        median,
        median / 50.0
    );
}

fn peak_memory() {
    let path = std::env::temp_dir().join(format!("sweephold-bench-{}.bin", std::process::id()));
    std::fs::write(&path, dump(200 << 20)).unwrap();
    let size = std::fs::metadata(&path).unwrap().len();
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .args(["decode", "--quiet", "--format", "csv", "-o", "/dev/null"])
        .arg(&path)
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let status_file = format!("/proc/{}/status", child.id());
    let mut peak_kb = 0u64;
    let start = Instant::now();
    let status = loop {
        if let Ok(status) = std::fs::read_to_string(&status_file) {
            if let Some(kb) = status
                .lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse::<u64>().ok())
            {
                peak_kb = peak_kb.max(kb);
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let secs = start.elapsed().as_secs_f64();
    std::fs::remove_file(&path).ok();
    assert!(status.success());
    println!(
        "decode --format csv of a {:.0} MB dump (binary, to /dev/null): peak RSS {:.1} MB (target < 50 MB), {:.2} s, {:.0} MB/s",
        size as f64 / 1e6,
        peak_kb as f64 / 1024.0,
        secs,
        size as f64 / secs / 1e6
    );
}

fn main() {
    throughput();
    peak_memory();
}
