"""Runs release the GIL: two threads solving two scenes at once take clearly less wall time than
one after the other (on two cores or more), and both answers are those of the serial runs."""

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


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores")
def test_two_threads_solve_in_parallel():
    ratios = []
    for attempt in range(3):  # a shared machine is noisy: the best of three attempts
        start = time.perf_counter()
        serial = [solve(job) for job in JOBS]
        t_serial = time.perf_counter() - start
        start = time.perf_counter()
        with ThreadPoolExecutor(max_workers=2) as pool:
            parallel = list(pool.map(solve, JOBS))
        t_parallel = time.perf_counter() - start
        for a, b in zip(serial, parallel):
            assert a.converged and b.converged, (a.message, b.message)
            assert without_timings(a.report) == without_timings(b.report)
            assert_same_columns(a.trajectory, b.trajectory)
        ratios.append(t_parallel / t_serial)
        if ratios[-1] < 0.75:
            break
    assert min(ratios) < 0.75, f"parallel/serial wall time {ratios}: the GIL is not released"


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
