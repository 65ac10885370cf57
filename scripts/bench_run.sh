#!/usr/bin/env bash
# Whole-run benchmark (docs/benchmarks.md): simulates the one-hour drive of config/bench_1h.yaml (100 Hz
# IMU, 1 Hz GNSS with heading, 10 Hz wheels) and a four-hour one (the same laps, 4x), then times
# `gins run --config config/default.yaml` in each mode: wall time (median of RUNS runs), real-time factor,
# peak resident memory (GNU time), and the accuracy of the same run (`gins eval` against the truth), so
# no speed is bought with accuracy. The 4 h runs show the memory does not grow with the log.
#
#   scripts/bench_run.sh [out_dir]        (default out/bench; RUNS=5 by default)
#
# Writes out_dir/results.md (the tables) and out_dir/raw.txt (every run). Run it on a quiet machine.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/bench}
runs=${RUNS:-5}
./scripts/install_deps.sh libbenchmark-dev time
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DGINS_BUILD_TESTS=OFF -DGINS_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build-bench --target gins -j"$(nproc)" >/dev/null
gins=build-bench/gins
mkdir -p "$out"
raw="$out/raw.txt"
: >"$raw"

echo "gins bench: simulating the 1 h and 4 h drives into $out"
[ -s "$out/drive_1h/log.txt" ] || $gins simulate --config config/bench_1h.yaml --out "$out/drive_1h" >/dev/null
sed 's/^  repeat: 20 /  repeat: 80 /' config/bench_1h.yaml >"$out/bench_4h.yaml"
grep -q '^  repeat: 80 ' "$out/bench_4h.yaml" || { echo "bench: could not make the 4 h config" >&2; exit 1; }
[ -s "$out/drive_4h/log.txt" ] || $gins simulate --config "$out/bench_4h.yaml" --out "$out/drive_4h" >/dev/null
# The simulated logs (~450 MB) reach the disk before any run is timed, not during the first ones.
sync

# One timed run: prints "wall_s peak_rss_kb".
timed_run() {  # mode drive run_dir
  /usr/bin/time -f "%e %M" -o "$out/time.txt" $gins run --mode "$1" --config config/default.yaml \
    --log "$out/$2/log.txt" --out "$3" >/dev/null 2>"$out/stderr.txt" || { cat "$out/stderr.txt" >&2; exit 1; }
  tail -1 "$out/time.txt"
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

{
  echo "| mode | log | wall (median of $runs) | min - max | first run | real-time factor | peak RSS | horizontal RMSE | heading RMSE | outage drift max |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
} >"$out/results.md"
for mode in eskf smoother both batch all; do
  n=$runs
  [ "$mode" = both ] && n=1  # both = the two above in one process; shown once
  walls=()
  rss=()
  # One run first, outside the median (docs/benchmarks.md): after it every run finds the log and the
  # binary in the page cache and the previous run's files in its output directory.
  read -r first _ < <(timed_run "$mode" drive_1h "$out/run_1h_$mode")
  echo "1h $mode first run (not in the median): wall $first s" | tee -a "$raw"
  for ((i = 1; i <= n; i++)); do
    read -r wall kb < <(timed_run "$mode" drive_1h "$out/run_1h_$mode")
    echo "1h $mode run $i: wall $wall s, peak RSS $kb kB" | tee -a "$raw"
    walls+=("$wall")
    rss+=("$kb")
  done
  med=$(printf '%s\n' "${walls[@]}" | median)
  lo=$(printf '%s\n' "${walls[@]}" | sort -g | head -1)
  hi=$(printf '%s\n' "${walls[@]}" | sort -g | tail -1)
  peak=$(printf '%s\n' "${rss[@]}" | sort -g | tail -1)
  # Accuracy of the last run's main output(s).
  files=()
  case "$mode" in
    eskf) files+=("$out/run_1h_$mode/eskf_states.csv") ;;
    smoother) files+=("$out/run_1h_$mode/smoother_states.csv") ;;
    both) files+=("$out/run_1h_$mode/eskf_states.csv" "$out/run_1h_$mode/smoother_states.csv") ;;
    batch) files+=("$out/run_1h_$mode/batch_states.csv") ;;
    all) for f in eskf eskf_rts smoother batch; do files+=("$out/run_1h_$mode/${f}_states.csv"); done ;;
  esac
  $gins eval --truth "$out/drive_1h/truth.csv" --summary "$out/run_1h_$mode/summary.json" \
    --json "$out/eval_1h_$mode.json" "${files[@]}" >>"$raw"
  acc=$(/usr/bin/python3 - "$out/eval_1h_$mode.json" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["trajectories"]
cell = lambda key, fmt: " / ".join(fmt.format(x[key]) for x in t)
print(" | ".join([cell("rmse_horizontal_m", "{:.3f} m"), cell("rmse_heading_deg", "{:.3f}°"),
                cell("outage_drift_max_m", "{:.2f} m")]))
PY
)
  printf '| %s | 1 h | %.2f s | %.2f - %.2f s | %.2f s | %.0fx | %.1f MB | %s |\n' "$mode" "$med" "$lo" "$hi" "$first" \
    "$(awk "BEGIN {print 3600 / $med}")" "$(awk "BEGIN {print $peak / 1024}")" "$acc" >>"$out/results.md"
  read -r wall4 kb4 < <(timed_run "$mode" drive_4h "$out/run_4h_$mode")
  echo "4h $mode: wall $wall4 s, peak RSS $kb4 kB" | tee -a "$raw"
  printf '| %s | 4 h | %.2f s (1 run) | | | %.0fx | %.1f MB | | | |\n' "$mode" "$wall4" \
    "$(awk "BEGIN {print 14400 / $wall4}")" "$(awk "BEGIN {print $kb4 / 1024}")" >>"$out/results.md"
done
rm -f "$out/time.txt" "$out/stderr.txt"
{
  echo
  echo "Machine: $(nproc) cores, $(sed -n 's/^model name\t*: *//p' /proc/cpuinfo | head -1), $(awk '/MemTotal/ {printf "%.0f", $2 / 1048576}' /proc/meminfo) GB;" \
    "gins $(git rev-parse --short HEAD 2>/dev/null || echo '?'); $(date -u +%Y-%m-%d)."
} >>"$out/results.md"
cat "$out/results.md"
