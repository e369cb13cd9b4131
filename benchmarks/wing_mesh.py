#!/usr/bin/env python3
"""A tapered, swept wing on a symmetry plane, made and meshed with tetrahedra by Gmsh's
OpenCASCADE kernel (Python API, Debian's python3-gmsh): the case of issue 34's "sharp CAD edges
in 3D". A loft of two NACA0012 sections (root chord 1 at y = 0, tip chord 0.5 at y = 1.5 with its
leading edge 0.6 aft), each section two splines joined at its sharp trailing edge and at its
leading edge; a flat tip cap; cut from the box [-3, 4] x [0, 4] x [-3, 3]. Groups wing (loft and
cap), symmetry (y = 0) and farfield, volume fluid; tetrahedra of WALL_SIZE at the wing growing
to 0.25 (--far-size). Writes the STEP model and the linear mesh; defaults_bench.py curves it
on the model with and without hand-set flags, wing_vs_gmsh.py against Gmsh's own curving.

  wing_mesh.py OUT.msh OUT.step [--wall-size H] [--far-size H]
"""
import argparse
import math
import sys

from gmsh_sizing import mesh_near_walls


def naca0012(chord, leading_edge, span, n=40):
    """The section's points from the trailing edge over the upper side to the leading edge and
    back along the lower side (the trailing edge once), cosine-spaced."""
    upper, lower = [], []
    for i in range(n + 1):
        x = 0.5 * (1 - math.cos(math.pi * i / n))
        t = 0.6 * (0.2969 * math.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
        upper.append((leading_edge + chord * x, span, chord * t))
        lower.append((leading_edge + chord * x, span, -chord * t))
    return upper[::-1], lower[1:]  # upper: TE .. LE; lower: after LE .. TE


def write_wing(msh, step, wall_size=0.05, size=0.25):
    import gmsh  # imported here: a machine without Gmsh's Python module still imports this file

    gmsh.initialize()
    try:
        build_wing(gmsh, msh, step, wall_size, size)
    finally:
        gmsh.finalize()


def build_wing(gmsh, msh, step, wall_size=0.05, size=0.25):
    """write_wing inside an initialized Gmsh session, which keeps the model and its linear mesh
    (wing_vs_gmsh.py curves them there)."""
    gmsh.option.setNumber("General.Terminal", 0)
    occ = gmsh.model.occ
    wires = []
    for chord, leading_edge, span in ((1.0, 0.0, 0.0), (0.5, 0.6, 1.5)):
        upper, lower = naca0012(chord, leading_edge, span)
        up = [occ.addPoint(*p) for p in upper]
        low = [occ.addPoint(*p) for p in lower[:-1]] + [up[0]]  # the trailing edge shared
        wires.append(occ.addWire([occ.addSpline(up), occ.addSpline([up[-1]] + low)]))
    wing = occ.addThruSections(wires, makeSolid=True, makeRuled=False)
    box = occ.addBox(-3, 0, -3, 7, 4, 6)
    fluid, _ = occ.cut([(3, box)], wing)
    occ.synchronize()
    gmsh.write(step)
    volume = fluid[0][1]
    walls, symmetry, farfield = [], [], []
    for _, s in gmsh.model.getBoundary([(3, volume)], oriented=False):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, s)
        if y1 < 1e-6:
            symmetry.append(s)
        elif x0 < -2.9 or x1 > 3.9 or y1 > 3.9 or z0 < -2.9 or z1 > 2.9:
            farfield.append(s)
        else:
            walls.append(s)
    for tag, (name, surfaces) in enumerate((("wing", walls), ("symmetry", symmetry), ("farfield", farfield)), start=1):
        gmsh.model.addPhysicalGroup(2, surfaces, tag)
        gmsh.model.setPhysicalName(2, tag, name)
    gmsh.model.addPhysicalGroup(3, [volume], 10)
    gmsh.model.setPhysicalName(3, 10, "fluid")
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    mesh_near_walls(gmsh, msh, walls, wall_size, size, 0.05, 1.5)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("msh")
    parser.add_argument("step")
    parser.add_argument("--wall-size", type=float, default=0.05)
    parser.add_argument("--far-size", type=float, default=0.25, help="the tetrahedra's size away from the wing")
    args = parser.parse_args()
    write_wing(args.msh, args.step, args.wall_size, args.far_size)
    return 0


if __name__ == "__main__":
    sys.exit(main())
