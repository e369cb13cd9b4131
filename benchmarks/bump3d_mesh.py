#!/usr/bin/env python3
"""A 3D channel with a bump on its bottom wall, meshed with tetrahedra by Gmsh (Python API,
Debian's python3-gmsh): the case of issue 34's "3D walls reconstructed without CAD". The wall
is a smooth surface z = A cos(pi x / 2L) cos(pi y / 2W) on [0, L] x [0, W], refused to a third
of the size near it; groups wall, inlet, outlet, symmetry, side (planes) and farfield (top),
volume fluid. defaults_bench.py curves it with and without hand-set flags.

  bump3d_mesh.py OUT.msh [--size H] [--amplitude A]
"""
import argparse
import math
import sys

from gmsh_sizing import mesh_near_walls

LENGTH, WIDTH, HEIGHT = 1.5, 0.5, 0.8


def write_bump(out, size=0.06, amplitude=0.1, samples=30):
    import gmsh  # imported here: a machine without Gmsh's Python module still imports this file

    def wall_z(x, y):
        return amplitude * math.cos(math.pi * x / (2 * LENGTH)) * math.cos(math.pi * y / (2 * WIDTH))

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        g = gmsh.model.geo

        def point(x, y, z):
            return g.addPoint(x, y, z, size)

        def on_wall(x, y):
            return point(x, y, wall_z(x, y))

        def wall_edge(a, b, at):
            inner = [on_wall(*at(i / samples)) for i in range(1, samples)]
            return g.addSpline([a, *inner, b])

        c00, cl0, clw, c0w = on_wall(0, 0), on_wall(LENGTH, 0), on_wall(LENGTH, WIDTH), on_wall(0, WIDTH)
        w_y0 = wall_edge(c00, cl0, lambda t: (LENGTH * t, 0))
        w_xl = wall_edge(cl0, clw, lambda t: (LENGTH, WIDTH * t))
        w_yw = wall_edge(clw, c0w, lambda t: (LENGTH * (1 - t), WIDTH))
        w_x0 = wall_edge(c0w, c00, lambda t: (0, WIDTH * (1 - t)))
        wall = g.addSurfaceFilling([g.addCurveLoop([w_y0, w_xl, w_yw, w_x0])])
        t00, tl0, tlw, t0w = point(0, 0, HEIGHT), point(LENGTH, 0, HEIGHT), point(LENGTH, WIDTH, HEIGHT), point(0, WIDTH, HEIGHT)
        top_y0, top_xl, top_yw, top_x0 = g.addLine(t00, tl0), g.addLine(tl0, tlw), g.addLine(tlw, t0w), g.addLine(t0w, t00)
        top = g.addPlaneSurface([g.addCurveLoop([top_y0, top_xl, top_yw, top_x0])])
        v00, vl0, vlw, v0w = g.addLine(c00, t00), g.addLine(cl0, tl0), g.addLine(clw, tlw), g.addLine(c0w, t0w)
        symmetry = g.addPlaneSurface([g.addCurveLoop([w_y0, vl0, -top_y0, -v00])])
        outlet = g.addPlaneSurface([g.addCurveLoop([w_xl, vlw, -top_xl, -vl0])])
        side = g.addPlaneSurface([g.addCurveLoop([w_yw, v0w, -top_yw, -vlw])])
        inlet = g.addPlaneSurface([g.addCurveLoop([w_x0, v00, -top_x0, -v0w])])
        volume = g.addVolume([g.addSurfaceLoop([wall, top, symmetry, outlet, side, inlet])])
        g.synchronize()
        groups = [("wall", wall), ("inlet", inlet), ("outlet", outlet), ("symmetry", symmetry), ("side", side), ("farfield", top)]
        for tag, (name, surface) in enumerate(groups, start=1):
            gmsh.model.addPhysicalGroup(2, [surface], tag)
            gmsh.model.setPhysicalName(2, tag, name)
        gmsh.model.addPhysicalGroup(3, [volume], 10)
        gmsh.model.setPhysicalName(3, 10, "fluid")
        mesh_near_walls(gmsh, out, [wall], size / 3, size, 0.02, 0.3)
    finally:
        gmsh.finalize()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("--size", type=float, default=0.06)
    parser.add_argument("--amplitude", type=float, default=0.1)
    args = parser.parse_args()
    write_bump(args.out, args.size, args.amplitude)
    return 0


if __name__ == "__main__":
    sys.exit(main())
