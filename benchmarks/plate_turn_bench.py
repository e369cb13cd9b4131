#!/usr/bin/python3
"""A body turned inside held walls from one setup (issue 68): a plate 2 x 0.2 x 1 with sharp
edges in a held 12^3 box (tetrahedra by Gmsh: 0.1 at the plate, 0.5 at the walls), set up once
with nothing moving, then moved from the reference about the plate's axis in 15 degree steps to
a half turn, as a solver's time loop does. Per step: the invalid cells (scaled Jacobian), the
minimum shape quality (a linear tetrahedron's scaled Jacobian is only its sign) and the move's
time, for the defaults (each move's rigid part blended, RigidPartAtMove, and the cells the move
folded repaired, RbfOptions::repair) beside repair=False (the blend alone) and rigid_part=none
(the whole motion interpolated), through Python's Warp; run
under mpiexec it also moves on the ranks (Warp(comm=)) and gives the largest distance from the
serial points. With --programs (the build's examples folder) the programs run the same case
as users run them: move_mesh --steps 12 to the half turn and move_mesh_mpi on 2 ranks to a
quarter turn (one move), each with its invalid cells and its largest distance from Warp's
points at that angle (the policy is one: set up at rest, each move's rigid part blended);
those rows alone, run without mpiexec. One JSON line per row.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/plate_turn_bench.py [--size 0.1]
    mpiexec -n 2 ... (the same, adding the distributed row on rank 0)
    PYTHONPATH=build/python /usr/bin/python3 benchmarks/plate_turn_bench.py --programs build/examples
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import meshmotion as mm

try:
    from mpi4py import MPI
except ImportError:
    MPI = None


def plate_mesh(path, near, far):
    import gmsh
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        box = gmsh.model.occ.addBox(-6, -6, -6, 12, 12, 12)
        plate = gmsh.model.occ.addBox(-1, -0.1, -0.5, 2, 0.2, 1)
        gmsh.model.occ.cut([(3, box)], [(3, plate)])
        gmsh.model.occ.synchronize()
        walls, body = [], []
        for _, tag in gmsh.model.getEntities(2):
            bounds = gmsh.model.getBoundingBox(2, tag)
            (walls if max(abs(v) for v in bounds) > 6 - 1e-6 else body).append(tag)
        for dim, tags, name in ((2, body, "plate"), (2, walls, "walls"), (3, [t for _, t in gmsh.model.getEntities(3)], "air")):
            gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
        for _, tag in gmsh.model.getEntities(0):
            x = gmsh.model.getValue(0, tag, [])
            gmsh.model.mesh.setSize([(0, tag)], far if max(abs(v) for v in x) > 6 - 1e-6 else near)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)
        gmsh.model.mesh.generate(3)
        gmsh.write(path)
    finally:
        gmsh.finalize()


def turn(points, degrees):
    a = math.radians(degrees)
    out = points.copy()
    out[:, 0] = math.cos(a) * points[:, 0] - math.sin(a) * points[:, 1]
    out[:, 1] = math.sin(a) * points[:, 0] + math.cos(a) * points[:, 1]
    return out


def run(mesh, options, comm=None):
    warp = mm.Warp(mesh, design=["plate"], fixed=["walls"], comm=comm, **options)
    surface = warp.surface_coordinates().copy()
    steps = []
    for degrees in range(15, 181, 15):
        warp.set_surface_coordinates(turn(surface, degrees))
        start = time.perf_counter()
        warp.warp()
        seconds = time.perf_counter() - start
        points = warp.gather_volume_coordinates() if comm is not None else warp.volume_coordinates()
        stats = warp._mover.stats
        steps.append((degrees, seconds, points, (int(stats["folded_cells"]), int(stats["repaired_nodes"]))))
    return warp, steps


def programs_rows(programs, path, tmp, cells, serial):
    """move_mesh and move_mesh_mpi on the plate, against Warp's serial points `serial` (by angle)."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    flags = ["--oversubscribe", "--allow-run-as-root"] if "open" in subprocess.run(
        ["mpiexec", "--version"], capture_output=True, text=True).stdout.lower() else []
    motion = ["--group", "plate", "--fixed", "walls", "--center", "0,0,0", "--axis", "0,0,1", "--json"]
    runs = (("move_mesh --steps 12", 180, [os.path.join(programs, "move_mesh"), path, "--rotate", "180", "--steps", "12"]),
            ("move_mesh_mpi -n 2", 90, ["mpiexec", *flags, "-n", "2", os.path.join(programs, "move_mesh_mpi"), path,
                                        "--rotate", "90"]))
    for name, degrees, command in runs:
        out = os.path.join(tmp, "moved.msh")
        start = time.perf_counter()
        done = subprocess.run([*command, "-o", out, *motion], capture_output=True, text=True, env=env)
        seconds = time.perf_counter() - start
        if done.returncode not in (0, 2):
            print(f"plate_turn_bench: {name} failed ({done.returncode}): {done.stderr.strip()}", file=sys.stderr)
            continue
        points = mm.read_mesh(out).points
        moved = mm.from_arrays(points, cells, {})
        print(json.dumps({"bench": "plate_turn", "options": f"{name} (defaults)", "ranks": 2 if "mpi" in name else 1,
                          "degrees": degrees, "invalid": int(mm.quality_report(moved, "scaled_jacobian")["invalid"]),
                          "min_shape": round(float(mm.quality_report(moved, "shape")["min"]), 4),
                          "program_seconds": round(seconds, 3),
                          "largest_difference_from_warp": float(np.abs(points - serial[degrees]).max())}), flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=float, default=0.1, help="cell size at the plate (0.5 at the walls)")
    parser.add_argument("--programs", help="folder of move_mesh and move_mesh_mpi: add their rows")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD if MPI is not None and MPI.COMM_WORLD.Get_size() > 1 else None
    rank = comm.Get_rank() if comm is not None else 0
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "plate.msh")
        if rank == 0:
            try:
                plate_mesh(path, args.size, 0.5)
            except ImportError:
                print("plate_turn_bench: Gmsh's Python module (python3-gmsh) is missing: skipped", file=sys.stderr)
                path = None
        if comm is not None:
            path = comm.bcast(path)
        if path is None:
            return
        mesh = mm.read_mesh(path)
        cells = {"tet4": mesh.cells[0][1]}
        if args.programs:
            programs_rows(args.programs, path, tmp, cells, {d: p for d, _, p, _ in run(mesh, {})[1]})
            return
        rows = {}
        for name, options in (("(defaults)", {}), ("repair=False", {"repair": False}),
                              ("rigid_part=none", {"rigid_part": "none"})):
            if rank == 0:
                warp, steps = run(mesh, options)
                rows[name] = steps
                for degrees, seconds, points, (folded, repaired) in steps:
                    moved = mm.from_arrays(points, cells, {})
                    report = mm.quality_report(moved, "scaled_jacobian")
                    row = {"bench": "plate_turn", "options": name, "ranks": 1, "nodes": len(points),
                           "cells": len(cells["tet4"]), "degrees": degrees, "invalid": int(report["invalid"]),
                           "min_shape": round(float(mm.quality_report(moved, "shape")["min"]), 4),
                           "move_seconds": round(seconds, 4),
                           "setups_again": int(warp._mover.stats["radius_growths"]),
                           "folded": folded, "repaired_nodes": repaired}
                    print(json.dumps(row), flush=True)
        if comm is not None:
            _, steps = run(mesh, {}, comm)
            if rank == 0:
                for (degrees, seconds, points, _), (_, _, serial, _) in zip(steps, rows["(defaults)"]):
                    print(json.dumps({"bench": "plate_turn", "options": "(defaults)", "ranks": comm.Get_size(),
                                      "degrees": degrees, "move_seconds": round(seconds, 4),
                                      "largest_difference_from_serial": float(np.abs(points - serial).max())}), flush=True)


if __name__ == "__main__":
    main()
