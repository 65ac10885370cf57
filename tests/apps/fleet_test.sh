#!/usr/bin/env bash
# The ways to run many logs of docs/fleet.md, run as written on three copies of the sample: the GNU parallel
# recipe (the block between that page's fleet-recipe markers, executed verbatim) and the Slurm job-array
# script (each array task run by hand with its SLURM_ARRAY_TASK_ID); then `gins report` must print one row
# per run. Usage: fleet_test.sh parallel|slurm BUILD_DIR SOURCE_DIR
set -euo pipefail
what=$1
build=$2
src=$3
work=$(mktemp -d /tmp/gins_fleet.XXXXXX)
fail() { echo "FAIL: $*" >&2; exit 1; }
cd "$work"
# What the recipes expect of the folder they run in: build/gins, config/, scripts/, the logs.
ln -s "$build" build
ln -s "$src/config" config
ln -s "$src/scripts" scripts
mkdir logs
for n in north south east; do cp "$src/data/sample/log.txt.gz" "logs/drive_$n.txt.gz"; done
cp "$src/data/sample/truth.csv.gz" logs/drive_north.truth.csv.gz  # one log brings its own truth

case $what in
  parallel)
    command -v parallel >/dev/null || fail "GNU parallel is not installed (scripts/install_deps.sh installs it)"
    sed -n '/<!-- fleet-recipe:begin -->/,/<!-- fleet-recipe:end -->/p' "$src/docs/fleet.md" | sed '/^```/d; /^<!--/d' >recipe.sh
    [ "$(grep -c 'parallel' recipe.sh)" -ge 1 ] || fail "no parallel recipe between docs/fleet.md's markers"
    bash -euo pipefail recipe.sh >recipe.out 2>&1 || { cat recipe.out; fail "docs/fleet.md's recipe failed"; }
    [ "$(grep -c . out/fleet/jobs.tsv)" -eq 4 ] || fail "the joblog does not list three jobs"
    report=recipe.out
    ;;
  slurm)
    ls logs/*.txt.gz >logs.list
    mkdir -p out/fleet
    for i in 0 1 2; do
      SLURM_ARRAY_TASK_ID=$i bash scripts/slurm_fleet.sbatch logs.list out/fleet --mode eskf --truth auto >/dev/null \
        || fail "array task $i failed"
    done
    ./build/gins report out/fleet/*/ >report.out
    report=report.out
    ;;
  *) fail "usage: $0 parallel|slurm BUILD_DIR SOURCE_DIR" ;;
esac
for n in north south east; do
  [ -f "out/fleet/drive_$n/summary.json" ] || fail "no run for drive_$n"
  grep -q "out/fleet/drive_$n .*logs/drive_$n.txt.gz *180.0" "$report" || { cat "$report"; fail "no report row for drive_$n"; }
done
grep -q "^3 runs, 0.15 h of log" "$report" || { cat "$report"; fail "the report's totals"; }
# --truth auto: the log with a truth beside it is scored (the ESKF's 0.055 m), the others have no score.
grep -q "out/fleet/drive_north .* 0\.055 " "$report" || { cat "$report"; fail "drive_north not scored against its truth"; }
for n in south east; do
  grep "out/fleet/drive_$n " "$report" | grep -q " 0\.0[0-9][0-9] " && { cat "$report"; fail "drive_$n scored without a truth"; }
done
grep -q '"truth"' out/fleet/drive_south/summary.json && fail "drive_south has a truth in its summary"
cd /
rm -rf "$work"
echo "fleet ($what): three runs, one report row each"
