"""The package itself: its version is the command's, its signatures and stubs are there for help() and editors."""
import ast
import inspect
import pathlib

import gins
from conftest import run_cli


def test_the_version_is_that_of_the_gins_command_of_the_same_build():
    assert run_cli("--version").stdout.strip() == f"gins {gins.__version__}"
    assert gins.__version__.count(".") == 2


def test_help_shows_the_signatures_and_the_package_ships_type_stubs():
    assert str(inspect.signature(gins.run)) == "(config, log, mode='both', truth=None, out=None)"
    assert "push_imu(self: gins._gins.Session, t: numpy.ndarray[numpy.float64]" in gins.Session.push_imu.__doc__
    assert "gins run" in gins.run.__doc__ and "Trajectory" in gins.run.__doc__
    package = pathlib.Path(gins.__file__).parent
    assert (package / "py.typed").exists()
    stubs = (package / "__init__.pyi").read_text()
    ast.parse(stubs)  # valid Python
    for name in ("def run(", "class Session:", "def push_imu(", "class Trajectory(", "class ConfigError(Error)"):
        assert name in stubs, name
    assert set(gins.__all__) <= set(dir(gins))


def test_the_errors_form_one_hierarchy_under_gins_error():
    for cls in (gins.ConfigError, gins.InputError, gins.NoSolutionError, gins.UsageError):
        assert issubclass(cls, gins.Error) and cls.__module__ == "gins"
    assert issubclass(gins.Error, RuntimeError)
