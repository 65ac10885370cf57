"""gins.run: the same states, files and summary as `gins run` on the bundled sample."""
import glob
import json
import os
import re
import tempfile

import numpy as np
import pytest

import gins
from gins import _gins
from conftest import ALL_STREAMS, CONFIG, LOG, TRUTH

# Each output file's columns: the Trajectory array and the column in it.
TUM_COLUMNS = {"t": ("t", None), "x": ("p", 0), "y": ("p", 1), "z": ("p", 2),
               "qx": ("q", 0), "qy": ("q", 1), "qz": ("q", 2), "qw": ("q", 3)}
CSV_COLUMNS = {"t": ("t", None), "odom_scale": ("odom_scale", None), "qw": ("q", 3), "qx": ("q", 0),
               "qy": ("q", 1), "qz": ("q", 2), "lat_deg": ("lla", 0), "lon_deg": ("lla", 1),
               "height_m": ("lla", 2), "sigma_e_m": ("sigma_p", 0), "sigma_n_m": ("sigma_p", 1),
               "sigma_u_m": ("sigma_p", 2)}
for _prefix, _key in (("p", "p"), ("v", "v"), ("bg", "gyro_bias"), ("ba", "acc_bias"),
                      ("sigma_p", "sigma_p"), ("sigma_v", "sigma_v")):
    for _i, _axis in enumerate("xyz"):
        CSV_COLUMNS[_prefix + _axis] = (_key, _i)
for _i, _axis in enumerate("enu"):
    CSV_COLUMNS["sigma_att_" + _axis] = ("sigma_att", _i)


GEODETIC_COLUMNS = ("lat_deg", "lon_deg", "height_m")


def read_rows(path):
    """(column names, rows of text fields) of one of gins's output files."""
    with open(path) as f:
        lines = f.read().splitlines()
    if path.endswith(".tum"):
        assert lines[0].startswith("# gins mode=")
        return list(TUM_COLUMNS), [line.split(" ") for line in lines[1:]]
    return lines[0].split(","), [line.split(",") for line in lines[1:]]


def formatted(values, example):
    """values written as the file writes them (the same formatter, core/io/number_format.h), in the
    precision and notation the file's own text `example` shows."""
    mantissa = example.split("e")[0]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return _gins._format(np.ascontiguousarray(values), decimals, "e" in example)


def assert_same_as_file(trajectory, path):
    names, rows = read_rows(path)
    assert len(rows) == len(trajectory["t"]), f"{path}: {len(rows)} rows, {len(trajectory['t'])} states in memory"
    assert rows, path
    table = TUM_COLUMNS if path.endswith(".tum") else CSV_COLUMNS
    for j, name in enumerate(names):
        key, index = table[name]
        column = trajectory[key] if index is None else trajectory[key][:, index]
        text = [row[j] for row in rows]
        expected = formatted(column, text[0])
        mismatches = [i for i in range(len(text)) if text[i] != expected[i]]
        if name in GEODETIC_COLUMNS:
            # The track CSV may be written from a first-order geodetic conversion near a reference point
            # (core/geodesy.h, NearGeodetic: below 4 µm); the arrays hold the exact one (State::lla). One
            # unit in the last digit written, no more.
            unit = 10.0 ** -len(text[0].split(".")[1])
            mismatches = [i for i in mismatches if abs(float(text[i]) - float(expected[i])) > 1.5 * unit]
        assert not mismatches, (f"{os.path.basename(path)} column {name}: row {mismatches[0] + 1} is "
                                f"{text[mismatches[0]]} in the file, {expected[mismatches[0]]} in memory "
                                f"({len(mismatches)} rows differ)")
        # The same, independently of gins's formatter: within half a unit of the last digit written.
        decimals = len(text[0].split("e")[0].split(".")[1])
        if "e" not in text[0]:
            units = 1.5 if name in GEODETIC_COLUMNS else 0.5
            assert np.all(np.abs(np.array(text, dtype=float) - column) <= units * 10.0 ** -decimals * (1 + 1e-9)
                          + 1e-15 * np.abs(column)), (path, name)


def test_run_gives_the_command_lines_states_bit_for_bit_in_the_files_precision(cli_all, py_all):
    result, _ = py_all
    assert sorted(result) == sorted(ALL_STREAMS)
    checked = 0
    for stream in ALL_STREAMS:
        for suffix in (".tum", "_states.csv", "_lla.csv"):
            path = os.path.join(cli_all, stream + suffix)
            if stream == "smoother_online" and suffix == "_states.csv":
                assert not os.path.exists(path)
                continue
            assert_same_as_file(result[stream], path)
            checked += 1
    assert checked == 14


def test_run_with_out_writes_the_same_files_as_the_command_line(cli_all, py_all):
    result, out = py_all
    names = sorted(os.path.basename(p) for p in glob.glob(os.path.join(cli_all, "*")))
    assert names == sorted(os.path.basename(p) for p in glob.glob(os.path.join(out, "*")))
    assert sorted(os.path.basename(p) for p in result.outputs) == names
    for name in names:
        if name == "summary.json":
            continue
        with open(os.path.join(cli_all, name), "rb") as a, open(os.path.join(out, name), "rb") as b:
            assert a.read() == b.read(), name


def strip_run_specifics(summary):
    """The summary less what differs between any two runs: the wall-clock timings (solver times too) and
    the paths."""
    def strip(value):
        if isinstance(value, dict):
            return {k: strip(v) for k, v in value.items() if not re.search(r"(time_s|_ms)$", k)}
        return value

    s = strip(summary)
    del s["timing"]
    for key in ("config", "log", "truth"):
        s.pop(key, None)
    return s


def test_run_gives_the_same_summary_figures_as_the_command_line(cli_all, py_all):
    result, out = py_all
    with open(os.path.join(cli_all, "summary.json")) as f:
        cli = json.load(f)
    with open(os.path.join(out, "summary.json")) as f:
        written = json.load(f)
    assert written == result.summary
    assert strip_run_specifics(result.summary) == strip_run_specifics(cli)
    assert result.summary["timing"]["log_duration_s"] == cli["timing"]["log_duration_s"]
    assert result.summary["estimators"]["smoother"]["solve_time_s"] > 0  # stripped above, but there
    # The figures a user reads: each output's accuracy against the truth, all present.
    for stream in ALL_STREAMS:
        assert result.summary["accuracy"][stream]["rmse_horizontal_m"] == cli["accuracy"][stream]["rmse_horizontal_m"]
        assert 0 < result.summary["accuracy"][stream]["rmse_horizontal_m"] < 1.0
    assert result.summary["config"] == os.path.normpath(os.path.abspath(CONFIG))


def test_run_without_out_writes_nothing_and_leaves_no_temporary_folder():
    before = set(glob.glob(os.path.join(tempfile.gettempdir(), "gins-run-*")))
    result = gins.run(CONFIG, LOG, mode="eskf")
    assert result.outputs == []
    assert set(glob.glob(os.path.join(tempfile.gettempdir(), "gins-run-*"))) == before
    assert list(result) == ["eskf"]
    assert len(result["eskf"]["t"]) > 17000
    assert "accuracy" not in result.summary  # no truth given
    assert result.summary["mode"] == "eskf"


def test_a_config_as_a_dict_or_yaml_text_gives_the_states_of_the_same_yaml_file(tmp_path):
    settings = {"gnss": {"sigma_m": np.array([0.05, 0.05, 0.1])}, "smoother": {"window_size": 8}}
    yaml_text = "gnss:\n  sigma_m: [0.05, 0.05, 0.1]\nsmoother:\n  window_size: 8\n"
    path = tmp_path / "c.yaml"
    path.write_text(yaml_text)
    from_file = gins.run(path, LOG, mode="smoother")
    default = gins.run(CONFIG, LOG, mode="smoother")
    assert not np.array_equal(from_file["smoother"]["p"], default["smoother"]["p"])  # the config counts
    for config in (settings, yaml_text, gins.Config.from_yaml(yaml_text), str(path)):
        other = gins.run(config, LOG, mode="smoother")
        for key in ("t", "p", "q", "sigma_p"):
            assert np.array_equal(other["smoother"][key], from_file["smoother"][key]), (type(config), key)


def test_trajectory_arrays_have_the_documented_shapes_and_to_pandas_the_files_columns(cli_all, py_all):
    result, _ = py_all
    eskf = result["eskf"]
    n = len(eskf["t"])
    assert eskf["p"].shape == (n, 3) and eskf["q"].shape == (n, 4) and eskf["lla"].shape == (n, 3)
    assert eskf["odom_scale"].shape == (n,) and eskf["sigma_att"].shape == (n, 3)
    assert eskf["p"].dtype == np.float64
    assert list(eskf) == ["t", "p", "q", "v", "lla", "gyro_bias", "acc_bias", "sigma_p", "sigma_v", "sigma_att",
                          "odom_scale"]
    assert eskf.origin == tuple(result.summary["origin_lla"])
    np.testing.assert_allclose(np.linalg.norm(eskf["q"], axis=1), 1.0, atol=1e-12)
    pandas = pytest.importorskip("pandas")
    df = eskf.to_pandas()
    from_csv = pandas.read_csv(os.path.join(cli_all, "eskf_states.csv"))
    assert list(df.columns[:len(from_csv.columns)]) == list(from_csv.columns)
    assert list(df.columns[len(from_csv.columns):]) == ["lat_deg", "lon_deg", "height_m"]
    np.testing.assert_allclose(df[from_csv.columns].to_numpy(), from_csv.to_numpy(), rtol=1e-4, atol=1e-5)
    frames = result.to_pandas()
    assert sorted(frames) == sorted(ALL_STREAMS) and len(frames["batch"]) == len(result["batch"]["t"])


def test_an_unknown_mode_is_a_value_error_naming_the_modes():
    with pytest.raises(ValueError, match="unknown mode 'fast'.*eskf, smoother, both"):
        gins.run(CONFIG, LOG, mode="fast")
