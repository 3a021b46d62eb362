#!/usr/bin/env bash
# `identify` on a campaign's own records against the campaign: for VEHICLE (default
# trex700l) and seeds FIRST..LAST (default 1..3), runs `campaign --vehicle VEHICLE --seed N
# --out OUT/cN`, then `identify OUT/cN/fly-cah OUT/cN/verify-doublet --vehicle VEHICLE
# --seed N` twice: with the campaign's trim points (`--trim-points OUT/cN/trim-points.csv`,
# into OUT/iN) and without any (what identify has without a simulator, into OUT/nN).
# Prints per seed and run whether frf.json, model6.json and model9.json's matrices and
# parameters equal the campaign's, J_ave, TIC p q r, and the nine key parameters' errors
# against the truth the campaign printed (its summary.json; identify has none).
#
#   cargo build -p sweephold && docs/identify_vs_campaign.sh [OUT [FIRST [LAST [VEHICLE]]]]
#
# SKIP_RUNS=1 reuses the folders already in OUT.
set -euo pipefail

out=${1:-/tmp/identify-vs-campaign}
first=${2:-1}
last=${3:-3}
vehicle=${4:-trex700l}
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${SWEEPHOLD:-$root/target/debug/sweephold}
[ -x "$bin" ] || { echo "no $bin: cargo build -p sweephold" >&2; exit 1; }
mkdir -p "$out"

for seed in $(seq "$first" "$last"); do
    c=$out/c$seed
    if [ -z "${SKIP_RUNS:-}" ]; then
        "$bin" campaign --vehicle "$vehicle" --seed "$seed" --out "$c" --quiet > /dev/null
        "$bin" identify "$c/fly-cah" "$c/verify-doublet" --vehicle "$vehicle" --seed "$seed" \
            --trim-points "$c/trim-points.csv" --out "$out/i$seed" -q > /dev/null
        "$bin" identify "$c/fly-cah" "$c/verify-doublet" --vehicle "$vehicle" --seed "$seed" \
            --out "$out/n$seed" -q > /dev/null
    fi
done

python3 - "$out" "$first" "$last" <<'EOF'
import json, sys

out, first, last = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
KEY = ["tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Lf_lat", "Lf_lon", "Mf_lat", "Mf_lon"]

def load(path):
    with open(path) as f:
        return json.load(f)

def same_model(a, b):
    return all(a.get(k) == b.get(k) for k in ["matrices", "delays", "average_cost", "parameters", "pairs"])

print("| seed | run | frf = | model6 = | model9 = | J_ave | TIC p q r | key within 10 % | key errors % (" + ", ".join(KEY) + ") |")
print("|---|---|---|---|---|---|---|---|---|")
for seed in range(first, last + 1):
    c = f"{out}/c{seed}"
    truth = {p["name"]: p["truth"] for p in load(f"{c}/summary.json")["fit"]["params"]}
    for run, name in [("campaign", c), ("identify --trim-points", f"{out}/i{seed}"), ("identify, no trim points", f"{out}/n{seed}")]:
        summary = load(f"{name}/summary.json")
        equal = [load(f"{c}/frf.json")["pairs"] == load(f"{name}/frf.json")["pairs"]]
        equal += [same_model(load(f"{c}/{m}"), load(f"{name}/{m}")) for m in ["model6.json", "model9.json"]]
        values = {p["name"]: p["value"] for p in summary["fit"]["params"]}
        errors = []
        for k in KEY:
            t = truth.get(k)
            errors.append(None if t in (None, 0) or k not in values else 100 * (values[k] - t) / abs(t))
        within = sum(1 for e in errors if e is not None and abs(e) <= 10)
        tic = summary["verify"]["tic"]
        print(f"| {seed} | {run} | " + " | ".join("yes" if e else "no" for e in equal)
              + f" | {summary['fit']['cost_ave']:.2f} | {tic['p']:.3f} {tic['q']:.3f} {tic['r']:.3f} | {within}/9 | "
              + ", ".join("-" if e is None else f"{e:+.1f}" for e in errors) + " |")
EOF
