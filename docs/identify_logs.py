#!/usr/bin/env python3
"""`identify` on the board's own logs of board-sim campaigns, scored against the truth.

    cargo build --release -p sweephold
    python3 docs/bars.py --vehicle V --seeds 1-10 --out CAMPAIGNS -- --fc board-sim
    python3 docs/identify_logs.py --vehicle V --campaigns CAMPAIGNS --seeds 1-10 --out DIR \
        [--trim-points | --flight-trim]

For each seed N, the campaign folder CAMPAIGNS/NAME-N (NAME: the vehicle file's stem, as
bars.py names it) holds the board's log of each power-up: `fly-cah/log/power-up-1.bin` (the
eight sweeps of the cah stage, one power-up) and `verify-doublet/log/power-up-1.bin` (the
four held-out doublets, another power-up). This script runs

    sweephold identify CAMPAIGN/fly-cah/log CAMPAIGN/verify-doublet/log --vehicle V --seed N
        [--trim-points CAMPAIGN/trim-points.csv]
        [--steady-flights CAMPAIGN/fly-steady/log/power-up-1.bin --gnss CAMPAIGN/fly-steady/gnss.csv]
        --out DIR/NAME-N -q

and scores its model9 against the truth the campaign computed (identify has none: it never
runs the simulator): the nine key parameters against `fit.params[].truth` of the campaign's
summary.json, the truth's hover modes (`fit.truth_modes`, hover: 10⁻⁶ ≤ |λ| < 3 rad/s)
against identify's `fit.modes` paired as `sysid::fit::modes::comparison::pair_modes` pairs
them (same name first, then nearest eigenvalue, closest pairs first; matched within 25 %),
and the verification's TIC of p, q, r (identify's own `verify`, on the held-out doublets).
Prints one Markdown row per seed and the count of seeds meeting each bar.
"""
import argparse
import json
import os
import subprocess
import sys
from runs import BINARY, seeds

KEY = ["tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Mf_lat", "Mf_lon", "Lf_lat", "Lf_lon"]
HOVER_TOLERANCE = 25.0


def load(path):
    with open(path) as f:
        return json.load(f)


def eigen(record):
    re, im = record["eigenvalue"]
    return complex(re, abs(im))


def hover_matched(identified, truth):
    """(matched, of, worst %) of the truth's hover modes, paired as pair_modes pairs."""
    pairing = {}
    taken = set()
    for same_name_only in (True, False):
        candidates = []
        for i, mode in enumerate(identified):
            for t, reference in enumerate(truth):
                if not same_name_only or mode["name"] == reference["name"]:
                    candidates.append((abs(eigen(mode) - eigen(reference)), i, t))
        candidates.sort()
        for _, i, t in candidates:
            if i not in pairing and t not in taken:
                pairing[i] = t
                taken.add(t)
    paired = {t: i for i, t in pairing.items()}
    matched, of, worst = 0, 0, None
    for t, reference in enumerate(truth):
        if not reference.get("hover"):
            continue
        of += 1
        if t in paired:
            error = 100 * abs(eigen(identified[paired[t]]) - eigen(reference)) / abs(eigen(reference))
            worst = error if worst is None else max(worst, error)
            matched += error <= HOVER_TOLERANCE
    return matched, of, worst


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", required=True)
    parser.add_argument("--campaigns", required=True, help="the bars.py --out folder")
    parser.add_argument("--seeds", type=seeds, default=seeds("1-10"))
    parser.add_argument("--out", required=True)
    trims = parser.add_mutually_exclusive_group()
    trims.add_argument("--trim-points", action="store_true",
                       help="pass the campaign's trim-points.csv (the simulator's trims)")
    trims.add_argument("--flight-trim", action="store_true",
                       help="pass the campaign's steady flights (fly-steady/: the board's log "
                            "and gnss.csv): trim points from the flight")
    args = parser.parse_args()
    name = os.path.splitext(os.path.basename(args.vehicle))[0]
    os.makedirs(args.out, exist_ok=True)
    source = ("the simulator's trim points" if args.trim_points else
              "trim points from the steady flights" if args.flight_trim else "no trim points")
    print(f"identify {args.vehicle} on board-sim logs, {source}, seeds "
          f"{args.seeds.start}-{args.seeds.stop - 1}\n")
    print("| seed | key ≤10 % (worst) | hover ≤25 % (worst) | TIC p, q, r | J_ave | tests used |")
    print("|---|---|---|---|---|---|")
    count = {"key": 0, "hover": 0, "tic": 0}
    for seed in args.seeds:
        campaign = os.path.join(args.campaigns, f"{name}-{seed}")
        out = os.path.join(args.out, f"{name}-{seed}")
        command = [BINARY, "identify", os.path.join(campaign, "fly-cah", "log"),
                   os.path.join(campaign, "verify-doublet", "log"), "--vehicle", args.vehicle,
                   "--seed", str(seed), "--out", out, "-q"]
        if args.trim_points:
            command += ["--trim-points", os.path.join(campaign, "trim-points.csv")]
        if args.flight_trim:
            steady = os.path.join(campaign, "fly-steady")
            command += ["--steady-flights", os.path.join(steady, "log", "power-up-1.bin"),
                        "--gnss", os.path.join(steady, "gnss.csv")]
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            print(f"| {seed} | identify failed: {run.stderr.strip().splitlines()[-1]} |")
            continue
        truth = load(os.path.join(campaign, "summary.json"))["fit"]
        summary = load(os.path.join(out, "summary.json"))
        fit = summary["fit"]
        values = {p["name"]: p["value"] for p in fit["params"]}
        truths = {p["name"]: p["truth"] for p in truth["params"]}
        errors = {k: 100 * (values[k] - truths[k]) / abs(truths[k])
                  for k in KEY if k in values and truths.get(k)}
        within = sum(abs(e) <= 10 for e in errors.values())
        worst = max(errors, key=lambda k: abs(errors[k]))
        matched, of, worst_mode = hover_matched(fit["modes"], truth["truth_modes"])
        tic = summary["verify"]["tic"]
        used = sum(t["verdict"] == "used" for t in summary["tests"])
        count["key"] += within == len(KEY)
        count["hover"] += of > 0 and matched == of
        count["tic"] += all(tic[o] <= 0.25 for o in "pqr")
        print(f"| {seed} | {within}/{len(KEY)} ({worst} {errors[worst]:+.1f} %) | {matched}/{of} "
              f"({'-' if worst_mode is None else f'{worst_mode:.1f} %'}) | "
              f"{tic['p']:.3f}, {tic['q']:.3f}, {tic['r']:.3f} | {fit['cost_ave']:.1f} | "
              f"{used} of {len(summary['tests'])} |")
    n = len(args.seeds)
    print(f"\nseeds meeting each bar, of {n}: key {count['key']}, hover {count['hover']}, "
          f"tic {count['tic']}")


if __name__ == "__main__":
    sys.exit(main())
