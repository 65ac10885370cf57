#!/usr/bin/env bash
# Soak run (docs/benchmarks.md, "Soak"): a simulated 24-hour drive (the laps of config/bench_1h.yaml, ×24)
# through `gins run --mode both --truth`, against the same run on the 1-hour drive. Prints the wall time,
# real-time factor and peak resident memory (GNU time) of each, and what the 24 h run's summary counted; fails
# if the 24 h run's peak memory is more than 20 % above the 1 h run's (the log, the truth, the outputs and the
# comparison all stream), or if any output state was not finite. Not a CI test: it takes several minutes on
# two cores and about 3 GB of disk in out_dir (the 24 h log and truth).
#
#   scripts/soak.sh [out_dir]        (default out/soak; GINS=path/to/gins runs that binary instead of build/gins)
#
# Writes out_dir/soak.md (the table) and keeps the simulated drives for a rerun.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/soak}
gins=${GINS:-build/gins}
./scripts/install_deps.sh time
if [ -z "${GINS:-}" ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build --target gins -j"$(nproc)" >/dev/null
fi
mkdir -p "$out"

sed 's/^  repeat: 20 /  repeat: 480 /' config/bench_1h.yaml >"$out/bench_24h.yaml"
grep -q '^  repeat: 480 ' "$out/bench_24h.yaml" || { echo "soak: could not make the 24 h config" >&2; exit 1; }
echo "gins soak: simulating the 1 h and 24 h drives into $out"
[ -s "$out/drive_1h/log.txt" ] || $gins simulate --config config/bench_1h.yaml --out "$out/drive_1h" >/dev/null
[ -s "$out/drive_24h/log.txt" ] || $gins simulate --config "$out/bench_24h.yaml" --out "$out/drive_24h" >/dev/null

# One timed run: prints "wall_s peak_rss_kb".
timed_run() {  # drive
  /usr/bin/time -f "%e %M" -o "$out/time_$1.txt" $gins run --mode both --config config/default.yaml \
    --log "$out/drive_$1/log.txt" --truth "$out/drive_$1/truth.csv" --out "$out/run_$1" >/dev/null \
    2>"$out/stderr_$1.txt" || { cat "$out/stderr_$1.txt" >&2; exit 1; }
  tail -1 "$out/time_$1.txt"
}

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
echo "gins soak: running the 1 h drive"
read -r wall1 kb1 < <(timed_run 1h)
echo "gins soak: running the 24 h drive"
read -r wall24 kb24 < <(timed_run 24h)
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

summary=$(/usr/bin/python3 - "$out/run_24h/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
out = s["outputs"]
states = ", ".join(f"{k} {v['states']}" for k, v in out.items())
bad = sum(v["non_finite_skipped"] for v in out.values())
est = s["estimators"]
def resets(name):
    return est[name]["watchdog"]["count"]
acc = s.get("accuracy", {})
rmse = " / ".join(f"{k} {v['rmse_horizontal_m']:.3f} m" for k, v in acc.items() if v and "rmse_horizontal_m" in v)
print(f"states: {states}; non-finite skipped: {bad}; watchdog resets: eskf {resets('eskf')}, "
      f"smoother {resets('smoother')}; horizontal RMSE: {rmse}")
print(bad)
PY
)
non_finite=$(echo "$summary" | tail -1)
{
  echo "| drive | log duration | wall | real-time factor | peak RSS |"
  echo "|---|---|---|---|---|"
  printf '| 1 h | 3600 s | %.1f s | %.0fx | %.1f MB |\n' "$wall1" "$(awk "BEGIN {print 3600 / $wall1}")" \
    "$(awk "BEGIN {print $kb1 / 1024}")"
  printf '| 24 h | 86400 s | %.1f s | %.0fx | %.1f MB |\n' "$wall24" "$(awk "BEGIN {print 86400 / $wall24}")" \
    "$(awk "BEGIN {print $kb24 / 1024}")"
  echo
  echo "24 h run: $(echo "$summary" | head -1)"
  echo "Load average (1, 5, 15 min) before: $load_before; after: $load_after."
  echo "Machine: $(nproc) cores, $(sed -n 's/^model name\t*: *//p' /proc/cpuinfo | head -1)," \
    "$(awk '/MemTotal/ {printf "%.0f", $2 / 1048576}' /proc/meminfo) GB; gins $(git rev-parse --short HEAD 2>/dev/null || echo '?');" \
    "$(date -u +%Y-%m-%d)."
} >"$out/soak.md"
cat "$out/soak.md"
awk "BEGIN {exit !($kb24 <= 1.2 * $kb1)}" || { echo "soak: peak memory grew: $kb1 kB (1 h) -> $kb24 kB (24 h)" >&2; exit 1; }
[ "$non_finite" = 0 ] || { echo "soak: $non_finite non-finite states were skipped" >&2; exit 1; }
