#!/usr/bin/env bash
# Tightly against loosely coupled cost (docs/benchmarks.md, "Tightly coupled GNSS"): simulates the one-hour
# drive of config/bench_1h.yaml near Boulder on 2025-08-28, when data/rinex/walk.nav's broadcast orbits are in
# date, with 1 Hz raw observations of GPS L1/L2, Galileo E1/E5b and BeiDou B1I/B3I (two frequencies each) of
# ~32 satellites in view, then times `gins run --config config/default.yaml` in each mode on
#   loose: the log with its 1 Hz fixes;
#   tight: the same log without GNSS lines, with --obs and --nav;
# wall time (median of RUNS runs, default 3) and the ratio tight / loose per estimator.
#
#   [GINS=path/to/gins] [RUNS=n] scripts/bench_raw.sh [out_dir]        (default out/bench_raw)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/bench_raw}
runs=${RUNS:-3}
./scripts/install_deps.sh time
gins=${GINS:-}  # GINS=path: that binary, no build
if [ -z "$gins" ]; then
  cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DGINS_BUILD_TESTS=OFF >/dev/null
  cmake --build build-bench --target gins -j"$(nproc)" >/dev/null
  gins=build-bench/gins
fi
mkdir -p "$out"

# walk.nav holds the 19 GPS, Galileo and BeiDou satellites the walk tracked (16 above the horizon): each gets
# a twin 12° ahead in its orbit (mean anomaly M0 + 12°, an unused number, not one of BeiDou's geostationary
# ones), which makes ~32 in view, in real orbits with real clocks. The run is given the same file.
nav="$out/nav_twins.rnx"
/usr/bin/python3 - data/rinex/walk.nav "$nav" <<'EOF'
import math, re, sys
lines = open(sys.argv[1]).read().split("\n")
head = next(i for i, l in enumerate(lines) if "END OF HEADER" in l) + 1
records, i = [], head
while i < len(lines):
    if re.match(r"[A-Z]\d\d ", lines[i]):
        n = 8 if lines[i][0] in "GEC" else 4
        records.append(lines[i:i + n])
        i += n
    else:
        i += 1
limits = {"G": range(1, 33), "E": range(1, 37), "C": range(6, 59)}
used = {(r[0][0], int(r[0][1:3])) for r in records}
twin = {}
out = lines[:head]
for r in records:
    out += r
    system, prn = r[0][0], int(r[0][1:3])
    if system not in limits:
        continue
    if (system, prn) not in twin:
        twin[(system, prn)] = next(k for k in limits[system] if (system, k) not in used)
        used.add((system, twin[(system, prn)]))
    m0 = math.remainder(float(r[1][61:80].replace("D", "E")) + math.radians(12.0), 2 * math.pi)
    orbit1 = r[1][:61] + ("%19.12E" % m0).replace("E", "D") + r[1][80:]
    out += ["%s%02d%s" % (system, twin[(system, prn)], r[0][3:]), orbit1] + r[2:]
open(sys.argv[2], "w").write("\n".join(out) + "\n")
EOF

if [ ! -s "$out/drive/obs.rnx" ]; then
  sed -e 's/^  start_time_s: .*/  start_time_s: 1440437500/' \
      -e 's/^  origin: .*/  origin: [40.0967, -105.1472, 1580.0]/' config/bench_1h.yaml >"$out/sim.yaml"
  cat >>"$out/sim.yaml" <<EOF
  raw_gnss_enabled: true
  raw_gnss_nav_file: $nav
  raw_gnss_rate_hz: 1
EOF
  $gins simulate --config "$out/sim.yaml" --out "$out/drive" >/dev/null
fi
grep -v '^GNSS' "$out/drive/log.txt" >"$out/drive/log_without_fixes.txt"
sync
epochs=$(grep -c '^>' "$out/drive/obs.rnx")
sats=$(awk '/^>/ {n += $NF; e++} END {printf "%.1f", n / e}' "$out/drive/obs.rnx")
echo "gins bench_raw: $epochs epochs, $sats satellites per epoch on average"

timed() {  # mode run_dir args...: prints the wall time
  local mode=$1 dir=$2
  shift 2
  /usr/bin/time -f "%e" -o "$out/time.txt" $gins run --mode "$mode" --config config/default.yaml --out "$dir" \
    "$@" >/dev/null 2>"$out/stderr.txt" || { cat "$out/stderr.txt" >&2; exit 1; }
  tail -1 "$out/time.txt"
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

{
  echo "| mode | loose (median of $runs) | tight (median of $runs) | tight / loose |"
  echo "|---|---|---|---|"
} >"$out/results.md"
for mode in eskf smoother batch; do
  loose=$(for i in $(seq "$runs"); do timed "$mode" "$out/loose_$mode" --log "$out/drive/log.txt"; done | median)
  tight=$(for i in $(seq "$runs"); do
    timed "$mode" "$out/tight_$mode" --log "$out/drive/log_without_fixes.txt" --obs "$out/drive/obs.rnx" \
      --nav "$nav"
  done | median)
  echo "| $mode | $loose s | $tight s | $(awk -v a="$tight" -v b="$loose" 'BEGIN {printf "%.2f", a / b}') |" \
    >>"$out/results.md"
done
cat "$out/results.md"
