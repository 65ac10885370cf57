"""The GIL is released while gins estimates: a Python thread keeps running during a run or a push."""
import os
import signal
import threading
import time

import pytest

import gins
from conftest import CONFIG, LOG

TICK_S = 0.001


class Ticker:
    """A Python thread that notes the time every TICK_S while it runs."""

    def __init__(self):
        self.ticks = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        while not self._stop.is_set():
            self.ticks.append(time.perf_counter())
            time.sleep(TICK_S)

    def __enter__(self):
        self._thread.start()
        time.sleep(0.02)  # running before the work starts
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()

    def during(self, begin, end):
        """Its ticks within [begin, end] and the longest pause between two of them (from begin to end)."""
        inside = [t for t in self.ticks if begin <= t <= end]
        marks = [begin] + inside + [end]
        return len(inside), max(b - a for a, b in zip(marks, marks[1:]))


def assert_kept_ticking(ticker, begin, end):
    wall = end - begin
    count, longest_pause = ticker.during(begin, end)
    # Holding the GIL, the work would leave the thread one tick at most and one pause as long as itself.
    assert count >= max(20, 0.2 * wall / TICK_S), (count, wall)
    assert longest_pause < wall / 3, (longest_pause, wall)


def test_a_python_thread_keeps_ticking_while_a_smoother_run_estimates():
    with Ticker() as ticker:
        begin = time.perf_counter()
        result = gins.run(CONFIG, LOG, mode="smoother")
        end = time.perf_counter()
    assert len(result["smoother"]["t"]) > 17000
    assert_kept_ticking(ticker, begin, end)


def test_a_python_thread_keeps_ticking_while_a_session_estimates_pushed_arrays():
    log = gins.read_log(LOG)
    session = gins.Session(CONFIG, "smoother")
    with Ticker() as ticker:
        begin = time.perf_counter()
        session.push_records(log)
        session.finish()
        end = time.perf_counter()
    assert len(session.poll()["smoother"]["t"]) > 17000
    assert_kept_ticking(ticker, begin, end)


class Interrupted(Exception):
    pass


def test_ctrl_c_stops_a_run_with_the_handlers_exception_and_leaves_no_output(tmp_path):
    """SIGINT, as Ctrl-C sends it, from another thread while gins.run estimates with the GIL released."""
    def handler(signum, frame):
        raise Interrupted()

    previous = signal.signal(signal.SIGINT, handler)
    try:
        timer = threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        with pytest.raises(Interrupted):
            gins.run(CONFIG, LOG, mode="all", out=tmp_path / "run")
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    # Stopped before the end: nothing committed (the run writes its files and summary.json only at its end).
    assert not (tmp_path / "run" / "summary.json").exists()
    assert list((tmp_path / "run").glob("*.tum")) == []
    # The package is usable again after it.
    assert len(gins.run(CONFIG, LOG, mode="eskf")["eskf"]["t"]) > 17000


def test_ctrl_c_stops_a_vectorised_push_and_the_session_goes_on():
    log = gins.read_log(LOG)

    def handler(signum, frame):
        raise Interrupted()

    session = gins.Session(CONFIG, "smoother")
    previous = signal.signal(signal.SIGINT, handler)
    try:
        timer = threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        with pytest.raises(Interrupted):
            session.push_records(log)
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    # Stopped part-way: the records before the signal were taken, and the session goes on after it.
    status = session.status()
    total = sum(len(log[k]["t"]) for k in ("imu", "wheel", "gnss", "gnss_velocity") if log.get(k) is not None)
    assert 0 < status.accepted < total
    imu = log["imu"]
    later = imu["t"] > status.last_time
    assert session.push_imu(imu["t"][later], imu["gyro"][later], imu["acc"][later]).all()
    session.finish()
    assert session.status().accepted > status.accepted
