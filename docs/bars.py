#!/usr/bin/env python3
"""The identification bars of a vehicle's default campaign over a range of seeds.

    cargo build --release -p sweephold
    python3 docs/bars.py [--vehicle NAME|FILE] [--seeds 1-10] [--out DIR] [--reuse] [--excursions] [-- CAMPAIGN ARGS]

Flies `sweephold campaign --vehicle V --seed N --out DIR/V-N` for each seed (unless
--reuse finds a completed campaign there) and prints one Markdown row per seed and a count
row, read from each campaign's summary.json and model6.json. Arguments after `--` are passed
to every campaign (e.g. `-- --trim-balance joint`, or `-- --fc board-sim:FLASH` for a
board booted from a saved parameter set). `--excursions` adds a second table: per seed the
records that aborted (and why) and the largest |φ|, |θ| from trim over the records, from each
fly stage's `fly-*/summary.json` (`aborted`, `abort_reason`, `max_from_trim_deg`).

- key: the nine key parameters (tau_f Lb1s Mb1c Zcol Nped Mf_lat Mf_lon Lf_lat Lf_lon)
  within 10 % of the truth;
- hover: truth hover modes (|lambda| < 3 rad/s) matched within 25 %, and poles at the origin;
- speed: the identified model's quasi-static M_u, L_v, N_v (flapping at its steady value:
  what the trim points fix, whichever parameters carry it) within 25 % of the truth's;
- rate J: the largest J against the truth over the angular-rate pairs (p, q, r outputs);
- truth J_ave, and TIC of p q r (the campaign's verification bias) with the count <= 0.25;
- 6-DOF: whether the 6-DOF fit found its minimum twice;
- flagged: free parameters above CR 20 % or insensitivity 10 % and not flagged `needed`
  (kept because the fit needs them: the reduction's reason is in summary.json);
- s: the campaign's wall time.

A degenerate model (`fit.degenerate` of summary.json: parameters outside their physical
range or on a range bound of the structure) is marked DEGENERATE in the key column and
counts as meeting no bar.
"""
import argparse
import json
import os
import subprocess
import sys
from runs import BINARY, seeds

KEY = ["tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Mf_lat", "Mf_lon", "Lf_lat", "Lf_lon"]
SPEED = ["Mu", "Lv", "Nv"]


def campaign(vehicle, seed, folder, reuse, extra):
    if not (reuse and os.path.isfile(os.path.join(folder, "report.html"))):
        subprocess.run(
            [BINARY, "campaign", "--vehicle", vehicle, "--seed", str(seed), "--out", folder, "--quiet", *extra],
            check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )
    path = os.path.join(folder, "summary.json")
    if not os.path.isfile(path):
        return None, None
    with open(path) as f:
        summary = json.load(f)
    six = None
    if os.path.isfile(os.path.join(folder, "model6.json")):
        with open(os.path.join(folder, "model6.json")) as f:
            six = json.load(f).get("minimum_confirmed")
    return summary, six


def row(seed, summary, six):
    fit = summary.get("fit") or {}
    if summary.get("error") or not fit:
        message = (summary.get("error") or {}).get("message", "no fit")
        return f"| {seed} | failed: {message} |", None
    params = {p["name"]: p for p in fit["params"]}
    def within(name, bound):
        p = params.get(name)
        return p is not None and p["error_percent"] is not None and abs(p["error_percent"]) <= bound
    key = sum(within(n, 10) for n in KEY)
    speeds = {d["name"]: d for d in fit.get("speed_derivatives") or []}
    def speed_within(name, bound):
        d = speeds.get(name)
        return d is not None and d["error_percent"] is not None and abs(d["error_percent"]) <= bound
    speed = " ".join(
        f"{n} {speeds[n]['error_percent']:+.0f}%" if speeds.get(n, {}).get("error_percent") is not None else f"{n} -"
        for n in SPEED
    )
    hover = fit.get("hover_modes_matched") or {}
    origin = fit.get("poles_at_origin")
    rate = [p for p in fit["pairs"] if p["output"] in ("p", "q", "r") and p.get("truth_cost") is not None]
    worst = max(rate, key=lambda p: p["truth_cost"]) if rate else None
    tic = (summary.get("verify") or {}).get("tic", {})
    pqr = [tic.get(o) for o in ("p", "q", "r")]
    tic_ok = all(t is not None and t <= 0.25 for t in pqr)
    flagged = [p["name"] for p in fit["params"] if p["status"] == "free" and p["flags"]
               and ("cr" in p["flags"] or "insensitive" in p["flags"])
               and "needed" not in p["flags"]]
    cells = [
        str(seed),
        f"{key}/9",
        f"{hover.get('matched', '-')}/{hover.get('of', '-')}, {origin if origin is not None else '-'}",
        speed,
        f"{worst['truth_cost']:.1f} ({worst['output']}/{worst['input']})" if worst else "-",
        f"{fit.get('truth_cost_ave', float('nan')):.1f}",
        ", ".join("-" if t is None else f"{t:.3f}" for t in pqr),
        "yes" if six else "no",
        " ".join(flagged) or "-",
        f"{summary['timings_s'].get('total', float('nan')):.1f}",
    ]
    degenerate = fit.get("degenerate") or []
    if degenerate:
        cells[1] += " DEGENERATE (" + ", ".join(d["parameter"] for d in degenerate) + ")"
    passes = {
        "key": key == 9,
        "hover": hover.get("matched") == hover.get("of") and origin == 0,
        "speed": all(speed_within(n, 25) for n in SPEED),
        "rate": worst is not None and worst["truth_cost"] <= 50,
        "tic": tic_ok,
        "six": bool(six),
        "flagged": not flagged,
    }
    # A degenerate model (summary.json `fit.degenerate`) meets no bar of the model's.
    if degenerate:
        passes = {name: False for name in passes}
    return "| " + " | ".join(cells) + " |", passes


def excursions(folder):
    """(aborted records with reasons, records, max |phi| and |theta| from trim) of a campaign."""
    aborted, records, phi, theta = [], 0, 0.0, 0.0
    for stage in sorted(os.listdir(folder)) if os.path.isdir(folder) else []:
        path = os.path.join(folder, stage, "summary.json")
        if not (stage.startswith("fly-") and os.path.isfile(path)):
            continue
        with open(path) as f:
            for run in json.load(f).get("runs", []):
                records += 1
                if run.get("aborted"):
                    aborted.append(f"{stage}/{run['file']} {run.get('abort_reason')}")
                trim = run.get("max_from_trim_deg") or {}
                phi = max(phi, trim.get("phi") or 0.0)
                theta = max(theta, trim.get("theta") or 0.0)
    return aborted, records, phi, theta


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="bo105", help="a shipped aircraft (bo105, trex700l, fbl700) or an aircraft file")
    parser.add_argument("--seeds", default="1-10", help="e.g. 1-10")
    parser.add_argument("--out", default="out/bars")
    parser.add_argument("--reuse", action="store_true", help="keep completed campaigns in OUT")
    parser.add_argument("--excursions", action="store_true", help="also print aborts and max |phi|, |theta| from trim per seed")
    parser.add_argument("extra", nargs="*", help="after --: arguments for every campaign")
    args = parser.parse_args()
    if not os.path.isfile(BINARY):
        sys.exit(f"error: {BINARY} not found: run `cargo build --release -p sweephold` first")
    setup = "default campaign" + (" " + " ".join(args.extra) if args.extra else "")
    print(f"{args.vehicle}, {setup}, seeds {args.seeds}\n")
    print("| seed | key ≤10 % | hover ≤25 %, origin poles | speed derivatives vs truth | worst rate-pair J vs truth | truth J_ave | TIC p, q, r | 6-DOF confirmed | flagged free | s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    counts, n, folders = {}, 0, []
    for seed in seeds(args.seeds):
        folder = os.path.join(args.out, f"{os.path.splitext(os.path.basename(args.vehicle))[0]}-{seed}")
        folders.append((seed, folder))
        summary, six = campaign(args.vehicle, seed, folder, args.reuse, args.extra)
        if summary is None:
            print(f"| {seed} | no summary.json |")
            continue
        text, passes = row(seed, summary, six)
        print(text, flush=True)
        n += 1
        for name, ok in (passes or {}).items():
            counts[name] = counts.get(name, 0) + bool(ok)
    print("\nseeds meeting each bar, of", n, ": " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    if args.excursions:
        print("\n| seed | records | aborted | max |φ| / |θ| from trim |")
        print("|---|---|---|---|")
        for seed, folder in folders:
            aborted, records, phi, theta = excursions(folder)
            print(f"| {seed} | {records} | {'; '.join(aborted) or 'none'} | {phi:.1f} / {theta:.1f}° |")


if __name__ == "__main__":
    main()
