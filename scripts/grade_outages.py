#!/usr/bin/env python3
"""The IMU-grade matrix with long outages (docs/accuracy.md "Every IMU grade, told the truth"): for each grade
(the specs of tests/solver/imu_grades_test.cc), the lap drive of config/bench_1h.yaml five times (15 min, Earth
rotation, 1 Hz RTK fixes, no heading, no wheels) with two 120 s GNSS outages, simulated with the grade's specs
and run with `gins run --mode all` told the same specs. Per output: horizontal RMSE outside the outages, the
drift in them (max), the horizontal NEES per axis (mean of (error / σ)², 1 for an honest σ) over the whole run
and over the 10 s after each outage, and per estimator the fixes rejected (every simulated fix is true).

    scripts/grade_outages.py [out_dir]      (default out/grade_outages; needs build/gins)

Prints the table (markdown) and writes it to out_dir/results.md.
"""
import json
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gins_geo import lla_to_enu, output_origin  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GINS = os.path.join(ROOT, "build", "gins")
# name: gyro noise deg/√h, accel noise m/s/√h, gyro bias RW deg/h/√h, accel bias RW m/s²/√h, turn-on deg/h, m/s²
GRADES = {
    "consumer": (0.8, 0.08, 60.0, 0.01, 100.0, 0.03),
    "tactical": (0.05, 0.02, 1.0, 1e-4, 5.0, 5e-4),
    "navigation": (0.002, 0.000025, 0.85, 0.00003, 0.5, 2e-4),
}
OUTAGES = [(250.0, 120.0), (600.0, 120.0)]
STREAMS = ["eskf", "eskf_rts", "smoother", "batch"]


def sim_config(grade):
    g, a, gb, ab, g0, a0 = GRADES[grade]
    keys = {"repeat": "5", "heading_invalid_fraction": "1.0", "gnss_outlier_probability": "0.0",
            "gnss_outages_s": "[" + ", ".join("[%g, %g]" % o for o in OUTAGES) + "]",
            "gyro_noise_deg_sqrt_h": g, "acc_noise_m_s_sqrt_h": a, "gyro_bias_rw_deg_h_sqrt_h": gb,
            "acc_bias_rw_m_s2_sqrt_h": ab, "gyro_turn_on_bias_deg_h": g0, "acc_turn_on_bias_m_s2": a0,
            "earth_rotation": "true"}
    out, seen = [], set()
    for line in open(os.path.join(ROOT, "config", "bench_1h.yaml")):
        m = re.match(r"^  (\w+):", line)
        if m and m.group(1) in keys:
            out.append("  %s: %s\n" % (m.group(1), keys[m.group(1)]))
            seen.add(m.group(1))
        else:
            out.append(line)
    text = "".join(out)
    missing = "".join("  %s: %s\n" % (k, v) for k, v in keys.items() if k not in seen)
    return text.replace("simulate:\n", "simulate:\n" + missing, 1)


def run_config(grade):
    g, a, gb, ab, g0, a0 = GRADES[grade]
    # The turn-on priors at twice the simulated bound, as the test's cells state them.
    return ("imu:\n  gyro_noise_deg_sqrt_h: %g\n  acc_noise_m_s_sqrt_h: %g\n  gyro_bias_rw_deg_h_sqrt_h: %g\n"
            "  acc_bias_rw_m_s2_sqrt_h: %g\n  init_gyro_bias_sigma_deg_h: %g\n  init_acc_bias_sigma_m_s2: %g\n"
            "gnss:\n  use_heading: false\nwheel:\n  enabled: false\n") % (g, a, gb, ab, 2 * g0, 2 * a0)


def nees_and_errors(states_csv, truth, t0):
    origin, _ = output_origin(states_csv)
    d = np.genfromtxt(states_csv, delimiter=",", names=True)
    tp = lla_to_enu(truth["lat"], truth["lon"], truth["alt"], origin)
    idx = np.clip(np.searchsorted(truth["t"], d["t"]), 0, len(truth) - 1)
    ok = np.abs(truth["t"][idx] - d["t"]) < 1e-3
    e = np.stack([d["px"] - tp[idx, 0], d["py"] - tp[idx, 1]], -1)[ok]
    s = np.stack([d["sigma_px"], d["sigma_py"]], -1)[ok]
    t = d["t"][ok] - t0
    return t, e, s


def main():
    out = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "out", "grade_outages"))
    os.makedirs(out, exist_ok=True)
    rows = ["| grade | output | H RMSE outside | drift max (2 outages) | NEES per axis | NEES 10 s after | fixes rejected |",
            "|---|---|---|---|---|---|---|"]
    for grade in GRADES:
        d = os.path.join(out, grade)
        os.makedirs(d, exist_ok=True)
        open(os.path.join(d, "sim.yaml"), "w").write(sim_config(grade))
        open(os.path.join(d, "run.yaml"), "w").write(run_config(grade))
        subprocess.run([GINS, "simulate", "--config", os.path.join(d, "sim.yaml"), "--out", d], check=True,
                       stdout=subprocess.DEVNULL)
        subprocess.run([GINS, "run", "--config", os.path.join(d, "run.yaml"), "--log", os.path.join(d, "log.txt"),
                        "--out", os.path.join(d, "run"), "--mode", "all"], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        summary = json.load(open(os.path.join(d, "run", "summary.json")))
        truth = np.genfromtxt(os.path.join(d, "truth.csv"), delimiter=",", names=True)
        t0 = truth["t"][0]
        for stream in STREAMS:
            t, e, s = nees_and_errors(os.path.join(d, "run", stream + "_states.csv"), truth, t0)
            h = np.hypot(e[:, 0], e[:, 1])
            inside = np.zeros(len(t), bool)
            after = np.zeros(len(t), bool)
            for b, dur in OUTAGES:
                inside |= (t >= b) & (t < b + dur)
                after |= (t >= b + dur) & (t < b + dur + 10.0)
            outside = ~inside & ~after
            z2 = (e / s) ** 2
            est = "eskf" if stream.startswith("eskf") else "smoother"
            g = summary["estimators"][est]["gnss_position"]
            rejected = sum(g["rejected"].values())
            rows.append("| %s | %s | %.3f m | %.3f m | %.2f | %.2f | %s |" % (
                grade, stream, np.sqrt(np.mean(h[outside] ** 2)), h[inside].max(), z2.mean(),
                z2[after].mean(), rejected if stream in ("eskf", "smoother") else "-"))
    table = "\n".join(rows) + "\n"
    open(os.path.join(out, "results.md"), "w").write(table)
    print(table)


if __name__ == "__main__":
    main()
