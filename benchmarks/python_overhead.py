#!/usr/bin/python3
"""Python against C++ on the same RBF job (issue 18's overhead target: Python <= 1.05x C++
per move, no copies on the hot path).

A hex box of N³ cells (default 80: 531,441 nodes) is written once by the C++ peer
(benchmarks/python_overhead_peer.cpp); both sides read it, prescribe a sine bump on "bottom"
with "top" fixed (the sides free), set up the RBF mover (Wendland C2, radius 6 cells) through the
same registry, then time MOVES moves into one preallocated array and MOVES reverse derivatives.
The sides alternate ROUNDS times; the table gives medians over rounds of each side's median
per operation, and the ratio Python / C++. One JSON line per case.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_overhead.py \
        [--peer build-bench/benchmarks/python_overhead_peer] [--cells 80] [--moves 100] [--rounds 3]
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import meshmotion as mm


def python_side(file, radius, moves):
    mesh = mm.read_mesh(file)
    spec = mm.Boundary(3).prescribed("bottom").fixed("top")
    b = spec.resolve(mesh)
    d = np.zeros((b.size, 3))
    bottom = mesh.groups["bottom"]
    x = mesh.points[bottom]
    bump = np.column_stack([np.zeros(len(bottom)), np.zeros(len(bottom)),
                            0.01 * np.sin(np.pi * x[:, 0]) * np.sin(np.pi * x[:, 1])])
    b.scatter(list(bottom), bump, d)
    start = time.perf_counter()
    mover = mm.Mover("rbf", 3, support_radius=radius)
    mover.setup(mesh, b)
    setup = time.perf_counter() - start
    out = np.empty((mesh.num_nodes, 3))
    move_seconds, reverse_seconds = [], []
    for _ in range(moves):
        start = time.perf_counter()
        mover.move_into(d, out)
        move_seconds.append(time.perf_counter() - start)
    seed = np.ones((mesh.num_nodes, 3))
    for _ in range(moves):
        start = time.perf_counter()
        gradient = mover.derivative_reverse(seed)
        reverse_seconds.append(time.perf_counter() - start)
    return {"side": "python", "nodes": mesh.num_nodes, "centres": b.size, "setup_s": setup,
            "move_median_s": statistics.median(move_seconds), "move_mean_s": statistics.fmean(move_seconds),
            "reverse_median_s": statistics.median(reverse_seconds), "reverse_mean_s": statistics.fmean(reverse_seconds),
            "move_checksum": float(np.abs(out).sum()), "reverse_checksum": float(np.abs(gradient).sum())}


def main():
    here = pathlib.Path(__file__).resolve().parent
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer", default=str(here.parent / "build-bench" / "benchmarks" / "python_overhead_peer"))
    parser.add_argument("--cells", type=int, default=80)
    parser.add_argument("--moves", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    if not os.access(args.peer, os.X_OK):
        sys.exit(f"python_overhead.py: no C++ peer at {args.peer} (build with -DMESHMOTION_BUILD_BENCHMARKS=ON, "
                 "or give --peer)")
    radius = 6.0 / args.cells
    with tempfile.TemporaryDirectory() as folder:
        file = str(pathlib.Path(folder) / f"box{args.cells}.msh")
        subprocess.run([args.peer, "write", str(args.cells), file], check=True)
        runs = {"c++": [], "python": []}
        for _ in range(args.rounds):
            line = subprocess.run([args.peer, "run", file, repr(radius), str(args.moves)], check=True,
                                  capture_output=True, text=True).stdout.strip().splitlines()[-1]
            runs["c++"].append(json.loads(line))
            runs["python"].append(python_side(file, radius, args.moves))

    cpp, py = runs["c++"][-1], runs["python"][-1]
    for key in ("move_checksum", "reverse_checksum"):
        if abs(cpp[key] - py[key]) > 1e-9 * abs(cpp[key]):
            sys.exit(f"python_overhead.py: the sides disagree on {key} ({cpp[key]!r} against {py[key]!r})")
    print(f"RBF on a hex box of {args.cells}^3 cells: {cpp['nodes']} nodes, {cpp['centres']} boundary centres, "
          f"radius {radius:.4g}, {args.moves} operations x {args.rounds} alternating rounds (median of round medians)")
    print(f"{'operation':<22}{'C++ (ms)':>12}{'Python (ms)':>14}{'Python/C++':>12}")
    rows = []
    for label, key in (("setup", "setup_s"), ("move_into", "move_median_s"), ("derivative_reverse", "reverse_median_s")):
        c = statistics.median(r[key] for r in runs["c++"])
        p = statistics.median(r[key] for r in runs["python"])
        rows.append((label, c, p))
        print(f"{label:<22}{1e3 * c:>12.3f}{1e3 * p:>14.3f}{p / c:>12.3f}")
    for label, c, p in rows:
        print(json.dumps({"benchmark": "python_overhead", "case": label, "nodes": cpp["nodes"], "centres": cpp["centres"],
                          "operations": args.moves, "rounds": args.rounds, "cpp_s": c, "python_s": p, "ratio": p / c,
                          "target_ratio": 1.05 if label != "setup" else None}))


if __name__ == "__main__":
    main()
