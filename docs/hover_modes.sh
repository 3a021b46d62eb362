#!/usr/bin/env bash
# The hover-mode table of README.md ("sweephold campaign") and
# docs/decisions/2026-11-24-hover-modes.md: the default Bo-105 campaign on seeds FIRST..LAST
# (default 1..10), one run each with the release binary, and per seed the truth hover modes
# (|λ| < 3 rad/s) matched within 25 %, the poles at the origin and the worst hover-mode
# error, read from each campaign's summary.json (`fit.hover_modes_matched`,
# `fit.poles_at_origin`, `fit.truth_modes`).
#
#   docs/hover_modes.sh [FIRST [LAST [OUT]]]      OUT: campaign folders (default /tmp/modes)
#
# Needs python3 (standard library only). Builds the release binary first.
set -euo pipefail
first=${1:-1}
last=${2:-10}
out=${3:-/tmp/modes}
root=$(cd "$(dirname "$0")/.." && pwd)
cargo build --release -p sweephold --manifest-path "$root/Cargo.toml" >&2
binary="$root/target/release/sweephold"
mkdir -p "$out"
for seed in $(seq "$first" "$last"); do
    "$binary" campaign --seed "$seed" --out "$out/s$seed" --quiet >/dev/null
done
python3 - "$out" "$first" "$last" <<'EOF'
import json, sys
out, first, last = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
print("| seed | hover modes within 25 % | poles at the origin (\\|λ\\| < 1e-6) | slowest pole [rad/s] "
      "| worst hover-mode error | truth hover modes missed (error) | Z_w |")
print("|---|---|---|---|---|---|---|")
all_matched = with_origin = with_slow = 0
for seed in range(first, last + 1):
    fit = json.load(open(f"{out}/s{seed}/summary.json"))["fit"]
    hover, poles = fit["hover_modes_matched"], fit["poles_at_origin"]
    worst = hover["worst_error_percent"]
    missed = [
        f"{t['name']} ({t['error_percent']:.0f} %)" if t["error_percent"] is not None
        else f"{t['name']} (no counterpart)"
        for t in fit["truth_modes"]
        if t["hover"] and not (t["error_percent"] is not None and t["error_percent"] <= 25.0)
    ]
    slowest = min(fit["modes"], key=lambda m: abs(complex(*m["eigenvalue"])))
    slowest_text = ("0 (origin)" if slowest["name"] == "origin"
                    else f"{slowest['eigenvalue'][0]:.4f} ({slowest['name']})")
    z_w = next(p["value"] for p in fit["params"] if p["name"] == "Zw")
    all_matched += hover["matched"] == hover["of"]
    with_origin += poles > 0
    with_slow += abs(complex(*slowest["eigenvalue"])) < 0.01
    print(f"| {seed} | {hover['matched']}/{hover['of']} | {poles} | {slowest_text} | "
          f"{'-' if worst is None else f'{worst:.1f} %'} | {', '.join(missed) or '-'} | {z_w:.4g} |")
n = last - first + 1
print()
print(f"every hover mode within 25 %: {all_matched}/{n} seeds; a pole at the origin "
      f"(|λ| < 1e-6 rad/s): {with_origin}/{n}; a pole slower than 0.01 rad/s: {with_slow}/{n}")
EOF
