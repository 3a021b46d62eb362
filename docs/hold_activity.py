#!/usr/bin/env python3
"""Where the conditional attitude hold's activity sits in cah records: how much of each
control it moves, and in which band the swept control and an off-axis control are coherent.

    cargo build --release -p sweephold
    sweephold fly --mode cah --seed N --out DIR [--amplitude adaptive]   (one folder per seed)
    python3 docs/hold_activity.py [--primary lat] [--other lon] DIR [DIR ...]

Reads every `<primary>-<n>.bin` in each folder (decoded with `sweephold decode`; the
excitation phases fade_in, sweep and fade_out only) and prints one row per record and the
median and range over all of them:

- hold share: the ticks on which the primary's and the other axis' hold is not released;
- hold/sweep: RMS of the primary's hold output against the RMS of its sweep, where the hold
  output is the command less the pilot's stick, the sweep and the noise (so it includes the
  controller while engaged and its fading output after a release);
- hold/noise: the same for the other axis against its off-axis noise;
- fade share: the share of the primary's hold-output energy on released ticks (the fade);
- coherence below and above 1 rad/s between the two commands (pilot's stick removed):
  Welch, Hann windows with half overlap, 30 s windows over 0.3-1 rad/s and 10 s windows over
  1-31.4 rad/s, raw (not bias-corrected) magnitude-squared coherence averaged over the DFT
  bins of the band. `sweephold fly` reports the bias-corrected, composite figure over the
  whole band in summary.json; this splits it by band.

Standard library only: the DFT is evaluated at the band's bins directly.
"""
import argparse
import cmath
import csv
import functools
import glob
import math
import os
import statistics
import subprocess
import sys
import tempfile

BINARY = os.path.join(os.path.dirname(__file__), "..", "target", "release", "sweephold")
RATE_HZ = 200.0
EXCITATION = ("fade_in", "sweep", "fade_out")
BANDS = ((0.3, 1.0, 30.0), (1.0, 31.4, 10.0))  # (lowest, highest rad/s, window s)


def decode(dump):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "record.csv")
        done = subprocess.run(
            [BINARY, "decode", "-q", "--format", "csv", dump, "-o", out],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ["decode failed"])[-1].removeprefix("error: ")
            raise SystemExit(f"error: {dump}: {last}")
        with open(out) as f:
            rows = [row for row in csv.DictReader(f) if row["phase"] in EXCITATION]
    if not rows:
        raise SystemExit(f"error: {dump}: no excitation phase")
    return rows


def centred(values):
    mean = sum(values) / len(values)
    return [v - mean for v in values]


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


@functools.lru_cache(maxsize=None)
def window_and_twiddles(n, bins):
    """The Hann window of n samples and the DFT factors of the given bins (the same for
    every record: computed once)."""
    hann = [0.5 - 0.5 * math.cos(2 * math.pi * i / (n - 1)) for i in range(n)]
    twiddles = {k: [cmath.exp(-2j * math.pi * k * i / n) for i in range(n)] for k in bins}
    return hann, twiddles


def band_coherence(a, b, lowest, highest, window_s):
    """Welch magnitude-squared coherence of a and b, averaged over the bins in the band."""
    n = int(window_s * RATE_HZ)
    step = n // 2
    bins = tuple(k for k in range(1, n // 2) if lowest <= 2 * math.pi * k / window_s < highest)
    hann, twiddles = window_and_twiddles(n, bins)
    saa = {k: 0.0 for k in bins}
    sbb = {k: 0.0 for k in bins}
    sab = {k: 0j for k in bins}
    for start in range(0, len(a) - n + 1, step):
        wa = [w * x for w, x in zip(hann, a[start:start + n])]
        wb = [w * x for w, x in zip(hann, b[start:start + n])]
        for k in bins:
            tw = twiddles[k]
            fa = sum(x * t for x, t in zip(wa, tw))
            fb = sum(x * t for x, t in zip(wb, tw))
            saa[k] += abs(fa) ** 2
            sbb[k] += abs(fb) ** 2
            sab[k] += fa * fb.conjugate()
    values = [abs(sab[k]) ** 2 / (saa[k] * sbb[k]) for k in bins if saa[k] > 0 and sbb[k] > 0]
    return sum(values) / len(values) if values else float("nan")


def record_figures(dump, primary, other):
    rows = decode(dump)
    columns = {}

    def column(name):
        if name not in columns:
            columns[name] = [float(row[name]) for row in rows]
        return columns[name]

    def command(axis):
        return [c - p for c, p in zip(column(f"cmd_{axis}"), column(f"pilot_{axis}"))]

    def hold_output(axis):
        parts = zip(command(axis), column(f"sweep_{axis}"), column(f"noise_{axis}"))
        return centred([c - s - n for c, s, n in parts])

    held = lambda axis: [row[f"hold_{axis}"] != "released" for row in rows]
    hold_primary = hold_output(primary)
    released_energy = sum(h * h for h, on in zip(hold_primary, held(primary)) if not on)
    a, b = centred(command(primary)), centred(command(other))
    return {
        "hold share": sum(held(primary)) / len(rows),
        "other hold share": sum(held(other)) / len(rows),
        "hold/sweep": rms(hold_primary) / rms(column(f"sweep_{primary}")),
        "other hold/noise": rms(hold_output(other)) / rms(column(f"noise_{other}")),
        "fade share": released_energy / sum(h * h for h in hold_primary),
        "coherence < 1": band_coherence(a, b, *BANDS[0]),
        "coherence > 1": band_coherence(a, b, *BANDS[1]),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", metavar="DIR", help="`sweephold fly` output folders")
    parser.add_argument("--primary", default="lat", choices=["lat", "lon", "ped", "col"])
    parser.add_argument("--other", default="lon", choices=["lat", "lon", "ped", "col"])
    args = parser.parse_args()
    if args.primary == args.other:
        raise SystemExit("error: --primary and --other must differ")
    if not os.path.isfile(BINARY):
        raise SystemExit(f"error: {BINARY} missing: run `cargo build --release -p sweephold`")
    table = []
    for folder in args.folders:
        dumps = sorted(glob.glob(os.path.join(folder, f"{args.primary}-*.bin")))
        if not dumps:
            raise SystemExit(f"error: {folder}: no {args.primary}-<n>.bin")
        for dump in dumps:
            figures = record_figures(dump, args.primary, args.other)
            table.append(figures)
            print(dump + ": " + ", ".join(f"{k} {v:.2f}" for k, v in figures.items()))
            sys.stdout.flush()
    print(f"over {len(table)} records (median, range):")
    for name in table[0]:
        values = [row[name] for row in table]
        print(f"  {name}: {statistics.median(values):.2f} ({min(values):.2f}-{max(values):.2f})")


if __name__ == "__main__":
    main()
