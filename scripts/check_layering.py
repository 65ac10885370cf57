#!/usr/bin/env python3
"""Checks that the production libraries include one another in one direction only (docs/architecture.md).

Each source folder is one static library; a file may include headers of its own library and of the
libraries it is allowed to use, never of a library above it. The allowed sets form a strict order, so the
include graph between libraries has no cycles. Exits non-zero and names every offending include.

  scripts/check_layering.py [source_root]
"""
import os
import re
import sys

# Library -> its folder and the libraries it may include (besides itself). "public" is the API's installed
# header, gins/gins.h: it may include no gins header at all, so its users need none of the internals.
LAYERS = {
    "core": ("core", []),
    "io": ("core/io", ["core"]),
    "eval": ("core/eval", ["core", "io"]),
    "sim": ("core/sim", ["core", "io"]),
    "factors": ("factors", ["core"]),
    "solver": ("solver", ["core", "io", "eval", "factors"]),
    "config": ("config", ["core", "io", "eval", "sim", "factors", "solver"]),
    "public": ("apps/include/gins", []),
    "api": ("apps/api", ["core", "io", "eval", "sim", "factors", "solver", "config", "public"]),
    "apps": ("apps", ["core", "io", "eval", "sim", "factors", "solver", "config", "public", "api"]),
    # The Python extension: the public API and `gins run` (apps), the error types Run throws (io, solver), the
    # output files' number format (io) and the world frame's geodetic conversion (core), no other internals.
    "python": ("apps/python", ["core", "io", "solver", "public", "apps"]),
}
# Include paths that are not the folder under the source root: the public header is included as
# "gins/gins.h" (its include directory is apps/include, as once installed).
INCLUDE_FOLDERS = {"gins": "apps/include/gins"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
SYSTEM_INCLUDE = re.compile(r'^\s*#\s*include\s+<([^>]+)>')


def library_of(path):
    """The library a header path (as included) belongs to, or None."""
    folder = os.path.dirname(path)
    folder = INCLUDE_FOLDERS.get(folder, folder)
    for name, (lib_folder, _) in LAYERS.items():
        if folder == lib_folder:
            return name
    return None


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    problems = []
    for name, (folder, allowed) in LAYERS.items():
        directory = os.path.join(root, folder)
        for entry in sorted(os.listdir(directory)):
            if not entry.endswith((".h", ".cc")):
                continue
            path = os.path.join(directory, entry)
            with open(path, encoding="utf-8") as f:
                for number, line in enumerate(f, 1):
                    system = SYSTEM_INCLUDE.match(line)
                    if system and name == "public" and re.search(r"[./]", system.group(1)):
                        # Only the C++ standard library (no Eigen, Ceres, ...): the header's users need nothing else.
                        problems.append(f"{folder}/{entry}:{number}: the public header may include only standard headers, not <{system.group(1)}>")
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    target = library_of(m.group(1))
                    if target is None:
                        problems.append(f"{folder}/{entry}:{number}: includes {m.group(1)}, which is in no library")
                    elif target != name and target not in allowed:
                        problems.append(f"{folder}/{entry}:{number}: {name} may not include {m.group(1)} ({target})")
    for p in problems:
        print(p)
    if problems:
        return 1
    print("layering: %d libraries, includes point one way only" % len(LAYERS))
    return 0


if __name__ == "__main__":
    sys.exit(main())
