"""`lpshoot study` end to end: the same rows locally with 1 and 2 threads, under mpirun with 1, 2
and 4 ranks (MPI builds), and as two shards merged; invalid and non-converging points are rows
with their status while the others match single solves; a rank killed mid-study is reported, its
points marked rank_lost, the study finishes and a rerun solves them; an interrupted study
completes on a rerun without redoing its finished points; bad study files fail naming the key.
Run by ctest (tests/cli/CMakeLists.txt) with LPSHOOT_CLI, LPSHOOT_SCENES and LPSHOOT_WITH_MPI."""

import json
import math
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

CLI = os.environ.get("LPSHOOT_CLI", "lpshoot")
SCENES = Path(os.environ.get("LPSHOOT_SCENES", Path(__file__).resolve().parents[2] / "examples" / "scenes"))
WITH_MPI = os.environ.get("LPSHOOT_WITH_MPI", "OFF") == "ON"
# vader without single-copy (CMA): containers often forbid the ptrace it needs.
MPIRUN = ["mpirun", "--oversubscribe", "--mca", "btl_vader_single_copy_mechanism", "none"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])

# 5 x 2 x 2 = 20 points of the beanie: I1 = -1 is invalid (4 rows), max_iterations = 1 stops
# Newton before convergence (8 rows, the beanie needs 3), the other 8 converge.
STUDY = {
    "scene": str(SCENES / "beanie.json"),
    "axes": {
        "parameters.I1": [0.5, 1.0, -1.0, 1.5, 2.0],
        "horizon.N": [40, 60],
        "solver.max_iterations": [30, 1],
    },
}


def lpshoot(*args, env=None, timeout=600):
    p = subprocess.run([CLI, *args], capture_output=True, text=True, timeout=timeout, env=env)
    return p.returncode, p.stdout, p.stderr


def write_study(path, study):
    path.write_text(json.dumps(study))
    return str(path)


def rows(directory):
    """study.jsonl's rows by index, without the timings."""
    out = {}
    for line in (Path(directory) / "study.jsonl").read_text().splitlines():
        r = json.loads(line)
        r.pop("wall_time_s")
        out[r["index"]] = r
    return out


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The study run locally on one thread: the rows every other way of running must give."""
    work = tmp_path_factory.mktemp("study")
    study = write_study(work / "grid.json", STUDY)
    code, out, err = lpshoot("study", study, "--threads", "1", "--out", str(work / "one"), "--no-plot")
    assert code == 1, out + err  # some points do not converge: exit 1, and it says so
    assert "points failed" in err
    return study, rows(work / "one"), work


def test_rows_have_their_status(reference):
    study, ref, work = reference
    assert sorted(ref) == list(range(20))
    by_status = {}
    for r in ref.values():
        by_status.setdefault(r["status"], []).append(r)
    assert len(by_status["invalid_scene"]) == 4
    assert all(r["parameters.I1"] == -1.0 and "parameters.I1" in r["message"] for r in by_status["invalid_scene"])
    assert len(by_status["not_converged"]) == 8
    assert all(r["solver.max_iterations"] == 1 and r["message"] for r in by_status["not_converged"])
    assert len(by_status["converged"]) == 8
    # A converged point is the single solve of the base scene with the point's values.
    for r in by_status["converged"][:2]:
        code, out, err = lpshoot("solve", STUDY["scene"], "--set", f"parameters.I1={r['parameters.I1']}",
                                 "--set", f"horizon.N={r['horizon.N']}", "--no-plot", "--quiet",
                                 "--out", str(work / f"single{r['index']}"))
        assert code == 0, err
        report = json.loads((work / f"single{r['index']}" / "report.json").read_text())
        assert r["cost"] == report["cost"] and r["iterations"] == report["iterations"]
    summary = json.loads((work / "one" / "study.json").read_text())
    assert summary["status"] == "completed_with_failures" and summary["rows"] == 20 and summary["failures"] == 12
    csv = (work / "one" / "study.csv").read_text().splitlines()
    assert csv[0].startswith("index,parameters.I1,horizon.N,solver.max_iterations,status,message,scheme_name,")
    assert len(csv) == 21


def test_two_threads_give_the_same_rows(reference):
    study, ref, work = reference
    code, out, err = lpshoot("study", study, "--threads", "2", "--out", str(work / "two"), "--no-plot")
    assert code == 1, err
    assert rows(work / "two") == ref


def test_two_shards_merged_give_the_same_rows(reference):
    study, ref, work = reference
    for i in range(2):
        code, out, err = lpshoot("study", study, "--shard", f"{i}/2", "--out", str(work / f"shard{i}"), "--no-plot")
        assert code == 1, err
        assert sorted(rows(work / f"shard{i}")) == list(range(i, 20, 2))
    code, out, err = lpshoot("study", "merge", str(work / "shard0"), str(work / "shard1"), "--out", str(work / "merged"),
                             "--no-plot")
    assert code == 1, err
    assert rows(work / "merged") == ref
    assert json.loads((work / "merged" / "study.json").read_text())["status"] == "completed_with_failures"


@pytest.mark.skipif(not WITH_MPI, reason="lpshoot was built without MPI")
@pytest.mark.parametrize("ranks", [1, 2, 4])
def test_mpirun_gives_the_same_rows(reference, ranks):
    study, ref, work = reference
    out_dir = work / f"mpi{ranks}"
    p = subprocess.run(MPIRUN + ["-np", str(ranks), CLI, "study", study, "--out", str(out_dir), "--no-plot"],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 1, p.stdout + p.stderr  # mpirun passes on the exit code of the failed points
    assert rows(out_dir) == ref
    if ranks > 1:
        assert f"on {ranks} MPI ranks" in p.stderr


def rank_pid(study, rank):
    """The pid of the lpshoot process of MPI rank `rank` running `study`, or None."""
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and study.encode() in (proc / "cmdline").read_bytes() and \
                    f"OMPI_COMM_WORLD_RANK={rank}".encode() in (proc / "environ").read_bytes().split(b"\0"):
                return int(proc.name)
        except OSError:
            pass
    return None


@pytest.mark.skipif(not WITH_MPI, reason="lpshoot was built without MPI")
def test_a_rank_that_dies_is_reported_and_the_study_finishes(tmp_path):
    # 16 points of about a quarter second on 3 ranks; rank 2 is killed once the first row is in.
    study = write_study(tmp_path / "slow.json", {
        "scene": str(SCENES / "beanie.json"),
        "axes": {"parameters.I2": {"from": 0.4, "to": 0.6, "count": 16}, "horizon.N": [4000]},
    })
    out_dir = tmp_path / "out"
    proc = subprocess.Popen(MPIRUN + ["--enable-recovery", "-np", "3", CLI, "study", study, "--out", str(out_dir),
                                      "--no-plot", "--rank-timeout", "3"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    jsonl = out_dir / "study.jsonl"
    deadline = time.time() + 120
    while time.time() < deadline and (not jsonl.exists() or not jsonl.read_text().strip()):
        time.sleep(0.05)
    try:
        pid = rank_pid(study, 2)
        assert pid, "rank 2 not found"
        os.kill(pid, signal.SIGKILL)
        out, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:  # a hang must not outlive the test
            proc.kill()
    # Rank 0 ends the job with MPI_Abort(1) (MPI_Finalize would wait for the lost rank); what
    # mpirun --enable-recovery then returns is its own affair (OpenMPI 4.1: 0). The study says it.
    assert "rank 2 stopped answering" in err, out + err
    assert json.loads((out_dir / "study.json").read_text())["status"] == "completed_with_failures"
    r = rows(out_dir)
    assert sorted(r) == list(range(16))
    lost = [x for x in r.values() if x["status"] == "rank_lost"]
    assert lost and all("MPI rank 2" in x["message"] for x in lost)
    assert all(x["status"] == "converged" for x in r.values() if x["status"] != "rank_lost")
    # A rerun solves the lost points only.
    code, out, err = lpshoot("study", study, "--out", str(out_dir), "--no-plot", "--quiet")
    assert code == 0, err
    assert f"{len(lost)} run now, {16 - len(lost)} done before" in out
    assert all(x["status"] == "converged" for x in rows(out_dir).values())


def test_an_interrupted_study_completes_on_a_rerun(tmp_path):
    # 12 points of about a quarter second each, on one thread: SIGINT after the third row.
    study = write_study(tmp_path / "slow.json", {
        "scene": str(SCENES / "beanie.json"),
        "axes": {"parameters.I2": {"from": 0.4, "to": 0.6, "count": 12}, "horizon.N": [4000]},
    })
    out_dir = tmp_path / "out"
    proc = subprocess.Popen([CLI, "study", study, "--threads", "1", "--out", str(out_dir), "--no-plot", "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    jsonl = out_dir / "study.jsonl"
    deadline = time.time() + 300
    while time.time() < deadline and (not jsonl.exists() or len(jsonl.read_text().splitlines()) < 3):
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 130, out + err
    assert "run the study again" in err
    before = [json.loads(l) for l in jsonl.read_text().splitlines()]
    assert 3 <= len(before) < 12
    assert not (out_dir / "study.csv").exists()  # no summary passed off as complete

    code, out, err = lpshoot("study", study, "--threads", "1", "--out", str(out_dir), "--no-plot", "--quiet")
    assert code == 0, err
    assert f"{12 - len(before)} run now, {len(before)} done before" in out
    after = {json.loads(l)["index"]: json.loads(l) for l in jsonl.read_text().splitlines()}
    assert sorted(after) == list(range(12))
    for r in before:  # the finished points were kept, not solved again (their timings are the first run's)
        assert after[r["index"]] == r


def test_pareto_and_cost_plots(tmp_path):
    study = write_study(tmp_path / "pareto.json", {
        "scene": str(SCENES / "electron.json"),
        "axes": {"horizon.N": [10, 20, 40],
                 "scheme": [{"discretization": "galerkin", "order": 4}, {"discretization": "galerkin", "order": 6}]},
    })
    code, out, err = lpshoot("study", study, "--out", str(tmp_path / "out"))
    assert code == 0, err
    r = rows(tmp_path / "out")
    assert all(x["error_kind"] == "exact" for x in r.values())
    # Errors against the exact optimum fall with the schemes' orders, 4 and 6 (Galerkin 6 reaches
    # roundoff by N = 40: its order is read from N = 10 to 20).
    err = {(x["horizon.N"], x["scheme_name"]): x["error"] for x in r.values()}
    assert 3.5 < math.log2(err[20, "galerkin4"] / err[40, "galerkin4"]) < 4.5
    assert 5.5 < math.log2(err[10, "galerkin6"] / err[20, "galerkin6"]) < 6.5
    for png in ("study_pareto.png", "study_cost.png"):
        assert (tmp_path / "out" / png).read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("study,key", [
    ({"scene": "missing.json", "axes": {}}, "missing.json"),
    ({"scene": {"problem": "beanie"}, "axes": {"horizon.N": []}}, "axes.horizon.N"),
    ({"scene": {"problem": "beanie"}, "axes": {"horizon.N": {"from": 1, "to": 2}}}, "axes.horizon.N.count"),
    ({"scene": {"problem": "beanie"}, "axes": {"parameters.m": {"from": 0, "to": 2, "count": 3, "log": True}}}, "log"),
    ({"scene": {"problem": "beanie"}, "axes": {"x": {"random": {"normal": [0, 1]}, "count": 2}}}, "axes.x.random"),
    ({"scene": {"problem": "beanie"}, "axis": {}}, "axis"),
])
def test_bad_study_files_name_the_key(tmp_path, study, key):
    code, out, err = lpshoot("study", write_study(tmp_path / "bad.json", study), "--out", str(tmp_path / "out"))
    assert code == 2, out + err
    assert key in err, err
    assert not (tmp_path / "out" / "study.json").exists()


def test_bad_shard(tmp_path):
    study = write_study(tmp_path / "s.json", STUDY)
    code, out, err = lpshoot("study", study, "--shard", "2/2", "--out", str(tmp_path / "out"))
    assert code == 2 and "--shard" in err


def test_random_axis_is_reproducible(tmp_path):
    study = {"scene": str(SCENES / "beanie.json"),
             "axes": {"parameters.I1": {"random": {"uniform": [0.5, 1.5]}, "count": 3, "seed": 7}, "horizon.N": [30]}}
    values = []
    for k in range(2):
        code, out, err = lpshoot("study", write_study(tmp_path / f"r{k}.json", study), "--out", str(tmp_path / f"o{k}"),
                                 "--no-plot")
        assert code == 0, err
        values.append([r["parameters.I1"] for r in rows(tmp_path / f"o{k}").values()])
    assert values[0] == values[1] and len(set(values[0])) == 3 and all(0.5 <= v <= 1.5 for v in values[0])
