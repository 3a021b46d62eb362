#!/usr/bin/env python3
"""Simulate the published R-50 hover model (r50_model.py) under frequency sweeps, as CSV.

    python3 simulate.py --out DIR [--noise-seed N]      # N omitted: noise-free outputs

Writes DIR/lat.csv, lon.csv, ped.csv, col.csv: one record per control, like a campaign. The
model is unstable in hover (its hover oscillation), so it flies under a fixed attitude,
yaw-rate and heave hold (GAINS below, closed-loop poles all left of -0.3 /s). In each record
that control carries an exponential sweep, 0.3 to 40 rad/s over 300 s (after 3 s of trim),
added to the hold's command; the other controls carry the hold's command plus small
band-limited random noise, its RMS half the sweep amplitude (a fixed seed, also in noise-free data: without it the off-axis
controls would be the hold's exact function of the response, and the multi-input
conditioning of `frf` would have nothing independent to work with). The recorded controls
are what the model received.

Integration: zero-order hold at 1 kHz (the controls change every 1 ms: 0.5 ms of lag, 1.1
degrees of phase at 40 rad/s), recorded every 5th step (200 Hz). Columns: time_s, lat, lon,
ped, col, u, v, w, p, q, r, phi, theta (ft/s, rad/s, rad, as the paper).

With --noise-seed N every output gets white measurement noise of NOISE_FRACTION times its
RMS over the record (seeded with N); without it the outputs are exact.
The output is deterministic: the same arguments give the same bytes.
"""
import argparse
import os

import numpy as np
from scipy.linalg import expm
from scipy.signal import butter, lfilter

import r50_model as model

INTERNAL_HZ = 1000
RECORD_EVERY = 5
TRIM_S = 3.0
SWEEP_S = 300.0
W_MIN, W_MAX = 0.3, 40.0
AMPLITUDE = {"lat": 0.05, "lon": 0.05, "ped": 0.05, "col": 0.05}
OFF_AXIS_FRACTION = 0.5  # RMS of the off-axis noise over the sweep amplitude
OFF_AXIS_SEED = 4242
NOISE_FRACTION = 0.05
# Hold gains (control = sum of gain * state), found once by minimising the largest real
# part of the closed loop's poles, rounded.
GAINS = {
    "lat": {"phi": -0.6, "p": 0.2, "v": -0.02},
    "lon": {"theta": 1.2, "q": 0.4, "u": -0.008},
    "ped": {"r": -0.1},
    "col": {"w": 0.02},
}


def hold_matrix():
    K = np.zeros((4, len(model.STATES)))
    for c, row in GAINS.items():
        for s, g in row.items():
            K[model.CONTROLS.index(c), model.STATES.index(s)] = g
    return K


def sweep(t):
    """Exponential sweep from W_MIN to W_MAX over SWEEP_S, zero during the trim."""
    tau = np.clip(t - TRIM_S, 0.0, None)
    k = np.log(W_MAX / W_MIN) / SWEEP_S
    phase = W_MIN * (np.exp(k * tau) - 1.0) / k
    out = np.sin(phase)
    out[(t < TRIM_S) | (t > TRIM_S + SWEEP_S)] = 0.0
    # fade in and out over 1 s so that the sweep starts and ends smoothly
    fade = np.clip(np.minimum(tau, TRIM_S + SWEEP_S - t), 0.0, 1.0)
    return out * fade


def simulate(swept, A, B, K, noise_seed):
    dt = 1.0 / INTERNAL_HZ
    n = int(round((2 * TRIM_S + SWEEP_S) * INTERNAL_HZ)) + 1
    t = np.arange(n) * dt
    big = np.zeros((17, 17))
    big[:13, :13] = A * dt
    big[:13, 13:] = B * dt
    e = expm(big)
    Ad, Bd = e[:13, :13], e[:13, 13:]
    rng = np.random.default_rng(OFF_AXIS_SEED + model.CONTROLS.index(swept))
    b, a = butter(2, 8.0 / (INTERNAL_HZ / 2))  # noise band-limited to 8 Hz
    excitation = np.zeros((n, 4))
    for j, c in enumerate(model.CONTROLS):
        if c == swept:
            excitation[:, j] = AMPLITUDE[c] * sweep(t)
        else:
            noise = lfilter(b, a, rng.standard_normal(n))
            excitation[:, j] = OFF_AXIS_FRACTION * AMPLITUDE[c] * noise / np.std(noise)
    x = np.zeros(13)
    xs = np.zeros((n, 13))
    us = np.zeros((n, 4))
    for k in range(n):
        u = K @ x + excitation[k]
        xs[k], us[k] = x, u
        x = Ad @ x + Bd @ u
    keep = slice(0, n, RECORD_EVERY)
    t, xs, us = t[keep], xs[keep], us[keep]
    ys = xs[:, [model.STATES.index(s) for s in model.MEASURED]]
    if noise_seed is not None:
        noise_rng = np.random.default_rng([noise_seed, model.CONTROLS.index(swept)])
        rms = np.sqrt(np.mean(ys**2, axis=0))
        ys = ys + NOISE_FRACTION * rms * noise_rng.standard_normal(ys.shape)
    return t, us, ys


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--noise-seed", type=int, default=None)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    A, B = model.matrices(model.PUBLISHED)
    K = hold_matrix()
    assert max(np.linalg.eigvals(A + B @ K).real) < -0.3
    header = ",".join(["time_s", *model.CONTROLS, *model.MEASURED])
    for c in model.CONTROLS:
        t, us, ys = simulate(c, A, B, K, args.noise_seed)
        rows = np.column_stack([t, us, ys])
        path = os.path.join(args.out, f"{c}.csv")
        with open(path + ".tmp", "w") as f:
            f.write(header + "\n")
            for row in rows:
                f.write(",".join(f"{v:.9g}" for v in row) + "\n")
        os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
