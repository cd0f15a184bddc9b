"""A run through Python and through the CLI on the same scene give the same report and the same
trajectory, bit for bit (the module is the application's own code, not a second implementation)."""

import json

import numpy as np
import pytest

import lpshoot
from conftest import assert_same_columns, read_csv, run_cli, scene_path, without_timings


@pytest.mark.parametrize("command,name,sets", [
    ("solve", "beanie", {"horizon.N": 120}),
    ("solve", "electron", {"scheme.error_estimate": True, "horizon.N": 80}),
    ("solve", "beanie_galerkin", {}),
    ("simulate", "beanie_free", {"horizon.N": 400}),
])
def test_run_matches_cli(work, command, name, sets):
    args = [command, scene_path(name), "--no-plot", "--quiet", "--out", str(work / "cli")]
    for k, v in sets.items():
        args += ["--set", f"{k}={json.dumps(v)}"]
    code, out, err = run_cli(*args)
    assert code == 0, out + err
    cli_report = json.loads((work / "cli" / "report.json").read_text())

    r = getattr(lpshoot, command)(scene_path(name), sets)
    assert r.converged and r.status == "converged", r.message
    assert without_timings(r.report) == without_timings(cli_report)
    assert list(r.trajectory)[0] == "t"
    assert_same_columns(r.trajectory, read_csv(work / "cli" / "trajectory.csv"))
    if (work / "cli" / "momentum.csv").exists():
        assert_same_columns(r.momentum, read_csv(work / "cli" / "momentum.csv"))
    if (work / "cli" / "trajectory_extrapolated.csv").exists():
        assert_same_columns(r.extrapolated, read_csv(work / "cli" / "trajectory_extrapolated.csv"))
    assert r.cost == cli_report["cost"] and r.iterations == cli_report["iterations"]
    value = f"cost={r.cost:.10g}" if r.cost is not None else f"action={r.action:.10g}"
    assert repr(r) == f"<lpshoot.Result {cli_report['problem']} converged, N={cli_report['N']}: {value}>"

    # The result writes the same files as the CLI, with the same contents.
    files = r.write(work / "py", plot=False)
    assert sorted(p.rsplit("/", 1)[1] for p in files) == sorted(p.name for p in (work / "cli").iterdir())
    assert without_timings(json.loads((work / "py" / "report.json").read_text())) == without_timings(cli_report)
    assert (work / "py" / "trajectory.csv").read_text() == (work / "cli" / "trajectory.csv").read_text()


def test_scene_as_dict_is_the_scene_file(work):
    """A dict scene is the file's contents: the same run, only the scene's name differs."""
    scene = json.loads(open(scene_path("beanie")).read())
    from_file = lpshoot.solve(scene_path("beanie"), **{"horizon.N": 100})
    from_dict = lpshoot.solve(scene, **{"horizon.N": 100})
    assert from_dict.report["scene_file"] == "scene"
    a, b = without_timings(from_file.report), without_timings(from_dict.report)
    a.pop("scene_file"), b.pop("scene_file")
    assert a == b
    assert_same_columns(from_file.trajectory, from_dict.trajectory)


def test_overrides_are_set_paths():
    """Overrides as a dict and as keywords are --set assignments; None removes a key."""
    r = lpshoot.check(scene_path("beanie"), {"horizon.N": 60}, **{"horizon.T": 1.5, "output": None})
    assert (r["N"], r["T"], r["h"]) == (60, 1.5, 1.5 / 60)
    assert "output" not in r["scene"]
    assert r["problem"] == "beanie" and r["command"] == "solve"
    assert lpshoot.check(scene_path("beanie_free"))["command"] == "simulate"
    assert lpshoot.check(scene_path("beanie"), {"horizon.N": np.int64(70)})["N"] == 70


def test_sweep_matches_cli(work):
    code, out, err = run_cli("sweep", scene_path("electron"), "--N", "40,80,160", "--scheme", "galerkin4",
                             "--no-plot", "--quiet", "--out", str(work / "cli"))
    assert code == 0, out + err
    cli = json.loads((work / "cli" / "sweep.json").read_text())
    sw = lpshoot.sweep(scene_path("electron"), [40, 80, 160], schemes=["galerkin4"])
    assert sw.converged
    assert without_timings(sw.report) == without_timings(cli)
    # The observed order is Galerkin-4's (against the exact solution): the sweep is real.
    assert sw.report["reference"].startswith("exact")
    assert 3.5 < sw.column("order")[-1] < 4.5
    np.testing.assert_array_equal(sw.column("N"), [40, 80, 160])
    sw.write(work / "py", plot=False)
    assert (work / "py" / "sweep.csv").read_text().splitlines()[0] == (work / "cli" / "sweep.csv").read_text().splitlines()[0]


def test_problems_are_the_cli_listing():
    code, out, err = run_cli("problems", "--json")
    assert code == 0, err
    assert lpshoot.problems() == json.loads(out)
    names = [p["name"] for p in lpshoot.problems()]
    assert {"electron", "beanie", "beanie_free", "spherical_pendulum"} <= set(names)
