#!/usr/bin/env python3
"""Write x8roll_scipy_h1.json: an independent H1 estimate of the x8 roll response (`rout` →
roll rate) from x8roll.csv, by scipy's Welch cross- and auto-spectra, for the tests that
read x8roll.csv as it is with `sweephold frf` (host/sysid/tests/x8roll_csv.rs,
host/cli/tests/cli/frf_csv.rs).

Run: python3 x8roll_scipy_h1.py  (needs numpy and scipy; the JSON is committed, so the
tests do not need Python). Written with numpy 2.4.6 and scipy 1.17.1 (Python 3.11).

x8roll.csv: three columns, no header: time [s] (100 Hz), rout (the roll rate
controller's output, unitless), gx (roll rate, deg/s). gx is converted to rad/s here, as
its source's own example does.

Estimate: scipy.signal.csd / welch with a Hann window of 2100 samples (21 s: two periods of
0.6 rad/s, the lowest frequency the tests analyse, the shortest window that resolves it by
the rule ω ≥ 4π/T; resolution 0.299 rad/s), 75 % overlap, linear detrend per segment, over
the whole file; H1 = P_xy / P_xx (x = rout, y = gx), coherence |P_xy|² / (P_xx·P_yy).
Kept: the bins from 0.3 to 62 rad/s (the band the tests analyse, 0.6–60 rad/s, with a bin
either side).

One segment length is one choice among several, and the estimate moves with it: the
median |difference| from `sweephold frf` (its 200 points over 0.6–60 rad/s, within its
valid range and where this estimate's coherence is at least 0.6) was, for segments of
1024 / 1800 / 2100 / 3000 / 4096 / 8192 samples, 0.34 / 0.29 / 0.28 / 0.25 / 0.39 / 0.52 dB
and 1.5 / 1.8 / 1.8 / 1.7 / 1.5 / 2.8°. A single Welch length trades resolution at the
bottom of the band against averages at the top; sweephold's composite blends five.

JSON: omega [rad/s], mag_db (20·log10|H1|, rad/s per unit of rout), phase_deg (wrapped to
±180°), coherence; 6 significant digits.
"""
import json
import os

import numpy as np
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))
NPERSEG = 2100
BAND = (0.3, 62.0)


def main():
    data = np.loadtxt(os.path.join(HERE, "x8roll.csv"), delimiter=",")
    t, rout, gx_deg = data[:, 0], data[:, 1], data[:, 2]
    fs = 1.0 / np.median(np.diff(t))
    gx = np.deg2rad(gx_deg)
    kw = dict(fs=fs, window="hann", nperseg=NPERSEG, noverlap=3 * NPERSEG // 4, detrend="linear")
    f, pxy = signal.csd(rout, gx, **kw)
    _, pxx = signal.welch(rout, **kw)
    _, pyy = signal.welch(gx, **kw)
    h = pxy / pxx
    coherence = np.abs(pxy) ** 2 / (pxx * pyy)
    omega = 2 * np.pi * f
    keep = (omega >= BAND[0]) & (omega <= BAND[1])
    g = lambda v: [float(f"{x:.6g}") for x in v]
    out = {
        "source": "x8roll.csv, scipy.signal csd/welch H1, Hann 2100, 75 % overlap, linear detrend; gx in rad/s",
        "sample_rate_hz": float(f"{fs:.6g}"),
        "omega": g(omega[keep]),
        "mag_db": g(20 * np.log10(np.abs(h[keep]))),
        "phase_deg": g(np.degrees(np.angle(h[keep]))),
        "coherence": g(coherence[keep]),
    }
    with open(os.path.join(HERE, "x8roll_scipy_h1.json"), "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
