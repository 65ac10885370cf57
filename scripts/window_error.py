#!/usr/bin/python3
"""Largest and RMS horizontal error of gins trajectories against a truth file inside a time window.

usage: window_error.py --truth truth.csv[.gz] --from T0 --to T1 TRAJ.tum [TRAJ.tum ...]
Positions are compared at the truth's sample times (trajectory interpolated linearly), in the local ENU frame
of the trajectory's origin_lla header (docs/formats.md §5.2, §4). numpy only.
"""
import argparse
import math
import sys

import numpy as np

from gins_geo import lla_to_enu as enu, open_text  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--truth", required=True)
    ap.add_argument("--from", dest="t0", type=float, required=True)
    ap.add_argument("--to", dest="t1", type=float, required=True)
    ap.add_argument("traj", nargs="+")
    args = ap.parse_args()
    truth = np.loadtxt(open_text(args.truth), delimiter=",", skiprows=1)
    truth = truth[(truth[:, 0] >= args.t0) & (truth[:, 0] <= args.t1)]
    for path in args.traj:
        origin, rows = None, []
        with open_text(path) as f:
            for line in f:
                if line.startswith("#"):
                    if "origin_lla=" in line:
                        origin = [float(v) for v in line.split("origin_lla=")[1].split()[:3]]
                    continue
                rows.append([float(v) for v in line.split()[:4]])
        est = np.array(rows)
        tr = truth[(truth[:, 0] >= est[0, 0]) & (truth[:, 0] <= est[-1, 0])]
        p_true = enu(tr[:, 1], tr[:, 2], tr[:, 3], origin)
        p_est = np.stack([np.interp(tr[:, 0], est[:, 0], est[:, i]) for i in (1, 2, 3)], axis=-1)
        eh = np.linalg.norm((p_est - p_true)[:, :2], axis=1)
        print(f"{path}: {len(tr)} samples in [{args.t0:.1f}, {args.t1:.1f}]: horizontal error max {eh.max():.4f} m, "
              f"RMS {math.sqrt(float(np.mean(eh ** 2))):.4f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
