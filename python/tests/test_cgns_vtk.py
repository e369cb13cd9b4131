"""CGNS node orders against VTK's own CGNS reader (Debian python3-vtk9): for a cell of each
type, linear and quadratic, written with write_mesh(".cgns"), every node VTK reads must sit
where VTK's parametric coordinates of that node put it on the cell's vertices (the cells are
straight-sided). VTK translates CGNS to its own order with its own tables, so this checks
ours independently.

Orientation: CGNS turns its prism (PENTA) as Gmsh does (the SIDS figure draws r, s, t from
node 1 to nodes 2, 3 and 4, a right-handed frame), and VTK's wedge turns the other way. VTK
9.1's CGNS reader hands the prism's nodes to a wedge as they are, so it sees a positive CGNS
prism as negative and every other positive cell as positive."""

import numpy as np
import pytest

from test_vtk_orientation import CELLS_2D, CELLS_3D, one_cell, scratch, signed_sizes

mm = pytest.importorskip("meshmotion", reason="the meshmotion module was not built (pybind11 absent?)")
vtk = pytest.importorskip("vtk", reason="python3-vtk9 is not installed")

if not mm.have_cgns:
    pytest.skip("meshmotion was built without the CGNS library (libcgns-dev)", allow_module_level=True)

LINEAR_CELL = {"tet4": vtk.vtkTetra, "hex8": vtk.vtkHexahedron, "prism6": vtk.vtkWedge, "pyramid5": vtk.vtkPyramid,
               "tri3": vtk.vtkTriangle, "quad4": vtk.vtkQuad}
# Nearly planar: the snapped base is its plane to 1e-6, so the cell is straight-sided to that.
FLAT = {3: "sphere:0.5,0.5,-1e6,1e6", 2: "straight"}


def cells_read_by_vtk(file):
    reader = vtk.vtkCGNSReader()
    reader.SetFileName(str(file))
    reader.Update()
    blocks = reader.GetOutput().NewIterator()
    blocks.InitTraversal()
    grid = blocks.GetCurrentDataObject()
    assert grid is not None and grid.GetNumberOfCells() == 1
    return grid


def cell_of(type_name, quadratic):
    dim = 3 if type_name in CELLS_3D else 2
    mesh = one_cell(type_name, CELLS_3D if dim == 3 else CELLS_2D)
    if quadratic:
        mesh, report = mm.curve_mesh(mesh, method="none", geometry={"base": FLAT[dim]})
        assert report["invalid"] == 0
    return mesh


@pytest.mark.parametrize("quadratic", [False, True], ids=["P1", "P2"])
@pytest.mark.parametrize("type_name", sorted(LINEAR_CELL))
def test_vtk_places_every_cgns_node_where_its_parametric_coordinates_say(type_name, quadratic):
    mesh = cell_of(type_name, quadratic)
    file = scratch(f"vtk_{type_name}_{'p2' if quadratic else 'p1'}.cgns")
    mm.write_mesh(file, mesh)
    grid = cells_read_by_vtk(file)
    cell = grid.GetCell(0)
    n = cell.GetNumberOfPoints()
    assert n == mesh.cells[0][1].shape[1]
    linear = LINEAR_CELL[type_name]()
    nv = linear.GetNumberOfPoints()
    for k in range(nv):
        linear.GetPoints().SetPoint(k, cell.GetPoints().GetPoint(k))
        linear.GetPointIds().SetId(k, k)
    pcoords = cell.GetParametricCoords()
    weights = [0.0] * nv
    # VTK's quadratic pyramid defines 13 nodes; its reader appends the base centre as a 14th.
    defined = {"vtkQuadraticPyramid": 13}.get(cell.GetClassName(), n)
    for k in range(defined):
        xi = [pcoords[3 * k + d] for d in range(3)]
        expected = [0.0, 0.0, 0.0]
        linear.EvaluateLocation(vtk.reference(0), xi, expected, weights)
        np.testing.assert_allclose(cell.GetPoints().GetPoint(k), expected, atol=1e-5,
                                   err_msg=f"{type_name} node {k} (VTK's order) is not where VTK expects it")
    if not quadratic:  # VTK's size filter gives 0 for some quadratic cells (triquadratic hexahedron)
        size = signed_sizes(grid)[0]
        assert (size < 0.0) if type_name == "prism6" else (size > 0.0)
    # The nodes VTK read are the mesh's nodes.
    ours = {tuple(np.round(p, 9)) for p in mesh.points}
    theirs = {tuple(np.round(cell.GetPoints().GetPoint(k)[:mesh.points.shape[1]], 9)) for k in range(n)}
    assert theirs == ours
