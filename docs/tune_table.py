#!/usr/bin/env python3
"""Markdown rows of `sweephold tune`'s tune.json files: per loop, the preset's and the tuned
crossover, phase margin and gain margin (above the crossover) on the identified model, and
the tuned margins' 5th percentile over the drawn models.

    python3 docs/tune_table.py DIR/V-1/tune.json DIR/V-2/tune.json ...
"""
import json
import sys


def number(value, decimals):
    return "—" if value is None else f"{value:.{decimals}f}"


def main():
    print("| model | loop | wc shipped → tuned [rad/s] | PM shipped → tuned (p5) [deg] "
          "| GM shipped → tuned (p5) [dB] |")
    print("|---|---|---|---|---|")
    for path in sys.argv[1:]:
        document = json.load(open(path))
        label = path.split("/")[-2]
        for shipped, tuned in zip(document["shipped_loops"], document["tuned_loops"]):
            w = lambda c: number(c["crossover_rad_s"]["value"], 2)
            pm = lambda c: number(c["phase_margin_deg"]["value"], 1)
            gm = lambda c: number(c["gain_margin_db"]["value"], 1)
            p5 = lambda c, k, d: number(c[k]["percentile"], d)
            print(f"| {label} | {tuned['name']} | {w(shipped)} → {w(tuned)} "
                  f"| {pm(shipped)} → {pm(tuned)} ({p5(tuned, 'phase_margin_deg', 1)}) "
                  f"| {gm(shipped)} → {gm(tuned)} ({p5(tuned, 'gain_margin_db', 1)}) |")


if __name__ == "__main__":
    main()
