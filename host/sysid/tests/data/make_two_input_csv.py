#!/usr/bin/env python3
"""Write two_input.csv: two correlated inputs driving one output through known transfer
functions, simulated by scipy (an outside simulator for the MISO frequency responses of
`sweephold frf`; the tests in host/sysid/tests/two_input_csv.rs and
host/cli/tests/cli/frf_inputs.rs read the CSV and compare with the exact responses).

Run: python3 make_two_input_csv.py  (needs numpy and scipy; the CSV is committed, so the
tests do not need Python). Written with numpy 2.4.6 and scipy 1.17.1 (Python 3.11); same versions,
same bytes.

Sample rate 100 Hz, 200 s (20 000 rows), random seed 19 (numpy.random.default_rng).

Inputs (stick fractions), each a sum of Gaussian white noise sequences through
4th-order Butterworth low-pass filters (scipy.signal.butter + sosfilt):
    lat = a + 0.8·c        a: cut-off 4 Hz
    lon = b − 0.7·c        b: cut-off 4 Hz
with c, common to both, cut off at 1.5 Hz: the inputs are correlated below 1.5 Hz
(9.4 rad/s; coherence lat–lon about 0.25–0.3 there, near 0 above). a, b and c have unit
variance before the sum; lat and lon are then scaled to RMS 0.05 and 0.04.

Output: roll rate p = H_lat(s)·lat + H_lon(s)·lon + n, with
    H_lat(s) = (12 s + 60) / (s² + 6 s + 60) · e^(−0.04 s)      (ωn 7.75 rad/s, ζ 0.39)
    H_lon(s) = −(2 s + 2) / (s + 4)
each simulated by scipy.signal.lsim (linear interpolation between samples) from its
input; the 40 ms delay is a shift of the lateral input by 4 samples (zeros before).
n: Gaussian white noise through a 4th-order Butterworth low-pass at 5 Hz, scaled to
2 % of the RMS of the noise-free p.

Columns: t [s], lat, lon, p [rad/s]; 7 significant digits.
"""

import os

import numpy as np
from scipy import signal

RATE_HZ = 100.0
DURATION_S = 200.0
SEED = 19
DELAY_SAMPLES = 4  # 40 ms on H_lat

H_LAT = ([12.0, 60.0], [1.0, 6.0, 60.0])
H_LON = ([-2.0, -2.0], [1.0, 4.0])


def lowpass_noise(rng, n, cutoff_hz):
    """Unit-variance Gaussian noise low-passed by a 4th-order Butterworth filter."""
    sos = signal.butter(4, cutoff_hz, fs=RATE_HZ, output="sos")
    x = signal.sosfilt(sos, rng.standard_normal(n))
    return x / np.std(x)


def main():
    n = int(RATE_HZ * DURATION_S)
    t = np.arange(n) / RATE_HZ
    rng = np.random.default_rng(SEED)
    a = lowpass_noise(rng, n, 4.0)
    b = lowpass_noise(rng, n, 4.0)
    c = lowpass_noise(rng, n, 1.5)
    lat = a + 0.8 * c
    lon = b - 0.7 * c
    lat *= 0.05 / np.std(lat)
    lon *= 0.04 / np.std(lon)

    delayed_lat = np.concatenate([np.zeros(DELAY_SAMPLES), lat[:-DELAY_SAMPLES]])
    _, p_lat, _ = signal.lsim(signal.lti(*H_LAT), delayed_lat, t)
    _, p_lon, _ = signal.lsim(signal.lti(*H_LON), lon, t)
    p = p_lat + p_lon
    noise = lowpass_noise(rng, n, 5.0)
    p = p + 0.02 * np.std(p) * noise

    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "two_input.csv")
    with open(path, "w", newline="\n") as f:
        f.write("t,lat,lon,p\n")
        for row in zip(t, lat, lon, p):
            f.write("%.2f,%.7g,%.7g,%.7g\n" % row)


if __name__ == "__main__":
    main()
