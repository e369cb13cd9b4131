#!/usr/bin/python3
"""Python against C++ on the same RBF job (issue 18's overhead target: Python <= 1.05x C++
per move, no copies on the hot path).

A hex box of N³ cells (default 80: 531,441 nodes) is written once by the C++ peer
(benchmarks/python_overhead_peer.cpp); both sides read it, prescribe a sine bump on "bottom"
with "top" fixed (the sides free), set up the RBF mover (Wendland C2, radius 6 cells) through the
same registry, then time MOVES moves into one preallocated array and MOVES reverse derivatives.
The sides alternate ROUNDS times; the table gives medians over rounds of each side's median
per operation, and the ratio Python / C++. One JSON line per case.

The MPI rows do the same job over MPI at each rank count of --mpi-ranks (Python: the
distributed mover Warp(comm=...) uses, through mpi4py; C++: python_mpi_overhead_peer), on a
box of --mpi-cells³ cells, each rank unbound with its share of the cores; the times are the
slowest rank's. They are skipped, saying why, without the module's MPI or the peer.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_overhead.py \
        [--peer build-bench/benchmarks/python_overhead_peer] [--cells 80] [--moves 100] [--rounds 5] \
        [--mpi-ranks 1,2,4] [--mpi-cells 40]
"""

import argparse
import json
import os
import pathlib
import shutil
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


def mpi_side(file, radius, moves):
    """Under mpiexec: the distributed mover's job; rank 0 prints the JSON line."""
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    mesh = spec = None
    if comm.rank == 0:
        mesh = mm.read_mesh(file)
        bottom = mesh.groups["bottom"]
        x = mesh.points[bottom]
        bump = np.column_stack([np.zeros(len(bottom)), np.zeros(len(bottom)),
                                0.01 * np.sin(np.pi * x[:, 0]) * np.sin(np.pi * x[:, 1])])
        spec = mm.Boundary(3).moving("bottom", list(bottom), bump).fixed("top").resolve(mesh)
    part = mm._core.DistributedMesh3.partition(comm, mesh)
    local = part.distribute_boundary(spec)
    d = local.displacements
    comm.Barrier()
    start = time.perf_counter()
    mover = mm._core.DistributedMover3("rbf", support_radius=radius)
    mover.setup(part, local)
    setup = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    out = np.empty((len(part.global_ids), 3))
    move_seconds, reverse_seconds = [], []
    for _ in range(moves):
        start = time.perf_counter()
        mover.move_into(d, out)
        move_seconds.append(comm.allreduce(time.perf_counter() - start, op=MPI.MAX))
    seed = np.ones((len(part.global_ids), 3))
    for _ in range(moves):
        start = time.perf_counter()
        gradient = mover.derivative_reverse(seed)
        reverse_seconds.append(comm.allreduce(time.perf_counter() - start, op=MPI.MAX))
    move_sum = comm.allreduce(float(np.abs(out[:part.num_owned]).sum()))
    reverse_sum = comm.allreduce(float(np.abs(gradient).sum()))
    if comm.rank == 0:
        print(json.dumps({"side": "python", "ranks": comm.size, "nodes": part.num_global_nodes, "setup_s": setup,
                          "move_median_s": statistics.median(move_seconds), "move_mean_s": statistics.fmean(move_seconds),
                          "reverse_median_s": statistics.median(reverse_seconds),
                          "reverse_mean_s": statistics.fmean(reverse_seconds), "move_checksum": move_sum,
                          "reverse_checksum": reverse_sum}))


def mpi_rows(args, here, folder):
    """The MPI rows: each side under mpiexec at each rank count, alternating ROUNDS times."""
    peer = args.mpi_peer or str(pathlib.Path(args.peer).with_name("python_mpi_overhead_peer"))
    mpiexec = shutil.which("mpiexec")
    if not getattr(mm._core, "have_mpi", False):
        print("python_overhead.py: MPI rows skipped: " + mm._core.mpi_missing)
        return
    if not os.access(peer, os.X_OK) or mpiexec is None:
        print(f"python_overhead.py: MPI rows skipped: no C++ peer at {peer} or no mpiexec")
        return
    file = str(pathlib.Path(folder) / f"box{args.mpi_cells}.msh")
    subprocess.run([args.peer, "write", str(args.mpi_cells), file], check=True)
    radius = 6.0 / args.mpi_cells
    version = subprocess.run([mpiexec, "--version"], capture_output=True, text=True).stdout
    # Open MPI binds each rank to one core up to two ranks: the one rank's OMP_NUM_THREADS threads
    # would take turns on one core while the other idles, timing the scheduler more than the call.
    open_mpi = "Open MPI" in version or "OpenRTE" in version
    flags = ["--oversubscribe", "--allow-run-as-root", "--bind-to", "none"] if open_mpi else []
    print(f"\nOver MPI: hex box of {args.mpi_cells}^3 cells, radius {radius:.4g}, {args.moves} operations x "
          f"{args.rounds} rounds, the slowest rank's times")
    print(f"{'ranks':>5}  {'operation':<22}{'C++ (ms)':>12}{'Python (ms)':>14}{'Python/C++':>12}")
    lines = []
    for ranks in [int(r) for r in args.mpi_ranks.split(",")]:
        env = dict(os.environ, OMP_NUM_THREADS=str(max(1, (os.cpu_count() or 1) // ranks)))
        runs = {"c++": [], "python": []}
        for _ in range(args.rounds):
            for side, command in (("c++", [peer, file, repr(radius), str(args.moves)]),
                                  ("python", [sys.executable, __file__, "--mpi-side", file, repr(radius), str(args.moves)])):
                done = subprocess.run([mpiexec, *flags, "-n", str(ranks), *command], capture_output=True, text=True, env=env)
                if done.returncode != 0:
                    sys.exit(f"python_overhead.py: {side} side at {ranks} ranks failed:\n{done.stderr[-2000:]}")
                output = done.stdout
                runs[side].append(json.loads([l for l in output.splitlines() if l.startswith("{")][-1]))
        cpp, py = runs["c++"][-1], runs["python"][-1]
        for key in ("move_checksum", "reverse_checksum"):
            if abs(cpp[key] - py[key]) > 1e-9 * abs(cpp[key]):
                sys.exit(f"python_overhead.py: the MPI sides disagree on {key} at {ranks} ranks "
                         f"({cpp[key]!r} against {py[key]!r})")
        for label, key in (("setup", "setup_s"), ("move_into", "move_median_s"), ("derivative_reverse", "reverse_median_s")):
            c = statistics.median(r[key] for r in runs["c++"])
            p = statistics.median(r[key] for r in runs["python"])
            print(f"{ranks:>5}  {label:<22}{1e3 * c:>12.3f}{1e3 * p:>14.3f}{p / c:>12.3f}")
            lines.append({"benchmark": "python_overhead", "case": "mpi_" + label, "ranks": ranks, "nodes": cpp["nodes"],
                          "operations": args.moves, "rounds": args.rounds, "cpp_s": c, "python_s": p, "ratio": p / c,
                          "target_ratio": 1.05 if label != "setup" else None})
    for line in lines:
        print(json.dumps(line))


def main():
    here = pathlib.Path(__file__).resolve().parent
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer", default=str(here.parent / "build-bench" / "benchmarks" / "python_overhead_peer"))
    parser.add_argument("--cells", type=int, default=80)
    parser.add_argument("--moves", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--mpi-ranks", default="1,2,4")
    parser.add_argument("--mpi-cells", type=int, default=40)
    parser.add_argument("--mpi-peer", default=None, help="default: python_mpi_overhead_peer beside --peer")
    parser.add_argument("--mpi-side", nargs=3, metavar=("FILE", "RADIUS", "MOVES"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.mpi_side:
        mpi_side(args.mpi_side[0], float(args.mpi_side[1]), int(args.mpi_side[2]))
        return
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
    if args.mpi_ranks:
        with tempfile.TemporaryDirectory() as folder:
            mpi_rows(args, here, folder)


if __name__ == "__main__":
    main()
