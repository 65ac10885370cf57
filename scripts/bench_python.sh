#!/usr/bin/env bash
# gins.run from Python against `gins run` on the one-hour benchmark drive (docs/benchmarks.md, "From
# Python"): the same log, config and mode, each writing its files (--out / out=); wall time, CPU time (user
# + system) and peak RSS of the whole process (GNU time; Python's start and `import gins` included), and
# the wall time of the gins.run call alone (what a session that has imported gins pays per run), the
# two interleaved run by run so that a shared machine's load falls on both alike. Prints a Markdown table:
# medians (and the fastest wall) of RUNS runs, and the Python run's cost over the command line's.
#
#   scripts/bench_python.sh [build_dir] [out_dir]     (default build, out/bench_python; RUNS=5,
#                                                      MODES="eskf smoother both")
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-out/bench_python}
runs=${RUNS:-5}
modes=${MODES:-eskf smoother both}
gins=$build/gins
export PYTHONPATH=$PWD/$build/apps/python/package
mkdir -p "$out"
[ -s "$out/drive_1h/log.txt" ] || $gins simulate --config config/bench_1h.yaml --out "$out/drive_1h" >/dev/null
log=$out/drive_1h/log.txt

timed() {  # prints "wall_s cpu_s peak_rss_kb" of the command
  /usr/bin/time -f "%e %U %S %M" -o "$out/time.txt" "$@" >/dev/null 2>"$out/stderr.txt" || { cat "$out/stderr.txt" >&2; exit 1; }
  tail -1 "$out/time.txt" | awk '{print $1, $2 + $3, $4}'
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

echo "| mode | wall: gins run | gins.run | Python over CLI | the call alone | over CLI | fastest wall: gins run | gins.run | over | CPU: gins run | gins.run | over | peak RSS: gins run | gins.run |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for mode in $modes; do
  cli_walls=() py_walls=() py_calls=() cli_cpu=() py_cpu=() cli_rss=() py_rss=()
  for ((i = 1; i <= runs; i++)); do
    read -r wall cpu kb < <(timed "$gins" run --config config/default.yaml --log "$log" --out "$out/cli_$mode" --mode "$mode")
    cli_walls+=("$wall") cli_cpu+=("$cpu") cli_rss+=("$kb")
    echo "$mode run $i: gins run $wall s wall, $cpu s CPU, $kb kB" >&2
    read -r wall cpu kb < <(timed /usr/bin/python3 -c '
import sys, time, gins
begin = time.perf_counter()
gins.run("config/default.yaml", sys.argv[1], mode=sys.argv[2], out=sys.argv[3])
open(sys.argv[4], "w").write(f"{time.perf_counter() - begin:.4f}\n")' "$log" "$mode" "$out/py_$mode" "$out/call.txt")
    py_walls+=("$wall") py_cpu+=("$cpu") py_rss+=("$kb") py_calls+=("$(cat "$out/call.txt")")
    echo "$mode run $i: gins.run $wall s wall (the call ${py_calls[-1]} s), $cpu s CPU, $kb kB" >&2
  done
  stats() { printf '%s\n' "$@" | median; }
  fastest() { printf '%s\n' "$@" | sort -g | head -1; }
  awk -v m="$mode" -v cw="$(stats "${cli_walls[@]}")" -v pw="$(stats "${py_walls[@]}")" \
      -v pcall="$(stats "${py_calls[@]}")" -v cf="$(fastest "${cli_walls[@]}")" -v pf="$(fastest "${py_walls[@]}")" \
      -v cc="$(stats "${cli_cpu[@]}")" -v pc="$(stats "${py_cpu[@]}")" \
      -v ck="$(stats "${cli_rss[@]}")" -v pk="$(stats "${py_rss[@]}")" 'BEGIN {
    printf "| %s | %.2f s | %.2f s | %+.1f %% | %.2f s | %+.1f %% | %.2f s | %.2f s | %+.1f %% | %.2f s | %.2f s | %+.1f %% | %.0f MB | %.0f MB |\n",
      m, cw, pw, 100 * (pw - cw) / cw, pcall, 100 * (pcall - cw) / cw, cf, pf, 100 * (pf - cf) / cf, cc, pc, 100 * (pc - cc) / cc, ck / 1024, pk / 1024 }'
  # The same outputs, byte for byte.
  for f in "$out/cli_$mode"/*.tum "$out/cli_$mode"/*.csv; do
    cmp -s "$f" "$out/py_$mode/$(basename "$f")" || { echo "bench_python: $(basename "$f") differs" >&2; exit 1; }
  done
done
