#!/usr/bin/python3
"""Independent accuracy check of a gins trajectory against a truth file (docs/formats.md §4).

Written apart from the C++ evaluation (numpy + GeographicLib-free ENU maths) so the two can check each
other. Reports whole-run metrics, metrics outside GNSS outages (found from the log's GNSS time gaps, each
extended by --settle seconds), and each outage's largest horizontal drift.

With --compare EVAL.json (the output of `gins eval --truth ... --json EVAL.json`) it instead recomputes every
metric of `gins eval` from the definitions in core/trajectory_metrics.h (its own file reading, geodesy,
interpolation, slerp and metric code: nothing shared with the C++), over the outage windows of --summary,
prints both, and exits 1 if any metric differs by more than --tolerance (relative, default 1 %).

usage: check_accuracy.py --truth truth.csv[.gz] --log log.txt[.gz] TRAJ.tum [TRAJ.tum ...]
       check_accuracy.py --truth truth.csv[.gz] --summary RUN/summary.json --compare EVAL.json TRAJ...
"""
import argparse
import json
import math
import os
import sys

import numpy as np

from gins_geo import lla_to_enu, open_text, output_origin, rot_enu_from_ecef  # noqa: E402


def yaw_of(qw, qx, qy, qz):
    # yaw of the body x axis: atan2(R10, R00)
    return np.arctan2(2 * (qx * qy + qw * qz), 1 - 2 * (qy * qy + qz * qz))


def read_tum(path):
    origin = None
    rows = []
    with open_text(path) as f:
        for line in f:
            if line.startswith("#"):
                if "origin_lla=" in line:
                    origin = [float(v) for v in line.split("origin_lla=")[1].split()[:3]]
                continue
            rows.append([float(v) for v in line.split()])
    return origin, np.array(rows)


def gnss_gaps(log_path, min_gap):
    times = []
    with open_text(log_path) as f:
        for line in f:
            if line.startswith("GNSS"):
                times.append(float(line.split()[1]))
    t = np.array(times)
    gaps = [(a, b) for a, b in zip(t[:-1], t[1:]) if b - a > min_gap]
    return gaps


# ---- The metrics of `gins eval`, recomputed (--compare) --------------------------------------------------

def quat_to_rot(q):  # q: (..., 4) as w, x, y, z
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
                     np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
                     np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def rot_to_quat(r):  # one 3x3 matrix -> w, x, y, z (Shepperd)
    t = np.trace(r)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return np.array([0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s])
    i = int(np.argmax(np.diag(r)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]) * 2
    q = np.zeros(4)
    q[0] = (r[k, j] - r[j, k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (r[j, i] + r[i, j]) / s
    q[1 + k] = (r[k, i] + r[i, k]) / s
    return q


def quat_mul(a, b):
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], -1)


def slerp(q0, q1, f):
    d = np.sum(q0 * q1, -1)
    q1 = np.where(d[:, None] < 0, -q1, q1)
    d = np.abs(d)
    theta = np.arccos(np.clip(d, -1, 1))
    small = theta < 1e-9
    st = np.where(small, 1.0, np.sin(theta))
    w0 = np.where(small, 1 - f, np.sin((1 - f) * theta) / st)
    w1 = np.where(small, f, np.sin(f * theta) / st)
    q = w0[:, None] * q0 + w1[:, None] * q1
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def yaw(q):
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.arctan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z))


def read_trajectory(path):
    """TUM (t x y z qx qy qz qw) or a CSV with a header (t,px,...,qw,qx,qy,qz[,vx,vy,vz]).
    Returns dict(t, p, q (w,x,y,z), v or None, origin, mode)."""
    origin, mode, cols, rows = None, "", None, []
    with open_text(path) as f:
        for line in f:
            s = line.strip()
            if not s:
                continue
            if s.startswith("#"):
                if origin is None and "origin_lla=" in s:
                    origin = [float(v) for v in s.split("origin_lla=")[1].split()[:3]]
                    if "mode=" in s:
                        mode = s.split("mode=")[1].split()[0]
                continue
            fields = s.replace(",", " ").split()
            try:
                rows.append([float(v) for v in fields])
            except ValueError:
                cols = {name: i for i, name in enumerate(fields)}
    if origin is None:  # a *_states.csv: its origin is in the TUM file beside it
        origin, mode = output_origin(path)
    a = np.array(rows)
    if cols is None:
        t, p, q, v = a[:, 0], a[:, 1:4], a[:, [7, 4, 5, 6]], None
    else:
        t = a[:, cols["t"]]
        p = a[:, [cols["px"], cols["py"], cols["pz"]]]
        q = a[:, [cols["qw"], cols["qx"], cols["qy"], cols["qz"]]]
        v = a[:, [cols["vx"], cols["vy"], cols["vz"]]] if "vx" in cols else None
    # equal times: the later row wins
    keep = np.append(t[1:] != t[:-1], True)
    q = q[keep] / np.linalg.norm(q[keep], axis=1, keepdims=True)
    return dict(t=t[keep], p=p[keep], q=q, v=None if v is None else v[keep], origin=origin, mode=mode, path=path)


def to_frame(traj, origin):
    """Re-express a trajectory given at traj['origin'] in the ENU frame at `origin`."""
    o = traj["origin"]
    r = rot_enu_from_ecef(np.array(origin[0]), np.array(origin[1])) @ \
        rot_enu_from_ecef(np.array(o[0]), np.array(o[1])).T
    shift = lla_to_enu(np.array(o[0]), np.array(o[1]), np.array(o[2]), origin)
    traj["p"] = traj["p"] @ r.T + shift
    traj["q"] = quat_mul(np.broadcast_to(rot_to_quat(r), traj["q"].shape), traj["q"])
    if traj["v"] is not None:
        traj["v"] = traj["v"] @ r.T
    return traj


def read_truth_enu(path, origin):
    tr = np.loadtxt(open_text(path), delimiter=",", comments="#", skiprows=1)
    keep = np.concatenate([[True], np.diff(tr[:, 0]) > 0])  # rows not later than the previous are dropped
    tr = tr[keep]
    p = lla_to_enu(tr[:, 1], tr[:, 2], tr[:, 3], origin)
    # attitude and velocity are given in the local ENU at each point: rotate them into the origin's ENU
    r_w_l = rot_enu_from_ecef(np.array(origin[0]), np.array(origin[1]))[None] @ \
        np.transpose(rot_enu_from_ecef(tr[:, 1], tr[:, 2]), (0, 2, 1))
    q_l = tr[:, 4:8] / np.linalg.norm(tr[:, 4:8], axis=1, keepdims=True)
    r_wb = r_w_l @ quat_to_rot(q_l)
    q = np.array([rot_to_quat(m) for m in r_wb])
    v = np.einsum("nij,nj->ni", r_w_l, tr[:, 8:11])
    return dict(t=tr[:, 0], p=p, q=q, v=v)


def merged_windows(summary):
    w = [(a, b, "config") for a, b in summary.get("gnss_outages", [])]
    w += [(a, b, "log gap") for a, b in summary.get("gnss_gaps", [])]
    w.sort()
    out = []
    for a, b, s in w:
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b), out[-1][2])
        else:
            out.append((a, b, s))
    return out


def eval_metrics(ref, est, windows, segment=100.0, min_gap=1.0, settle=5.0):
    dt = np.diff(est["t"])
    gap = max(min_gap, 3.0 * np.sort(dt)[len(dt) // 2])
    t = ref["t"]
    inside = (t >= est["t"][0]) & (t <= est["t"][-1])
    idx = np.nonzero(inside)[0]
    k = np.clip(np.searchsorted(est["t"], t[idx], side="right") - 1, 0, len(est["t"]) - 1)
    exact = est["t"][k] == t[idx]
    k1 = np.minimum(k + 1, len(est["t"]) - 1)
    span = est["t"][k1] - est["t"][k]
    ok = exact | (span <= gap)
    idx, k, k1, exact, span = idx[ok], k[ok], k1[ok], exact[ok], span[ok]
    f = np.where(exact, 0.0, (t[idx] - est["t"][k]) / np.where(span > 0, span, 1.0))
    p = (1 - f)[:, None] * est["p"][k] + f[:, None] * est["p"][k1]
    q = slerp(est["q"][k], est["q"][k1], f)
    e = p - ref["p"][idx]
    eh = np.linalg.norm(e[:, :2], axis=1)
    rms = lambda x: float(np.sqrt(np.mean(np.square(x))))
    out = dict(samples=len(idx), rmse_3d_m=rms(np.linalg.norm(e, axis=1)), rmse_horizontal_m=rms(eh),
               rmse_vertical_m=rms(e[:, 2]), rmse_east_m=rms(e[:, 0]), rmse_north_m=rms(e[:, 1]),
               mean_horizontal_m=float(eh.mean()), max_horizontal_m=float(eh.max()))
    if est["v"] is not None:
        v = (1 - f)[:, None] * est["v"][k] + f[:, None] * est["v"][k1]
        out["rmse_velocity_m_s"] = rms(np.linalg.norm(v - ref["v"][idx], axis=1))
    qe = quat_mul(ref["q"][idx] * np.array([1, -1, -1, -1]), q)
    ang = 2 * np.arctan2(np.linalg.norm(qe[:, 1:], axis=1), np.abs(qe[:, 0]))
    out["rmse_attitude_deg"] = math.degrees(rms(ang))
    dyaw = np.angle(np.exp(1j * (yaw(q) - yaw(ref["q"][idx]))))
    out["rmse_heading_deg"] = math.degrees(rms(dyaw))
    out["max_heading_deg"] = math.degrees(float(np.abs(dyaw).max()))
    # relative error: from every pair, the first pair >= segment further along the reference's path,
    # with no reference sample skipped in between
    travelled = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ref["p"], axis=0), axis=1))])
    d = travelled[idx]
    run = np.concatenate([[0], np.cumsum(np.diff(idx) != 1)])
    j = np.searchsorted(d, d + segment, side="left")
    valid = j < len(idx)
    i_ok, j_ok = np.nonzero(valid)[0], j[valid]
    same = run[i_ok] == run[j_ok]
    i_ok, j_ok = i_ok[same], j_ok[same]
    dist = d[j_ok] - d[i_ok]
    rel = 100 * np.linalg.norm((p[j_ok] - p[i_ok]) - (ref["p"][idx][j_ok] - ref["p"][idx][i_ok]), axis=1) / dist
    out["relative_error"] = dict(segments=len(rel), mean_percent=float(rel.mean()) if len(rel) else None,
                                 rms_percent=rms(rel) if len(rel) else None,
                                 max_percent=float(rel.max()) if len(rel) else None)
    drifts = []
    for a, b, _ in windows:
        w = (t[idx] >= a) & (t[idx] <= b)
        drifts.append(float(eh[w].max()) if w.any() else None)
    out["outages"] = drifts
    scored = [x for x in drifts if x is not None]
    out["outage_drift_rms_m"] = rms(scored) if scored else None
    out["outage_drift_max_m"] = max(scored) if scored else None
    if windows:  # the horizontal RMSE outside every window and the settle time after it
        keep = np.ones(len(idx), bool)
        for a, b, _ in windows:
            keep &= ~((t[idx] >= a) & (t[idx] <= b + settle))
        out["outside_outages_samples"] = int(keep.sum())
        out["rmse_horizontal_outside_outages_m"] = rms(eh[keep]) if keep.any() else None
    return out


def compare(args):
    with open(args.compare) as f:
        ev = json.load(f)
    summary = {}
    if args.summary:
        with open(args.summary) as f:
            summary = json.load(f)
    windows = merged_windows(summary)
    trajs = [read_trajectory(p) for p in args.traj]
    origin = next(t["origin"] for t in trajs if t["origin"] is not None)
    for t in trajs:
        if t["origin"] is not None:
            to_frame(t, origin)
    ref = read_truth_enu(args.truth, origin)
    by_path = {os.path.realpath(t["path"]): t for t in ev["trajectories"]}
    worst, failures = 0.0, []
    print(f"{'trajectory':16s} {'metric':28s} {'numpy':>12s} {'gins eval':>12s} {'rel diff':>9s}")
    for tr in trajs:
        theirs = by_path.get(os.path.realpath(tr["path"]))
        settle = theirs.get("outage_settle_s", 5.0) if theirs else 5.0
        mine = eval_metrics(ref, tr, windows, ev.get("segment_length_m", 100.0), ev.get("max_gap_s", 1.0), settle)
        if theirs is None:
            print(f"{tr['path']}: not in {args.compare}")
            failures.append(tr["path"])
            continue
        pairs = [(k, mine[k], theirs.get(k)) for k in
                 ["samples", "rmse_3d_m", "rmse_horizontal_m", "rmse_vertical_m", "rmse_east_m", "rmse_north_m",
                  "mean_horizontal_m", "max_horizontal_m", "rmse_velocity_m_s", "rmse_attitude_deg",
                  "rmse_heading_deg", "max_heading_deg", "outage_drift_rms_m", "outage_drift_max_m",
                  "outside_outages_samples", "rmse_horizontal_outside_outages_m"] if k in mine]
        for k in ["segments", "mean_percent", "rms_percent", "max_percent"]:
            pairs.append(("relative_error." + k, mine["relative_error"][k], theirs["relative_error"][k]))
        for i, x in enumerate(mine["outages"]):
            pairs.append((f"outage[{i}].max_horizontal_m", x, theirs["outages"][i]["max_horizontal_m"]))
        name = theirs.get("name", tr["path"])
        for k, a, b in pairs:
            if a is None or b is None:
                ok = a is None and b is None
                rel = 0.0 if ok else float("inf")
            else:
                rel = abs(a - b) / max(abs(b), 1e-12) if abs(a - b) > 1e-9 else 0.0
                ok = rel <= args.tolerance
            worst = max(worst, rel)
            if not ok:
                failures.append(f"{name} {k}")
            fa = "-" if a is None else f"{a:.6g}"
            fb = "-" if b is None else f"{b:.6g}"
            print(f"{name:16s} {k:28s} {fa:>12s} {fb:>12s} {100 * rel:9.2e}%{'' if ok else '  <-- differs'}")
    print(f"largest relative difference {100 * worst:.4f} % (tolerance {100 * args.tolerance:g} %): "
          f"{'OK' if not failures else 'FAILED: ' + ', '.join(failures)}")
    return 0 if not failures else 1


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--truth", required=True)
    ap.add_argument("--log", help="log, to find GNSS outages")
    ap.add_argument("--settle", type=float, default=5.0, help="seconds after an outage also excluded")
    ap.add_argument("--min-gap", type=float, default=3.0, help="GNSS gap that counts as an outage (s)")
    ap.add_argument("--compare", help="gins eval --json output to check metric by metric")
    ap.add_argument("--summary", help="run summary.json: its outage windows (simulated outages and the log's own "
                    "gaps; without --compare they are excluded too, with the log's)")
    ap.add_argument("--tolerance", type=float, default=0.01, help="relative tolerance of --compare")
    ap.add_argument("traj", nargs="+")
    args = ap.parse_args()
    if args.compare:
        return compare(args)

    truth = np.loadtxt(open_text(args.truth), delimiter=",", skiprows=1)
    gaps = gnss_gaps(args.log, args.min_gap) if args.log else []
    if args.summary:
        with open(args.summary) as f:
            gaps = sorted(set(gaps) | {(a, b) for a, b, _ in merged_windows(json.load(f))})
    for path in args.traj:
        origin, est = read_tum(path)
        tt = truth[:, 0]
        sel = (tt >= est[0, 0]) & (tt <= est[-1, 0])
        tr = truth[sel]
        p_true = lla_to_enu(tr[:, 1], tr[:, 2], tr[:, 3], origin)
        p_est = np.stack([np.interp(tr[:, 0], est[:, 0], est[:, i]) for i in (1, 2, 3)], axis=-1)
        # nearest-sample attitude is enough at 100 Hz
        idx = np.clip(np.searchsorted(est[:, 0], tr[:, 0]), 0, len(est) - 1)
        yaw_est = yaw_of(est[idx, 7], est[idx, 4], est[idx, 5], est[idx, 6])
        yaw_true = yaw_of(tr[:, 4], tr[:, 5], tr[:, 6], tr[:, 7])
        dyaw = np.degrees(np.angle(np.exp(1j * (yaw_est - yaw_true))))
        err = p_est - p_true
        eh = np.linalg.norm(err[:, :2], axis=1)
        outage = np.zeros(len(tr), bool)
        for a, b in gaps:
            outage |= (tr[:, 0] > a) & (tr[:, 0] < b + args.settle)
        ok = ~outage

        def rms(x):
            return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float("nan")

        print(f"{path}")
        print(f"  whole run  ({len(tr)} samples): horizontal RMSE {rms(eh):.4f} m, max {eh.max():.4f} m, "
              f"vertical RMSE {rms(err[:, 2]):.4f} m, heading RMSE {rms(dyaw):.4f} deg")
        print(f"  outside outages+{args.settle:g}s ({ok.sum()} samples): horizontal RMSE {rms(eh[ok]):.4f} m, "
              f"max {eh[ok].max():.4f} m, vertical RMSE {rms(err[ok, 2]):.4f} m, heading RMSE {rms(dyaw[ok]):.4f} deg")
        drifts = []
        for a, b in gaps:
            w = (tr[:, 0] > a) & (tr[:, 0] < b)
            if w.any():
                drifts.append(eh[w].max())
                print(f"  outage {a:.1f}-{b:.1f} ({b - a:.1f} s): largest horizontal drift {eh[w].max():.4f} m")
        if drifts:
            print(f"  outage drift: RMS of the per-outage maxima {rms(np.array(drifts)):.4f} m, "
                  f"max {max(drifts):.4f} m ({len(drifts)} outages)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
