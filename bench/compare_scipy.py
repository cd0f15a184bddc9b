#!/usr/bin/python3
"""Accuracy per unit time on the paper's two examples: lpshoot's schemes (the paper's nodal
windows, Galerkin of order 4, 6 and 8) against scipy's solve_bvp, measured in the same run on the
same machine.

electron (METHOD.md 6.1): the continuous optimum is linear, y = (x, x', u, u') solves y' = A y;
the exact answer is expm(A t) y0 (scipy.linalg.expm, independent of lpshoot's C++ oracle).
beanie (METHOD.md 6.2): the group motion is fixed by the shape (Omega3 from theta(T), the centre
moving with constant spatial velocity), so the optimum is the shape problem
min int 1/2 u^2, u = mu psi'' + V'(psi), whose Euler-Lagrange equation is mu u'' + V''(psi) u = 0:
y = (psi, psi', u, u'). Reference: shooting on (u(0), u'(0)) with DOP853 at rtol 1e-13
(scipy.integrate.solve_ivp + scipy.optimize.fsolve), independent of lpshoot.

scipy's solve_bvp (4th-order collocation) gets the continuous optimality system written by hand,
with analytic fun_jac and bc_jac, vectorized; lpshoot gets the scene only (it derives its
equations from the Lagrangian). Timed: the solve_bvp call (repetitions in one Python process);
lpshoot's solve (wall_time_s of the report, not the process start), warm: all grids in one
`lpshoot sweep` process after a smaller warm-up grid (a new process's first solve also pays page faults
and lazy symbol binding, ~0.2 ms on the electron and ~0.7 ms on the beanie; that time is printed too). Error: max over lpshoot's nodes
(scipy: over 401 points) of the
positions (electron) or of psi, theta, x, y (beanie).

usage: /usr/bin/python3 bench/compare_scipy.py [path/to/lpshoot] [repetitions]
(needs python3-scipy; prints Markdown tables)
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.integrate import solve_bvp, solve_ivp
from scipy.linalg import expm
from scipy.optimize import fsolve

LPSHOOT = sys.argv[1] if len(sys.argv) > 1 else "build/examples/app/lpshoot"
REPS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
SCENES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "scenes")
LEVELS = [1e-6, 1e-8, 1e-10]
SCHEMES = {  # scheme name -> (scene "scheme" object, grids)
    "paper": ({"closure": "second_order"}, [50, 100, 200, 400, 800, 1600, 3200]),
    "galerkin4": ({"discretization": "galerkin", "order": 4}, [10, 20, 40, 80, 160, 320]),
    "galerkin6": ({"discretization": "galerkin", "order": 6}, [4, 8, 16, 32, 64]),
    "galerkin8": ({"discretization": "galerkin", "order": 8}, [3, 4, 8, 16, 32]),
}


def load(name):
    with open(os.path.join(SCENES, name + ".json")) as f:
        return json.load(f)


class Electron:
    name, scene, columns = "electron", "electron", ["x1", "x2", "x3"]

    def __init__(self):
        s = load(self.scene)
        par, bd = s["parameters"], s["boundary"]
        m, ec, B, kappa = par["m"], par["e_over_c"], np.array(par["B"]), par["potential"]
        self.T = s["horizon"]["T"]
        self.x0, self.v0 = np.array(bd["initial"]["position"]), np.array(bd["initial"]["velocity"])
        self.xT, self.vT = np.array(bd["final"]["position"]), np.array(bd["final"]["velocity"])
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
        self.A = A
        Phi = expm(A * self.T)
        a, b = np.concatenate([self.x0, self.v0]), np.concatenate([self.xT, self.vT])
        self.y0 = np.concatenate([a, np.linalg.solve(Phi[:6, 6:], b - Phi[:6, :6] @ a)])

    def exact(self, ts):  # columns at times ts
        return np.array([(expm(self.A * t) @ self.y0)[:3] for t in ts])

    def scipy(self, tol):
        A = self.A
        fun = lambda t, y: A @ y
        jac = lambda t, y: np.repeat(A[:, :, None], y.shape[1], axis=2)
        I6 = np.eye(12)[:6]
        bc = lambda ya, yb: np.concatenate([ya[:6] - np.concatenate([self.x0, self.v0]),
                                            yb[:6] - np.concatenate([self.xT, self.vT])])
        bc_jac = lambda ya, yb: (np.vstack([I6, np.zeros((6, 12))]), np.vstack([np.zeros((6, 12)), I6]))
        mesh = np.linspace(0, self.T, 11)
        return solve_bvp(fun, bc, mesh, np.zeros((12, mesh.size)), fun_jac=jac, bc_jac=bc_jac, tol=tol,
                         max_nodes=1000000), lambda sol, ts: sol.sol(ts)[:3].T


class Beanie:
    name, scene, columns = "beanie", "beanie", ["psi", "theta", "x", "y"]

    def __init__(self):
        s = load(self.scene)
        p, bd = s["parameters"], s["boundary"]
        self.m, I1, I2 = p["m"], p["I1"], p["I2"]
        self.amp = p["potential"]["amplitude"] if p["potential"]["type"] == "cosine" else 0.0
        self.c, self.mu = I2 / (I1 + I2), I1 * I2 / (I1 + I2)
        self.T = s["horizon"]["T"]
        a, b = bd["initial"], bd["final"]
        self.psi0, self.dpsi0, self.psiT, self.dpsiT = a["psi"], a["psi_dot"], b["psi"], b["psi_dot"]
        self.theta0, self.r0, self.Om12 = a["theta"], np.array([a["x"], a["y"]]), np.array([a["Omega1"], a["Omega2"]])
        self.Omega3 = (b["theta"] - self.theta0 + self.c * (self.psiT - self.psi0)) / self.T
        # Reference: shooting on (u(0), u'(0)) with DOP853.
        def end(s):
            sol = solve_ivp(self.rhs, (0, self.T), [self.psi0, self.dpsi0, s[0], s[1]], method="DOP853", rtol=1e-13,
                            atol=1e-15)
            return [sol.y[0, -1] - self.psiT, sol.y[1, -1] - self.dpsiT]
        self.s0 = fsolve(end, [0.0, 0.0], xtol=1e-14)
        self.ref = solve_ivp(self.rhs, (0, self.T), [self.psi0, self.dpsi0, *self.s0], method="DOP853", rtol=1e-13,
                             atol=1e-15, dense_output=True)

    def rhs(self, t, y):  # y = (psi, psi', u, u'); vectorized over columns
        psi, dpsi, u, du = y
        return np.array([dpsi, (u - self.amp * np.sin(psi)) / self.mu, du, -self.amp * np.cos(psi) * u / self.mu])

    def group(self, ts, psi):  # theta, x, y of the free beanie on psi(t)
        theta = self.theta0 + self.Omega3 * ts - self.c * (psi - self.psi0)
        R = np.array([[np.cos(self.theta0), -np.sin(self.theta0)], [np.sin(self.theta0), np.cos(self.theta0)]])
        xy = self.r0[None, :] + ts[:, None] * (R @ self.Om12)[None, :]
        return np.column_stack([psi, theta, xy])

    def exact(self, ts):
        return self.group(np.asarray(ts), self.ref.sol(ts)[0])

    def scipy(self, tol):
        mu, A = self.mu, self.amp

        def jac(t, y):
            psi, dpsi, u, du = y
            J = np.zeros((4, 4, y.shape[1]))
            J[0, 1] = 1
            J[1, 0], J[1, 2] = -A * np.cos(psi) / mu, 1 / mu
            J[2, 3] = 1
            J[3, 0], J[3, 2] = A * np.sin(psi) * u / mu, -A * np.cos(psi) / mu
            return J
        bc = lambda ya, yb: np.array([ya[0] - self.psi0, ya[1] - self.dpsi0, yb[0] - self.psiT, yb[1] - self.dpsiT])
        E = np.eye(4)[:2]
        bc_jac = lambda ya, yb: (np.vstack([E, np.zeros((2, 4))]), np.vstack([np.zeros((2, 4)), E]))
        mesh = np.linspace(0, self.T, 11)
        guess = np.zeros((4, mesh.size))
        guess[0] = self.psi0 + (self.psiT - self.psi0) * mesh / self.T
        return solve_bvp(self.rhs, bc, mesh, guess, fun_jac=jac, bc_jac=bc_jac, tol=tol, max_nodes=1000000), \
            lambda sol, ts: self.group(ts, sol.sol(ts)[0])


def scipy_rows(prob):
    ts = np.linspace(0, prob.T, 401)
    ref = prob.exact(ts)
    rows = []
    for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]:
        times = []
        for _ in range(REPS):
            t0 = time.perf_counter()
            sol, at = prob.scipy(tol)
            times.append(time.perf_counter() - t0)
        err = float(np.max(np.abs(at(sol, ts) - ref)))
        rows.append((f"tol {tol:g} ({sol.x.size} nodes)", sol.status == 0, err, statistics.median(times), None))
    return rows


def warmup_grid(scheme, grids):
    """A grid below every grid of the curve (sweep runs grids in increasing N): the first solve of
    a process pays its cold start. The paper's windows need N >= 2k + 1 = 5."""
    return max(5 if scheme == "paper" else 2, min(grids) // 2)


def lpshoot_rows(prob, scheme):
    """Rows (setting, converged, error, warm time, new-process time). The error is read from the
    trajectory of a `solve` (a new process, whose solve time is also kept). The warm time: every
    grid in one `lpshoot sweep` process after a warm-up grid, as scipy's repetitions run in one
    warm Python process; median over REPS sweeps."""
    obj, grids = SCHEMES[scheme]
    rows = []
    scene = os.path.join(SCENES, prob.scene + ".json")
    common = ["--set", "solver.segments=auto", "--set", "scheme=" + json.dumps(obj), "--no-plot", "--quiet"]
    with tempfile.TemporaryDirectory() as out:
        warm = {N: [] for N in grids}
        for _ in range(REPS):
            subprocess.run([LPSHOOT, "sweep", scene, "--N", ",".join(str(n) for n in [warmup_grid(scheme, grids)] + grids),
                            "--scheme", scheme] + common + ["--out", out], check=False, capture_output=True)
            with open(os.path.join(out, "sweep.json")) as f:
                for run in json.load(f)["runs"]:
                    if run["N"] in warm and run["converged"]:
                        warm[run["N"]].append(run["wall_time_s"])
        for N in grids:
            subprocess.run([LPSHOOT, "solve", scene, "--set", f"horizon.N={N}"] + common + ["--out", out],
                           check=False, capture_output=True)
            with open(os.path.join(out, "report.json")) as f:
                r = json.load(f)
            ok, err = r["converged"] and len(warm[N]) == REPS, None
            if ok:
                data = np.genfromtxt(os.path.join(out, "trajectory.csv"), delimiter=",", names=True)
                got = np.column_stack([data[c] for c in prob.columns])
                err = float(np.max(np.abs(got - prob.exact(data["t"]))))
            rows.append((f"N = {N}", ok, err, statistics.median(warm[N]) if ok else float("nan"), r["wall_time_s"]))
    return rows


def time_for(points, level):
    """Time to reach an error level, log-log interpolation along a curve of (error, time)."""
    pts = sorted((e, t) for e, t in points if e and e > 0)
    for (e1, t1), (e2, t2) in zip(pts, pts[1:]):
        if e1 <= level <= e2:
            w = np.log(level / e1) / np.log(e2 / e1)
            return float(np.exp(np.log(t1) + w * (np.log(t2) - np.log(t1))))
    return None


def main():
    for prob in [Electron(), Beanie()]:
        print(f"\n### {prob.name} (examples/scenes/{prob.scene}.json, T = {prob.T}); median of {REPS} runs\n")
        curves = {"scipy solve_bvp": scipy_rows(prob)}
        for s in SCHEMES:
            curves["lpshoot " + s] = lpshoot_rows(prob, s)
        print("| solver | setting | converged | error | time [ms] | lpshoot: solve time in a new process [ms] |")
        print("|---|---|---|---|---|---|")
        for name, rows in curves.items():
            for setting, ok, err, t, cold in rows:
                e = f"{err:.2e}" if err is not None else "-"
                c = f"{1e3 * cold:.2f}" if cold is not None else "-"
                print(f"| {name} | {setting} | {ok} | {e} | {1e3 * t:.2f} | {c} |")
        ref = {lv: time_for([(e, t) for _, ok, e, t, _ in curves["scipy solve_bvp"] if ok], lv) for lv in LEVELS}
        print("\n| error level | " + " | ".join(f"{n} [ms]" for n in curves) + " | " +
              " | ".join(f"{n} / scipy" for n in list(curves)[1:]) + " |")
        print("|---" * (2 * len(curves)) + "|")
        for lv in LEVELS:
            ts = [time_for([(e, t) for _, ok, e, t, _ in rows if ok], lv) for rows in curves.values()]
            cells = [f"{1e3 * t:.2f}" if t else "-" for t in ts]
            ratios = [f"{t / ref[lv]:.2f}" if t and ref[lv] else "n/a" for t in ts[1:]]
            print(f"| {lv:g} | " + " | ".join(cells) + " | " + " | ".join(ratios) + " |")
        print("(times interpolated log-log along each curve; '-': the level is outside that curve)")


if __name__ == "__main__":
    main()
