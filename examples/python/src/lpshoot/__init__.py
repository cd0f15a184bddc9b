"""lpshoot from Python: scenes in, NumPy arrays out.

The same scenes, runs, reports and files as the ``lpshoot`` command line (this package is a thin
layer over the application's own C++ code)::

    import lpshoot
    r = lpshoot.solve("examples/scenes/beanie.json", {"horizon.N": 400})
    if r.converged:
        t, psi = r.trajectory["t"], r.trajectory["psi"]

A scene is a path to a scene file or a dict with the file's contents (README, "Scene
reference"). Overrides are ``--set`` key paths with their values, given as a dict, as keyword
arguments (``**{"horizon.N": 400}``), or both; ``None`` removes a key, as ``--set key=null`` does.

A run that does not converge returns a result that says so (``converged``, ``status``,
``message``); a scene that cannot be used raises :class:`SceneError` (a ``ValueError``) naming
the file and the key. Runs release the GIL: threads (``concurrent.futures``) solve in parallel.
"""

import json
import os
import sys

import numpy as np

from ._core import OutputError, PluginError, SceneError
from . import _core

__all__ = ["solve", "simulate", "sweep", "check", "problems", "load_problem", "Result", "SweepResult",
           "SceneError", "OutputError", "PluginError"]

if _core.registration_errors():  # a built-in problem is ill-defined: a broken build
    raise ImportError("lpshoot: a built-in problem is ill-defined: " + _core.registration_errors()[0])


def _plain(value):
    """NumPy scalars and arrays as the JSON values they stand for."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not a JSON value")


def _scene_source(scene):
    """(text or path, is_text) for the C++ side."""
    if isinstance(scene, dict):
        try:
            return json.dumps(scene, allow_nan=False, default=_plain), True
        except (TypeError, ValueError) as e:
            raise SceneError(f"scene: not a JSON scene: {e}") from None
    if isinstance(scene, (str, os.PathLike)):
        return os.fspath(scene), False
    raise TypeError(f"scene: a dict or a path to a scene file, not {type(scene).__name__}")


def _set_list(overrides, more):
    """The --set assignments "key.path=<JSON value>" of a dict and keyword arguments."""
    items = dict(overrides or {})
    items.update(more)
    out = []
    for key, value in items.items():
        if not isinstance(key, str) or not key:
            raise SceneError(f"overrides: a key must be a non-empty key path such as 'horizon.N' (got {key!r})")
        try:
            out.append(key + "=" + json.dumps(value, allow_nan=False, default=_plain))
        except (TypeError, ValueError) as e:
            raise SceneError(f"overrides: {key}: not a JSON value: {e}") from None
    return out


class Result:
    """One run (solve or simulate) of a scene.

    ``report`` is report.json's content as a dict (without the list of files written);
    ``trajectory`` and ``momentum`` map column names to float64 arrays, ``t`` first (empty when
    the run did not converge: no partial trajectory is passed off as a result).
    """

    def __init__(self, run):
        self._run = run
        self.report = run.report

    status = property(lambda self: self.report["status"])
    converged = property(lambda self: self.report["converged"])
    message = property(lambda self: self.report["message"])
    cost = property(lambda self: self.report.get("cost"))
    action = property(lambda self: self.report.get("action"))
    iterations = property(lambda self: self.report["iterations"])
    residual_norm = property(lambda self: self.report.get("residual_norm"))
    wall_time_s = property(lambda self: self.report["wall_time_s"])

    @property
    def trajectory(self):
        return self._run.trajectory if self.converged else {}

    @property
    def momentum(self):
        return self._run.momentum if self.converged else {}

    @property
    def extrapolated(self):
        """Richardson-extrapolated state columns (scheme.error_estimate), else empty."""
        return self._run.extrapolated if self.converged else {}

    @property
    def state_columns(self):
        return list(self._run.state_columns)

    def write(self, out=None, plot=None):
        """Writes report.json, trajectory.csv, momentum.csv and the plots as `lpshoot solve` does
        (into ``out``, default the scene's output.dir); returns the files written."""
        return self._run.write(os.fspath(out) if out is not None else self._run.out_dir,
                               self._run.plot if plot is None else bool(plot))

    def __repr__(self):
        head = f"<lpshoot.Result {self.report['problem']} {self.status}, N={self.report['N']}"
        if not self.converged:  # no value to show: the reason instead
            return f"{head}: {self.message}>"
        if self.cost is not None:
            return f"{head}: cost={self.cost:.10g}>"
        return f"{head}: action={self.action:.10g}>" if self.action is not None else head + ">"


class SweepResult:
    """One sweep: ``report`` is sweep.json's content; ``runs`` its rows (dicts)."""

    def __init__(self, sweep):
        self._sweep = sweep
        self.report = sweep.report

    converged = property(lambda self: self.report["status"] == "converged")
    status = property(lambda self: self.report["status"])
    message = property(lambda self: self.report["message"])
    runs = property(lambda self: self.report["runs"])

    def column(self, name):
        """One column of the runs as an array (float, NaN for null) or, for text, a list."""
        values = [run.get(name) for run in self.runs]
        if all(v is None or isinstance(v, (int, float)) for v in values):
            return np.array([np.nan if v is None else v for v in values], dtype=float)
        return values

    def write(self, out=None, plot=None):
        """Writes sweep.json, sweep.csv and the error-time plot as `lpshoot sweep` does."""
        return self._sweep.write(os.fspath(out) if out is not None else self._sweep.out_dir,
                                 self._sweep.plot if plot is None else bool(plot))

    def __repr__(self):
        return f"<lpshoot.SweepResult {self.report['problem']} {self.status}: {len(self.runs)} runs>"


def _run(command, scene, overrides, more, progress):
    source, is_text = _scene_source(scene)
    return Result(_core.run(command, source, is_text, _set_list(overrides, more), progress))


def solve(scene, overrides=None, /, *, progress=None, **more):
    """Solves the scene's boundary value problem (optimal control); returns a :class:`Result`.

    ``progress``: a function called with each progress line (solver iterations)."""
    return _run("solve", scene, overrides, more, progress)


def simulate(scene, overrides=None, /, *, progress=None, **more):
    """Runs the discrete flow from the scene's initial data; returns a :class:`Result`."""
    return _run("simulate", scene, overrides, more, progress)


def sweep(scene, N, overrides=None, /, *, schemes=(), methods=(), backends=(), steps_per_segment=0,
          reference="auto", progress=None, **more):
    """Solves (or simulates) the scene on the grids ``N`` and, optionally, several schemes
    ("paper", "galerkin4", "galerkin6", "galerkin8"), methods ("single", "multiple") and backends ("kinsol",
    "nlopt"); errors against the exact solution ("auto", where the problem has one) or the finest
    grid ("finest"). Returns a :class:`SweepResult`."""
    if reference not in ("auto", "finest"):
        raise SceneError(f"reference: must be 'auto' or 'finest' (got {reference!r})")
    source, is_text = _scene_source(scene)
    grids = [int(n) for n in (N if np.iterable(N) else [N])]
    return SweepResult(_core.sweep(source, is_text, _set_list(overrides, more), grids, list(schemes), list(methods),
                                   list(backends), int(steps_per_segment), reference == "auto", progress))


def check(scene, overrides=None, /, **more):
    """Validates the scene as `lpshoot check` does: a dict (problem, command, N, T, h and the
    effective scene), or SceneError."""
    source, is_text = _scene_source(scene)
    return _core.check(source, is_text, _set_list(overrides, more))


def problems():
    """The registered problems (built-in and loaded ones) with their descriptors: parameters
    and defaults, boundary components, output columns, schemes."""
    return json.loads(_core.problems_json())


def load_problem(file, cache_dir=None, quiet=False):
    """Builds (once, then cached) and loads a problem of one's own from its C++ file, as
    ``lpshoot --problem FILE`` does; returns what was loaded (``problems``: their names).
    The first build takes minutes; raises PluginError with the compiler's diagnostics on failure."""
    notify = None if quiet else (lambda what: print("lpshoot:", what, file=sys.stderr, flush=True))
    return _core.load_problem(os.fspath(file), "" if cache_dir is None else os.fspath(cache_dir), notify)
