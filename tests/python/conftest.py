"""Shared helpers of the Python module's tests: the CLI built alongside (LPSHOOT_CLI), the example
scenes (LPSHOOT_SCENES), and readers for what the CLI writes. ctest sets the variables and
PYTHONPATH (tests/python/CMakeLists.txt)."""

import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

CLI = os.environ.get("LPSHOOT_CLI", "lpshoot")
SCENES = Path(os.environ.get("LPSHOOT_SCENES", Path(__file__).resolve().parents[2] / "examples" / "scenes"))


def scene_path(name):
    return str(SCENES / f"{name}.json")


def run_cli(*args, cwd=None):
    """Runs the lpshoot executable; (exit code, stdout, stderr)."""
    p = subprocess.run([CLI, *args], cwd=cwd, capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def read_csv(path):
    """A CSV the CLI wrote as {column: float64 array}; empty cells are NaN."""
    lines = Path(path).read_text().splitlines()
    names = lines[0].split(",")
    rows = [[float(x) if x else math.nan for x in line.split(",")] for line in lines[1:]]
    return {n: np.array([r[i] for r in rows]) for i, n in enumerate(names)}


def without_timings(report):
    """A report without what differs between two identical runs: times and the files written."""
    r = json.loads(json.dumps(report))
    for key in ("wall_time_s", "files", "warnings"):
        r.pop(key, None)
    if isinstance(r.get("error_estimate"), dict):
        r["error_estimate"].pop("wall_time_s", None)
    for run in r.get("runs", []):
        run.pop("wall_time_s", None)
    return r


def assert_same_columns(a, b):
    """Same column names in the same order, bit-identical values (NaN where the other has NaN)."""
    assert list(a) == list(b)
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.fixture
def work(tmp_path):
    return tmp_path
