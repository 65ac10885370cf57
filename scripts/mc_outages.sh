#!/usr/bin/env bash
# Monte Carlo of the GNSS-outage metrics (docs/benchmarks.md): simulates the drive of
# config/mc_outages_sim.yaml with seeds FIRST..FIRST+N-1, runs `gins run --mode all` on each with
# config/outages_3x60s.yaml (three 60 s outages), scores it with `gins eval`, and tabulates per estimator
# the spread over the seeds of the horizontal RMSE outside the outages (and 5 s after each) and of the
# outage drift (RMS of the per-outage maxima). It says what a single drive's figures can show by chance,
# and what an estimator reaches on average with these sensors.
#
#   scripts/mc_outages.sh [out_dir] [N] [FIRST]     (default out/mc_outages, 16 seeds from 1)
#
# Writes out_dir/results.md (the table) and out_dir/raw.txt (one line per seed and estimator).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/mc_outages}
n=${2:-16}
first=${3:-1}
./scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --target gins -j"$(nproc)" >/dev/null
gins=$PWD/build/gins
mkdir -p "$out"
out=$(cd "$out" && pwd)

one_seed() {  # seed
  local d="$out/seed_$1"
  mkdir -p "$d"
  sed "s/^  seed: 1 /  seed: $1 /" config/mc_outages_sim.yaml >"$d/sim.yaml"
  grep -q "^  seed: $1 " "$d/sim.yaml" || { echo "mc: could not set the seed in $d/sim.yaml" >&2; return 1; }
  "$gins" simulate --config "$d/sim.yaml" --out "$d" >/dev/null
  "$gins" run --mode all --config config/outages_3x60s.yaml --log "$d/log.txt" --out "$d/run" >"$d/run.txt" 2>&1 ||
    { echo "mc: seed $1: gins run failed (see $d/run.txt)" >&2; return 1; }
  "$gins" eval --truth "$d/truth.csv" --json "$d/eval.json" "$d/run" >/dev/null
  rm -f "$d/log.txt" "$d/run/"*.csv  # keep the truth, the .tum outputs and the summaries
}
export -f one_seed
export out gins
echo "gins mc: $n seeds from $first into $out"
seq "$first" $((first + n - 1)) | xargs -P "$(nproc)" -I{} bash -c 'one_seed {}'

python3 - "$out" "$first" "$n" <<'EOF'
import json, statistics, sys
out, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = {}
with open(f"{out}/raw.txt", "w") as raw:
    raw.write("seed estimator rmse_h_outside_m outage_drift_rms_m outage_drift_max_m\n")
    for seed in range(first, first + n):
        ev = json.load(open(f"{out}/seed_{seed}/eval.json"))
        for t in ev["trajectories"]:
            x = (t["rmse_horizontal_outside_outages_m"], t["outage_drift_rms_m"], t["outage_drift_max_m"])
            rows.setdefault(t["name"], []).append(x)
            raw.write(f"{seed} {t['name']} {x[0]:.5f} {x[1]:.4f} {x[2]:.4f}\n")
def spread(v, digits):
    return f"{statistics.median(v):.{digits}f} ({min(v):.{digits}f} - {max(v):.{digits}f})"
with open(f"{out}/results.md", "w") as f:
    f.write(f"{n} seeds ({first}..{first + n - 1}) of config/mc_outages_sim.yaml, `gins run --mode all --config "
            "config/outages_3x60s.yaml`; median (min - max) over the seeds\n\n")
    f.write("| estimator | H RMSE outside outages (m) | outage drift RMS (m) | outage drift max (m) |\n")
    f.write("|---|---|---|---|\n")
    for name in ("eskf", "eskf_rts", "smoother", "batch"):
        v = rows.get(name)
        if v:
            f.write(f"| {name} | {spread([x[0] for x in v], 4)} | {spread([x[1] for x in v], 3)} | "
                    f"{spread([x[2] for x in v], 3)} |\n")
print(open(f"{out}/results.md").read())
EOF
