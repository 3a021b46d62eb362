#!/usr/bin/env python3
"""Fit the published R-50 hover model from its simulated sweeps and score the fit.

    cargo build --release -p sweephold
    python3 docs/published_model/run_fit.py [--noise-seed N] [--seeds 1-11] [--out DIR]
                                            [--binary PATH] [-- FIT ARGS]

1. `simulate.py` writes the four records (noise-free without --noise-seed) into
   OUT/data-free or OUT/data-noiseN, unless they are there already;
2. `sweephold frf` reads them (columns named on the command line, band 0.3-40 rad/s);
3. `sweephold fit --model r50-hover.toml --seed S [FIT ARGS]` for every seed S;
4. for each fit: J_ave, the starts made, whether the minimum was confirmed, and how many of
   the 32 free parameters lie within 10 % of the published values (r50_model.PUBLISHED),
   as one Markdown row; the last row is the published model itself, scored by the same fit
   with every parameter fixed at its published value (its J_ave on these data).

With --exact the fit is given the model's exact responses instead (frf.json's pairs with
magnitude and phase replaced by the model's, coherence 1, random error 0, valid over the
whole band 0.3-40 rad/s): no estimation error, so the published values are the global
minimum (J_ave 0) and what the fit reaches measures the search alone.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import numpy as np  # noqa: E402

import r50_model  # noqa: E402

STRUCTURE = os.path.join(HERE, "r50-hover.toml")
BINARY = os.path.join(HERE, "..", "..", "target", "release", "sweephold")
CHANNELS = ["--time", "time_s", "--inputs", "lat=lat,lon=lon,ped=ped,col=col",
            "--outputs", "u=u,v=v,w=w,p=p,q=q,r=r,phi=phi,theta=theta"]


def seeds(text):
    lo, _, hi = text.partition("-")
    return range(int(lo), int(hi or lo) + 1)


def published_structure(path):
    """The structure file with every free parameter fixed at its published value."""
    text = open(STRUCTURE).read()
    out = []
    section = None
    for line in text.splitlines():
        m = re.match(r"^\[(.*)\]", line)
        if m:
            section = m.group(1)
        m = re.match(r"^(\w+) = ", line)
        if section == "parameters" and m and m.group(1) in r50_model.PUBLISHED:
            line = f"{m.group(1)} = {{ fixed = {r50_model.PUBLISHED[m.group(1)]!r} }}"
        out.append(line)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def score(model_path):
    doc = json.load(open(model_path))
    values = {p["name"]: p["value"] for p in doc["parameters"]}
    within = [n for n, v in r50_model.PUBLISHED.items()
              if abs(values[n] - v) <= 0.1 * abs(v)]
    worst = sorted(r50_model.PUBLISHED, key=lambda n: -abs(values[n] - r50_model.PUBLISHED[n])
                   / abs(r50_model.PUBLISHED[n]))[:3]
    worst_text = ", ".join(
        f"{n} {100 * (values[n] - r50_model.PUBLISHED[n]) / abs(r50_model.PUBLISHED[n]):+.0f} %"
        for n in worst)
    return doc, len(within), worst_text


def make_exact(frf, out):
    """frf.json with every pair's response replaced by the published model's own."""
    doc = json.load(open(frf))
    with open(STRUCTURE, "rb") as f:
        fitted = {(p["input"], p["output"]) for p in tomllib.load(f)["pairs"]}
    doc["pairs"] = [p for p in doc["pairs"] if (p["input"], p["output"]) in fitted]
    A, B = r50_model.matrices(r50_model.PUBLISHED)
    n = A.shape[0]
    for pair in doc["pairs"]:
        row = r50_model.STATES.index(pair["output"])
        col = r50_model.CONTROLS.index(pair["input"])
        h = np.array([np.linalg.solve(1j * w * np.eye(n) - A, B[:, col])[row]
                      for w in pair["omega"]])
        pair["mag_db"] = list(20 * np.log10(np.maximum(np.abs(h), 1e-30)))
        pair["phase_deg"] = list(np.degrees(np.unwrap(np.angle(h))))
        for key in ("coherence", "multiple_coherence"):
            if key in pair:
                pair[key] = [1.0] * len(pair["omega"])
        pair["random_error"] = [0.0] * len(pair["omega"])
        pair["valid_range"] = [pair["omega"][0], pair["omega"][-1]]
    with open(out, "w") as f:
        json.dump(doc, f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise-seed", type=int, default=None)
    parser.add_argument("--seeds", default="1-11")
    parser.add_argument("--out", default="/tmp/r50-fit")
    parser.add_argument("--binary", default=BINARY)
    parser.add_argument("--exact", action="store_true", help="fit the model's exact responses")
    parser.add_argument("extra", nargs="*", help="after --: arguments for every fit")
    args = parser.parse_args()
    tag = "free" if args.noise_seed is None else f"noise{args.noise_seed}"
    data = os.path.join(args.out, f"data-{tag}")
    records = [os.path.join(data, f"{c}.csv") for c in r50_model.CONTROLS]
    if not all(os.path.isfile(r) for r in records):
        cmd = [sys.executable, os.path.join(HERE, "simulate.py"), "--out", data]
        if args.noise_seed is not None:
            cmd += ["--noise-seed", str(args.noise_seed)]
        subprocess.run(cmd, check=True)
    frf = os.path.join(data, "frf.json")
    subprocess.run([args.binary, "frf", *records, *CHANNELS, "--band", "0.3,40", "--out", frf],
                   check=True, stderr=subprocess.DEVNULL)
    if args.exact:
        exact = os.path.join(data, "frf-exact.json")
        make_exact(frf, exact)
        frf, tag = exact, tag + " (exact responses)"
    print(f"data: {tag}; fit arguments: {' '.join(args.extra) or '(none)'}\n")
    print("| seed | J_ave | starts | confirmed | within 10 % | worst |")
    print("|---|---|---|---|---|---|")
    counts = []
    for seed in seeds(args.seeds):
        model = os.path.join(data, f"model-s{seed}{'-exact' if args.exact else ''}.json")
        run = subprocess.run([args.binary, "fit", "--frf", frf, "--model", STRUCTURE,
                              "--seed", str(seed), "--out", model, *args.extra],
                             capture_output=True, text=True)
        if run.returncode != 0:
            print(f"| {seed} | failed: {run.stderr.strip().splitlines()[-1]} | | | | |")
            continue
        doc, within, worst = score(model)
        counts.append(within)
        print(f"| {seed} | {doc['average_cost']:.1f} | {len(doc['starts'])} | "
              f"{doc['minimum_confirmed']} | {within}/32 | {worst} |")
    fixed = os.path.join(data, "published.toml")
    published_structure(fixed)
    model = os.path.join(data, "model-published.json")
    subprocess.run([args.binary, "fit", "--frf", frf, "--model", fixed, "--out", model],
                   check=True, capture_output=True)
    doc = json.load(open(model))
    print(f"| published | {doc['average_cost']:.1f} | | | 32/32 | |")
    if counts:
        print(f"\nwithin 10 %: min {min(counts)}, max {max(counts)} of 32 over {len(counts)} seeds")


if __name__ == "__main__":
    main()
