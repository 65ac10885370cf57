#!/usr/bin/python3
"""Plots of a gins run: PNG files written into the run directory.

  trajectory.png      top-down view: truth, GNSS fixes (those dropped by simulated outages marked), every
                      estimator the run wrote (ESKF, smoother, and with --mode all ESKF + RTS and batch);
                      one zoomed panel per GNSS outage, where the estimators drift
  errors.png          horizontal error (log scale) and vertical error against time, outages shaded and
                      labelled with each estimator's largest drift                                  (truth)
  outage_drift.png    largest horizontal drift per outage and whole-run RMSEs, side by side        (truth)
  heading_error.png   heading error against time with the estimators' ±3σ, outages shaded           (truth)
  biases.png          gyro and accelerometer bias estimates against time
  gnss_residuals.png  each fix against the estimated antenna position at its time; rejected fixes marked

usage: plot_run.py RUN_DIR [--truth truth.csv[.gz]] [--log log.txt[.gz]]
The truth and log default to those recorded in RUN_DIR/summary.json (when the files exist). Uses numpy and
matplotlib only (Debian: python3-numpy, python3-matplotlib).
"""
import argparse
import json
import math
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from gins_geo import lla_to_enu as to_enu, open_text, output_origin, rot_enu_from_ecef as r_enu_ecef  # noqa: E402

STYLE = {  # name: (label, colour); --mode all writes the four
    "eskf": ("ESKF", "tab:blue"),
    "smoother": ("smoother", "tab:orange"),
    "eskf_rts": ("ESKF + RTS", "tab:cyan"),
    "batch": ("batch", "tab:green"),
}
TRUTH_COLOUR = "black"
OUTAGE_COLOUR = "tab:red"
GAP_COLOUR = "0.55"


def quat_rot(q):  # w, x, y, z -> R
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
                     np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
                     np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def read_states(path):
    """A *_states.csv: dict of columns, plus the origin from the TUM file beside it."""
    with open_text(path) as f:
        header = f.readline().strip().split(",")
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    origin, _ = output_origin(path)
    cols = {h: data[:, i] for i, h in enumerate(header)}
    cols["origin"] = origin
    return cols


def read_truth(path, origin):
    tr = np.loadtxt(open_text(path), delimiter=",", comments="#", skiprows=1, ndmin=2)
    p = to_enu(tr[:, 1], tr[:, 2], tr[:, 3], origin)
    # attitude is given in the local ENU at each point: rotate into the run's frame
    r_w_l = r_enu_ecef(np.array(origin[0]), np.array(origin[1]))[None] @ \
        np.transpose(r_enu_ecef(tr[:, 1], tr[:, 2]), (0, 2, 1))
    r_wb = r_w_l @ quat_rot(tr[:, 4:8] / np.linalg.norm(tr[:, 4:8], axis=1, keepdims=True))
    return dict(t=tr[:, 0], p=p, yaw=np.arctan2(r_wb[:, 1, 0], r_wb[:, 0, 0]))


def read_fixes(path, origin):
    rows = []
    with open_text(path) as f:
        for line in f:
            if line.startswith("GNSS"):
                v = line.split()
                try:
                    rows.append([float(v[1]), float(v[2]), float(v[3]), float(v[4])])
                except (ValueError, IndexError):
                    pass
    a = np.array(rows).reshape(-1, 4)
    return a[:, 0], to_enu(a[:, 1], a[:, 2], a[:, 3], origin)


def yaw_of(s):
    q = np.stack([s["qw"], s["qx"], s["qy"], s["qz"]], -1)
    r = quat_rot(q)
    return np.arctan2(r[:, 1, 0], r[:, 0, 0])


def interp(t, tq, v):
    return np.stack([np.interp(tq, t, v[:, i]) for i in range(v.shape[1])], -1)


def wrap_deg(a):
    return (a + 180.0) % 360.0 - 180.0


def shade(ax, windows, t0, with_labels=True):
    for a, b, kind in windows:
        ax.axvspan(a - t0, b - t0, color=OUTAGE_COLOUR if kind == "config" else GAP_COLOUR,
                   alpha=0.13 if kind == "config" else 0.25, lw=0)


def outage_legend_handles(windows):
    h = []
    if any(k == "config" for *_, k in windows):
        h.append(Patch(color=OUTAGE_COLOUR, alpha=0.2, label="simulated GNSS outage"))
    if any(k != "config" for *_, k in windows):
        h.append(Patch(color=GAP_COLOUR, alpha=0.35, label="GNSS gap in the log"))
    return h


def metres(x):
    """A length with the digits that matter: 0.12, 7.3, 11."""
    if not np.isfinite(x):
        return "-"
    return f"{x:.2f}" if x < 1 else f"{x:.1f}" if x < 10 else f"{x:.0f}"


def save(fig, path, written):
    fig.savefig(path, dpi=110)
    plt.close(fig)
    written.append(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--truth", help="truth CSV (default: the one recorded in summary.json)")
    ap.add_argument("--log", help="log (default: the one recorded in summary.json)")
    args = ap.parse_args()
    run = args.run_dir
    with open(os.path.join(run, "summary.json")) as f:
        summary = json.load(f)
    t0 = summary["input"]["first_time"]
    origin = summary["origin_lla"]
    lever = np.array(summary.get("gnss_lever_arm_m", [0.0, 0.0, 0.0]))
    truth_path = args.truth or summary.get("truth")
    log_path = args.log or summary.get("log")
    if truth_path and not os.path.exists(truth_path):
        print(f"plot_run: truth {truth_path} not found; plotting without it", file=sys.stderr)
        truth_path = None
    if log_path and not os.path.exists(log_path):
        print(f"plot_run: log {log_path} not found; plotting without GNSS fixes", file=sys.stderr)
        log_path = None

    windows = [(a, b, "config") for a, b in summary.get("gnss_outages", [])]
    windows += [(a, b, "log gap") for a, b in summary.get("gnss_gaps", [])]
    windows.sort()

    est = {}
    for name in STYLE:
        path = os.path.join(run, name + "_states.csv")
        if os.path.exists(path):
            est[name] = read_states(path)
            est[name]["p"] = np.stack([est[name]["px"], est[name]["py"], est[name]["pz"]], -1)
            est[name]["yaw"] = yaw_of(est[name])
    if not est:
        print(f"plot_run: no eskf, smoother, eskf_rts or batch _states.csv in {run}", file=sys.stderr)
        return 1
    truth = read_truth(truth_path, origin) if truth_path else None
    fix_t, fix_p = read_fixes(log_path, origin) if log_path else (np.zeros(0), np.zeros((0, 3)))
    init_t = summary.get("initialization", {}).get("time", t0)
    dropped = np.zeros(len(fix_t), bool)
    for a, b, kind in windows:
        if kind == "config":
            dropped |= (fix_t >= a) & (fix_t < b) & (fix_t > init_t)
    run_name = os.path.basename(os.path.normpath(run))
    written = []

    # Horizontal errors at the truth times (for the error plots and the outage annotations).
    err = {}
    if truth is not None:
        for name, s in est.items():
            sel = (truth["t"] >= s["t"][0]) & (truth["t"] <= s["t"][-1])
            tt = truth["t"][sel]
            e = interp(s["t"], tt, s["p"]) - truth["p"][sel]
            dyaw = wrap_deg(np.degrees(np.interp(tt, s["t"], np.unwrap(s["yaw"])) - truth["yaw"][sel]))
            sig_yaw = np.degrees(np.interp(tt, s["t"], s["sigma_att_u"]))
            err[name] = dict(t=tt, h=np.linalg.norm(e[:, :2], axis=1), v=e[:, 2], yaw=dyaw, sig_yaw=sig_yaw)

    def drift(name, a, b):
        e = err[name]
        w = (e["t"] >= a) & (e["t"] <= b)
        return float(e["h"][w].max()) if w.any() else float("nan")

    # ---- trajectory.png ---------------------------------------------------------------------------------
    n_zoom = min(len(windows), 6)
    zoom_cols = 1 if n_zoom <= 1 else 2
    zoom_rows = max(1, math.ceil(n_zoom / zoom_cols))
    fig = plt.figure(figsize=(8.5 + 4.2 * zoom_cols * (n_zoom > 0), 8.5))
    outer = fig.add_gridspec(1, 2 if n_zoom else 1, width_ratios=[1.25, 1.0] if n_zoom else [1.0])
    ax = fig.add_subplot(outer[0, 0])
    zoom_grid = outer[0, 1].subgridspec(zoom_rows, zoom_cols) if n_zoom else None
    if truth is not None:
        ax.plot(truth["p"][:, 0], truth["p"][:, 1], color=TRUTH_COLOUR, lw=2.4, alpha=0.35, label="truth")
    if len(fix_t):
        ax.plot(fix_p[~dropped, 0], fix_p[~dropped, 1], ".", color="tab:green", ms=3, label="GNSS fix (used)")
        if dropped.any():
            ax.plot(fix_p[dropped, 0], fix_p[dropped, 1], "x", color=OUTAGE_COLOUR, ms=3, mew=0.8,
                    label="GNSS fix dropped (simulated outage)")
    for name, s in est.items():
        ax.plot(s["px"], s["py"], color=STYLE[name][1], lw=1.0, label=STYLE[name][0])
    for i, (a, b, kind) in enumerate(windows[:n_zoom]):
        if truth is None:
            break
        w = (truth["t"] >= a) & (truth["t"] <= b)
        if w.any():
            c = truth["p"][w][len(truth["p"][w]) // 2]
            ax.annotate(f"{i + 1}", c[:2], fontsize=10, fontweight="bold", color=OUTAGE_COLOUR,
                        xytext=(6, 6), textcoords="offset points")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_title("Top-down trajectory (numbers: GNSS outages, zoomed right)")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    for i, (a, b, kind) in enumerate(windows[:n_zoom]):
        zx = fig.add_subplot(zoom_grid[i // zoom_cols, i % zoom_cols])
        ref = truth if truth is not None else next(iter(est.values()))
        w = (ref["t"] >= a - 5) & (ref["t"] <= b + 5)
        if not w.any():
            continue
        # Centre on the truth where the estimators are furthest off inside the outage, sized to show it.
        centre, size, t_worst = ref["p"][w][len(ref["p"][w]) // 2], 20.0, None
        if err:
            worst = max(est, key=lambda n: drift(n, a, b))
            e = err[worst]
            ww = (e["t"] >= a) & (e["t"] <= b)
            if ww.any():
                t_worst = e["t"][ww][np.argmax(e["h"][ww])]
                centre = ref["p"][np.argmin(np.abs(ref["t"] - t_worst))]
                size = max(3.0, 1.6 * drift(worst, a, b))
        zx.plot(ref["p"][w, 0], ref["p"][w, 1], color=TRUTH_COLOUR, lw=2.4, alpha=0.35)
        fw = (fix_t >= a - 5) & (fix_t <= b + 5)
        zx.plot(fix_p[fw & ~dropped, 0], fix_p[fw & ~dropped, 1], ".", color="tab:green", ms=5)
        for name, s in est.items():
            ws = (s["t"] >= a - 5) & (s["t"] <= b + 5)
            zx.plot(s["px"][ws], s["py"][ws], color=STYLE[name][1], lw=1.2)
            if t_worst is not None:
                k = np.argmin(np.abs(s["t"] - t_worst))
                zx.plot(s["px"][k], s["py"][k], "o", color=STYLE[name][1], ms=5)
        if t_worst is not None:
            zx.plot(centre[0], centre[1], "o", color=TRUTH_COLOUR, ms=5)
        zx.set_xlim(centre[0] - size, centre[0] + size)
        zx.set_ylim(centre[1] - size, centre[1] + size)
        title = f"outage {i + 1}: {a - t0:.0f}-{b - t0:.0f} s" + (" (log gap)" if kind != "config" else "")
        if err:
            title += "\nlargest drift " + ", ".join(f"{STYLE[n][0]} {metres(drift(n, a, b))} m" for n in est)
        zx.set_title(title, fontsize=8)
        zx.set_aspect("equal", adjustable="box")
        zx.tick_params(labelsize=7)
        zx.grid(alpha=0.3)
    fig.suptitle(f"gins run {run_name}: trajectories in ENU at {origin[0]:.6f}, {origin[1]:.6f}"
                 + ("\n(right: each outage zoomed where the drift is largest; dots = positions at that time, truth black)"
                    if n_zoom else ""), fontsize=10)
    fig.tight_layout()
    save(fig, os.path.join(run, "trajectory.png"), written)

    if err:
        # ---- errors.png --------------------------------------------------------------------------------
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(12, 7.5), sharex=True, gridspec_kw=dict(height_ratios=[2, 1]))
        for name, e in err.items():
            a1.semilogy(e["t"] - t0, np.maximum(e["h"], 1e-4), color=STYLE[name][1], lw=0.9,
                        label=f"{STYLE[name][0]} (RMSE {math.sqrt(np.mean(e['h'] ** 2)):.2f} m)")
            a2.plot(e["t"] - t0, e["v"], color=STYLE[name][1], lw=0.9)
        shade(a1, windows, t0)
        shade(a2, windows, t0)
        for a, b, kind in windows:
            text = "\n".join(f"{STYLE[n][0]} {metres(drift(n, a, b))}" for n in est)
            a1.text((a + b) / 2 - t0, 0.97, text, transform=a1.get_xaxis_transform(), ha="center", va="top",
                    fontsize=7.5, bbox=dict(fc="white", ec="none", alpha=0.7, pad=1))
        lo, hi = a1.get_ylim()
        a1.set_ylim(lo, hi * 8)  # room for the outage labels
        a1.set_ylabel("horizontal error (m, log scale)")
        a1.set_title(f"gins run {run_name}: position error against truth "
                     "(numbers: largest horizontal drift in each outage, m)")
        a1.grid(alpha=0.3, which="both")
        a1.legend(handles=a1.get_legend_handles_labels()[0] + outage_legend_handles(windows), loc="lower right",
                  fontsize=8)
        a2.set_ylabel("vertical error (m)")
        a2.set_xlabel("time since the first record (s)")
        a2.grid(alpha=0.3)
        fig.tight_layout()
        save(fig, os.path.join(run, "errors.png"), written)

        # ---- outage_drift.png --------------------------------------------------------------------------
        if windows:
            fig, (b1, b2) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw=dict(width_ratios=[3, 2]))
            x = np.arange(len(windows))
            width = 0.8 / len(est)
            for k, name in enumerate(est):
                d = [drift(name, a, b) for a, b, _ in windows]
                bars = b1.bar(x + (k - (len(est) - 1) / 2) * width, d, width, color=STYLE[name][1],
                              label=STYLE[name][0])
                b1.bar_label(bars, labels=[metres(v) for v in d], fontsize=7)
            b1.set_xticks(x, [f"{i + 1}: {a - t0:.0f} s\n{b - a:.0f} s {'sim.' if k == 'config' else 'log gap'}"
                              for i, (a, b, k) in enumerate(windows)], fontsize=8)
            b1.set_ylabel("largest horizontal drift (m)")
            b1.set_title("Drift in each GNSS outage (lower is better)")
            b1.grid(alpha=0.3, axis="y")
            b1.legend(fontsize=8)
            labels = ["H RMSE (m)", "V RMSE (m)", "outage drift\nRMS (m)"]
            for k, name in enumerate(est):
                e = err[name]
                dr = [drift(name, a, b) for a, b, _ in windows]
                vals = [math.sqrt(np.mean(e["h"] ** 2)), math.sqrt(np.mean(e["v"] ** 2)),
                        math.sqrt(np.nanmean(np.square(dr)))]
                bars = b2.bar(np.arange(3) + (k - (len(est) - 1) / 2) * width, vals, width, color=STYLE[name][1],
                              label=STYLE[name][0])
                b2.bar_label(bars, fmt="%.2f", fontsize=7)
            b2.set_xticks(np.arange(3), labels, fontsize=8)
            b2.set_title("Whole run (lower is better)")
            b2.grid(alpha=0.3, axis="y")
            fig.suptitle(f"gins run {run_name}: " + ", ".join(STYLE[n][0] for n in est), fontsize=10)
            fig.tight_layout()
            save(fig, os.path.join(run, "outage_drift.png"), written)

        # ---- heading_error.png -------------------------------------------------------------------------
        fig, ax = plt.subplots(figsize=(12, 4.5))
        lim = 0.0
        for name, e in err.items():
            ax.plot(e["t"] - t0, e["yaw"], color=STYLE[name][1], lw=0.8,
                    label=f"{STYLE[name][0]} (RMSE {math.sqrt(np.mean(e['yaw'] ** 2)):.3f}°)")
            ax.plot(e["t"] - t0, 3 * e["sig_yaw"], color=STYLE[name][1], lw=0.6, ls="--", alpha=0.7)
            ax.plot(e["t"] - t0, -3 * e["sig_yaw"], color=STYLE[name][1], lw=0.6, ls="--", alpha=0.7)
            moving = e["t"] > init_t + 1
            lim = max(lim, np.percentile(np.abs(e["yaw"][moving]), 99.5) if moving.any() else 0.0)
        shade(ax, windows, t0)
        ax.set_ylim(-1.6 * lim - 0.01, 1.6 * lim + 0.01)
        ax.set_xlabel("time since the first record (s)")
        ax.set_ylabel("heading error (deg)")
        ax.set_title(f"gins run {run_name}: heading error against truth (dashed: ±3σ of each estimator)")
        ax.grid(alpha=0.3)
        ax.legend(handles=[h for h, l in zip(*ax.get_legend_handles_labels()) if not l.startswith("_")]
                  + outage_legend_handles(windows), fontsize=8, loc="upper left")
        fig.tight_layout()
        save(fig, os.path.join(run, "heading_error.png"), written)

    # ---- biases.png -----------------------------------------------------------------------------------
    fig, (g1, g2) = plt.subplots(2, 1, figsize=(12, 7), sharex=True)
    axis_colour = {"x": "tab:red", "y": "tab:green", "z": "tab:blue"}
    dash = {"eskf": "-", "smoother": "--", "eskf_rts": "-.", "batch": ":"}
    for name, s in est.items():
        for ax_name in "xyz":
            g1.plot(s["t"] - t0, s["bg" + ax_name] * 180 / math.pi * 3600, color=axis_colour[ax_name],
                    ls=dash[name], lw=0.9, label=f"{STYLE[name][0]} {ax_name}")
            g2.plot(s["t"] - t0, s["ba" + ax_name], color=axis_colour[ax_name], ls=dash[name], lw=0.9,
                    label=f"{STYLE[name][0]} {ax_name}")
    for g in (g1, g2):
        shade(g, windows, t0)
        g.grid(alpha=0.3)
        g.legend(handles=g.get_legend_handles_labels()[0] + outage_legend_handles(windows), fontsize=7, ncol=4,
                 loc="upper right")
    g1.set_ylabel("gyro bias (deg/h)")
    g2.set_ylabel("accelerometer bias (m/s²)")
    g2.set_xlabel("time since the first record (s)")
    g1.set_title(f"gins run {run_name}: bias estimates (body axes; solid ESKF, dashed smoother)")
    fig.tight_layout()
    save(fig, os.path.join(run, "biases.png"), written)

    # ---- gnss_residuals.png ---------------------------------------------------------------------------
    if len(fix_t):
        fig, (r1, r2) = plt.subplots(2, 1, figsize=(12, 7), sharex=True, gridspec_kw=dict(height_ratios=[2, 1]))
        for name, s in est.items():
            sel = (fix_t >= s["t"][0]) & (fix_t <= s["t"][-1]) & ~dropped
            tf = fix_t[sel]
            q = np.stack([np.interp(tf, s["t"], s[c]) for c in ("qw", "qx", "qy", "qz")], -1)
            q /= np.linalg.norm(q, axis=1, keepdims=True)
            ant = interp(s["t"], tf, s["p"]) + quat_rot(q) @ lever
            res = fix_p[sel] - ant
            rh = np.linalg.norm(res[:, :2], axis=1)
            stats = summary.get("estimators", {}).get(name, {}).get("gnss_position", {})
            rejected = np.array(stats.get("rejected_times", []))
            n_rej = sum(stats.get("rejected", {}).values())
            r1.semilogy(tf - t0, np.maximum(rh, 1e-4), ".", color=STYLE[name][1], ms=2.5,
                        label=f"{STYLE[name][0]}: {len(tf)} fixes, {n_rej} rejected")
            r2.plot(tf - t0, res[:, 2], ".", color=STYLE[name][1], ms=2.5)
            idx = [int(np.argmin(np.abs(tf - r))) for r in rejected if len(tf)]
            idx = [i for i, r in zip(idx, rejected) if abs(tf[i] - r) < 1e-3]
            if idx:
                r1.semilogy(tf[idx] - t0, np.maximum(rh[idx], 1e-4), "X", color=STYLE[name][1], mec="k",
                            ms=12 if name == "eskf" else 7, label=f"{STYLE[name][0]}: rejected fix")
        shade(r1, windows, t0)
        shade(r2, windows, t0)
        r1.set_ylabel("horizontal residual (m, log)")
        r1.set_title(f"gins run {run_name}: GNSS fix minus estimated antenna position at the fix time "
                     "(fixes in simulated outages not shown)")
        r1.grid(alpha=0.3, which="both")
        lo, hi = r1.get_ylim()
        r1.set_ylim(lo, hi * 30)  # room for the legend above the residuals
        r1.legend(handles=r1.get_legend_handles_labels()[0] + outage_legend_handles(windows), fontsize=8,
                  loc="upper left", ncol=3)
        r2.set_ylabel("up residual (m)")
        r2.set_xlabel("time since the first record (s)")
        r2.grid(alpha=0.3)
        fig.tight_layout()
        save(fig, os.path.join(run, "gnss_residuals.png"), written)

    for p in written:
        print(f"wrote {p}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
