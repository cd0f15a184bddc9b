"""The cart-pendulum (examples/app/problem_cart_pendulum.cpp) against what it models. The force
that moves the solved cart, u = (M+m) v' + m l (cos psi psi_dot' - sin psi psi_dot^2) from the
columns, fed to the full two-degree-of-freedom equations of cart and pendulum (integrated here by
RK4) reproduces the solved pendulum angle: the unactuated pendulum obeys its own equation (a
wrong sign or term in the model's constraint is off by O(0.1)). The scheme's momentum map is
conserved; the error falls at the schemes' orders."""

import math

import numpy as np

import lpshoot
from conftest import scene_path


def dynamics(state, u, M, m, l, g):
    """(x, psi, v, psi_dot)' under cart force u: the Euler-Lagrange equations of
    L = 1/2 (M+m) v^2 + m l cos(psi) v psi' + 1/2 m l^2 psi'^2 + m g l cos(psi)."""
    x, psi, v, w = state
    c, s = math.cos(psi), math.sin(psi)
    a, alpha = np.linalg.solve(np.array([[M + m, m * l * c], [c, l]]), np.array([u + m * l * s * w * w, -g * s]))
    return np.array([v, w, a, alpha])


def local_cubic(t_nodes, values, t):
    """The cubic through the four nodes around t (uniform grid)."""
    h = t_nodes[1] - t_nodes[0]
    i = min(max(int(t / h) - 1, 0), len(t_nodes) - 4)
    ts, ys = t_nodes[i:i + 4], values[i:i + 4]
    return sum(ys[j] * np.prod([(t - ts[k]) / (ts[j] - ts[k]) for k in range(4) if k != j]) for j in range(4))


def test_the_pendulum_obeys_its_equation_under_the_cart_force():
    scene = scene_path("cart_pendulum")
    p = lpshoot.check(scene)["scene"]["parameters"]
    M, m, l, g = p["M"], p["m"], p["l"], p["g"]
    r = lpshoot.solve(scene, {"horizon.N": 600})
    assert r.converged, r.message
    tr = r.trajectory
    t = tr["t"]
    h = t[1] - t[0]
    assert abs(tr["x"][-1] - 1.0) < 1e-10 and abs(tr["psi"][-1]) < 1e-10 and abs(tr["v"][-1]) < 1e-10
    # The cart's force from the solved motion (second-order differences of the node velocities).
    a, alpha = np.gradient(tr["v"], h, edge_order=2), np.gradient(tr["psi_dot"], h, edge_order=2)
    psi, w = tr["psi"], tr["psi_dot"]
    u = (M + m) * a + m * l * (np.cos(psi) * alpha - np.sin(psi) * w * w)
    state = np.array([tr["x"][0], psi[0], tr["v"][0], w[0]])
    steps = 4
    dt = h / steps
    worst = 0.0
    f = lambda tt, y: dynamics(y, local_cubic(t, u, tt), M, m, l, g)
    for n in range(len(t) - 1):
        for k in range(steps):
            s = t[n] + k * dt
            k1 = f(s, state)
            k2 = f(s + dt / 2, state + dt / 2 * k1)
            k3 = f(s + dt / 2, state + dt / 2 * k2)
            k4 = f(s + dt, state + dt * k3)
            state = state + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        worst = max(worst, abs(state[1] - psi[n + 1]), abs(state[0] - tr["x"][n + 1]))
    assert max(abs(psi)) > 0.05  # the pendulum does swing: the check is not vacuous
    assert worst < 1e-3 * max(abs(psi)), worst
    # J is conserved by the scheme up to the Newton residual (tolerance 1e-10 per condition, N = 600).
    assert r.report["momentum_drift"] < 1e-8


def test_orders_of_the_schemes():
    sw = lpshoot.sweep(scene_path("cart_pendulum"), [15, 30, 60, 120], schemes=["galerkin4", "galerkin6"])
    assert sw.converged, sw.message
    order = {(row["scheme"], row["N"]): row["order"] for row in sw.runs}
    assert 3.6 < order["galerkin4", 60] < 4.4, sw.runs
    assert 5.4 < order["galerkin6", 30] < 6.6, sw.runs


def test_the_papers_windows_derived_from_the_model_are_second_order():
    """scheme paper: the windows from the continuous model (core/paper_windows.hpp, central jet),
    every boundary value given: second order against Galerkin 6 on the finest grid (error ~6e-12
    there). Measured: 2.13, 2.03. The reported cost adds half of each end window to the windows'
    sum (a midpoint rule on [h/2, T - h/2]): second order, measured 1.81, 1.89, 1.94 (errors
    1.2e-3 ... 2.4e-5); the action, the sum alone, is first order (3.6e-2 ... 5.9e-3)."""
    sw = lpshoot.sweep(scene_path("cart_pendulum"), [30, 60, 120, 240], schemes=["paper", "galerkin6"])
    assert sw.converged, sw.message
    order = {(row["scheme"], row["N"]): row["order"] for row in sw.runs}
    assert 1.85 < order["paper", 60] < 2.25, sw.runs
    assert 1.85 < order["paper", 120] < 2.15, sw.runs
    cost_error = {row["N"]: row["cost_error"] for row in sw.runs if row["scheme"] == "paper"}
    cost_orders = [math.log2(cost_error[N] / cost_error[2 * N]) for N in (30, 60)]
    print("paper windows, cost errors", cost_error, "orders", cost_orders)
    assert all(1.7 < q < 2.2 for q in cost_orders), (cost_error, cost_orders)


def test_the_force_column_is_the_force_of_the_solved_motion():
    """The u column: the constraint depends on psi'' (and l couples psi'' with Omega'), so the node
    jets come from differentiating the node values (the report says so). It must be the force of the solved
    motion, u = (M+m) v' + m l (cos psi psi_dot' - sin psi psi_dot^2) from the columns by
    second-order differences (O(h^2) apart), and converge under refinement."""
    scene = scene_path("cart_pendulum")
    p = lpshoot.check(scene)["scene"]["parameters"]
    M, m, l = p["M"], p["m"], p["l"]
    r = lpshoot.solve(scene, {"horizon.N": 600})
    assert r.converged, r.message
    assert r.report["outputs_from"] == "node_differences"
    tr = r.trajectory
    h = tr["t"][1] - tr["t"][0]
    a, alpha = np.gradient(tr["v"], h, edge_order=2), np.gradient(tr["psi_dot"], h, edge_order=2)
    psi, w = tr["psi"], tr["psi_dot"]
    u = (M + m) * a + m * l * (np.cos(psi) * alpha - np.sin(psi) * w * w)
    scale = max(abs(u))
    assert scale > 0.1
    worst = max(abs(np.asarray(tr["u"]) - u))
    assert worst < 1e-4 * scale, worst  # measured 2.3e-5: the differences' own O(h^2)
    # Self-convergence of the column at the common nodes of N = 30, 60, 120, 240 (the scene's
    # Galerkin 6; measured orders 8.6 and 5.7, Omega' = 0 or the curves' p'' would give 0 to 3).
    cols = {N: np.asarray(lpshoot.solve(scene, {"horizon.N": N}).trajectory["u"]) for N in (30, 60, 120, 240)}
    d = [max(abs(cols[2 * N][::2] - cols[N])) for N in (30, 60, 120)]
    orders = [math.log2(d[i] / d[i + 1]) for i in range(2)]
    print("u column: differences", d, "orders", orders)
    assert min(orders) > 5.0, (d, orders)
