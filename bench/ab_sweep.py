#!/usr/bin/python3
"""A/B of solve wall times between two lpshoot binaries, in the same run.

For each binary, scene and scheme: `lpshoot sweep <scene> --N <warm-up>,<grid> --set
solver.segments=auto --set scheme=<scheme> --no-plot --quiet`, reading each N's wall_time_s from
sweep.json (the first, warm-up N takes the process's cold start and is dropped). The binaries
alternate `reps` times; medians are printed with A / B.

usage: /usr/bin/python3 bench/ab_sweep.py path/to/lpshoot-A path/to/lpshoot-B [reps] [--set ...]
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile

SCENES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "scenes")
CASES = [  # scene, scheme object, warm-up N then the grid
    ("beanie", '{"discretization":"galerkin","order":4}', [5, 10, 40, 80, 160, 320]),
    ("beanie", '{"discretization":"galerkin","order":6}', [2, 4, 16, 64]),
    ("beanie", '{"closure":"second_order"}', [50, 100, 400, 1600]),
    ("electron", '{"discretization":"galerkin","order":4}', [5, 10, 80, 320]),
]


def main():
    a, b = sys.argv[1], sys.argv[2]
    reps = int(sys.argv[3]) if len(sys.argv) > 3 and not sys.argv[3].startswith("--") else 3
    extra = [x for x in sys.argv[3:] if not x.isdigit()]
    times = {}
    for _ in range(reps):
        for label, binary in (("A", a), ("B", b)):
            for scene, scheme, grid in CASES:
                with tempfile.TemporaryDirectory() as out:
                    subprocess.run([binary, "sweep", os.path.join(SCENES, scene + ".json"), "--N", ",".join(map(str, grid)),
                                    "--set", "solver.segments=auto", "--set", "scheme=" + scheme, "--no-plot", "--quiet",
                                    "--out", out] + extra, check=True, capture_output=True)
                    with open(os.path.join(out, "sweep.json")) as f:
                        runs = json.load(f)["runs"]
                    for r in runs[1:]:
                        times.setdefault((scene, scheme, r["N"], label), []).append(1e3 * r["wall_time_s"])
    print("| scene | scheme | N | A [ms] | B [ms] | A / B |\n|---|---|---|---|---|---|")
    for scene, scheme, grid in CASES:
        for n in grid[1:]:
            ta, tb = (statistics.median(times[(scene, scheme, n, x)]) for x in ("A", "B"))
            print(f"| {scene} | {scheme} | {n} | {ta:.2f} | {tb:.2f} | {ta / tb:.2f} |")


if __name__ == "__main__":
    main()
