#!/usr/bin/python3
"""The filtering optimum: how well any causal estimator with gins's models could do on a log.

usage: filtering_optimum.py --config C --log LOG --truth TRUTH --run DIR [--obs OBS --nav NAV]
                            [--every N] [--gins PATH] [--remove-offset] [--out WORK]

For every N-th truth epoch t_k, the batch smoother (`gins run --mode batch`) is run on the log (and the RINEX
observations) cut at t_k, and its state at t_k is kept: the estimate given every measurement up to t_k,
which a causal output at t_k with the same models can at best match on average (on a few epochs one may
be closer by chance). An epoch where that run cannot initialise (too little motion before t_k) has no such
estimate and is counted apart. The horizontal RMSE of these estimates is printed beside that of each output of the full run in DIR (`gins run --mode all`), on
the same epochs: a causal output (eskf, smoother) near the optimum has nothing left to gain from these
measurements, only from more of them or from the future (eskf_rts, batch). --remove-offset removes one
constant horizontal offset per output (a reference in another frame, as the RTK track of rtkx_walk_raw).
Positions are compared in the ENU frame of the truth's first point (docs/formats.md §4). numpy only.
"""
import argparse
import datetime
import os
import subprocess
import sys

import numpy as np

from gins_geo import lla_to_enu, open_text

GPS_EPOCH = datetime.datetime(1980, 1, 6)


def record_time(line):
    """A log line's time (its second field), or None for a comment."""
    if line.startswith("#") or not line.strip():
        return None
    return float(line.split()[1])


def rinex_epochs(lines):
    """(header end, [(GPS s, first line, end line)]) of a RINEX 3 observation file."""
    head = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 1
    starts = [i for i in range(head, len(lines)) if lines[i].startswith(">")] + [len(lines)]
    epochs = []
    for a, b in zip(starts[:-1], starts[1:]):
        f = lines[a][1:].split()
        day = datetime.datetime(int(f[0]), int(f[1]), int(f[2]), int(f[3]), int(f[4])) - GPS_EPOCH
        epochs.append((day.total_seconds() + float(f[5]), a, b))
    return head, epochs


def horizontal(lat, lon, origin):
    return lla_to_enu(lat, lon, np.full_like(lat, origin[2]), origin)[:, :2]


def rmse(diff, remove_offset):
    if remove_offset:
        diff = diff - diff.mean(axis=0)
    return float(np.sqrt((diff ** 2).sum(axis=1).mean()))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config", required=True)
    ap.add_argument("--log", required=True)
    ap.add_argument("--truth", required=True)
    ap.add_argument("--run", required=True, help="a `gins run --mode all` of the whole log")
    ap.add_argument("--obs")
    ap.add_argument("--nav")
    ap.add_argument("--every", type=int, default=8)
    ap.add_argument("--gins", default=os.path.join(os.path.dirname(__file__), "..", "build", "gins"))
    ap.add_argument("--remove-offset", action="store_true")
    ap.add_argument("--out", default="out/filtering_optimum")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    truth = np.loadtxt(open_text(args.truth), delimiter=",", skiprows=1)
    origin = truth[0, 1:4]
    with open_text(args.log) as f:
        log = f.read().splitlines()
    obs_lines, head, epochs = None, 0, []
    if args.obs:
        with open_text(args.obs) as f:
            obs_lines = f.read().splitlines(keepends=True)
        head, epochs = rinex_epochs(obs_lines)

    kept, estimates, before = [], [], []
    for k in range(0, len(truth), args.every):
        t_k = truth[k, 0]
        cut_log = os.path.join(args.out, "log.txt")
        with open(cut_log, "w") as f:
            # IMU samples up to the first one at or after t_k, so that the run reaches t_k.
            f.write("\n".join(l for l in log if (record_time(l) or -np.inf) <= t_k + 0.02) + "\n")
        cmd = [args.gins, "run", "--config", args.config, "--log", cut_log, "--mode", "batch",
               "--out", os.path.join(args.out, "run")]
        if obs_lines is not None:
            cut_obs = os.path.join(args.out, "obs.rnx")
            with open(cut_obs, "w") as f:
                f.write("".join(obs_lines[:head]))
                f.write("".join("".join(obs_lines[a:b]) for t, a, b in epochs if t <= t_k + 1e-3))
            cmd += ["--obs", cut_obs, "--nav", args.nav]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            if "initialisation did not complete" not in run.stderr and "no usable" not in run.stderr:
                sys.exit(f"t={t_k:.3f}: {run.stderr.strip()}")
            before.append(k)
            continue
        d = np.genfromtxt(os.path.join(args.out, "run", "batch_lla.csv"), delimiter=",", names=True)
        if d["t"][0] > t_k or d["t"][-1] < t_k:
            before.append(k)
            continue
        kept.append(k)
        estimates.append((np.interp(t_k, d["t"], d["lat_deg"]), np.interp(t_k, d["t"], d["lon_deg"])))

    if not kept:
        sys.exit("no epoch where the cut log initialises")
    kept = np.array(kept)
    est = np.array(estimates)
    ref = horizontal(truth[kept, 1], truth[kept, 2], origin)
    before = np.array(before, dtype=int)
    print(f"of {len(kept) + len(before)} truth epochs (every {args.every}-th of {len(truth)}), {len(kept)} have a "
          f"causal estimate and {len(before)} come before the cut log initialises")
    opt = rmse(horizontal(est[:, 0], est[:, 1], origin) - ref, args.remove_offset)
    print(f"  filtering optimum (batch up to t_k, at t_k): {opt:.3f} m on those {len(kept)}")
    # Each output: over every truth epoch (one offset for the whole walk, as scored), over those before the
    # cut log initialises (the same offset), and over the epochs that have a causal estimate (an offset of
    # their own, as the optimum's).
    every = horizontal(truth[:, 1], truth[:, 2], origin)
    for name in ["eskf", "smoother", "eskf_rts", "batch"]:
        path = os.path.join(args.run, f"{name}_lla.csv")
        if not os.path.exists(path):
            continue
        d = np.genfromtxt(path, delimiter=",", names=True)
        err = horizontal(np.interp(truth[:, 0], d["t"], d["lat_deg"]),
                         np.interp(truth[:, 0], d["t"], d["lon_deg"]), origin) - every
        inside = (truth[:, 0] >= d["t"][0]) & (truth[:, 0] <= d["t"][-1])  # no extrapolation
        off = err[inside].mean(axis=0) if args.remove_offset else np.zeros(2)
        b = before[inside[before]]
        line = f"  {name:9s} all {rmse(err[inside] - off, False):.3f} m ({inside.mean():.0%} of the epochs)"
        if len(b):
            line += f", before {rmse(err[b] - off, False):.3f} m"
        line += f", on those {len(kept)} {rmse(err[kept], args.remove_offset):.3f} m"
        print(line)

if __name__ == "__main__":
    main()
