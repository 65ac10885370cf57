"""Shared by the scripts: reading plain or gzip text, and WGS-84 geodesy (LLA -> ECEF -> local ENU).

Written independently of gins's C++ (GeographicLib) so the scripts can check its numbers.
"""
import gzip

import numpy as np

A = 6378137.0
F = 1.0 / 298.257223563
E2 = F * (2 - F)


def open_text(path):
    """Text stream of a plain or gzip file (detected by its magic bytes, as gins does)."""
    with open(path, "rb") as f:
        magic = f.read(2)
    return gzip.open(path, "rt") if magic == b"\x1f\x8b" else open(path, "rt")


def output_origin(path):
    """(origin (lat, lon, alt) or None, mode) of a gins output: from its first comment line (TUM files), or
    for a *_states.csv, which starts with its column names, from the TUM file beside it."""
    candidates = [path]
    for suffix in ("_states.csv", "_states.csv.gz"):
        if path.endswith(suffix):
            stem = path[:-len(suffix)]
            candidates += [stem + ".tum", stem + ".tum.gz"]
    for c in candidates:
        try:
            with open_text(c) as f:
                first = f.readline()
        except OSError:
            continue
        if first.startswith("#") and "origin_lla=" in first:
            origin = [float(v) for v in first.split("origin_lla=")[1].split()[:3]]
            mode = first.split("mode=")[1].split()[0] if "mode=" in first else ""
            return origin, mode
    return None, ""


def lla_to_ecef(lat, lon, alt):
    lat, lon = np.radians(lat), np.radians(lon)
    n = A / np.sqrt(1 - E2 * np.sin(lat) ** 2)
    return np.stack([(n + alt) * np.cos(lat) * np.cos(lon), (n + alt) * np.cos(lat) * np.sin(lon),
                     (n * (1 - E2) + alt) * np.sin(lat)], axis=-1)


def rot_enu_from_ecef(lat_deg, lon_deg):
    """Rows: the E, N, U unit vectors in ECEF (vectorised over points)."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    z = np.zeros_like(lat)
    return np.stack([np.stack([-so, co, z], -1),
                     np.stack([-sl * co, -sl * so, cl], -1),
                     np.stack([cl * co, cl * so, sl], -1)], -2)


def lla_to_enu(lat, lon, alt, origin):
    """Points in the ENU frame at origin = (lat, lon, alt) in degrees and metres."""
    o = [np.array(v, dtype=float) for v in origin[:3]]
    d = lla_to_ecef(lat, lon, alt) - lla_to_ecef(o[0], o[1], o[2])
    return d @ rot_enu_from_ecef(o[0], o[1]).T
