#!/usr/bin/python3
"""A body turned inside held walls from one setup (issue 68): a plate 2 x 0.2 x 1 with sharp
edges in a held 12^3 box (tetrahedra by Gmsh: 0.1 at the plate, 0.5 at the walls), set up once
with nothing moving, then moved from the reference about the plate's axis in 15 degree steps to
a half turn, as a solver's time loop does. Per step: the invalid cells (scaled Jacobian), the
minimum shape quality (a linear tetrahedron's scaled Jacobian is only its sign) and the move's
time, for the defaults (each move's rigid part blended, RigidPartAtMove) beside
rigid_part=none (the whole motion interpolated, as before), through Python's Warp; run
under mpiexec it also moves on the ranks (Warp(comm=)) and gives the largest distance from the
serial points. One JSON line per row.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/plate_turn_bench.py [--size 0.1]
    mpiexec -n 2 ... (the same, adding the distributed row on rank 0)
"""

import argparse
import json
import math
import os
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
        steps.append((degrees, seconds, points))
    return warp, steps


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=float, default=0.1, help="cell size at the plate (0.5 at the walls)")
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
        rows = {}
        for name, options in (("(defaults)", {}), ("rigid_part=none", {"rigid_part": "none"})):
            if rank == 0:
                warp, steps = run(mesh, options)
                rows[name] = steps
                for degrees, seconds, points in steps:
                    moved = mm.from_arrays(points, cells, {})
                    report = mm.quality_report(moved, "scaled_jacobian")
                    row = {"bench": "plate_turn", "options": name, "ranks": 1, "nodes": len(points),
                           "cells": len(cells["tet4"]), "degrees": degrees, "invalid": int(report["invalid"]),
                           "min_shape": round(float(mm.quality_report(moved, "shape")["min"]), 4),
                           "move_seconds": round(seconds, 4),
                           "setups_again": int(warp._mover.stats["radius_growths"])}
                    print(json.dumps(row), flush=True)
        if comm is not None:
            _, steps = run(mesh, {}, comm)
            if rank == 0:
                for (degrees, seconds, points), (_, _, serial) in zip(steps, rows["(defaults)"]):
                    print(json.dumps({"bench": "plate_turn", "options": "(defaults)", "ranks": comm.Get_size(),
                                      "degrees": degrees, "move_seconds": round(seconds, 4),
                                      "largest_difference_from_serial": float(np.abs(points - serial).max())}), flush=True)


if __name__ == "__main__":
    main()
