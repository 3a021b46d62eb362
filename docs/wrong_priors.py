#!/usr/bin/env python3
"""The TREX 700L identified with a wrong aircraft file: the bars of its default campaign
when the identification's a-priori knowledge comes from a copy of trex700l.toml with
priors off by 15 %, while the simulator flies the true one (`campaign --priors FILE`).

    cargo build --release -p sweephold
    python3 docs/wrong_priors.py [--case servo-slow|servo-fast|all] [--seeds 1-10] [--out DIR]

Writes the copy as DIR/trex700l-CASE.toml and runs `docs/bars.py --vehicle trex700l
--seeds SEEDS --out DIR/CASE -- --priors DIR/trex700l-CASE.toml`, then prints the servo
estimate of each seed (summary.json's fit.priors) beside its truth (60 rad/s).

The cases, each value and the direction it is off written here:
- servo-slow: servo natural_frequency 60 -> 51 rad/s (-15 %);
- servo-fast: servo natural_frequency 60 -> 69 rad/s (+15 %);
- all: every airframe and servo prior the structure takes, 15 % off in the directions
  below (ixz is 0 and stays 0; a zero cannot be off by a fraction).
"""
import argparse
import json
import os
import subprocess
import sys
from runs import seeds

HERE = os.path.dirname(os.path.abspath(__file__))
TREX = os.path.join(HERE, "..", "host", "aircraft", "vehicles", "trex700l.toml")

# (text in trex700l.toml, replacement): one line each, 15 % off.
CASES = {
    "servo-slow": [('natural_frequency = "60 rad/s"', 'natural_frequency = "51 rad/s"')],
    "servo-fast": [('natural_frequency = "60 rad/s"', 'natural_frequency = "69 rad/s"')],
    "all": [
        ('natural_frequency = "60 rad/s"', 'natural_frequency = "51 rad/s"'),  # servo -15 %
        ("damping = 0.7", "damping = 0.805"),  # servo damping +15 % (held by the structure)
        ('mass = "5.0 kg"', 'mass = "5.75 kg"'),  # +15 %
        ('ixx = "0.12 kg*m^2"', 'ixx = "0.138 kg*m^2"'),  # +15 %
        ('iyy = "0.40 kg*m^2"', 'iyy = "0.34 kg*m^2"'),  # -15 %
        ('izz = "0.35 kg*m^2"', 'izz = "0.4025 kg*m^2"'),  # +15 %
        ('flap_inertia = "0.046 kg*m^2"', 'flap_inertia = "0.0529 kg*m^2"'),  # +15 % (K_cs)
        ('hub_stiffness = "350 N*m/rad"', 'hub_stiffness = "297.5 N*m/rad"'),  # -15 % (K_cs)
        ('hub = ["0 m", "0 m", "-0.25 m"]', 'hub = ["0 m", "0 m", "-0.2875 m"]'),  # height +15 %
        ('hub = ["-0.95 m", "0 m", "-0.12 m"]', 'hub = ["-0.8075 m", "0 m", "-0.138 m"]'),  # tail arm -15 %, height +15 %
    ],
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="servo-slow", choices=sorted(CASES))
    parser.add_argument("--seeds", default="1-10")
    parser.add_argument("--out", default="out/wrong-priors")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    with open(TREX) as f:
        text = f.read()
    for old, new in CASES[args.case]:
        if text.count(old) != 1:
            sys.exit(f"error: `{old}` is not once in {TREX}")
        text = text.replace(old, new)
    text = text.replace('name = "trex700l"', f'name = "trex700l-{args.case}"')
    variant = os.path.join(args.out, f"trex700l-{args.case}.toml")
    with open(variant, "w") as f:
        f.write(text)
    folder = os.path.join(args.out, args.case)
    subprocess.run(
        [sys.executable, os.path.join(HERE, "bars.py"), "--vehicle", "trex700l", "--seeds", args.seeds,
         "--out", folder, "--", "--priors", variant],
        check=True,
    )
    print("\n| seed | servo ω_n (truth 60) | error | moved σ | warnings |\n|---|---|---|---|---|")
    for seed in seeds(args.seeds):
        path = os.path.join(folder, f"trex700l-{seed}", "summary.json")
        if not os.path.isfile(path):
            print(f"| {seed} | failed |")
            continue
        with open(path) as f:
            priors = {p["name"]: p for p in (json.load(f).get("fit") or {}).get("priors") or []}
        w = priors.get("servo_omega")
        warned = ", ".join(p["name"] for p in priors.values() if p["warning"]) or "-"
        if w is None:
            print(f"| {seed} | no servo estimate |")
            continue
        print(f"| {seed} | {w['estimate']:.1f} | {100 * (w['estimate'] - 60) / 60:+.1f}% | "
              f"{w['moved_sigma']:+.2f} | {warned} |")


if __name__ == "__main__":
    main()
