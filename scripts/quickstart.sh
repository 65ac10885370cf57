#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run both estimators on the bundled
# simulated sample (data/sample), with an accuracy summary against its truth, the comparison table
# (gins eval) and the plots (scripts/plot_run.py).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh
./scripts/build.sh --target gins  # only what it runs: the test suite is scripts/test.sh's
out=out/sample
./build/gins run --config config/default.yaml --log data/sample/log.txt.gz --truth data/sample/truth.csv.gz \
  --out "$out" --mode both
echo
# The full comparison (table on stdout, every metric in eval.json) and the plots.
./build/gins eval --truth data/sample/truth.csv.gz --json "$out/eval.json" "$out"
echo
/usr/bin/python3 scripts/plot_run.py "$out" >/dev/null
echo "Trajectories and summary are in $out/ (eskf.tum, smoother.tum, *_states.csv, summary.json, eval.json)."
echo "Plots (PNG) are in $out/: trajectory, errors, outage_drift, heading_error, biases, gnss_residuals."
