#!/usr/bin/env python3
"""Checks every C++ source of the tree for what the build cannot take (names each offending line).

<regex>: GCC 12 warns inside std::regex (-Wmaybe-uninitialized) at the sanitizer build's -O1, which
-Werror turns into a failed CI run, while the Release build stays quiet. Parse by hand instead.

An anonymous namespace in a test file (tests/**/*_test.cc, tests/test_util.cc): the tests are compiled several files to a
translation unit (a unity build, tests/CMakeLists.txt), where two files' helpers of the same name would
clash or, worse, overload each other. Their helpers go in `namespace GINS_TEST_FILE`, unique per file.

  scripts/check_sources.py [source_root]
"""
import os
import re
import sys

BANNED = {"regex": "std::regex fails the sanitizer build (GCC 12 -Wmaybe-uninitialized at -O1 -Werror)"}
FOLDERS = ["core", "factors", "solver", "config", "apps", "tests", "examples"]
SYSTEM_INCLUDE = re.compile(r"^\s*#\s*include\s+<([^>]+)>")
ANONYMOUS_NAMESPACE = re.compile(r"^\s*namespace\s*\{")


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    problems = []
    for folder in FOLDERS:
        for directory, _, files in os.walk(os.path.join(root, folder)):
            for entry in sorted(files):
                if not entry.endswith((".h", ".cc", ".cpp")):
                    continue
                path = os.path.join(directory, entry)
                # The sources of the test executables, which tests/CMakeLists.txt compiles as a unity build.
                test_file = folder == "tests" and (entry.endswith("_test.cc") or entry == "test_util.cc")
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = SYSTEM_INCLUDE.match(line)
                        if m and m.group(1) in BANNED:
                            problems.append(f"{os.path.relpath(path, root)}:{number}: <{m.group(1)}>: {BANNED[m.group(1)]}")
                        if test_file and ANONYMOUS_NAMESPACE.match(line):
                            problems.append(f"{os.path.relpath(path, root)}:{number}: an anonymous namespace in a test "
                                            "file (unity build): write `namespace GINS_TEST_FILE {`")
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
