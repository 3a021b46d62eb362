"""The published hover model the harness fits: Yamaha R-50, 13 states, 32 free parameters.

Source: B. Mettler, M. B. Tischler, T. Kanade, "System Identification Modeling of a
Small-Scale Unmanned Rotorcraft for Flight Control Design", Journal of the American
Helicopter Society 47(1), 2002, pp. 50-63 (the hover model's identified parameters; the same
model in B. Mettler, T. Kanade, M. B. Tischler, "System Identification Modeling of a
Model-Scale Helicopter", Carnegie Mellon University report CMU-RI-TR-00-03, 2000).
Units as published: ft, s, rad; controls in the paper's normalised servo units.

The numbers below were written down without a copy of the paper at hand to compare against
(see README.md): treat them as "a published-like 13-state small-helicopter hover model" and
check them against the paper's table before quoting them as its values. Nothing in the fit
depends on their being the paper's: the harness asks whether the fit recovers the model that
generated the data.

    u' = Xu u - g theta + Xa a              v' = Yv v + g phi + Yb b
    p' = Lu u + Lv v + Lb b                 q' = Mu u + Mv v + Ma a
    phi' = p                                theta' = q
    tf a' = -a - tf q + Ab b + Ac c + Alat lat + Alon lon
    tf b' = -b - tf p + Ba a + Bd d + Blat lat + Blon lon
    ts c' = -c - ts q + Clon lon            ts d' = -d - ts p + Dlat lat
    w' = Za a + Zb b + Zw w + Zr r + Zcol col
    r' = Np p + Nw w + Nr r + Nped (ped - rfb) + Ncol col
    rfb' = Kr r + Krfb rfb

Xa = -g and Yb = g are fixed (the thrust vector tilts with the tip-path plane). The yaw
damper's state r_fb is not measured, so its scale is free: r_fb -> k r_fb with Kr -> k Kr,
Nrfb -> Nrfb/k leaves every response unchanged, and only the product Nrfb*Kr could be
identified. The model takes the damper's correction as subtracted from the pedal command,
Nrfb = -Nped (the published values have |Nrfb| = Nped), which fixes that scale. The other
32 entries are free (the issue counted 33 with Nrfb free).
"""
import os

import numpy as np

G_FT = 32.17  # ft/s^2

STATES = ["u", "v", "p", "q", "phi", "theta", "a", "b", "c", "d", "w", "r", "rfb"]
CONTROLS = ["lat", "lon", "ped", "col"]
MEASURED = ["u", "v", "w", "p", "q", "r", "phi", "theta"]

# The 32 free parameters, in the order the structure file lists them (published_values.csv).
def _read_published():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "published_values.csv")
    values = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or line.startswith("name,"):
                continue
            name, value = line.strip().split(",")
            values[name] = float(value)
    return values


PUBLISHED = _read_published()


def matrices(p):
    """A, B of x' = A x + B u for parameter dict p."""
    i = {s: k for k, s in enumerate(STATES)}
    c = {s: k for k, s in enumerate(CONTROLS)}
    A = np.zeros((13, 13))
    B = np.zeros((13, 4))

    def a(row, col, v):
        A[i[row], i[col]] += v

    def b(row, col, v):
        B[i[row], c[col]] += v

    a("u", "u", p["Xu"]); a("u", "theta", -G_FT); a("u", "a", -G_FT)
    a("v", "v", p["Yv"]); a("v", "phi", G_FT); a("v", "b", G_FT)
    a("p", "u", p["Lu"]); a("p", "v", p["Lv"]); a("p", "b", p["Lb"])
    a("q", "u", p["Mu"]); a("q", "v", p["Mv"]); a("q", "a", p["Ma"])
    a("phi", "p", 1.0); a("theta", "q", 1.0)
    tf, ts = p["tau_f"], p["tau_s"]
    a("a", "a", -1 / tf); a("a", "q", -1.0); a("a", "b", p["Ab"] / tf); a("a", "c", p["Ac"] / tf)
    b("a", "lat", p["Alat"] / tf); b("a", "lon", p["Alon"] / tf)
    a("b", "b", -1 / tf); a("b", "p", -1.0); a("b", "a", p["Ba"] / tf); a("b", "d", p["Bd"] / tf)
    b("b", "lat", p["Blat"] / tf); b("b", "lon", p["Blon"] / tf)
    a("c", "c", -1 / ts); a("c", "q", -1.0); b("c", "lon", p["Clon"] / ts)
    a("d", "d", -1 / ts); a("d", "p", -1.0); b("d", "lat", p["Dlat"] / ts)
    a("w", "a", p["Za"]); a("w", "b", p["Zb"]); a("w", "w", p["Zw"]); a("w", "r", p["Zr"])
    b("w", "col", p["Zcol"])
    a("r", "p", p["Np"]); a("r", "w", p["Nw"]); a("r", "r", p["Nr"]); a("r", "rfb", -p["Nped"])
    b("r", "ped", p["Nped"]); b("r", "col", p["Ncol"])
    a("rfb", "r", p["Kr"]); a("rfb", "rfb", p["Krfb"])
    return A, B
