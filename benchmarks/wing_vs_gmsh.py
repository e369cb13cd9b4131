#!/usr/bin/env python3
"""The swept wing of wing_mesh.py curved at orders 2 to 4 by curve_mesh's defaults and by Gmsh
on the same linear mesh and the same model (issue 71's "cells at the edges between CAD faces").

Gmsh curves inside the session that made the mesh (its OpenCASCADE model): SetOrder N alone
(HighOrderOptimize 0, snapping), then with HighOrderOptimize 2 (the elastic analogy, then the
optimizer on the patches of the worst cells: Gmsh's answer to invalid cells, which its
documentation recommends); --full adds HighOrderOptimize 1 (the optimizer alone). curve_mesh
curves the linear mesh Gmsh wrote, on the STEP file Gmsh wrote, with no option but the order.
Every curved mesh is judged by the same certified scaled Jacobian (mesh_quality). Times: Gmsh's
CPU seconds of its high-order calls alone (the model and the linear mesh are already in
memory); ours the whole curve_mesh process (reading the mesh and the STEP file, curving,
certifying, writing), wall clock. One table and one JSON line per row,
{"bench": "wing_vs_gmsh", "order", "tool", "method", "seconds", "min", "invalid", "cells"}, then
per order the target line {"bench": "wing_vs_gmsh", "case": "target", "order", "invalid",
"min_over_gmsh", "time_over_gmsh"} against HighOrderOptimize 2.

  wing_vs_gmsh.py CURVE_MESH MESH_QUALITY [--orders 234] [--wall-size 0.1] [--far-size 0.5]
                  [--work DIR] [--full]

Skipped with a message without Gmsh's Python module (python3-gmsh).
"""
import argparse
import contextlib
import json
import os
import subprocess
import sys
import time

import wing_mesh

VARIANTS = {0: "SetOrder (HOO=0)", 1: "optimization (HOO=1)", 2: "elastic+optimization (HOO=2)"}


def certified(mesh_quality, msh):
    """(min, invalid, cells) of the certified scaled Jacobian of a curved mesh."""
    done = subprocess.run([mesh_quality, msh, "--json", "--metric", "jacobian"], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"wing_vs_gmsh: mesh_quality failed on {msh}:\n{done.stderr[-2000:]}")
    q = json.loads(done.stdout)["metrics"]["scaled_jacobian"]
    return q["min"], q["invalid"], q["elements"]


@contextlib.contextmanager
def quiet_stdout():
    """OpenCASCADE's STEP writer prints its statistics on the process's own stdout."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def gmsh_curve(gmsh, args, order, variant, linear, step, out):
    """Makes the wing in a fresh session (the same linear mesh every time: Gmsh meshes it
    deterministically on one thread), curves it, writes `out`; the high-order calls' CPU seconds."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.NumThreads", 1)
        with quiet_stdout():
            wing_mesh.build_wing(gmsh, linear, step, args.wall_size, args.far_size)
        start = time.process_time()
        gmsh.model.mesh.setOrder(order)
        if variant == 2:
            gmsh.model.mesh.optimize("HighOrderElastic")
        if variant in (1, 2):
            gmsh.model.mesh.optimize("HighOrder")
        seconds = time.process_time() - start
        gmsh.write(out)
    finally:
        gmsh.finalize()
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("curve_mesh")
    parser.add_argument("mesh_quality")
    parser.add_argument("--orders", default="234")
    parser.add_argument("--wall-size", type=float, default=0.1)
    parser.add_argument("--far-size", type=float, default=0.5)
    parser.add_argument("--work", default="/tmp/meshmotion_wing_vs_gmsh")
    parser.add_argument("--full", action="store_true", help="also Gmsh's HighOrderOptimize 1")
    args = parser.parse_args()
    try:
        import gmsh
    except ImportError:
        print("wing_vs_gmsh: Gmsh's Python module is missing (apt-get install python3-gmsh): skipped")
        print(json.dumps({"bench": "wing_vs_gmsh", "peer": "gmsh", "status": "missing"}))
        return 0
    os.makedirs(args.work, exist_ok=True)
    linear, step = os.path.join(args.work, "wing.msh"), os.path.join(args.work, "wing.step")
    variants = [0, 1, 2] if args.full else [0, 2]
    print(f"wing_vs_gmsh: Gmsh {gmsh.__version__}, wall size {args.wall_size}, far size {args.far_size};"
          f" Gmsh: CPU s of its high-order calls; curve_mesh: the whole program, wall s")
    print(f"{'order':>5} {'tool':10} {'method':30} {'seconds':>8} {'min':>8} {'invalid':>7} {'cells':>7}")
    lines = []
    for order in (int(c) for c in args.orders):
        rows = {}
        for variant in variants:
            out = os.path.join(args.work, f"gmsh_p{order}_hoo{variant}.msh")
            seconds = gmsh_curve(gmsh, args, order, variant, linear, step, out)
            rows[variant] = dict(bench="wing_vs_gmsh", order=order, tool="gmsh", method=VARIANTS[variant],
                                 seconds=seconds, **dict(zip(("min", "invalid", "cells"), certified(args.mesh_quality, out))))
        out = os.path.join(args.work, f"ours_p{order}.msh")
        start = time.perf_counter()
        done = subprocess.run([args.curve_mesh, linear, "-o", out, "--geometry", step, "--order", str(order)],
                              capture_output=True, text=True)
        seconds = time.perf_counter() - start
        if done.returncode not in (0, 2):  # 2: written, some cells invalid (the row says how many)
            sys.exit(f"wing_vs_gmsh: curve_mesh failed at order {order}:\n{done.stderr[-2000:]}")
        ours = dict(bench="wing_vs_gmsh", order=order, tool="meshmotion", method="curve_mesh (defaults)",
                    seconds=seconds, **dict(zip(("min", "invalid", "cells"), certified(args.mesh_quality, out))))
        for r in [*rows.values(), ours]:
            print(f"{order:5} {r['tool']:10} {r['method']:30} {r['seconds']:8.2f} {r['min']:8.4f} {r['invalid']:7}"
                  f" {r['cells']:7}")
            lines.append(r)
        peer = rows[2]
        lines.append(dict(bench="wing_vs_gmsh", case="target", order=order, invalid=ours["invalid"],
                          min_over_gmsh=ours["min"] / peer["min"] if peer["min"] > 0 else None,
                          time_over_gmsh=ours["seconds"] / peer["seconds"] if peer["seconds"] > 0 else None))
    for line in lines:
        print(json.dumps(line))
    return 0


if __name__ == "__main__":
    sys.exit(main())
