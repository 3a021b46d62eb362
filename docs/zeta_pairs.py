#!/usr/bin/env python3
"""Which measured responses pull the TREX 700L's servo damping ζ off its truth.

    cargo build --release -p sweephold
    python3 docs/bars.py --vehicle trex700l --seeds 1-3 --out CAMPAIGNS
    python3 docs/zeta_pairs.py --campaign CAMPAIGNS/trex700l-1 --seed 1 [--zoh]

Fits the campaign's 9-DOF stage again (`fit --frf … --model STRUCT --start-from model6.json
--reduce --trim-points trim-points.csv --trim-balance joint --truth trex700l`) with the
servo's ζ a parameter under a prior of 0.7 ± 0.07, on responses in which some pairs are
replaced by the exact ones: the simulator's linearization at hover (`sim linearize --json`)
times the 60 rad/s, ζ 0.7 servo. Prints the fitted ω_n, ζ, τ_f for: every pair measured;
every pair exact; the on-axis pairs measured and the rest exact; the other way round; and
each off-axis pair measured alone. `--zoh` first divides the control tick's sample-and-hold
(e^(−jωT/2)·sinc(ωT/2), T = 5 ms) out of the measured responses.
"""
import argparse
import json
import os
import re
import subprocess
import tempfile

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
BINARY = os.path.join(ROOT, "target", "release", "sweephold")
STRUCTURE = os.path.join(ROOT, "host", "sysid", "models", "trex700l-9dof-hybrid.toml")
ON_AXIS = ["p/lat", "q/lon", "r/ped", "az/col", "w/col"]
SERVO = (60.0, 0.7)


def zeta_free_structure(folder):
    text = open(STRUCTURE).read()
    line = next(l for l in text.splitlines() if l.startswith("servo_omega = "))
    text = text.replace(line, line + '\nservo_zeta = { prior = "servo_damping", sigma = 0.07, min = 0.05, max = 3.0 }')
    text = text.replace('damping = "servo_damping"', 'damping = "servo_zeta"')
    path = os.path.join(folder, "zeta-free.toml")
    open(path, "w").write(text)
    return path


def exact_response(lin, output, control, omega):
    a, b, c, d = (np.array(lin[k]) for k in "ABCD")
    i, j = lin["outputs"].index(output), lin["controls"].index(control)
    wn, zeta = SERVO
    values = []
    for w in omega:
        s = 1j * w
        h = (c @ np.linalg.solve(s * np.eye(len(a)) - a, b) + d)[i, j]
        values.append(h * wn * wn / (s * s + 2 * zeta * wn * s + wn * wn))
    return np.array(values)


def responses(frf, lin, exact_pairs, zoh):
    data = json.loads(json.dumps(frf))
    for key in ("pairs", "siso"):
        for pair in data[key]:
            omega = np.array(pair["omega"])
            if zoh:
                x = omega * 0.005 / 2
                pair["phase_deg"] = list(np.array(pair["phase_deg"]) + np.degrees(x))
                pair["mag_db"] = list(np.array(pair["mag_db"]) - 20 * np.log10(np.sin(x) / x))
            name = pair["output"] + "/" + pair["input"]
            if name not in exact_pairs or pair["output"] not in lin["outputs"]:
                continue
            h = exact_response(lin, pair["output"], pair["input"], omega)
            phase = np.degrees(np.unwrap(np.angle(h)))
            phase += 360 * np.round(np.median(np.array(pair["phase_deg"]) - phase) / 360)
            pair["mag_db"] = list(20 * np.log10(np.maximum(np.abs(h), 1e-30)))
            pair["phase_deg"] = list(phase)
    for key in ("pairs", "siso"):
        for pair in data[key]:
            pair["mag_db"] = [float(v) for v in pair["mag_db"]]
            pair["phase_deg"] = [float(v) for v in pair["phase_deg"]]
    return data


def fit(campaign, seed, structure, data, folder):
    frf_path = os.path.join(folder, "frf.json")
    out = os.path.join(folder, "model.json")
    json.dump(data, open(frf_path, "w"))
    subprocess.run(
        [BINARY, "fit", "--frf", frf_path, "--model", structure, "--start-from",
         os.path.join(campaign, "model6.json"), "--reduce", "--trim-points",
         os.path.join(campaign, "trim-points.csv"), "--trim-balance", "joint", "--truth",
         "trex700l", "--seed", str(seed), "--out", out],
        check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    model = json.load(open(out))
    value = {p["name"]: p["value"] for p in model["parameters"]}
    tau_f = next(p for p in model["truth"]["parameters"] if p["name"] == "tau_f")
    return value["servo_omega"], value["servo_zeta"], tau_f["error_percent"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", required=True)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--zoh", action="store_true")
    args = parser.parse_args()
    lin = json.loads(subprocess.run([BINARY, "sim", "linearize", "--vehicle", "trex700l", "--json"],
                                    check=True, capture_output=True, text=True).stdout)
    frf = json.load(open(os.path.join(args.campaign, "frf.json")))
    fitted = {f"{o}/{i}" for o, i in re.findall(r'\{ output = "(\w+)", input = "(\w+)" \}',
                                               open(STRUCTURE).read())}
    everything = [p["output"] + "/" + p["input"] for p in frf["pairs"]]
    everything = [p for p in everything if p in fitted]
    off_axis = [p for p in everything if p not in ON_AXIS]
    cases = [("every pair measured", []), ("every pair exact", everything),
             ("on-axis measured, the rest exact", off_axis),
             ("off-axis measured, on-axis exact", ON_AXIS)]
    cases += [(f"{p} measured, on-axis measured, the rest exact", [q for q in off_axis if q != p])
              for p in off_axis]
    with tempfile.TemporaryDirectory() as folder:
        structure = zeta_free_structure(folder)
        print("| responses | servo ω_n | ζ | τ_f error % |\n|---|---|---|---|")
        for label, exact in cases:
            wn, zeta, tau = fit(args.campaign, args.seed, structure,
                                responses(frf, lin, set(exact), args.zoh), folder)
            print(f"| {label} | {wn:.2f} | {zeta:.3f} | {tau:+.1f} |")


if __name__ == "__main__":
    main()
