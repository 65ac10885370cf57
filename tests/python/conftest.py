"""Fixtures of the Python package's tests (ctest: Python.*; run with Debian's /usr/bin/python3 -m pytest).

ctest sets PYTHONPATH to the built package, GINS_BINARY to the `gins` command of the same build and
GINS_SOURCE_DIR to the source tree. Run by hand:
  PYTHONPATH=build/apps/python/package GINS_BINARY=build/gins /usr/bin/python3 -m pytest tests/python
"""
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("GINS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
GINS_BINARY = os.environ.get("GINS_BINARY", str(SOURCE_DIR / "build" / "gins"))
CONFIG = SOURCE_DIR / "config" / "default.yaml"
LOG = SOURCE_DIR / "data" / "sample" / "log.txt.gz"
TRUTH = SOURCE_DIR / "data" / "sample" / "truth.csv.gz"
# Every output stream: --mode all runs the ESKF with its RTS pass, the window and the batch.
ALL_STREAMS = ("eskf", "eskf_rts", "smoother", "smoother_online", "batch")


def run_cli(*args, check=True):
    """`gins ARGS...`: the CompletedProcess (text)."""
    p = subprocess.run([GINS_BINARY, *map(str, args)], capture_output=True, text=True, timeout=600)
    if check and p.returncode != 0:
        raise AssertionError(f"gins {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}")
    return p


@pytest.fixture(scope="session")
def cli_all(tmp_path_factory):
    """`gins run --mode all --truth` on the bundled sample: its output folder."""
    out = tmp_path_factory.mktemp("cli_all")
    run_cli("run", "--config", CONFIG, "--log", LOG, "--truth", TRUTH, "--out", out, "--mode", "all")
    return out


@pytest.fixture(scope="session")
def py_all(tmp_path_factory):
    """gins.run(..., mode="all", truth=, out=) on the bundled sample: (result, its output folder)."""
    import gins

    out = tmp_path_factory.mktemp("py_all")
    return gins.run(CONFIG, LOG, mode="all", truth=TRUTH, out=out), out


def output_filter(trajectory):
    """The rows of a Session's states that `gins run` writes (apps/run_command.h, StateFilter): every
    number finite, one state per time stamp (the first), in time order."""
    t = trajectory["t"]
    finite = np.ones(len(t), dtype=bool)
    for key, column in trajectory.items():
        if key == "lla":
            continue
        finite &= np.isfinite(column.reshape(len(t), -1)).all(axis=1)
    keep = np.zeros(len(t), dtype=bool)
    last = -math.inf
    for i in range(len(t)):
        if finite[i] and t[i] > last:
            keep[i] = True
            last = t[i]
    return {key: column[keep] for key, column in trajectory.items()}
