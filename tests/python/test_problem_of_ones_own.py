"""lpshoot.load_problem: a problem of one's own from its C++ file through the application's plugin
path (built once, cached; the CLI shares the cache), solved against its closed-form optimum."""

import json
import os
from pathlib import Path

import numpy as np
import pytest

import lpshoot
from conftest import run_cli, without_timings

PLUGINS = Path(os.environ.get("LPSHOOT_EXAMPLE_PLUGINS", Path(__file__).resolve().parents[2] / "examples" / "plugins"))
BAD_PLUGINS = Path(__file__).resolve().parents[1] / "cli" / "plugins"


def exact_oscillator(w, T, x0, v0, x1, v1):
    """x(t) = (a + b t) cos wt + (c + d t) sin wt, the optimum's form ((d²/dt² + w²)² x = 0),
    with a, b, c, d from the boundary data; returns x and u = x'' + w² x as functions."""
    def rows(t):
        c, s = np.cos(w * t), np.sin(w * t)
        return (np.array([c, t * c, s, t * s]),
                np.array([-w * s, c - w * t * s, w * c, s + w * t * c]))
    A = np.array([rows(0)[0], rows(0)[1], rows(T)[0], rows(T)[1]])
    a, b, c, d = np.linalg.solve(A, [x0, v0, x1, v1])
    x = lambda t: (a + b * t) * np.cos(w * t) + (c + d * t) * np.sin(w * t)
    u = lambda t: 2 * w * (d * np.cos(w * t) - b * np.sin(w * t))  # x'' + w² x
    return x, u


def test_oscillator_from_its_file(tmp_path):
    cache = tmp_path / "cache"
    loaded = lpshoot.load_problem(PLUGINS / "oscillator.cpp", cache_dir=cache, quiet=True)
    assert loaded["built"] and loaded["problems"] == ["oscillator"]
    assert "oscillator" in [p["name"] for p in lpshoot.problems()]
    again = lpshoot.load_problem(PLUGINS / "oscillator.cpp", cache_dir=cache, quiet=True)
    assert not again["built"]  # from the cache; registering it again is a no-op

    scene = json.loads((PLUGINS / "oscillator.json").read_text())
    r = lpshoot.solve(scene)
    assert r.converged, r.message
    w, T, b = scene["parameters"]["omega"], scene["horizon"]["T"], scene["boundary"]
    t = r.trajectory["t"]
    for i in range(2):
        x, u = exact_oscillator(w, T, b["initial"]["position"][i], b["initial"]["velocity"][i],
                                b["final"]["position"][i], b["final"]["velocity"][i])
        assert np.max(np.abs(r.trajectory[f"x{i + 1}"] - x(t))) < 1e-8
        assert np.max(np.abs(r.trajectory[f"u{i + 1}"] - u(t))) < 1e-6

    # The CLI takes the module's build from the same cache (same build stamp) and agrees.
    code, out, err = run_cli("solve", "--problem", str(PLUGINS / "oscillator.cpp"), "--plugin-cache", str(cache),
                             str(PLUGINS / "oscillator.json"), "--no-plot", "--out", str(tmp_path / "cli"))
    assert code == 0, out + err
    assert "building" not in err
    cli = json.loads((tmp_path / "cli" / "report.json").read_text())
    mine = lpshoot.solve(PLUGINS / "oscillator.json")
    assert without_timings(mine.report) == without_timings(cli)


def test_a_file_that_does_not_compile(tmp_path):
    with pytest.raises(lpshoot.PluginError, match=r"syntax_error\.cpp:9:"):
        lpshoot.load_problem(BAD_PLUGINS / "syntax_error.cpp", cache_dir=tmp_path / "cache", quiet=True)
    with pytest.raises(lpshoot.PluginError):
        lpshoot.load_problem(tmp_path / "missing.cpp", cache_dir=tmp_path / "cache", quiet=True)
