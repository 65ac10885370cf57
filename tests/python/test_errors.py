"""Errors are gins.Error exceptions carrying the command line's message (file, line, key)."""
import gzip

import pytest

import gins
from conftest import CONFIG, LOG, run_cli


def cli_error(*args):
    """The one line `gins run` prints on stderr for an error (exit 1), less its "gins: error: "."""
    p = run_cli(*args, check=False)
    assert p.returncode == 1, p.stderr
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("gins: error: ")
    return line[len("gins: error: "):]


def test_a_misspelt_config_key_raises_config_error_naming_the_key_as_the_cli_does(tmp_path):
    path = tmp_path / "typo.yaml"
    path.write_text("# a typo on line 4\n\ngnss:\n  sigma_mm: 0.02\n")
    with pytest.raises(gins.ConfigError) as e:
        gins.run(path, LOG, mode="eskf", out=tmp_path / "out")
    assert str(e.value) == f"{path}: gnss.sigma_mm: unknown key (did you mean gnss.sigma_m?) (line 4)"
    assert str(e.value) == cli_error("run", "--config", path, "--log", LOG, "--out", tmp_path / "cli", "--mode", "eskf")
    assert isinstance(e.value, gins.Error) and isinstance(e.value, RuntimeError)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("config", [{"gnss": {"sigma_mm": 0.02}}, "gnss:\n  sigma_mm: 0.02\n"])
def test_a_misspelt_key_in_a_dict_or_yaml_text_names_the_key(config):
    with pytest.raises(gins.ConfigError, match=r"gnss\.sigma_mm"):
        gins.Session(config, "eskf")


def test_a_log_that_cannot_be_read_raises_input_error_with_the_cli_message(tmp_path):
    missing = tmp_path / "no_such_log.txt"
    with pytest.raises(gins.InputError) as e:
        gins.run(CONFIG, missing, mode="eskf", out=tmp_path / "out")
    assert "no_such_log.txt" in str(e.value)
    assert str(e.value) == cli_error("run", "--config", CONFIG, "--log", missing, "--out", tmp_path / "c", "--mode", "eskf")
    with pytest.raises(gins.InputError, match="no_such_log.txt"):
        gins.read_log(missing)


def test_a_damaged_line_under_on_error_stop_names_its_line_as_the_cli_does(tmp_path):
    with gzip.open(LOG, "rt") as f:
        lines = f.read().splitlines()
    lines[9] = "IMU 1700000000.070000 0.1 0.2"
    log = tmp_path / "damaged.txt"
    log.write_text("\n".join(lines) + "\n")
    config = tmp_path / "stop.yaml"
    config.write_text("input:\n  on_error: stop\n")
    with pytest.raises(gins.InputError) as e:
        gins.run(config, log, mode="eskf", out=tmp_path / "out")
    assert "damaged.txt:10" in str(e.value)
    assert str(e.value) == cli_error("run", "--config", config, "--log", log, "--out", tmp_path / "c", "--mode", "eskf")


def test_a_log_without_gnss_raises_no_solution_error_with_the_cli_message(tmp_path):
    with gzip.open(LOG, "rt") as f:
        log_text = "".join(line for line in f if not line.startswith("GNSS"))
    log = tmp_path / "no_gnss.txt"
    log.write_text(log_text)
    with pytest.raises(gins.NoSolutionError) as e:
        gins.run(CONFIG, log, mode="both", out=tmp_path / "out")
    assert "no usable GNSS records" in str(e.value)
    assert str(e.value) == cli_error("run", "--config", CONFIG, "--log", log, "--out", tmp_path / "c", "--mode", "both")
