#!/usr/bin/python3
"""Observed orders of the paper's windows (a scene's problem given by its model) against
Galerkin 6 on the finest grid, at every output column: max over the coarse grid's nodes.

usage: NS=20,40,80,160,320 /usr/bin/python3 bench/orders_against_galerkin.py [path/to/lpshoot] scene [--set key=value ...]
(prints one line per N: the errors, the orders from the previous N, the solver's status)
"""
import csv
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

LPSHOOT = sys.argv[1] if len(sys.argv) > 2 and not sys.argv[1].endswith(".json") else "build/examples/app/lpshoot"
rest = sys.argv[2:] if LPSHOOT == sys.argv[1] else sys.argv[1:]
scene, extra = rest[0], rest[1:]
Ns = [int(x) for x in os.environ.get("NS", "20,40,80,160,320").split(",")]
work = tempfile.mkdtemp(prefix="lpshoot_orders_")


def run(scheme, N, out):
    r = subprocess.run([LPSHOOT, "solve", scene, "--no-plot", "--quiet", "--out", out, "--set", f"horizon.N={N}",
                        "--set", "scheme=" + scheme] + extra, capture_output=True, text=True)
    if r.returncode:
        sys.exit(r.stdout + r.stderr)
    rows = list(csv.DictReader(open(os.path.join(out, "trajectory.csv"))))
    cols = {k: np.array([float(x[k]) if x[k] not in ("", "nan") else np.nan for x in rows]) for k in rows[0]}
    status = [line for line in r.stdout.splitlines() if line.startswith("status")][0]
    return cols, status


ref, _ = run('{"discretization":"galerkin","order":6}', max(Ns), os.path.join(work, "reference"))
prev = None
for N in Ns:
    cols, status = run('{"discretization":"paper","closure":"second_order"}', N, os.path.join(work, f"paper{N}"))
    step = max(Ns) // N
    errs = {}
    for k in cols:
        if k == "t":
            continue
        a, b = cols[k], ref[k][::step]
        known = ~np.isnan(a)
        errs[k] = float(np.max(np.abs(a[known] - b[known])))
    line = f"N={N:5d} " + " ".join(f"{k} {e:.2e}" for k, e in errs.items())
    if prev:
        line += " | orders " + " ".join(f"{k} {math.log2(prev[k] / errs[k]):.2f}" for k in errs)
    print(line, "|", status)
    prev = errs
