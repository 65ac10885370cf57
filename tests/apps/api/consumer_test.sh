#!/usr/bin/env bash
# The installed package as a user gets it: `cmake --install` into a temporary prefix; only the public header
# is installed; the stand-alone examples/ project finds gins with find_package (no path into the source
# tree), builds and runs on the sample; its states match `gins run`'s (the installed gins); the same program
# builds with pkg-config. ctest runs this (Api.InstalledPackage); usage: consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d /tmp/gins_consumer.XXXXXX)
prefix=$work/prefix
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >/dev/null
for f in include/gins/gins.h lib/libgins.a lib/cmake/gins/ginsConfig.cmake lib/cmake/gins/ginsConfigVersion.cmake \
         lib/cmake/gins/ginsTargets.cmake lib/pkgconfig/gins.pc bin/gins share/gins/default.yaml; do
  [ -f "$prefix/$f" ] || fail "not installed: $f"
done
headers=$(cd "$prefix/include" && find . -type f | sort | tr '\n' ' ')
[ "$headers" = "./gins/gins.h " ] || fail "installed headers are not just gins/gins.h: $headers"

# The example project, copied away from the source tree so that nothing can reach into it.
cp -r "$src/examples" "$work/examples"
cmake -S "$work/examples" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" -j2 >/dev/null
if grep -rq -- "$src" "$work/build/CMakeFiles/gins_example.dir/flags.make"; then
  fail "the example's compile flags point into the source tree"
fi

"$work/build/gins_example" "$prefix/share/gins/default.yaml" "$src/data/sample/log.txt.gz" >"$work/example.txt" \
  2>"$work/example.err" || fail "gins_example failed: $(cat "$work/example.err")"
"$prefix/bin/gins" run --config "$prefix/share/gins/default.yaml" --log "$src/data/sample/log.txt.gz" \
  --out "$work/run" --mode eskf >/dev/null
# One line per state; the last state's position as gins run wrote it (the run keeps one state per time).
python3 - "$work/example.txt" "$work/run/eskf.tum" <<'PY' || fail "the example's states differ from gins run's"
import sys
example = [l.split() for l in open(sys.argv[1])]
tum = [l.split() for l in open(sys.argv[2]) if not l.startswith("#")]
assert len(example) >= len(tum) > 10000, (len(example), len(tum))
by_time = {round(float(l[0]), 3): l for l in example}
for row in tum[::500] + tum[-1:]:
    e = by_time[round(float(row[0]), 3)]
    for k in range(3):
        assert abs(float(e[1 + k]) - float(row[1 + k])) < 1.5e-3, (row, e)
print("example: %d states, %d in gins run's eskf.tum, positions agree" % (len(example), len(tum)))
PY
grep -Eq "gins [0-9]+\.[0-9]+\.[0-9]+" "$work/example.err" || fail "no status line: $(cat "$work/example.err")"

# pkg-config: the same program without CMake.
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
g++ -std=c++17 -O1 "$work/examples/gins_example.cc" -o "$work/example_pc" $(pkg-config --cflags --libs gins)
"$work/example_pc" "$prefix/share/gins/default.yaml" "$src/data/sample/log.txt.gz" 2>/dev/null | cmp -s - "$work/example.txt" \
  || fail "the pkg-config build prints something else"

# A version this package does not satisfy is refused.
sed 's/find_package(gins 0.1 REQUIRED)/find_package(gins 0.2 REQUIRED)/' "$src/examples/CMakeLists.txt" \
  >"$work/examples/CMakeLists.txt"
if cmake -S "$work/examples" -B "$work/build_v" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null 2>&1; then
  fail "find_package(gins 0.2) accepted version 0.1"
fi
rm -rf "$work"
echo "installed package: found by find_package and pkg-config, example built and run"
