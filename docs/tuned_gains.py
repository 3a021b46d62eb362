#!/usr/bin/env python3
"""Pilot-mode gains from `sweephold tune`, pushed to a board-sim board and flown on the simulator.

For each seed: the vehicle's default campaign (`sweephold campaign --vehicle V --seed N`, in
process unless arguments after `--` say otherwise, e.g. `-- --fc board-sim`) identifies
model9.json; `sweephold tune model9.json --vehicle V --params tuned.toml` designs the gains
and writes them as parameters. Two board-sim boards are set up from the aircraft file
(`fc params push host/aircraft/vehicles/V.toml --save --fc board-sim:shipped.flash`); the
second also gets the tuned parameters (`fc params push tuned.toml --save`). On each board:
the loop tests (`fly --input loop --axes lat,lon,ped --fc board-sim:FLASH --seed N`) and
their measured margins (`margins model9.json --measured ...`), then the campaign's sweeps
(`fly --fc board-sim:FLASH --seed N`, every axis, cah), their aborts and their largest
attitude excursion from trim.
With `--gust AT_S:U,V,W`, also on each board the lateral doublet, then the pilot mode's hover
(`--fly-on`, hands at trim) with `--gust-pulse AT_S:U,V,W` and its peak attitude excursion
from the attitude at the gust's onset, and the same flight in still air (AT_S:0,0,0) on the
same board: the same seed and board fly the same flight up to the onset, so the gust
flight's excursion trace less the still-air one is the attitude response to the gust alone
(its peak: "gust response"), and the still-air flight's own peak is the floor the raw
excursion stands on. With `--onsets T1,T2,…` the gust is flown at each of those onsets instead
(seconds after the doublet; each flight flown on for 4 s after its onset) and the response is
the mean over them, with the per-onset values: one onset's response depends on the hover state
the gust meets. Prints one row per seed and loop. Needs a build of the CLI:

    cargo build --release -p sweephold
    python3 docs/tuned_gains.py --vehicle trex700l --seeds 1-3 --out out/tuned
"""

import argparse
import json
import os
import shutil
import sys
from runs import BINARY, ROOT, run, seeds

LOOPS = ("roll_attitude", "pitch_attitude", "heading")


def aircraft_file(vehicle):
    path = os.path.join(ROOT, "host", "aircraft", "vehicles", f"{vehicle}.toml")
    return path if os.path.isfile(path) else vehicle


def board(binary, flash, files):
    """A board-sim FLASH set up from `files` (each pushed and saved, in order)."""
    if os.path.exists(flash):
        os.remove(flash)
    for path in files:
        run([binary, "fc", "params", "push", path, "--save", "--fc", f"board-sim:{flash}"])


def measured_loops(binary, vehicle, seed, model, flash, folder, reuse):
    if not (reuse and os.path.isfile(os.path.join(folder, "ped-1.bin"))):
        run([binary, "fly", "--vehicle", vehicle, "--seed", str(seed), "--input", "loop",
             "--axes", "lat,lon,ped", "--out", folder, "--quiet", "--fc", f"board-sim:{flash}"])
    out = folder + "-margins.json"
    measured = []
    for axis in ("lat", "lon", "ped"):
        measured += ["--measured", os.path.join(folder, f"{axis}-1.bin")]
    run([binary, "margins", model, "--vehicle", vehicle, "--samples", "0", "--out", out, *measured])
    with open(out) as f:
        return {loop["name"]: loop for loop in json.load(f)["measured"]}


def aborts(folder):
    """(aborted records, records, largest |φ − φ_trim|, |θ − θ_trim| over them [deg])."""
    with open(os.path.join(folder, "summary.json")) as f:
        records = json.load(f)["runs"]
    trims = [r["max_from_trim_deg"] for r in records if r.get("max_from_trim_deg")]
    return (sum(1 for r in records if r.get("aborted")), len(records),
            max((t["phi"] for t in trims), default=float("nan")),
            max((t["theta"] for t in trims), default=float("nan")))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="trex700l")
    parser.add_argument("--seeds", default="1-3")
    parser.add_argument("--out", default="out/tuned")
    parser.add_argument("--binary", default=BINARY, help="the sweephold binary")
    parser.add_argument("--reuse", action="store_true", help="keep completed runs in OUT")
    parser.add_argument("--no-campaign", action="store_true", help="skip the campaign's sweeps")
    parser.add_argument("--gust", metavar="AT_S:U,V,W",
                        help="also fly the lateral doublet, then --fly-on with `--gust-pulse AT_S:U,V,W`")
    parser.add_argument("--fly-on", type=float, default=12.0, help="seconds flown on after the doublet")
    parser.add_argument("--onsets", metavar="T1,T2,...",
                        help="fly the gust at each of these onsets [s after the doublet] (--fly-on: onset + 4 s) and average")
    parser.add_argument("extra", nargs="*", help="after --: arguments for every campaign")
    args = parser.parse_args()
    if not os.path.isfile(args.binary):
        sys.exit(f"error: {args.binary} not found: run `cargo build --release -p sweephold` first")
    rows, flights, gusts = [], [], []
    for seed in seeds(args.seeds):
        base = os.path.join(args.out, f"{args.vehicle}-{seed}")
        campaign = base + "-campaign"
        model = os.path.join(campaign, "model9.json")
        if not (args.reuse and os.path.isfile(model)):
            run([args.binary, "campaign", "--vehicle", args.vehicle, "--seed", str(seed),
                 "--out", campaign, "--quiet", *args.extra])
        tuned = base + "-tuned.toml"
        run([args.binary, "tune", model, "--vehicle", args.vehicle, "--out", base + "-tune.json",
             "--params", tuned])
        shipped_flash, tuned_flash = base + "-shipped.flash", base + "-tuned.flash"
        board(args.binary, shipped_flash, [aircraft_file(args.vehicle)])
        shutil.copyfile(shipped_flash, tuned_flash)
        run([args.binary, "fc", "params", "push", tuned, "--save", "--fc", f"board-sim:{tuned_flash}"])
        # What the push changed: the shipped board's set against the tuned board.
        run([args.binary, "fc", "params", "pull", base + "-shipped.toml", "--fc",
             f"board-sim:{shipped_flash}"])
        diff = run([args.binary, "fc", "params", "diff", base + "-shipped.toml", "--fc",
                    f"board-sim:{tuned_flash}"], capture=True)
        changed = [line.split(":")[0] for line in diff.splitlines() if line.strip()]
        shipped = measured_loops(args.binary, args.vehicle, seed, model, shipped_flash,
                                 base + "-loops-shipped", args.reuse)
        flown = measured_loops(args.binary, args.vehicle, seed, model, tuned_flash,
                               base + "-loops-tuned", args.reuse)
        for name in LOOPS:
            rows.append((seed, name, shipped.get(name), flown.get(name)))
        if not args.no_campaign:
            flown_sweeps = []
            for label, flash in (("shipped", shipped_flash), ("tuned", tuned_flash)):
                folder = f"{base}-fly-{label}"
                if not (args.reuse and os.path.isfile(os.path.join(folder, "summary.json"))):
                    run([args.binary, "fly", "--vehicle", args.vehicle, "--seed", str(seed),
                         "--out", folder, "--quiet", "--fc", f"board-sim:{flash}"])
                flown_sweeps.append(aborts(folder))
            flights.append((seed, *flown_sweeps))
        if args.gust:
            at, _, wind = args.gust.partition(":")
            onsets = [float(t) for t in args.onsets.split(",")] if args.onsets else [float(at)]
            per_onset = {"shipped": [], "tuned": []}
            for onset in onsets:
                fly_on = onset + 4.0 if args.onsets else args.fly_on
                suffix = f"-{onset:g}" if args.onsets else ""
                gust = {}
                for label, flash in (("shipped", shipped_flash), ("tuned", tuned_flash)):
                    for kind, pulse in (("still", f"{onset:g}:0,0,0"), ("gust", f"{onset:g}:{wind}")):
                        folder = f"{base}-{kind}-{label}{suffix}"
                        if not (args.reuse and os.path.isfile(os.path.join(folder, "summary.json"))):
                            run([args.binary, "fly", "--vehicle", args.vehicle, "--seed", str(seed),
                                 "--axes", "lat", "--input", "doublet", "--fly-on", f"{fly_on:g}",
                                 "--gust-pulse", pulse, "--out", folder, "--quiet",
                                 "--fc", f"board-sim:{flash}"])
                        with open(os.path.join(folder, "summary.json")) as f:
                            gust[kind, label] = json.load(f)["runs"][0]["after"]["gust_pulse"]
                for label in ("shipped", "tuned"):
                    flown, calm = gust["gust", label], gust["still", label]
                    raw = flown["peak_excursion_deg"]
                    floor = calm["peak_excursion_deg"]
                    response = [max((abs(a - b) for a, b in zip(flown["excursion_deg"][k],
                                                                calm["excursion_deg"][k])), default=0.0)
                                for k in ("phi", "theta")]
                    per_onset[label].append(((raw["phi"], raw["theta"]),
                                             (floor["phi"], floor["theta"]), response))
            mean = lambda values: sum(values) / len(values)
            figures = {}
            for label, runs in per_onset.items():
                figures[label] = tuple(tuple(mean([r[i][k] for r in runs]) for k in (0, 1))
                                       for i in range(3))
                figures[label + " per onset"] = [r[2] for r in runs]
            gusts.append((seed, figures))
        print(f"seed {seed}: tuned parameters on the board: {' '.join(changed)}", file=sys.stderr)

    def cell(value, digits):
        return "—" if value is None else f"{value:.{digits}f}"

    def figures(loop):
        if loop is None:
            return ("—", "—", "—", "—")
        return (cell(loop["crossover_rad_s"], 2), cell(loop["gain_margin_db"], 1),
                cell(loop.get("gain_margin_above_crossover_db"), 1),
                cell(loop["phase_margin_deg"], 1))

    # GM: python-control's least |GM| over every phase crossover (negative where the phase
    # crosses −180° below the crossover: the gain reduction the loop tolerates); GM > ω_c:
    # the least over the phase crossovers above the crossover (what `tune` constrains).
    print(f"| seed | loop | ω_c shipped → tuned [rad/s] | GM shipped → tuned [dB] | "
          f"GM > ω_c shipped → tuned [dB] | PM shipped → tuned [°] |")
    print("|---:|---|---:|---:|---:|---:|")
    for seed, name, shipped, flown in rows:
        (ws, gs, us, ps), (wt, gt, ut, pt) = figures(shipped), figures(flown)
        print(f"| {seed} | {name} | {ws} → {wt} | {gs} → {gt} | {us} → {ut} | {ps} → {pt} |")
    for seed, shipped, flown in flights:
        print(f"seed {seed}: the campaign's sweeps (fly, cah): aborted {shipped[0]} of {shipped[1]} "
              f"shipped, {flown[0]} of {flown[1]} tuned; max from trim |φ|, |θ| "
              f"{shipped[2]:.1f}, {shipped[3]:.1f} shipped, {flown[2]:.1f}, {flown[3]:.1f} tuned deg")
    for seed, figures in gusts:
        (sr, sf, sg), (tr, tf, tg) = figures["shipped"], figures["tuned"]
        what = f"mean of onsets {args.onsets}" if args.onsets else args.gust
        print(f"seed {seed}: gust {args.gust} ({what}): gust response (gust flight less still air) "
              f"|φ|, |θ| shipped {sg[0]:.2f}, {sg[1]:.2f} → tuned {tg[0]:.2f}, {tg[1]:.2f} deg; raw peak "
              f"excursion shipped {sr[0]:.2f}, {sr[1]:.2f} → tuned {tr[0]:.2f}, {tr[1]:.2f} deg "
              f"(still air {sf[0]:.2f}, {sf[1]:.2f} → {tf[0]:.2f}, {tf[1]:.2f})")
        if args.onsets:
            for k, axis in ((0, "φ"), (1, "θ")):
                ship = ", ".join(f"{r[k]:.2f}" for r in figures["shipped per onset"])
                tune = ", ".join(f"{r[k]:.2f}" for r in figures["tuned per onset"])
                print(f"seed {seed}: |Δ{axis}| per onset shipped {ship} → tuned {tune} deg")

if __name__ == "__main__":
    main()
