"""The sample's outputs opened by the clients users have (docs/formats.md §5): pandas reads every CSV with named
columns; GDAL's ogrinfo reads the KML, GPX and GeoJSON of `gins export` with the right features and extent;
pynmea2 parses every sentence of `gins stream --out-format nmea` and `gins export --format nmea` with its
checksum, and their positions are the TUM output's to 1 cm; a truth exported as TUM in a run's frame is the
truth. The expectations come from the run's own files and an independent geodesy (scripts/gins_geo.py).

usage: export_clients_test.py GINS_BINARY SOURCE_DIR
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd
import pynmea2

gins, src = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.join(src, "scripts"))
from gins_geo import lla_to_enu  # noqa: E402

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def run(args, stdin=None):
    r = subprocess.run([gins] + args, stdin=stdin, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"gins {' '.join(args)} exited {r.returncode}: {r.stderr}")
    return r.stdout


def read_tum(path):
    with open(path) as f:
        first = f.readline()
    origin = [float(v) for v in first.split("origin_lla=")[1].split()[:3]]
    return origin, np.loadtxt(path, comments="#", ndmin=2)


work = tempfile.mkdtemp(prefix="gins_export_")
log, truth = os.path.join(src, "data/sample/log.txt.gz"), os.path.join(src, "data/sample/truth.csv.gz")
config = os.path.join(src, "config/default.yaml")
out = os.path.join(work, "run")
run(["run", "--config", config, "--log", log, "--truth", truth, "--out", out, "--mode", "both"])
summary = json.load(open(os.path.join(out, "summary.json")))

# 1. Every CSV output opens in pandas as it is: named columns, numbers only, a row per TUM row.
for name in sorted(os.listdir(out)):
    if not name.endswith(".csv"):
        continue
    d = pd.read_csv(os.path.join(out, name))
    check(d.columns[0] == "t" and len(d.columns) in (7, 27), f"{name}: columns {list(d.columns)[:5]}")
    check(all(np.issubdtype(t, np.number) for t in d.dtypes), f"{name}: a column that is not numeric")
    check(not d.isna().any().any(), f"{name}: empty or NaN fields")
    stream = name.rsplit("_", 1)[0]
    _, tum = read_tum(os.path.join(out, stream + ".tum"))
    check(len(d) == len(tum), f"{name}: {len(d)} rows, {stream}.tum {len(tum)}")

# 2. The map formats in GDAL: features (track pieces at the gap, the smoother's rejected fix) and extent.
lla = pd.read_csv(os.path.join(out, "smoother_lla.csv"))
t = lla["t"].to_numpy()
windows = [w for w in summary["gnss_outages"] + summary["gnss_gaps"] if np.any((t >= w[0]) & (t <= w[1]))]
expected_lines = 1 + 2 * len(windows)
expected_points = len(summary["estimators"]["smoother"]["gnss_position"]["rejected_times"])
check(expected_lines == 3 and expected_points == 1, f"the sample has one gap and one rejected outlier "
      f"({expected_lines} lines, {expected_points} points)")
extent = (lla["lon_deg"].min(), lla["lat_deg"].min(), lla["lon_deg"].max(), lla["lat_deg"].max())


def ogr_layers(path):
    text = subprocess.run(["ogrinfo", "-ro", "-al", "-so", path], capture_output=True, text=True, check=True).stdout
    layers = {}
    for block in text.split("Layer name: ")[1:]:
        name = block.split("\n", 1)[0].strip()
        count = int(re.search(r"Feature Count: (\d+)", block).group(1))
        m = re.search(r"Extent: \(([-\d.]+), ([-\d.]+)\) - \(([-\d.]+), ([-\d.]+)\)", block)
        layers[name] = (count, tuple(float(v) for v in m.groups()) if m else None)
    return layers


def ogr_geometry_count(path, geometry):
    text = subprocess.run(["ogrinfo", "-ro", "-al", "-so", "-where", f"OGR_GEOMETRY='{geometry}'", path],
                          capture_output=True, text=True, check=True).stdout
    return sum(int(n) for n in re.findall(r"Feature Count: (\d+)", text))


def near_extent(got, want, what):
    # Points lie on the track (rejected fixes may lie off it); a track's extent is the CSV's to ogrinfo's digits.
    check(got is not None and all(abs(a - b) < 2e-6 for a, b in zip(got, want)), f"{what}: extent {got} vs {want}")


for fmt in ("kml", "gpx", "geojson"):
    path = os.path.join(work, "sample." + fmt)
    run(["export", "--format", fmt, out, "--out", path])
    layers = ogr_layers(path)
    if fmt == "kml":
        check(layers.get("lines", (0,))[0] == expected_lines, f"kml lines {layers}")
        check(layers.get("points", (0,))[0] == expected_points, f"kml points {layers}")
        near_extent(layers["lines"][1], extent, "kml")
    elif fmt == "gpx":
        check(layers["tracks"][0] == expected_lines, f"gpx tracks {layers}")
        check(layers["waypoints"][0] == expected_points, f"gpx waypoints {layers}")
        # Every state, the pieces sharing their boundary states.
        check(layers["track_points"][0] == len(lla) + expected_lines - 1, f"gpx track points {layers}")
        near_extent(layers["tracks"][1], extent, "gpx")
    else:
        check(ogr_geometry_count(path, "LINESTRING") == expected_lines, "geojson lines")
        check(ogr_geometry_count(path, "POINT") == expected_points, "geojson points")
        (count, ext), = layers.values()
        check(count == expected_lines + expected_points, f"geojson features {layers}")
        lo = (min(extent[0], ext[0]), min(extent[1], ext[1]))
        near_extent(ext[:2], lo, "geojson")

# 3. NMEA: every sentence parses with its checksum; positions are the TUM file's to 1 cm.
origin, tum = read_tum(os.path.join(out, "eskf.tum"))


def gga_positions(text, what):
    sentences = [s for s in text.split("\r\n") if s]
    check(all(len(s) <= 82 for s in sentences), f"{what}: a sentence over 82 characters")
    parsed = [pynmea2.parse(s, check=True) for s in sentences]  # raises on a bad checksum or sentence
    kinds = {type(p).__name__ for p in parsed}
    check({"GGA", "RMC"} <= kinds, f"{what}: sentence kinds {kinds}")
    gga = [p for p in parsed if isinstance(p, pynmea2.types.talker.GGA)]
    lat = np.array([p.latitude for p in gga])
    lon = np.array([p.longitude for p in gga])
    alt = np.array([float(p.altitude) for p in gga])
    return lla_to_enu(lat, lon, alt, origin), gga, parsed


with open(log, "rb") as f:
    import gzip
    log_text = gzip.decompress(f.read())
streamed = subprocess.run([gins, "stream", "--config", config, "--mode", "eskf", "--out-format", "nmea",
                           "--rate", "0"], input=log_text, capture_output=True, check=True).stdout.decode()
p_enu, gga, _ = gga_positions(streamed, "gins stream")
check(len(gga) == len(tum), f"stream: {len(gga)} GGA for {len(tum)} TUM rows")
if len(gga) == len(tum):
    err = np.linalg.norm(p_enu - tum[:, 1:4], axis=1).max()
    print(f"stream NMEA vs eskf.tum: largest difference {err * 1000:.2f} mm over {len(gga)} states")
    check(err < 0.01, f"stream NMEA positions {err:.4f} m from the TUM file")

exported = os.path.join(work, "eskf.nmea")
run(["export", "--format", "nmea", "--stream", "eskf", out, "--out", exported])
p_enu, gga, parsed = gga_positions(open(exported, newline="").read(), "gins export")
# One epoch per second: the first state at or after each whole second.
grid = []
next_t = -math.inf
for row in tum:
    if row[0] >= next_t - 1e-6:
        grid.append(row)
        next_t = math.floor(row[0] + 1e-6) + 1.0
grid = np.array(grid)
check(len(gga) == len(grid), f"export: {len(gga)} GGA for {len(grid)} whole seconds")
if len(gga) == len(grid):
    err = np.linalg.norm(p_enu - grid[:, 1:4], axis=1).max()
    print(f"export NMEA (1 Hz) vs eskf.tum: largest difference {err * 1000:.2f} mm over {len(gga)} epochs")
    check(err < 0.01, f"export NMEA positions {err:.4f} m from the TUM file")
    # Dead reckoning (quality 6) exactly in the log's gap.
    gap = summary["gnss_gaps"][0]
    inside = (grid[:, 0] >= gap[0]) & (grid[:, 0] <= gap[1])
    q = np.array([int(g.gps_qual) for g in gga])
    check(np.all(q[inside] == 6) and np.all(q[~inside] != 6) and inside.any(), "GGA quality 6 only in the gap")
check(any(isinstance(p, pynmea2.types.talker.GST) for p in parsed), "export: no GST from a states CSV")

# 4. A truth as TUM in the run's frame (for evo) is the truth, through an independent geodesy.
truth_tum = os.path.join(work, "truth.tum")
run(["export", "--format", "tum", truth, "--frame", out, "--out", truth_tum])
t_origin, t_rows = read_tum(truth_tum)
check(np.allclose(t_origin, origin, atol=1e-9), f"truth.tum origin {t_origin} vs the run's {origin}")
tr = pd.read_csv(truth)
want = lla_to_enu(tr["lat"].to_numpy(), tr["lon"].to_numpy(), tr["alt"].to_numpy(), origin)
check(len(t_rows) == len(tr), "truth.tum rows")
err = np.linalg.norm(t_rows[:, 1:4] - want, axis=1).max()
check(err < 2e-5, f"truth.tum positions {err} m from the truth")

# 5. Refusals name the cause: a foreign TUM file without --origin, --stream on a file.
foreign = os.path.join(work, "foreign.tum")
np.savetxt(foreign, tum[:10])
r = subprocess.run([gins, "export", "--format", "kml", foreign, "--out", os.path.join(work, "f.kml")],
                   capture_output=True, text=True)
check(r.returncode == 1 and "--origin" in r.stderr and not os.path.exists(os.path.join(work, "f.kml")),
      f"foreign TUM: {r.returncode} {r.stderr}")
r = subprocess.run([gins, "export", "--format", "kml", foreign, "--origin", "31.5,120.4,10", "--out",
                    os.path.join(work, "f.kml")], capture_output=True, text=True)
check(r.returncode == 0 and os.path.exists(os.path.join(work, "f.kml")), f"foreign TUM with --origin: {r.stderr}")

if failures:
    sys.exit(f"{len(failures)} check(s) failed")
print("export clients: all checks passed")
