#!/usr/bin/python3
"""The paper scheme's error at tolerance 1e-12 against Galerkin 6 (bench/RESULTS.md, "The paper's windows without
their roundoff floor"). usage: /usr/bin/python3 bench/paper_floor.py LPSHOOT 100,1000,4000 (steps per segment);
first: LPSHOOT solve examples/scenes/cart_pendulum.json --set horizon.N=1000 --set solver.tolerance=1e-12 --out /tmp/ref"""
import csv, subprocess, sys, numpy as np
L = sys.argv[1]; S = "examples/scenes/cart_pendulum.json"
def load(d):
    rows = list(csv.DictReader(open(d + "/trajectory.csv")))
    return {k: np.array([float(r[k]) for r in rows]) for k in ("psi", "x")}
ref = load("/tmp/ref")  # lpshoot solve SCENE --set horizon.N=1000 --set solver.tolerance=1e-12 --out /tmp/ref
for spp in [int(a) for a in sys.argv[2].split(",")]:
  for N in [1000, 2000, 4000, 8000, 16000]:
    seg = max(1, N // spp)
    out = f"/tmp/fl_{N}_{spp}"
    r = subprocess.run([L, "solve", S, "--no-plot", "--quiet", "--out", out, "--set", f"horizon.N={N}", "--set", 'scheme={"discretization":"paper"}',
                        "--set", "solver.tolerance=1e-12", "--set", f"solver.segments={seg}"], capture_output=True, text=True)
    st = [l for l in r.stdout.splitlines() if l.startswith("status")]
    st = st[0][8:60] if st else r.stderr[:80]
    try:
        c = load(out); k = N // 1000
        e = max(np.max(np.abs(c[v][::k] - ref[v])) for v in ("psi", "x"))
    except Exception as ex:
        e = float("nan")
    print(f"{spp:5d} steps/segment N = {N:6d}: error {e:.3e}  {st}")
