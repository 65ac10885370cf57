#!/usr/bin/env bash
# The rtkx check of `gins convert --format rtklib-pos | nmea` (docs/formats.md §6): single-point solutions of
# ../shared/data/rtkx_walk_raw's RINEX by Debian's rnx2rtkp (-p 0; GPS+Galileo+BeiDou, broadcast
# ionosphere, Saastamoinen, 15° mask) as a .pos and as NMEA (-n), each converted with the walk's IMU log and
# run through `gins run --mode eskf`; the reference is the same fixes written as gins GNSS (and, from NMEA,
# GVEL) records by an independent reader in this script (Python), merged with the same IMU log. The tracks
# must be the same: the script prints the records that differ and the TUM files' largest difference, and
# fails unless both are zero. It also prints how far the .pos and NMEA tracks are apart (not the same fixes:
# NMEA has no σ and adds RMC's velocity) and how the ECEF form of the .pos compares.
#
#   [KEEP=1] scripts/check_gnss_formats.sh [BUILD_DIR (default build-conv)] [DATA_DIR (default ../shared/data/rtkx_walk_raw)]
# KEEP=1 keeps the work folder (its path is printed).
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build-conv}"
data="${2:-../shared/data/rtkx_walk_raw}"
gins="$build/gins"
[ -x "$gins" ] || { echo "check_gnss_formats: no $gins (cmake --build $build --target gins)"; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "check_gnss_formats: rnx2rtkp missing (apt-get install rtklib)"; exit 2; }
work="$(mktemp -d /tmp/gins_gnss_formats.XXXXXX)"
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
[ -z "${KEEP:-}" ] || echo "work folder: $work"

zcat "$data/obs.rnx.gz" >"$work/obs.rnx"
zcat "$data/nav.rnx.gz" >"$work/nav.rnx"
# The options the shared data's README states for its single-point check: rnx2rtkp has no flags for the
# ionosphere and troposphere models, so they go in an options file.
cat >"$work/spp.conf" <<'EOF'
pos1-ionoopt       =brdc
pos1-tropopt       =saas
EOF
spp=(rnx2rtkp -k "$work/spp.conf" -p 0 -sys G,E,C -m 15)
"${spp[@]}" -o "$work/spp.pos" "$work/obs.rnx" "$work/nav.rnx" 2>/dev/null
"${spp[@]}" -n -o "$work/spp.nmea" "$work/obs.rnx" "$work/nav.rnx" 2>/dev/null
"${spp[@]}" -e -o "$work/spp_ecef.pos" "$work/obs.rnx" "$work/nav.rnx" 2>/dev/null
echo "rnx2rtkp: $(grep -vc '^%' "$work/spp.pos") solutions in spp.pos, $(grep -c GGA "$work/spp.nmea") GGA in spp.nmea"

# The walk's sensors (the data README's "For gins"): no heading, no wheels, no non-holonomic constraint.
cat >"$work/rtkx.yaml" <<'EOF'
imu:
  gyro_noise_deg_sqrt_h: 0.15
  acc_noise_m_s_sqrt_h: 0.04
  init_gyro_bias_sigma_deg_h: 720
gnss:
  lever_arm_m: [0.0, 0.05, 0.0]
  mount_yaw_deg: 0.0
  use_heading: false
wheel:
  enabled: false
vehicle:
  nonholonomic: false
init:
  static_duration_s: 1.5
EOF

imu_log="$data/log.txt.gz"
for f in pos nmea ecef; do
  case $f in
    pos) format=rtklib-pos; gnss="$work/spp.pos" ;;
    nmea) format=nmea; gnss="$work/spp.nmea" ;;
    ecef) format=rtklib-pos; gnss="$work/spp_ecef.pos" ;;
  esac
  "$gins" convert --format "$format" --gnss "$gnss" --imu "$imu_log" --out "$work/$f.txt" --on-error stop \
    >"$work/convert_$f.txt"
done
sed 's/^/  /' "$work/convert_nmea.txt"

# The reference: the same fixes written as gins records by this script's own reading of the two files.
/usr/bin/python3 - "$work" "$imu_log" <<'EOF'
import gzip, math, sys
work, imu_log = sys.argv[1], sys.argv[2]
GPS_EPOCH_DAYS = 3657            # 1970-01-01 .. 1980-01-06
LEAP = 18                        # GPS - UTC since 2017-01-01 (the walk is 2025)

def days_from_civil(y, m, d):
    y -= m <= 2
    era = (y if y >= 0 else y - 399) // 400
    yoe = y - era * 400
    doy = (153 * (m + (-3 if m > 2 else 9)) + 2) // 5 + d - 1
    return era * 146097 + yoe * 365 + yoe // 4 - yoe // 100 + doy - 719468

def split(sec):                  # "39.750" -> 39, 0.75: the whole seconds and the fraction, as gins splits them
    whole, _, frac = sec.partition(".")
    return int(whole), float("." + frac) if frac else 0.0

def gnss(t, lat, lon, h, s):
    return (t, "GNSS %r %r %r %r 0 0 %r %r %r" % (t, lat, lon, h, s[0], s[1], s[2]))

def pos_records(path):           # RTKLIB: GPST calendar time, lat lon height, Q ns sdn sde sdu ...
    out = []
    for line in open(path):
        if line.startswith("%"):
            continue
        f = line.split()
        y, mo, d = map(int, f[0].split("/"))
        hh, mm, ss = f[1].split(":")
        s, frac = split(ss)
        whole = (days_from_civil(y, mo, d) - GPS_EPOCH_DAYS) * 86400 + int(hh) * 3600 + int(mm) * 60 + s
        t = whole + frac
        out.append(gnss(t, float(f[2]), float(f[3]), float(f[4]), (float(f[8]), float(f[7]), float(f[9]))))
    return out

def coord(text, hemi, neg):
    dot = text.index(".")
    return (-1.0 if hemi == neg else 1.0) * (float(text[:dot - 2]) + float(text[dot - 2:]) / 60.0)

def nmea_records(path):          # RMC (date, speed, course) then GGA per epoch, UTC; no GST: HDOP x 2 m (single)
    out, date = [], None
    for line in open(path):
        body = line.strip()[1:].split("*")[0]
        f = body.split(",")
        hhmmss, frac = split(f[1])
        sod = hhmmss // 10000 * 3600 + hhmmss // 100 % 100 * 60 + hhmmss % 100
        if f[0].endswith("RMC"):
            date = days_from_civil(2000 + int(f[9][4:6]), int(f[9][2:4]), int(f[9][0:2])) - GPS_EPOCH_DAYS
            v = float(f[7]) * (1852.0 / 3600.0)
            c = float(f[8]) * (math.pi / 180.0)
            vel = (v * math.sin(c), v * math.cos(c), v)
            continue
        t = (date * 86400 + sod + LEAP) + frac
        hdop = float(f[8])
        out.append(gnss(t, coord(f[2], f[3], "S"), coord(f[4], f[5], "W"), float(f[9]) + float(f[11]),
                        (hdop * 2.0, hdop * 2.0, hdop * 4.0)))
        out.append((t, "GVEL %r %r %r %r 0.1 0.1 %r" % (t, vel[0], vel[1], 0.0, max(0.5, 0.1 * vel[2]))))
    return out

def merged(records, name):       # stable: at equal times the IMU line first
    imu = []
    for line in gzip.open(imu_log, "rt"):
        if line.startswith("IMU"):
            imu.append((float(line.split()[1]), line.rstrip("\n")))
    i = j = 0
    with open(f"{work}/{name}", "w") as out:
        while i < len(imu) or j < len(records):
            if j == len(records) or (i < len(imu) and imu[i][0] <= records[j][0]):
                out.write(imu[i][1] + "\n"); i += 1
            else:
                out.write(records[j][1] + "\n"); j += 1

merged(pos_records(f"{work}/spp.pos"), "pos_ref.txt")
merged(nmea_records(f"{work}/spp.nmea"), "nmea_ref.txt")
EOF

for f in pos pos_ref nmea nmea_ref ecef; do
  "$gins" run --config "$work/rtkx.yaml" --log "$work/$f.txt" --out "$work/run_$f" --mode eskf >"$work/run_$f.txt" 2>&1 ||
    { cat "$work/run_$f.txt"; exit 1; }
done

/usr/bin/python3 - "$work" <<'EOF'
import math, sys
work = sys.argv[1]

def records(name):               # the GNSS and GVEL records as numbers, in file order
    out = []
    for line in open(f"{work}/{name}.txt"):
        if line.startswith(("GNSS", "GVEL")):
            f = line.split()
            out.append((f[0], tuple(float(x) for x in f[1:])))
    return out

def tum(name):
    rows = {}
    for line in open(f"{work}/run_{name}/eskf.tum"):
        if not line.startswith("#"):
            v = [float(x) for x in line.split()]
            rows[v[0]] = v[1:4]  # a repeated time: the later row supersedes (docs/formats.md §5.2)
    return rows

def compare(a, b):
    ta, tb = tum(a), tum(b)
    common = sorted(set(ta) & set(tb))
    d = [math.dist(ta[t], tb[t]) for t in common]
    return len(ta), len(tb), len(common), max(d), math.sqrt(sum(x * x for x in d) / len(d))

ok = True
for a, b in (("pos", "pos_ref"), ("nmea", "nmea_ref")):
    ra, rb = records(a), records(b)
    differ = sum(1 for x, y in zip(ra, rb) if x != y) + abs(len(ra) - len(rb))
    na, nb, n, dmax, drms = compare(a, b)
    same = differ == 0 and na == nb == n and dmax == 0.0
    ok &= same
    print(f"{a:>4} converted vs written as GNSS records: {len(ra)} vs {len(rb)} records, {differ} differ; "
          f"eskf.tum {na} vs {nb} rows, max |dp| {dmax:.3e} m, rms {drms:.3e} m: {'same' if same else 'DIFFERENT'}")
na, nb, n, dmax, drms = compare("pos", "nmea")
print(f".pos vs NMEA tracks (NMEA: σ from HDOP 1.0 x 2 m, RMC velocity as GVEL): {n} rows, max |dp| {dmax:.3f} m, "
      f"rms {drms:.3f} m")
na, nb, n, dmax, drms = compare("pos", "ecef")
print(f".pos lat/lon/height vs x/y/z-ecef (σ rotated to ENU): {n} rows, max |dp| {dmax:.4f} m, rms {drms:.4f} m")
sys.exit(0 if ok else 1)
EOF
