"""Elroy's beanie from Python: solve the minimum-energy rotor manoeuvre, plot the rotor angle psi,
the control u and the plane path, then sweep the schemes over grids and plot error against time.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/beanie.py [--out DIR]

Writes DIR/beanie.png and DIR/beanie_error_time.png (default DIR: lpshoot-out/python).
"""

import argparse
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files, no display
import matplotlib.pyplot as plt

import lpshoot

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "beanie.json"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="lpshoot-out/python", help="where the plots go")
    out = Path(parser.parse_args().out)
    os.makedirs(out, exist_ok=True)

    # One solve: the scene as written, on the Galerkin scheme of order 6.
    r = lpshoot.solve(SCENE, {"scheme": {"discretization": "galerkin", "order": 6}, "horizon.N": 100})
    print(r)
    if not r.converged:
        raise SystemExit(f"the beanie did not converge: {r.message}")
    x = r.trajectory
    print(f"cost {r.cost:.12g}, momentum drift {r.report['momentum_drift']:.2e}, {r.wall_time_s:.3f} s")
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    ax[0].plot(x["t"], x["psi"], label="psi (rotor)")
    ax[0].plot(x["t"], x["theta"], label="theta (body)")
    ax[0].set_xlabel("t"), ax[0].legend(), ax[0].set_title("angles")
    ax[1].plot(x["t"], x["u"])
    ax[1].set_xlabel("t"), ax[1].set_title("control u")
    ax[2].plot(x["x"], x["y"])
    ax[2].set_xlabel("x"), ax[2].set_ylabel("y"), ax[2].set_aspect("equal", "datalim"), ax[2].set_title("plane path")
    fig.tight_layout()
    fig.savefig(out / "beanie.png", dpi=100)

    # The speed/accuracy trade: each scheme over grids, errors against the finest Galerkin-6 grid.
    sw = lpshoot.sweep(SCENE, [25, 50, 100, 200], schemes=["paper", "galerkin4", "galerkin6"])
    print(sw, sw.report["reference"])
    fig, ax = plt.subplots(figsize=(6, 4.5))
    schemes = sw.column("scheme")
    for scheme in dict.fromkeys(schemes):
        rows = [i for i, s in enumerate(schemes) if s == scheme]
        err, time = sw.column("error")[rows], sw.column("wall_time_s")[rows]
        ax.loglog(time, err, "o-", label=scheme)
    ax.set_xlabel("wall time [s]"), ax.set_ylabel("max error over the nodes"), ax.legend()
    ax.set_title("beanie: error against cost\n(reference: " + sw.report["reference"] + ")", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "beanie_error_time.png", dpi=100)
    print("wrote", out / "beanie.png", out / "beanie_error_time.png")


if __name__ == "__main__":
    main()
