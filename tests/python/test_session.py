"""gins.Session, the push API: the sample's records from numpy give gins.run's states again, bit for bit."""
import gzip

import numpy as np
import pytest

import gins
from conftest import ALL_STREAMS, CONFIG, LOG, output_filter

BIG_QUEUE = 10 ** 7  # every state of the sample stays queued until polled


@pytest.fixture(scope="module")
def log():
    return gins.read_log(LOG)


def assert_same_states(pushed, run_result, streams):
    assert sorted(pushed) == sorted(streams)
    for stream in streams:
        kept = output_filter(pushed[stream])
        expected = run_result[stream]
        assert len(kept["t"]) == len(expected["t"]), stream
        for key in expected:
            assert np.array_equal(kept[key], expected[key]), (stream, key)  # every bit


def test_read_log_gives_every_record_of_the_sample_with_its_line(log):
    assert log["counts"] == {"lines": 19969, "imu": 18001, "wheel": 1800, "gnss": 166, "gnss_velocity": 0,
                             "skipped": 0}
    assert log["imu"]["gyro"].shape == (18001, 3) and log["gnss"]["sigma_enu"].shape == (166, 3)
    assert log["imu"]["t"][1] == 1700000000.01
    assert log["imu"]["acc"][0].tolist() == [1.829505607e-02, -2.017109179e-02, 9.804690444e+00]
    assert log["gnss"]["line"][:2].tolist() == [4, 115]  # the lines of the file, comments counted
    assert log["gnss"]["heading_valid"].dtype == bool
    with gzip.open(LOG, "rt") as f:
        valid = [line.split()[6] == "1" for line in f if line.startswith("GNSS")]
    assert log["gnss"]["heading_valid"].tolist() == valid and 0 < sum(valid) < 166
    lines = np.concatenate([log[k]["line"] for k in ("imu", "wheel", "gnss")])
    assert len(np.unique(lines)) == 18001 + 1800 + 166


def test_push_records_from_numpy_gives_the_states_of_gins_run_again(log, py_all):
    session = gins.Session(CONFIG, "all", max_queued_states=BIG_QUEUE)
    assert session.push_records(log) == 18001 + 1800 + 166
    session.finish()
    assert_same_states(session.poll(), py_all[0], ALL_STREAMS)
    status = session.status()
    assert status.initialized and status.rejected == 0 and status.states_dropped == 0
    assert status.accepted == 18001 + 1800 + 166
    assert status.origin == pytest.approx(tuple(py_all[0].summary["origin_lla"]), abs=1e-12)


def test_a_modules_records_read_and_pushed_give_the_states_of_gins_run_again(tmp_path):
    """A log with barometer records (a measurement module's: read_log gives them under their token, with
    each record's numbers and line); push_records takes them with the rest, in the file's order."""
    with gzip.open(LOG, "rt") as f:
        lines = f.read().splitlines()
    with_baro = []
    for line in lines:
        with_baro.append(line)
        fields = line.split()
        if fields and fields[0] == "GNSS":
            with_baro.append(f"BARO {fields[1]} {fields[4]} 0.5")
    path = tmp_path / "log_baro.txt"
    path.write_text("\n".join(with_baro) + "\n")
    log = gins.read_log(path)
    assert len(log["BARO"]["values"]) == 166 and log["BARO"]["values"][0][2] == 0.5
    assert log["BARO"]["line"][0] == log["gnss"]["line"][0] + 1
    session = gins.Session(CONFIG, "eskf", max_queued_states=BIG_QUEUE)
    assert session.push_records(log) == 18001 + 1800 + 166 + 166
    session.finish()
    run = gins.run(CONFIG, path, mode="eskf")
    assert_same_states(session.poll(), run, ("eskf",))
    assert run.summary["estimators"]["eskf"]["barometer"]["used"] > 100


def test_vectorised_pushes_of_each_sensor_in_chunks_give_the_same_states(log, py_all):
    """push_imu / push_wheel / push_gnss with numpy slices, 50 ms of each sensor at a time: the reorder
    window (0.1 s) puts them in time order, equal stamps in the order pushed, as in the file."""
    session = gins.Session(CONFIG, "both", parallel=True)
    states = {}
    session.on_state(lambda s: states.setdefault(s.stream, []).append(s))
    imu, wheel, gnss = log["imu"], log["wheel"], log["gnss"]
    start = imu["t"][0]
    taken = 0
    for k in range(int((imu["t"][-1] - start) / 0.05) + 2):
        edge = start + 0.05 * (k + 1) - 1e-6
        i = [np.searchsorted(x["t"], [edge - 0.05, edge]) for x in (imu, wheel, gnss)]
        taken += session.push_imu(imu["t"][slice(*i[0])], imu["gyro"][slice(*i[0])], imu["acc"][slice(*i[0])]).sum()
        taken += session.push_wheel(*(wheel[c][slice(*i[1])] for c in ("t", "left_pulses", "right_pulses"))).sum()
        g = {c: gnss[c][slice(*i[2])] for c in ("t", "lat_deg", "lon_deg", "alt_m", "heading_deg", "heading_valid",
                                                  "sigma_enu")}
        taken += session.push_gnss(**g).sum()
    session.finish()
    assert taken == 18001 + 1800 + 166
    pushed = {}
    for stream, items in states.items():
        pushed[stream] = {"t": np.array([s.t for s in items]), "p": np.array([s.p for s in items]),
                          "q": np.array([s.q for s in items]), "v": np.array([s.v for s in items]),
                          "lla": np.array([s.lla for s in items]), "gyro_bias": np.array([s.gyro_bias for s in items]),
                          "acc_bias": np.array([s.acc_bias for s in items]),
                          "sigma_p": np.array([s.sigma_p for s in items]),
                          "sigma_v": np.array([s.sigma_v for s in items]),
                          "sigma_att": np.array([s.sigma_att for s in items]),
                          "odom_scale": np.array([s.odom_scale for s in items])}
    assert_same_states(pushed, py_all[0], ("eskf", "smoother", "smoother_online"))


def test_single_pushes_give_the_states_of_one_vectorised_push(log):
    first = {k: v for k, v in log.items() if k != "counts"}
    n = {k: np.searchsorted(first[k]["t"], 1700000030.0) for k in ("imu", "wheel", "gnss")}
    head = {k: {c: a[:n[k]] for c, a in first[k].items()} for k in n}
    vectorised = gins.Session(CONFIG, "eskf")
    vectorised.push_records(head)
    one_by_one = gins.Session(CONFIG, "eskf")
    order = sorted((head[k]["line"][i], k, i) for k in n for i in range(n[k]))
    for _, kind, i in order:
        r = {c: a[i] for c, a in head[kind].items()}
        if kind == "imu":
            assert one_by_one.push_imu(r["t"], r["gyro"], r["acc"]) is True
        elif kind == "wheel":
            assert one_by_one.push_wheel(r["t"], r["left_pulses"], r["right_pulses"]) is True
        else:
            assert one_by_one.push_gnss(r["t"], r["lat_deg"], r["lon_deg"], r["alt_m"], r["heading_deg"],
                                        r["heading_valid"], r["sigma_enu"]) is True
    a, b = vectorised.poll()["eskf"], one_by_one.poll()["eskf"]
    assert len(a["t"]) > 2000
    for key in a:
        assert np.array_equal(a[key], b[key]), key


class Stop(Exception):
    pass


@pytest.mark.parametrize("parallel", [False, True])
def test_a_callback_that_raises_stops_the_push_with_its_exception(log, parallel):
    seen = []

    def callback(state):
        seen.append(state)
        if len(seen) == 100:
            raise Stop("enough states")

    session = gins.Session(CONFIG, "both", parallel=parallel)
    session.on_state(callback)
    with pytest.raises(Stop, match="enough states"):
        session.push_records(log)
    status = session.status()
    assert status.callback_errors == 1
    assert 100 <= len(seen) and status.accepted < 18001 + 1800 + 166  # stopped early, cleanly
    # The session goes on: the rest of the records, then the end.
    rest = {k: {c: a[log[k]["t"] > status.last_time] for c, a in log[k].items()} for k in ("imu", "wheel", "gnss")}
    session.push_records(rest)
    session.finish()
    assert session.status().callback_errors == 1 and len(seen) > 17000


def test_a_call_on_the_session_from_its_own_callback_is_a_usage_error_not_a_deadlock(log):
    session = gins.Session(CONFIG, "eskf")
    session.on_state(lambda state: session.status())
    with pytest.raises(gins.UsageError, match="another call on it runs"):
        session.push_records(log)


def test_out_of_turn_calls_and_bad_shapes_raise():
    session = gins.Session(CONFIG, "eskf")
    with pytest.raises(ValueError, match="gyro: 2 records where the time stamps give 3"):
        session.push_imu(np.zeros(3), np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="acc: expected 3 numbers or an n×3 array"):
        session.push_imu(0.0, [0, 0, 0], [0, 0])
    assert session.push_imu(1.0, [0, 0, 0], [0, 0, 9.8]) is True
    assert session.push_imu(2.0, [np.nan, 0, 0], [0, 0, 9.8]) is False  # refused and counted, not an error
    assert [(r.source, r.measurement, r.reason, r.count) for r in session.status().rejections] == [
        ("input", "imu", "non_finite", 1)]
    with pytest.raises(gins.UsageError, match="before the first push"):
        session.on_state(print)
    with pytest.raises(gins.NoSolutionError, match="no GNSS fix, so no world frame"):
        session.finish()
    with pytest.raises(gins.UsageError, match="Push after Finish"):
        session.push_imu(3.0, [0, 0, 0], [0, 0, 9.8])
    with pytest.raises(ValueError, match="unknown mode 'fast'"):
        gins.Session(CONFIG, "fast")
