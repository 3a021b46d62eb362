#!/usr/bin/env python3
"""Degenerate minima of the TREX 700L's 9-DOF hybrid fit over campaign seeds × fit seeds.

    cargo build --release -p sweephold
    python3 docs/degenerate_sweep.py [--vehicle trex700l] [--seeds 1-10] [--fit-seeds 1-10] [--out DIR] [--binary PATH] [-- FIT ARGS]

For each campaign seed N: `sweephold campaign --vehicle V --seed N --out DIR/N` (kept when
DIR/N/summary.json exists; the sweep dumps `fly-*/*.bin` are deleted afterwards, the
held-out doublets kept), then the campaign's 9-DOF fit again from the command line with each
fit seed S, with the campaign's inputs and options (`identify/stages.rs`, `fit_9dof`):

    sweephold fit --frf frf.json --model trex700l-9dof-hybrid --start-from model6.json
        --reduce --trim-points trim-points.csv --trim-balance joint --seed S
        --constant sin_phi0=… (the trim attitude the campaign's structure was written about,
        read back from its model9.json's kinematic entries) --truth V --out fit-S.json

and `sweephold verify --model fit-S.json verify-doublet/*.bin`. One Markdown row per
(N, S):

- exit: the fit's exit status (1: refused, no model written);
- degenerate: the reasons `model.json` gives (`degenerate`), and independently of the
  binary, the script's own reading of the rule: a free parameter within 0.1 % of a bound
  of the structure file that is not zero (models README, "Degenerate minima");
- J_ave, key: the nine key parameters within 10 % of the truth (count), the worst key
  error, tau_f;
- TIC p q r: mean over the held-out doublets, and whether each is <= 0.25;
- pass: J_ave <= 50, 9/9 key within 10 %, TIC p q r <= 0.25, and not degenerate.

A count row at the end: degenerate models, and degenerate models that pass the bars
(the figure issue 39 wants at 0).
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tomllib
from runs import BINARY, ROOT, seeds

KEY = ["tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Mf_lat", "Mf_lon", "Lf_lat", "Lf_lon"]
ON_BOUND_RELATIVE = 1e-3


def structure_bounds(vehicle):
    """Nonzero bounds of the structure file's parameters: {name: [(side, bound)]}."""
    path = os.path.join(ROOT, "host", "sysid", "models", f"{vehicle}-9dof-hybrid.toml")
    with open(path, "rb") as f:
        doc = tomllib.load(f)
    bounds = {}
    for name, spec in (doc.get("parameters") or {}).items():
        if not isinstance(spec, dict):
            continue
        for side, key in (("lower", "min"), ("upper", "max")):
            value = spec.get(key)
            if isinstance(value, (int, float)) and value != 0:
                bounds.setdefault(name, []).append((side, float(value)))
    return bounds


def trim_constants(model):
    """The trim attitude's constants of the structure the campaign fitted, from its F."""
    states = model["states"]
    n = len(states)
    data = model["matrices"]["F"]["data"]
    f = lambda r, c: data[states.index(r) * n + states.index(c)]
    g = 9.80665
    cos_phi = f("theta", "q")
    sin_phi = -f("theta", "r")
    cos_theta = -f("u", "theta") / g
    sin_theta = -f("w", "theta") / (g * cos_phi)
    return {
        "sin_phi0": sin_phi,
        "cos_phi0": cos_phi,
        "sin_theta0": sin_theta,
        "cos_theta0": cos_theta,
        "tan_theta0": sin_theta / cos_theta,
    }


def campaign(vehicle, seed, folder):
    if not os.path.isfile(os.path.join(folder, "summary.json")):
        subprocess.run(
            [BINARY, "campaign", "--vehicle", vehicle, "--seed", str(seed), "--out", folder, "--quiet"],
            check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )
    for dump in glob.glob(os.path.join(folder, "fly-*", "*.bin")):
        os.remove(dump)
    return os.path.isfile(os.path.join(folder, "model9.json"))


def tic_pqr(model_path, folder):
    dumps = sorted(glob.glob(os.path.join(folder, "verify-doublet", "*.bin")))
    run = subprocess.run([BINARY, "verify", "--model", model_path, *dumps], capture_output=True, text=True)
    if run.returncode != 0:
        return None
    sums = {"p": [], "q": [], "r": []}
    for line in run.stdout.splitlines():
        m = re.match(r"^(p|q|r)\s+([0-9.eE+-]+|NaN|inf)\s", line)
        if m:
            sums[m.group(1)].append(float(m.group(2)))
    return {k: sum(v) / len(v) for k, v in sums.items() if v}


def fit(vehicle, folder, fit_seed, bounds, extra):
    with open(os.path.join(folder, "model9.json")) as f:
        constants = trim_constants(json.load(f))
    out = os.path.join(folder, f"fit-{fit_seed}.json")
    if os.path.exists(out):
        os.remove(out)
    argv = [
        BINARY, "fit", "--frf", os.path.join(folder, "frf.json"),
        "--model", f"{vehicle}-9dof-hybrid",
        "--start-from", os.path.join(folder, "model6.json"),
        "--reduce", "--trim-points", os.path.join(folder, "trim-points.csv"),
        *(["--trim-balance", "joint"] if "--trim-balance" not in extra else []), "--seed", str(fit_seed), "--truth", vehicle, "--out", out,
    ]
    for name, value in constants.items():
        argv += ["--constant", f"{name}={value!r}"]
    argv += extra
    run = subprocess.run(argv, capture_output=True, text=True)
    row = {"exit": run.returncode, "stderr": run.stderr.strip().splitlines()[-1:] or [""]}
    if not os.path.isfile(out):
        return row
    with open(out) as f:
        model = json.load(f)
    params = {p["name"]: p for p in model["parameters"]}
    truth = {p["name"]: p for p in (model.get("truth") or {}).get("parameters", [])}
    errors = {n: truth[n].get("error_percent") for n in KEY if n in truth}
    on_bound = []
    for name, sides in bounds.items():
        p = params.get(name)
        if p is None or p["status"] != "free":
            continue
        for side, bound in sides:
            if abs(p["value"] - bound) <= ON_BOUND_RELATIVE * abs(bound):
                on_bound.append(f"{name} on {side} {bound:g}")
    row.update(
        j_ave=model["average_cost"],
        degenerate=[f"{d['parameter']}: {d['reason']}" for d in model.get("degenerate") or []],
        on_bound=on_bound,
        key=sum(1 for e in errors.values() if e is not None and abs(e) <= 10),
        worst_key=max((abs(e) for e in errors.values() if e is not None), default=None),
        tau_f=params.get("tau_f", {}).get("value"),
        tic=tic_pqr(out, folder),
    )
    os.remove(out)
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="trex700l")
    parser.add_argument("--seeds", default="1-10")
    parser.add_argument("--fit-seeds", default="1-10")
    parser.add_argument("--out", default="/tmp/degenerate_sweep")
    parser.add_argument("fit_args", nargs="*", help="after `--`: more arguments of every fit, e.g. `-- --constant servo_natural_frequency=51`")
    parser.add_argument("--binary", help="the sweephold binary (default: this worktree's release build)")
    args = parser.parse_args()
    global BINARY
    BINARY = args.binary or BINARY
    bounds = structure_bounds(args.vehicle)
    print("| seed | fit seed | exit | degenerate (model.json) | on a nonzero bound (script) | J_ave | key ≤10 % | worst key % | tau_f | TIC p q r | pass |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    count = {"models": 0, "refused": 0, "degenerate": 0, "degenerate_pass": 0, "pass": 0}
    for seed in seeds(args.seeds):
        folder = os.path.join(args.out, str(seed))
        if not campaign(args.vehicle, seed, folder):
            print(f"| {seed} | - | campaign failed |")
            continue
        for fit_seed in seeds(args.fit_seeds):
            r = fit(args.vehicle, folder, fit_seed, bounds, args.fit_args)
            if "j_ave" not in r:
                count["refused"] += 1
                print(f"| {seed} | {fit_seed} | {r['exit']} | refused: {r['stderr'][0][:90]} | | | | | | | no |")
                continue
            count["models"] += 1
            tic = r["tic"] or {}
            tic_ok = len(tic) == 3 and all(v <= 0.25 for v in tic.values())
            degenerate = bool(r["degenerate"] or r["on_bound"])
            bars = r["j_ave"] <= 50 and r["key"] == 9 and tic_ok
            passed = bars and not r["degenerate"]
            count["degenerate"] += degenerate
            count["degenerate_pass"] += degenerate and passed
            count["pass"] += passed
            worst = "-" if r["worst_key"] is None else f"{r['worst_key']:.3g}"
            tics = " ".join(f"{tic.get(k, float('nan')):.3f}" for k in "pqr")
            print(
                f"| {seed} | {fit_seed} | {r['exit']} | {'; '.join(r['degenerate']) or '-'} | "
                f"{'; '.join(r['on_bound']) or '-'} | {r['j_ave']:.1f} | {r['key']}/9 | {worst} | "
                f"{r['tau_f']:.4g} | {tics} | {'yes' if passed else ('bars met, degenerate' if bars else 'no')} |"
            )
            sys.stdout.flush()
    print(
        f"\nmodels written {count['models']}, refused {count['refused']}, degenerate "
        f"{count['degenerate']}, degenerate and passing {count['degenerate_pass']}, passing {count['pass']}"
    )


if __name__ == "__main__":
    main()
