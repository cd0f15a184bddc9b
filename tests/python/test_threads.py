"""Runs release the GIL: other Python threads run while a solve computes, two threads solving
two scenes at once give the answers of the serial runs, and loading a problem file leaves other
threads running."""

import os
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

import lpshoot
from conftest import assert_same_columns, scene_path, without_timings

# Two solves of about a second each (Release build), each on one thread (solver.threads = 1;
# multiple shooting would otherwise spread its segments over every core by itself).
ONE_THREAD = {"horizon.N": 10000, "solver.segments": "auto", "solver.threads": 1}
JOBS = [(scene_path("beanie"), ONE_THREAD), (scene_path("beanie"), {**ONE_THREAD, "boundary.final.psi": 0.8})]


def solve(job):
    return lpshoot.solve(*job)


def test_two_threads_solving_at_once_give_the_serial_answers():
    serial = [solve(job) for job in JOBS]
    with ThreadPoolExecutor(max_workers=2) as pool:
        parallel = list(pool.map(solve, JOBS))
    for a, b in zip(serial, parallel):
        assert a.converged and b.converged, (a.message, b.message)
        assert without_timings(a.report) == without_timings(b.report)
        assert_same_columns(a.trajectory, b.trajectory)


def test_a_solve_lets_other_threads_run_between_its_progress_lines():
    """The solve computes with the GIL released: a counting thread (which gives the GIL up at
    each count, in a sleep) advances between the solve's progress lines. Were the GIL held through
    the solve, the counter could run only while a progress callback's own Python code runs, and
    a switch interval of 10 s keeps it from taking the GIL there. No wall time is compared (the
    speed-up of two threads is a benchmark's matter: bench/RESULTS.md)."""
    import sys
    import threading

    count, stop, at_lines = [0], threading.Event(), []

    def counter():
        while not stop.is_set():
            count[0] += 1
            time.sleep(0.0005)

    interval = sys.getswitchinterval()
    sys.setswitchinterval(10.0)
    thread = threading.Thread(target=counter)
    thread.start()
    try:
        r = lpshoot.solve(*JOBS[0], progress=lambda line: at_lines.append(count[0]))
    finally:
        stop.set()
        thread.join()
        sys.setswitchinterval(interval)
    assert r.converged, r.message
    assert len(at_lines) >= 3, f"{len(at_lines)} progress lines: too few to tell"
    advanced = at_lines[-1] - at_lines[0]
    assert advanced >= 1, f"the counter stood still through {len(at_lines)} progress lines: the GIL is held"


def test_progress_lines_and_a_raising_callback():
    lines = []
    r = lpshoot.solve(scene_path("beanie"), {"horizon.N": 100}, progress=lines.append)
    assert r.converged and lines and all(isinstance(l, str) for l in lines)

    class Stop(Exception):
        pass

    def stop(line):
        raise Stop(line)

    with pytest.raises(Stop):  # the callback's exception ends the run and reaches the caller
        lpshoot.solve(scene_path("beanie"), {"horizon.N": 100}, progress=stop)


def test_loading_a_problem_file_releases_the_gil(tmp_path):
    """A plugin build (here one that fails to compile: seconds of cmake and g++) leaves other
    Python threads running: a counting thread keeps at least a fifth of its solo rate during the
    call, where a held GIL would stop it for the whole call. The notification (quiet=False)
    takes the GIL back to print."""
    import threading
    from pathlib import Path

    bad = Path(__file__).resolve().parents[1] / "cli" / "plugins" / "syntax_error.cpp"
    count, stop = [0], threading.Event()

    def counter():
        while not stop.is_set():
            count[0] += 1

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        time.sleep(0.3)
        c0, t0 = count[0], time.perf_counter()
        time.sleep(0.3)
        solo_rate = (count[0] - c0) / (time.perf_counter() - t0)  # the counter alone (main thread asleep)
        c0, t0 = count[0], time.perf_counter()
        with pytest.raises(lpshoot.PluginError, match=r"syntax_error\.cpp:9:"):
            lpshoot.load_problem(bad, cache_dir=tmp_path / "cache", quiet=False)
        elapsed = time.perf_counter() - t0
        rate = (count[0] - c0) / elapsed
    finally:
        stop.set()
        thread.join()
    assert elapsed > 0.5, f"the build took {elapsed:.2f} s: too short to tell"
    assert rate > 0.2 * solo_rate, f"counter at {rate:.3g}/s during the load against {solo_rate:.3g}/s alone: GIL held"
