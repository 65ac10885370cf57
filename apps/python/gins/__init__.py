"""gins from Python: GNSS/INS fusion (an error-state Kalman filter and a sliding-window smoother).

The same library as the ``gins`` command, through its public C++ API (docs/python.md):

- ``gins.run(config, log, mode="both", truth=None, out=None)``: a whole log, as ``gins run`` does it (the
  same code: same states, same summary), the outputs as numpy arrays; ``out=`` also writes its files.
- ``gins.Session(config, mode)``: push measurements one at a time or as numpy arrays; states come to a
  callback or are polled as arrays.
- ``gins.read_log(path)``: a log's records as numpy arrays.

Errors are ``gins.Error`` and its subclasses, with the command line's one-line message.
"""

import json as _json
import os as _os
from collections.abc import Mapping as _Mapping

from . import _gins

__version__ = _gins.__version__
__all__ = [
    "Config", "Error", "ConfigError", "InputError", "NoSolutionError", "UsageError", "State", "Status",
    "Rejection", "Trajectory", "Result", "Session", "run", "read_log", "load_config", "MODES",
]

Config = _gins.Config
State = _gins.State
Status = _gins.Status
Rejection = _gins.Rejection
Error = _gins.Error
ConfigError = _gins.ConfigError
InputError = _gins.InputError
NoSolutionError = _gins.NoSolutionError
UsageError = _gins.UsageError

MODES = ("eskf", "smoother", "both", "batch", "all")

# The states CSV's column names (docs/formats.md §5.3) and the geodetic track's (§5.4), for to_pandas().
_VECTOR_COLUMNS = (
    ("p", ("px", "py", "pz")),
    ("v", ("vx", "vy", "vz")),
    ("gyro_bias", ("bgx", "bgy", "bgz")),
    ("acc_bias", ("bax", "bay", "baz")),
    ("sigma_p", ("sigma_px", "sigma_py", "sigma_pz")),
    ("sigma_v", ("sigma_vx", "sigma_vy", "sigma_vz")),
    ("sigma_att", ("sigma_att_e", "sigma_att_n", "sigma_att_u")),
    ("lla", ("lat_deg", "lon_deg", "height_m")),
)


def _json_default(value):
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return value.tolist()
    raise TypeError(f"config value {value!r} is not a number, string, list or mapping")


def load_config(config=None):
    """A ``gins.Config`` from any of the forms ``run`` and ``Session`` take.

    ``None``: the defaults (config/default.yaml). A ``Config``: itself. A mapping: the config's sections as
    nested dicts, e.g. ``{"gnss": {"sigma_m": 0.05}}`` (keys not given keep their defaults). A path
    (``str`` or ``os.PathLike``) of a YAML file. A ``str`` that is no existing file and holds a newline
    or a colon: YAML text. Raises ``gins.ConfigError`` naming the key and line.
    """
    if config is None:
        return Config()
    if isinstance(config, Config):
        return config
    if isinstance(config, _Mapping):
        text = _json.dumps(config, indent=2, default=_json_default)  # JSON is YAML
        return Config.from_yaml(text, "<dict>")
    if isinstance(config, _os.PathLike):
        return Config.from_file(_os.fspath(config))
    if isinstance(config, str):
        if not _os.path.exists(config) and ("\n" in config or ":" in config):
            return Config.from_yaml(config, "<yaml>")
        return Config.from_file(config)
    raise TypeError(f"config: expected a path, YAML text, a mapping or gins.Config, not {type(config).__name__}")


def _config_path(config):
    if isinstance(config, _os.PathLike) or (isinstance(config, str) and _os.path.exists(config)):
        return _os.fspath(config)
    return ""


# A Trajectory's keys, in order.
_KEYS = ("t", "p", "q", "v", "lla", "gyro_bias", "acc_bias", "sigma_p", "sigma_v", "sigma_att", "odom_scale")


class Trajectory(_Mapping):
    """One output stream's states as numpy arrays, one row per state (those its files hold).

    Keys: ``t`` (n), ``p`` position ENU (n×3, m), ``q`` attitude q_wb (n×4, x, y, z, w as in TUM), ``v``
    velocity ENU (n×3, m/s), ``lla`` latitude, longitude (deg), ellipsoidal height (m) (n×3),
    ``gyro_bias`` (rad/s), ``acc_bias`` (m/s²), ``sigma_p``, ``sigma_v``, ``sigma_att`` (1-σ; attitude
    about E, N, U, rad) (n×3), ``odom_scale`` (n).

    ``origin``: the ENU frame's (lat_deg, lon_deg, alt_m). From ``gins.run``, ``lla`` is made from ``p``
    and the origin when first asked for (the conversion of gins::api::State::lla, bit for bit).
    """

    def __init__(self, stream, arrays, origin=None):
        self.stream = stream
        self.origin = None if origin is None else tuple(origin)
        self._arrays = dict(arrays)
        if "lla" not in self._arrays and self.origin is None:
            raise ValueError("a Trajectory without lla needs its origin")

    def __getitem__(self, key):
        if key == "lla" and "lla" not in self._arrays:
            self._arrays["lla"] = _gins._enu_to_lla(list(self.origin), self._arrays["p"])
        return self._arrays[key]

    def __iter__(self):
        return (key for key in _KEYS if key in self._arrays or key == "lla")

    def __len__(self):
        return len(_KEYS)

    def __repr__(self):
        return f"<gins.Trajectory {self.stream}: {len(self._arrays['t'])} states>"

    def to_pandas(self):
        """A pandas DataFrame with the states CSV's columns (t, px, ..., qw, qx, qy, qz, ...) and the
        geodetic track's (lat_deg, lon_deg, height_m)."""
        import pandas

        a = self
        columns = {"t": a["t"]}
        for key, names in _VECTOR_COLUMNS[:2]:
            columns.update(zip(names, a[key].T))
        q = a["q"]
        columns.update({"qw": q[:, 3], "qx": q[:, 0], "qy": q[:, 1], "qz": q[:, 2]})
        for key, names in _VECTOR_COLUMNS[2:7]:
            columns.update(zip(names, a[key].T))
        columns["odom_scale"] = a["odom_scale"]
        columns.update(zip(_VECTOR_COLUMNS[7][1], a["lla"].T))
        return pandas.DataFrame(columns)


class Result(_Mapping):
    """What ``gins.run`` returns: a mapping of output stream name ("eskf", "smoother",
    "smoother_online", "batch", "eskf_rts") to its ``Trajectory``, with ``summary`` (summary.json as a
    dict) and ``outputs`` (the files written with ``out=``; empty without)."""

    def __init__(self, streams, summary, outputs):
        origin = summary.get("origin_lla")
        self._streams = {name: Trajectory(name, arrays, origin) for name, arrays in streams.items()}
        self.summary = summary
        self.outputs = list(outputs)

    def __getitem__(self, stream):
        return self._streams[stream]

    def __iter__(self):
        return iter(self._streams)

    def __len__(self):
        return len(self._streams)

    def __repr__(self):
        return "<gins.Result " + ", ".join(f"{k}: {len(v['t'])}" for k, v in self._streams.items()) + ">"

    def to_pandas(self):
        """Each stream's ``Trajectory.to_pandas()``: a dict of DataFrames by stream name."""
        return {name: t.to_pandas() for name, t in self._streams.items()}


def run(config, log, mode="both", truth=None, out=None):
    """Run a whole log through the estimators, as ``gins run`` does (the same code).

    config: a path, YAML text, a mapping or a ``gins.Config`` (see ``load_config``). log: the log's path
    (plain or gzip). mode: "eskf", "smoother", "both", "batch" or "all". truth: a truth CSV for the
    accuracy in the summary. out: a folder to write the files of ``gins run --out`` into (without it
    they go to a temporary folder, removed after: the summary's comparison reads them back).

    Returns a ``gins.Result``: ``result["eskf"]``, ``result["smoother"]``, ... each a ``Trajectory`` of
    numpy arrays holding exactly the states the files hold, ``result.summary`` (summary.json as a dict)
    and ``result.to_pandas()``. The GIL is released while it runs. Raises ``gins.ConfigError``,
    ``gins.InputError``, ``gins.NoSolutionError`` (or ``gins.Error``) with the command line's message.
    """
    cfg = load_config(config)
    fspath = _os.fspath
    streams, summary, outputs = _gins.run(
        cfg, fspath(log), mode, None if truth is None else fspath(truth), None if out is None else fspath(out),
        _config_path(config))
    return Result(streams, _json.loads(summary), outputs)


def read_log(path, config=None):
    """A log's records (docs/formats.md §3) as numpy arrays, read with the config's ``input.*`` rules.

    Returns a dict: ``"imu"`` (``t``, ``gyro`` n×3, ``acc`` n×3), ``"wheel"`` (``t``, ``left_pulses``,
    ``right_pulses``), ``"gnss"`` (``t``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``heading_deg``,
    ``heading_valid``, ``sigma_enu`` n×3, NaN where the record has none), ``"gnss_velocity"`` (``t``,
    ``v_enu``, ``sigma_enu``), each with ``line`` (the record's line in the file), and ``"counts"``.
    ``Session.push_records`` takes it as it is.
    """
    return _gins.read_log(_os.fspath(path), load_config(config))


class Session(_gins.Session):
    """The push API: measurements in, states out, as they are estimated (gins::api::Session).

    ``Session(config, mode="eskf", *, parallel=False, geodetic=True, max_queued_states=100000)``; config as
    for ``run``; mode "eskf", "smoother", "both", "batch" or "all". ``parallel``: with more than one
    estimator, each on its own thread (the same states, bit for bit; the callback is then called from
    those threads). Each ``push_*`` takes one measurement (numbers and 3-vectors) or n of them as numpy
    arrays (n, n×3), looped over in C++ with the GIL released, and returns whether each was taken. States go
    to ``on_state(callback)``, else they queue (up to ``max_queued_states``, the oldest dropped and
    counted) for ``poll()``. An exception raised by the callback is raised again from the push that
    produced the state, after the estimator finished its step; the records after it in the same call are
    not pushed.
    """

    def __init__(self, config=None, mode="eskf", *, parallel=False, geodetic=True, max_queued_states=100000):
        super().__init__(load_config(config), mode, parallel, geodetic, max_queued_states)

    def poll(self, max_states=None):
        """The queued states (no callback set), oldest first: a dict of stream name to ``Trajectory``."""
        return {name: Trajectory(name, arrays) for name, arrays in self._poll(max_states).items()}

    def stats(self):
        """Everything the session counts (the "estimators" and "initialization" of summary.json, ...)."""
        return _json.loads(self._stats_json())
