#!/usr/bin/env python3
"""Structure-aware fuzzing of the lpshoot command line (issue 14).

Mutates the example scenes (values, types, keys, nesting, bytes), --set overrides, command lines
and output directories; runs lpshoot on each case and checks, whatever the input:
  - no abort or signal, and an exit code in the documented set (0, 1, 2, 3; 4 = internal error
    counts as a failure);
  - exit 0 only with a complete report (report.json / sweep.json that parses, says converged) and
    no non-finite number in the report, the CSV files or the printed summary;
  - exit 2 or 3 leaves no output directory behind; no temporary or staging files anywhere;
  - a run killed (SIGTERM or SIGKILL) while writing into a directory holding an earlier result
    leaves either the complete earlier result or the complete new one; concurrent runs into one
    directory leave one complete result.

  fuzz_cli.py LPSHOOT SCENES_DIR [--cases 2000] [--seed 1] [--jobs 2] [--kills 12]
Exit status 0 when every case passed; the failures are listed by class with a reproducer.
"""
import argparse
import concurrent.futures as cf
import copy
import json
import math
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

DOCUMENTED = {0, 1, 2, 3}
TIMEOUT_S = 60

EXTREME_NUMBERS = [0, -1, 1, 1e-320, 1e-300, 1e300, -1e300, 1e308, -1e308, 2147483647, -2147483648,
                   4294967296, 1e9, 1e19, 0.5, 1e-6, 3.5, -0.0, 99999999999999999999]
ODD_VALUES = [None, True, False, "", "x", "auto", [], {}, [1, 2], {"a": 1}, "\u00e9\u4e2d", [[[]]], "1e999"]
# N values that run fast, or must be refused at once (no minutes of work).
SMALL_N = [2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 40]
REFUSED_N = [0, -5, 1.5, 1e9, 2147483647, 1e12, "100"]
TINY_N_SCENES = {"electron.json": 40, "electron_unstable.json": 120, "beanie.json": 40, "beanie_free.json": 100,
                 "beanie_galerkin.json": 16}


def key_paths(node, prefix=""):
    """All key paths of a JSON value, e.g. boundary.initial.position.1."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            p = f"{prefix}.{k}" if prefix else k
            out.append(p)
            out += key_paths(v, p)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            p = f"{prefix}.{i}" if prefix else str(i)
            out.append(p)
            out += key_paths(v, p)
    return out


def get_parent(doc, path):
    parts = path.split(".")
    node = doc
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node[p]
    return node, parts[-1]


def random_value(rng):
    r = rng.random()
    if r < 0.45:
        return rng.choice(EXTREME_NUMBERS)
    if r < 0.75:
        return rng.choice(ODD_VALUES)
    if r < 0.9:
        return rng.uniform(-10, 10)
    return [rng.choice(EXTREME_NUMBERS) for _ in range(rng.randint(0, 5))]


def mutate_document(doc, rng):
    """Structural mutations of a scene; returns (doc, note). A mutation that does not fit the
    document's current shape (e.g. horizon already replaced by a list) is skipped."""
    try:
        return mutate_once(doc, rng)
    except (TypeError, KeyError, IndexError, ValueError, AttributeError):
        return doc, "skipped"


def mutate_once(doc, rng):
    paths = key_paths(doc)
    kind = rng.choice(["value", "value", "value", "delete", "add", "type", "nest", "problem", "N", "N"])
    if kind == "N":
        v = rng.choice(SMALL_N * 3 + REFUSED_N)
        doc.setdefault("horizon", {})["N"] = v
        return doc, f"horizon.N={v!r}"
    if kind == "problem":
        v = rng.choice(["electron", "beanie", "beanie_free", "pendulum", 3])
        doc["problem"] = v
        return doc, f"problem={v!r}"
    if not paths:
        return doc, "none"
    path = rng.choice(paths)
    parent, last = get_parent(doc, path)
    idx = int(last) if isinstance(parent, list) else last
    if kind == "delete":
        del parent[idx]
        return doc, f"delete {path}"
    if kind == "add":
        if isinstance(parent, dict):
            parent[rng.choice(["extra", last + "x", last.upper(), "segmnets"])] = random_value(rng)
        else:
            parent.append(random_value(rng))
        return doc, f"add near {path}"
    if kind == "nest":
        v = parent[idx]
        for _ in range(rng.choice([2, 10, 70, 200])):
            v = [v] if rng.random() < 0.5 else {"a": v}
        parent[idx] = v
        return doc, f"nest {path}"
    v = random_value(rng)
    parent[idx] = v
    return doc, f"{path}={v!r}"


def scene_bytes(doc, rng):
    """JSON text of a scene, sometimes damaged at the byte level; returns (bytes, note)."""
    text = json.dumps(doc, allow_nan=True).encode("utf-8")
    r = rng.random()
    if r < 0.06:
        i = rng.randrange(len(text) + 1)
        return text[:i] + bytes([rng.choice([0xFF, 0xFE, 0xC0, 0x80, 0xED])]) + text[i:], "invalid UTF-8 byte"
    if r < 0.10:
        return text[: rng.randrange(len(text))], "truncated"
    if r < 0.13:
        return b"[" * 100000 + b"]" * 100000, "100000 levels of nesting"
    if r < 0.16:
        return text[:-1] + b', "problem": "electron"}', "duplicate key"
    if r < 0.18:
        return rng.choice([b"5", b"null", b"[]", b'"scene"', b""]), "not an object"
    return text, ""


def set_options(doc, rng):
    sets = []
    paths = key_paths(doc) or ["horizon.N"]
    for _ in range(rng.choice([0, 0, 1, 1, 2, 3])):
        r = rng.random()
        if r < 0.1:
            sets.append(rng.choice([b"output.dir=\xff", b"\xfe=1", b"horizon.N=\xc3\x28"]))
        elif r < 0.2:
            sets.append(rng.choice(["noequals", "=5", "a..b=1", ".x=1", "horizon.N.3=1", "boundary.initial.position.99999999999999999999=1",
                                    'solver.continuation={"parameter":"B.99999999999999999999","from":0}',
                                    "solver.threads=200", "horizon.T=1e-300", "horizon.T=1e300"]).encode())
        else:
            value = random_value(rng)
            sets.append(f"{rng.choice(paths)}={json.dumps(value)}".encode())
    return sets


def command_line(lpshoot, name, rng, scene_path, out_dir):
    cmd = rng.choice(["solve"] * 4 + ["simulate"] * 2 + ["sweep", "check"])
    args = [lpshoot.encode(), cmd.encode(), scene_path.encode()]
    if cmd == "sweep":
        grids = rng.choice(["8,16", "6,12", "10,20", "7,8", "2147483647", "0,4", "-3", "a,b", "16"])
        args += [b"--N", grids.encode()]
        if rng.random() < 0.3:
            args += [b"--scheme", rng.choice([b"paper,galerkin4", b"galerkin6", b"bogus"])]
        if rng.random() < 0.2:
            args += [b"--steps-per-segment", rng.choice([b"2147483647", b"4", b"0", b"-1"])]
    if cmd != "check":
        r = rng.random()
        if r < 0.05:
            args += [b"--out", b""]
        elif r < 0.10:
            args += [b"--out", b"/proc/lpshoot-cannot-write"]
        elif r < 0.13:
            args += [b"--out", scene_path.encode()]  # a file
        else:
            args += [b"--out", out_dir.encode()]
        if rng.random() < 0.9:
            args.append(b"--no-plot")
    return cmd, args


class Failures:
    def __init__(self):
        self.by_class = {}

    def add(self, cls, case):
        self.by_class.setdefault(cls, []).append(case)

    def count(self):
        return sum(len(v) for v in self.by_class.values())


NONFINITE_WORDS = ("nan", "inf")


def has_nonfinite_token(text):
    for token in text.replace(",", " ").replace("(", " ").replace(")", " ").replace("=", " ").split():
        t = token.lower().lstrip("+-")
        if t in NONFINITE_WORDS or t == "infinity" or t == "-nan":
            return True
    return False


def csv_problems(path):
    """Non-finite cells, or empty cells away from the first and last 4 rows."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    rows = lines[1:]
    for n, line in enumerate(rows):
        for cell in line.split(","):
            if cell.strip().lower().lstrip("+-") in ("nan", "inf", "infinity"):
                return f"{os.path.basename(path)} row {n}: {cell}"
            if cell == "" and 4 <= n < len(rows) - 4 and not path.endswith("sweep.csv"):
                return f"{os.path.basename(path)} row {n}: empty cell inside"
    return None


def check_case(proc, cmd, out_dir, parent):
    """Returns (class, detail) of the first failed check, or None."""
    rc = proc.returncode
    stdout = proc.stdout.decode("utf-8", "replace")
    if rc < 0:
        return "abort or signal", f"signal {-rc}: {proc.stderr.decode('utf-8', 'replace')[-300:]}"
    if rc not in DOCUMENTED:
        return f"exit {rc}", proc.stderr.decode("utf-8", "replace")[-300:]
    leftovers = [n for n in os.listdir(parent) if ".lpshoot-" in n]
    if os.path.isdir(out_dir):
        leftovers += [n for n in os.listdir(out_dir) if n.startswith(".")]
    if leftovers:
        return "temporary files left", ", ".join(leftovers)
    if cmd == "check":
        return None
    if rc in (2, 3) and os.path.exists(out_dir) and os.listdir(out_dir):
        return "output written on bad input", f"exit {rc} but {out_dir} holds {os.listdir(out_dir)}"
    if rc not in (0, 1):
        return None
    report = os.path.join(out_dir, "sweep.json" if cmd == "sweep" else "report.json")
    if not os.path.exists(report):
        return ("exit 0 without a complete report" if rc == 0 else "exit 1 without a report"), stdout[-200:]
    try:
        with open(report, encoding="utf-8") as f:
            rep = json.load(f, parse_constant=lambda c: float("nan"))
    except (ValueError, UnicodeDecodeError) as e:
        return "unreadable report", str(e)
    if rc == 0:
        if rep.get("status") != "converged" and not rep.get("converged", False):
            return "exit 0 with a report that is not converged", rep.get("status")
        if has_nonfinite_token(stdout):
            return "non-finite number printed with exit 0", stdout[-300:]
        keys = {"solve": ("cost", "residual_norm"), "simulate": ("residual_norm", "action")}.get(cmd, ())
        for key in keys:
            v = rep.get(key)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                return "exit 0 with a non-finite report value", f"{key} = {v!r}"
        for name in os.listdir(out_dir):
            if name.endswith(".csv"):
                why = csv_problems(os.path.join(out_dir, name))
                if why:
                    return "exit 0 with a non-finite CSV value", why
    return None


def run_case(lpshoot, scenes, seed, work):
    rng = random.Random(seed)
    name = rng.choice(sorted(scenes))
    doc = copy.deepcopy(scenes[name])
    notes = [name]
    if "horizon" in doc:  # keep the runs short
        doc["horizon"]["N"] = TINY_N_SCENES.get(name, 20)
    doc.pop("output", None)
    for _ in range(rng.choice([0, 1, 1, 2, 3])):
        doc, note = mutate_document(doc, rng)
        notes.append(note)
    text, note = scene_bytes(doc, rng)
    if note:
        notes.append(note)
    case_dir = os.path.join(work, f"case{seed}")
    os.makedirs(case_dir)
    scene_path = os.path.join(case_dir, "scene.json")
    if rng.random() < 0.02:
        scene_path = case_dir  # a directory as the scene
    else:
        with open(scene_path, "wb") as f:
            f.write(text)
    parent = os.path.join(case_dir, "out")
    os.makedirs(parent)
    out_dir = os.path.join(parent, "result")
    cmd, args = command_line(lpshoot, name, rng, scene_path, out_dir)
    for s in set_options(doc, rng):
        args += [b"--set", s]
    started = time.monotonic()
    try:
        proc = subprocess.run(args, capture_output=True, timeout=TIMEOUT_S, cwd=case_dir)
        failure = check_case(proc, cmd, out_dir, parent)
    except subprocess.TimeoutExpired:
        failure = ("hang", f"no result after {TIMEOUT_S} s")
    elapsed = time.monotonic() - started
    repro = " ".join(a.decode("utf-8", "backslashreplace") for a in args[1:])
    if failure is None:
        shutil.rmtree(case_dir, ignore_errors=True)
    return seed, failure, "; ".join(notes) + f" | {repro}", elapsed


def kill_case(lpshoot, scenes_dir, seed, work):
    """A run killed while replacing an earlier complete result: the directory stays consistent."""
    rng = random.Random(seed)
    case_dir = os.path.join(work, f"kill{seed}")
    os.makedirs(case_dir)
    out_dir = os.path.join(case_dir, "result")
    scene = os.path.join(scenes_dir, "electron_unstable.json")
    first = subprocess.run([lpshoot, "solve", scene, "--out", out_dir, "--set", "horizon.N=240"], capture_output=True)
    if first.returncode != 0:
        return seed, ("kill: first run failed", first.stderr.decode()[-200:]), "", 0
    proc = subprocess.Popen([lpshoot, "solve", scene, "--out", out_dir, "--set", "horizon.N=2400",
                             "--set", "scheme.error_estimate=true"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    time.sleep(rng.uniform(0.0, 1.5))
    sig = rng.choice([signal.SIGTERM, signal.SIGKILL, signal.SIGINT])
    proc.send_signal(sig)
    proc.wait()
    with open(os.path.join(out_dir, "report.json"), encoding="utf-8") as f:
        rep = json.load(f)
    names = sorted(os.listdir(out_dir))
    failure = None
    if rep["status"] == "converged":
        with open(os.path.join(out_dir, "trajectory.csv"), encoding="utf-8") as f:
            rows = len(f.read().splitlines()) - 1
        if rows != rep["N"] + 1:
            failure = ("mixed output directory", f"report N = {rep['N']}, trajectory rows {rows}")
    elif rep["status"] == "interrupted":
        if sig == signal.SIGKILL:
            failure = ("interrupted report after SIGKILL", "")
        elif names != ["report.json"]:
            failure = ("interrupted run left results", str(names))
    else:
        failure = ("unexpected status after a kill", rep["status"])
    if failure is None and proc.returncode >= 0 and sig != signal.SIGKILL and rep["status"] == "interrupted":
        if proc.returncode != 128 + int(sig):
            failure = ("interrupted exit code", str(proc.returncode))
    if failure is None and any(n.startswith(".") for n in names):
        failure = ("temporary files left", str(names))
    return seed, failure, f"signal {int(sig)}", 0


def concurrent_case(lpshoot, scenes_dir, seed, work):
    """Ten runs with different N into one directory: one complete result at the end."""
    case_dir = os.path.join(work, f"concurrent{seed}")
    os.makedirs(case_dir)
    out_dir = os.path.join(case_dir, "result")
    scene = os.path.join(scenes_dir, "electron.json")
    procs = [subprocess.Popen([lpshoot, "solve", scene, "--out", out_dir, "--no-plot", "--set", f"horizon.N={200 + 4 * i}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for i in range(10)]
    codes = [p.wait() for p in procs]
    failure = None
    if any(c != 0 for c in codes):
        failure = ("concurrent run failed", str(codes))
    else:
        with open(os.path.join(out_dir, "report.json"), encoding="utf-8") as f:
            rep = json.load(f)
        for name in ("trajectory.csv",):
            with open(os.path.join(out_dir, name), encoding="utf-8") as f:
                rows = len(f.read().splitlines()) - 1
            if rows != rep["N"] + 1:
                failure = ("mixed output directory", f"report N = {rep['N']}, {name} rows {rows}")
        if [n for n in os.listdir(case_dir) if n != "result"]:
            failure = ("staging directories left", str(os.listdir(case_dir)))
    return seed, failure, "10 concurrent runs", 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("lpshoot")
    ap.add_argument("scenes")
    ap.add_argument("--cases", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--kills", type=int, default=12)
    ap.add_argument("--keep", action="store_true", help="keep the work directory")
    a = ap.parse_args()
    a.lpshoot = os.path.abspath(a.lpshoot)
    a.scenes = os.path.abspath(a.scenes)
    scenes = {}
    for n in sorted(os.listdir(a.scenes)):
        if n.endswith(".json"):
            with open(os.path.join(a.scenes, n), encoding="utf-8") as f:
                scenes[n] = json.load(f)
    work = tempfile.mkdtemp(prefix="lpshoot-fuzz-")
    failures = Failures()
    started = time.monotonic()
    seeds = [a.seed * 1000003 + i for i in range(a.cases)]
    slowest = (0, "")
    with cf.ThreadPoolExecutor(a.jobs) as pool:
        jobs = [pool.submit(run_case, a.lpshoot, scenes, s, work) for s in seeds]
        jobs += [pool.submit(kill_case, a.lpshoot, a.scenes, a.seed * 7919 + i, work) for i in range(a.kills)]
        jobs += [pool.submit(concurrent_case, a.lpshoot, a.scenes, a.seed * 104729 + i, work) for i in range(max(1, a.kills // 6))]
        for j in cf.as_completed(jobs):
            seed, failure, note, elapsed = j.result()
            if elapsed > slowest[0]:
                slowest = (elapsed, note)
            if failure:
                failures.add(failure[0], f"seed {seed}: {failure[1]} <- {note}")
    total = len(jobs)
    print(f"fuzz: {total} cases ({a.cases} mutated inputs, {a.kills} kills, concurrent rounds) in "
          f"{time.monotonic() - started:.1f} s, {failures.count()} failing; slowest case {slowest[0]:.1f} s: {slowest[1][:200]}")
    for cls, cases in sorted(failures.by_class.items()):
        print(f"  {cls}: {len(cases)}")
        for c in cases[:3]:
            print(f"    {c[:600]}")
    if not a.keep and failures.count() == 0:
        shutil.rmtree(work, ignore_errors=True)
    else:
        print(f"fuzz: work directory kept: {work}")
    return 1 if failures.count() else 0


if __name__ == "__main__":
    sys.exit(main())
