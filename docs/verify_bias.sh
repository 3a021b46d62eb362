#!/usr/bin/env bash
# The verification TIC of the default Bo-105 campaign on seeds FIRST..LAST (default 1..10),
# with each output's bias taken from the trim (what `campaign` does) and fitted by least
# squares (`sweephold verify --bias fitted` on the same model and doublets).
#
#   cargo build --release -p sweephold && docs/verify_bias.sh [OUT [FIRST [LAST]]]
#
# Runs `campaign --seed N --out OUT/sN --quiet` per seed (OUT defaults to /tmp/verify),
# reads OUT/sN/summary.json (trim bias: `verify.tic`, `tic_mean_pqr`, `tic_mean_all`) and
# averages the per-dump TICs that `verify --bias fitted` prints, then prints a Markdown
# table: per seed TIC p, q, r with the trim and the fitted bias, the means over p q r and
# over all outputs; the number of seeds with TIC <= 0.25 on each of p, q, r; and per
# output its mean TIC over the seeds and the seeds with TIC <= 0.25.
# SKIP_CAMPAIGNS=1 reuses the folders already in OUT.
set -euo pipefail

out=${1:-/tmp/verify}
first=${2:-1}
last=${3:-10}
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${SWEEPHOLD:-$root/target/release/sweephold}
[ -x "$bin" ] || { echo "no $bin: cargo build --release -p sweephold" >&2; exit 1; }
mkdir -p "$out"

for seed in $(seq "$first" "$last"); do
    dir=$out/s$seed
    if [ -z "${SKIP_CAMPAIGNS:-}" ]; then
        "$bin" campaign --seed "$seed" --out "$dir" --quiet > /dev/null
    fi
    "$bin" verify --bias fitted --model "$dir/model9.json" "$dir"/verify-doublet/*.bin \
        > "$dir/verify-fitted.txt"
done

python3 - "$out" "$first" "$last" <<'EOF'
import json, re, sys

out, first, last = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rates = ["p", "q", "r"]

def fitted_tic(path, outputs):
    """Per output, the mean over the dumps of the TIC `verify` printed (1 if diverged)."""
    per_dump, current = [], None
    for line in open(path):
        if re.match(r"^\S.*: \d+ samples at ", line):
            current = {}
            per_dump.append(current)
        elif current is not None and "diverged" in line:
            current.update({o: 1.0 for o in outputs})
        elif current is not None:
            m = re.match(r"^(\w+)\s+([0-9.]+)\s", line)
            if m and m.group(1) in outputs:
                current[m.group(1)] = float(m.group(2))
    return {o: sum(d[o] for d in per_dump) / len(per_dump) for o in outputs}

def mean(values):
    return sum(values) / len(values)

print("| seed | TIC p, q, r (trim bias) | TIC p, q, r (fitted bias) "
      "| mean p q r, trim / fitted | mean all 9 outputs, trim / fitted |")
print("|---|---|---|---|---|")
passing = {bias: {o: 0 for o in rates + ["all three"]} for bias in ["trim", "fitted"]}
per_output = {}
columns = {"pqr_trim": [], "pqr_fitted": [], "all_trim": [], "all_fitted": []}
for seed in range(first, last + 1):
    summary = json.load(open(f"{out}/s{seed}/summary.json"))
    verify = summary["verify"]
    assert verify["bias"] == "trim", verify["bias"]
    trim = verify["tic"]
    fitted = fitted_tic(f"{out}/s{seed}/verify-fitted.txt", list(trim))
    for bias, tic in [("trim", trim), ("fitted", fitted)]:
        for o in rates:
            passing[bias][o] += tic[o] <= 0.25
        passing[bias]["all three"] += all(tic[o] <= 0.25 for o in rates)
    for o in trim:
        per_output.setdefault(o, []).append((trim[o], fitted[o]))
    row = {
        "pqr_trim": verify["tic_mean_pqr"],
        "pqr_fitted": mean([fitted[o] for o in rates]),
        "all_trim": verify["tic_mean_all"],
        "all_fitted": mean(list(fitted.values())),
    }
    for key, value in row.items():
        columns[key].append(value)
    print(f"| {seed} | {', '.join(f'{trim[o]:.3f}' for o in rates)} "
          f"| {', '.join(f'{fitted[o]:.3f}' for o in rates)} "
          f"| {row['pqr_trim']:.3f} / {row['pqr_fitted']:.3f} "
          f"| {row['all_trim']:.3f} / {row['all_fitted']:.3f} |")
print(f"| mean | | | {mean(columns['pqr_trim']):.3f} / {mean(columns['pqr_fitted']):.3f} "
      f"| {mean(columns['all_trim']):.3f} / {mean(columns['all_fitted']):.3f} |")
n = last - first + 1
print()
print(f"| seeds with TIC <= 0.25, of {n} | p | q | r | all three |")
print("|---|---|---|---|---|")
for bias in ["trim", "fitted"]:
    counts = passing[bias]
    print(f"| {bias} bias | " + " | ".join(str(counts[o]) for o in rates + ["all three"]) + " |")
print()
print(f"| output | mean TIC over the seeds, trim / fitted | seeds with TIC <= 0.25, trim / fitted |")
print("|---|---|---|")
order = ["u", "v", "w", "p", "q", "r", "ax", "ay", "az"]
for o in sorted(per_output, key=lambda o: order.index(o) if o in order else len(order)):
    pairs = per_output[o]
    print(f"| {o} | {mean([t for t, _ in pairs]):.3f} / {mean([f for _, f in pairs]):.3f} "
          f"| {sum(t <= 0.25 for t, _ in pairs)} / {sum(f <= 0.25 for _, f in pairs)} |")
EOF
