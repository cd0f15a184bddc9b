"""Bad input raises SceneError (a ValueError) naming the key; a run that does not converge
returns a result that says so and why, with no trajectory."""

import pytest

import lpshoot
from conftest import scene_path


def raises_naming(key, *args, **kwargs):
    with pytest.raises(lpshoot.SceneError) as e:
        lpshoot.solve(*args, **kwargs)
    assert key in str(e.value), str(e.value)
    assert isinstance(e.value, ValueError)
    return str(e.value)


def test_bad_values_name_their_key():
    raises_naming("horizon.T", scene_path("beanie"), {"horizon.T": -1.0})
    raises_naming("horizon.N", scene_path("beanie"), {"horizon.N": "many"})
    raises_naming("parameters.I1", scene_path("beanie"), {"parameters.I1": float("inf")})
    msg = raises_naming("parameters.mass", scene_path("beanie"), {"parameters.mass": 1.0})
    assert "parameters" in msg
    raises_naming("problem", {"problem": "no_such_problem", "horizon": {"T": 1, "N": 10}})
    raises_naming("no_such_scene.json", "no_such_scene.json")


def test_bad_arguments():
    with pytest.raises(TypeError):
        lpshoot.solve(42)
    with pytest.raises(lpshoot.SceneError, match="reference"):
        lpshoot.sweep(scene_path("electron"), [20, 40], reference="best")
    with pytest.raises(lpshoot.SceneError, match="methods"):
        lpshoot.sweep(scene_path("electron"), [20, 40], methods=["triple"])
    with pytest.raises(lpshoot.SceneError, match="simulation"):
        lpshoot.sweep(scene_path("beanie_free"), [20, 40], schemes=["galerkin4"])
    with pytest.raises(lpshoot.SceneError, match="optimal control problem"):
        lpshoot.simulate(scene_path("beanie"))  # an optimal control problem has no free flow to run


def test_not_converging_returns_the_reason():
    r = lpshoot.solve(scene_path("electron_unstable"), {"solver.method": "single"})
    assert not r.converged
    assert r.status == "not_converged"
    assert r.message and "nan" not in r.message.lower()
    assert r.trajectory == {} and r.momentum == {}
    assert r.report["converged"] is False
    # Its repr gives the reason, not a missing value.
    assert repr(r) == f"<lpshoot.Result electron not_converged, N={r.report['N']}: {r.message}>"


def test_output_errors(tmp_path):
    r = lpshoot.solve(scene_path("beanie"), {"horizon.N": 60})
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    with pytest.raises(lpshoot.OutputError):
        r.write(blocker / "out", plot=False)
    assert isinstance(lpshoot.OutputError("x"), OSError)
