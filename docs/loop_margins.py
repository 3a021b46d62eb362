#!/usr/bin/env python3
"""Loop margins predicted from the identified model against those measured in loop tests.

For each seed: the vehicle's default campaign (`sweephold campaign --vehicle V --seed N`,
with the arguments after `--`, e.g. `--fc board-sim`) identifies model9.json; the loop
tests (`sweephold fly --input loop --axes lat,lon,ped --fc board-sim --seed N`) break
the roll, pitch and heading loops at their actuator inputs; `sweephold margins
model9.json --measured ...` puts the measured margins beside the predicted ones. Prints
one row per seed and loop and the largest differences. Needs the release build:

    cargo build --release -p sweephold
    python3 docs/loop_margins.py --vehicle trex700l --seeds 1-5 --out out/loops -- --fc board-sim
"""

import argparse
import json
import os
import sys
from runs import BINARY, run, seeds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="trex700l")
    parser.add_argument("--seeds", default="1-5")
    parser.add_argument("--out", default="out/loops")
    parser.add_argument("--binary", default=BINARY, help="the sweephold binary")
    parser.add_argument("--reuse", action="store_true", help="keep completed runs in OUT")
    parser.add_argument("extra", nargs="*", help="after --: arguments for every campaign")
    args = parser.parse_args()
    if not os.path.isfile(args.binary):
        sys.exit(f"error: {args.binary} not found: run `cargo build --release -p sweephold` first")
    fc = ["--fc", "board-sim"]
    rows = []
    for seed in seeds(args.seeds):
        base = os.path.join(args.out, f"{args.vehicle}-{seed}")
        campaign, loops = base + "-campaign", base + "-loops"
        model = os.path.join(campaign, "model9.json")
        if not (args.reuse and os.path.isfile(model)):
            run([args.binary, "campaign", "--vehicle", args.vehicle, "--seed", str(seed),
                 "--out", campaign, "--quiet", *args.extra])
        if not (args.reuse and os.path.isfile(os.path.join(loops, "ped-1.bin"))):
            run([args.binary, "fly", "--vehicle", args.vehicle, "--seed", str(seed), "--input", "loop",
                 "--axes", "lat,lon,ped", "--out", loops, "--quiet", *fc])
        measured = []
        for axis in ("lat", "lon", "ped"):
            measured += ["--measured", os.path.join(loops, f"{axis}-1.bin")]
        out = base + "-margins.json"
        run([args.binary, "margins", model, "--vehicle", args.vehicle, "--samples", "0",
             "--out", out, *measured])
        with open(out) as f:
            document = json.load(f)
        for loop in document["measured"]:
            rows.append((seed, loop))
    print(f"{'seed':>4} {'loop':<15} {'wc pred':>8} {'wc meas':>8} {'GM pred':>8} {'GM meas':>8} "
          f"{'dGM':>6} {'PM pred':>8} {'PM meas':>8} {'dPM':>6}")

    def cell(value, digits):
        return "—" if value is None else f"{value:.{digits}f}"

    worst_gm = worst_pm = 0.0
    for seed, loop in rows:
        pred = loop["predicted"]
        d_gm, d_pm = loop["gain_margin_difference_db"], loop["phase_margin_difference_deg"]
        if d_gm is not None:
            worst_gm = max(worst_gm, abs(d_gm))
        if d_pm is not None:
            worst_pm = max(worst_pm, abs(d_pm))
        print(f"{seed:>4} {loop['name']:<15} {cell(pred['crossover_rad_s'], 2):>8} "
              f"{cell(loop['crossover_rad_s'], 2):>8} {cell(pred['gain_margin_db'], 1):>8} "
              f"{cell(loop['gain_margin_db'], 1):>8} {cell(d_gm, 2):>6} "
              f"{cell(pred['phase_margin_deg'], 1):>8} {cell(loop['phase_margin_deg'], 1):>8} "
              f"{cell(d_pm, 1):>6}")
    print(f"largest |dGM| {worst_gm:.2f} dB, largest |dPM| {worst_pm:.1f} deg")


if __name__ == "__main__":
    main()
