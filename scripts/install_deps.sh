#!/usr/bin/env bash
# Installs the Debian packages gins needs that are not installed yet (run as root on Debian 12). --test adds
# the clients the test suite opens gins's outputs with; other arguments are further packages wanted (the
# benchmark scripts add libbenchmark-dev and time).
set -euo pipefail
extra=()
for a in "$@"; do
  if [ "$a" = --test ]; then
    # tests/apps/export_clients_test.py: GDAL's ogrinfo (KML, GPX, GeoJSON), pynmea2, pandas.
    extra+=(gdal-bin python3-nmea2 python3-pandas)
  else
    extra+=("$a")
  fi
done
packages=("${extra[@]}"
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev libgoogle-glog-dev libyaml-cpp-dev
  libgeographiclib-dev libcli11-dev nlohmann-json3-dev zlib1g-dev
  libgtest-dev libgmock-dev
  python3 python3-numpy python3-matplotlib
  python3-dev python3-pybind11 pybind11-dev python3-pytest  # the Python package gins (apps/python), its tests
  parallel  # docs/fleet.md's recipe, which the tests run
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "gins: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
