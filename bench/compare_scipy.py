#!/usr/bin/python3
"""Accuracy per unit time on the paper's electron (METHOD.md 6.1): lpshoot against scipy's
solve_bvp, measured in the same run on the same machine.

The continuous optimum is linear: y = (x, x', u, u') solves y' = A y, so the exact answer is
expm(A t) y0 (computed here with scipy.linalg.expm, independently of lpshoot's C++ oracle).
scipy solve_bvp (4th-order collocation) solves that 12-dimensional two-point problem directly;
lpshoot solves the discrete variational problem (multiple shooting,
second-order closure, the default segments of at most 100 steps) through `lpshoot sweep`, whose errors are against lpshoot's own exact
oracle; one lpshoot trajectory is cross-checked here against the Python oracle.

usage: /usr/bin/python3 bench/compare_scipy.py [path/to/lpshoot] [repetitions]
(needs python3-scipy; prints a Markdown table)
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.integrate import solve_bvp
from scipy.linalg import expm

LPSHOOT = sys.argv[1] if len(sys.argv) > 1 else "build/examples/app/lpshoot"
REPS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "scenes", "electron.json")

with open(SCENE) as f:
    scene = json.load(f)
par, bd = scene["parameters"], scene["boundary"]
m, ec, B, kappa = par["m"], par["e_over_c"], np.array(par["B"]), par["potential"]
T = scene["horizon"]["T"]
x0, v0 = np.array(bd["initial"]["position"]), np.array(bd["initial"]["velocity"])
xT, vT = np.array(bd["final"]["position"]), np.array(bd["final"]["velocity"])

# u = m x'' + K x' + 2 kappa x with K v = (e/c) B x v;  optimality: m u'' + K u' + 2 kappa u = 0.
K = ec * np.array([[0, -B[2], B[1]], [B[2], 0, -B[0]], [-B[1], B[0], 0]])
I3 = np.eye(3)
A = np.zeros((12, 12))
A[0:3, 3:6] = I3
A[3:6, 0:3] = -(2 * kappa / m) * I3
A[3:6, 3:6] = -K / m
A[3:6, 6:9] = I3 / m
A[6:9, 9:12] = I3
A[9:12, 6:9] = -(2 * kappa / m) * I3
A[9:12, 9:12] = -K / m
Phi = expm(A * T)
a, b = np.concatenate([x0, v0]), np.concatenate([xT, vT])
y0 = np.concatenate([a, np.linalg.solve(Phi[:6, 6:], b - Phi[:6, :6] @ a)])


def exact_x(ts):
    return np.array([(expm(A * t) @ y0)[:3] for t in ts])


check_t = np.linspace(0, T, 401)
check_x = exact_x(check_t)


def scipy_run(tol):
    def bc(ya, yb):
        return np.concatenate([ya[:3] - x0, ya[3:6] - v0, yb[:3] - xT, yb[3:6] - vT])

    mesh = np.linspace(0, T, 11)
    guess = np.zeros((12, mesh.size))
    times, sol = [], None
    for _ in range(REPS):
        t0 = time.perf_counter()
        sol = solve_bvp(lambda t, y: A @ y, bc, mesh, guess, tol=tol, max_nodes=100000)
        times.append(time.perf_counter() - t0)
    err = np.max(np.abs(sol.sol(check_t)[:3].T - check_x))
    return sol.status == 0, err, statistics.median(times), sol.x.size


def lpshoot_sweep(grids):
    runs = {}
    with tempfile.TemporaryDirectory() as out:
        for _ in range(REPS):
            subprocess.run([LPSHOOT, "sweep", SCENE, "--N", ",".join(map(str, grids)), "--set", "solver.segments=auto",
                            "--no-plot", "--quiet", "--out", out], check=True, capture_output=True)
            with open(os.path.join(out, "sweep.json")) as f:
                for r in json.load(f)["runs"]:
                    runs.setdefault(r["N"], []).append(r)
        # Cross-check one lpshoot trajectory against this script's oracle.
        subprocess.run([LPSHOOT, "solve", SCENE, "--set", "horizon.N=200", "--set", "solver.segments=8", "--no-plot",
                        "--quiet", "--out", out], check=True, capture_output=True)
        data = np.genfromtxt(os.path.join(out, "trajectory.csv"), delimiter=",", names=True)
        cross = np.max(np.abs(np.stack([data["x1"], data["x2"], data["x3"]], 1) - exact_x(data["t"])))
    rows = []
    for N, rs in sorted(runs.items()):
        rows.append((N, all(r["converged"] for r in rs), rs[0]["error"], statistics.median(r["wall_time_s"] for r in rs)))
    return rows, cross


def lpshoot_richardson(grids):
    """lpshoot solve with scheme.error_estimate: the extrapolated trajectory (N, N/2, N/4 solves);
    time = the run's wall time plus the estimate's, error against this script's oracle."""
    rows = []
    with tempfile.TemporaryDirectory() as out:
        for N in grids:
            times, err = [], None
            for _ in range(REPS):
                subprocess.run([LPSHOOT, "solve", SCENE, "--set", f"horizon.N={N}", "--set", "solver.segments=auto",
                                "--set", "scheme.error_estimate=true", "--no-plot", "--quiet", "--out", out],
                               check=True, capture_output=True)
                with open(os.path.join(out, "report.json")) as f:
                    r = json.load(f)
                times.append(r["wall_time_s"] + r["error_estimate"]["wall_time_s"])
                data = np.genfromtxt(os.path.join(out, "trajectory_extrapolated.csv"), delimiter=",", names=True)
                err = np.max(np.abs(np.stack([data["x1"], data["x2"], data["x3"]], 1) - exact_x(data["t"])))
            rows.append((N, err, statistics.median(times)))
    return rows


def main():
    print(f"electron scene {os.path.relpath(SCENE)}, T = {T}; median of {REPS} runs; error = max |x - x_exact|\n")
    sc = [(tol,) + scipy_run(tol) for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-8]]
    ls, cross = lpshoot_sweep([25, 50, 100, 200, 400, 800, 1600])
    print("| solver | setting | converged | error | time [ms] |")
    print("|---|---|---|---|---|")
    for tol, ok, err, t, nodes in sc:
        print(f"| scipy solve_bvp | tol {tol:g} ({nodes} nodes) | {ok} | {err:.2e} | {1e3 * t:.2f} |")
    for N, ok, err, t in ls:
        print(f"| lpshoot (multiple, 2nd-order closure) | N = {N} | {ok} | {err:.2e} | {1e3 * t:.2f} |")
    rich = lpshoot_richardson([100, 200, 400, 800])
    for N, err, t in rich:
        print(f"| lpshoot + Richardson (error_estimate) | N = {N} (and N/2, N/4) | True | {err:.2e} | {1e3 * t:.2f} |")
    print(f"\ncross-check: lpshoot N = 200 against this script's expm oracle: {cross:.2e}")

    # Time to reach an error level (log-log interpolation along each method's curve).
    def time_for(points, level):
        pts = sorted((e, t) for e, t in points if e and e > 0)
        for (e1, t1), (e2, t2) in zip(pts, pts[1:]):
            if e1 <= level <= e2:
                w = np.log(level / e1) / np.log(e2 / e1)
                return float(np.exp(np.log(t1) + w * (np.log(t2) - np.log(t1))))
        return None

    sp = [(err, t) for _, ok, err, t, _ in sc if ok]
    lp = [(err, t) for _, ok, err, t in ls if ok]
    lr = [(err, t) for _, err, t in rich]
    fmt = lambda x: f"{x * 1e3:.2f}" if x else "-"
    ratio = lambda b, a: f"{b / a:.2f}" if a and b else "n/a"
    print("\n| error level | scipy solve_bvp [ms] | lpshoot [ms] | lpshoot + Richardson [ms] | lpshoot / scipy | Richardson / scipy |")
    print("|---|---|---|---|---|---|")
    for level in [1e-4, 1e-5, 1e-6, 1e-7]:
        a, b, c = time_for(sp, level), time_for(lp, level), time_for(lr, level)
        print(f"| {level:g} | {fmt(a)} | {fmt(b)} | {fmt(c)} | {ratio(b, a)} | {ratio(c, a)} |")
    print("(times interpolated log-log along each curve; '-': the level is outside that curve)")


if __name__ == "__main__":
    main()
