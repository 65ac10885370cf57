"""The GIL is released while gins estimates: a Python thread keeps running during a run or a push."""
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
