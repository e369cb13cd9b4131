"""Each element type's orientation against VTK itself (Debian python3-vtk9): the signed cell
sizes VTK computes for a .vtu we write, and for the element lines of an .su2 we write (SU2
lists nodes in VTK's order), must be positive for cells that are positive in the library's
(Gmsh's) convention. VTK's wedge turns its base the other way from Gmsh's prism (issue 21)."""

import os
import pathlib
import re

import numpy as np
import pytest

mm = pytest.importorskip("meshmotion", reason="the meshmotion module was not built (pybind11 absent?)")
vtk = pytest.importorskip("vtk", reason="python3-vtk9 is not installed")
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

CELLS_3D = {
    "tet4": ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [("tri3", [0, 2, 1])]),
    "hex8": ([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
             [("quad4", [0, 3, 2, 1])]),
    "prism6": ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)], [("tri3", [0, 2, 1])]),
    "pyramid5": ([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)], [("quad4", [0, 3, 2, 1])]),
}
CELLS_2D = {
    "tri3": ([(0, 0), (1, 0), (0, 1)], [("line2", [0, 1])]),
    "quad4": ([(0, 0), (1, 0), (1, 1), (0, 1)], [("line2", [0, 1])]),
}


def scratch(name):
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder / name


def one_cell(type_name, table):
    points, (facet,) = table[type_name]
    mesh = mm.from_arrays(np.array(points, dtype=float), {type_name: np.array([list(range(len(points)))])},
                          {"base": (facet[0], np.array([facet[1]]))})
    assert mm.quality_report(mesh)["invalid"] == 0, f"{type_name}: the test cell itself is not positive"
    return mesh


def signed_sizes(grid):
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.Update()
    data = sizes.GetOutput().GetCellData()
    name = "Volume" if grid.GetCell(0).GetCellDimension() == 3 else "Area"
    return vtk_to_numpy(data.GetArray(name))


def read_vtu(file):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(file))
    reader.Update()
    return reader.GetOutput()


def grid_of_su2(file):
    """The cells of an .su2 file's NELEM section as VTK cells, node lists as the file has them."""
    lines = pathlib.Path(file).read_text().splitlines()
    dim = int(lines[0].split("=")[1])
    start = next(k for k, line in enumerate(lines) if line.startswith("NELEM="))
    count = int(lines[start].split("=")[1])
    elements = [list(map(int, line.split())) for line in lines[start + 1:start + 1 + count]]
    p = next(k for k, line in enumerate(lines) if line.startswith("NPOIN="))
    n = int(re.split(r"[=\s]+", lines[p])[1])
    coords = [list(map(float, line.split()[:dim])) for line in lines[p + 1:p + 1 + n]]
    points = vtk.vtkPoints()
    for c in coords:
        points.InsertNextPoint(*(c + [0.0] * (3 - dim)))
    grid = vtk.vtkUnstructuredGrid()
    grid.SetPoints(points)
    size = {3: 2, 5: 3, 9: 4, 10: 4, 12: 8, 13: 6, 14: 5}
    for e in elements:
        grid.InsertNextCell(e[0], size[e[0]], e[1:1 + size[e[0]]])
    return grid


@pytest.mark.parametrize("type_name", sorted(CELLS_3D) + sorted(CELLS_2D))
def test_linear_cells_are_positive_for_vtk(type_name):
    mesh = one_cell(type_name, CELLS_3D if type_name in CELLS_3D else CELLS_2D)
    vtu = scratch(f"orientation_{type_name}.vtu")
    mm.write_mesh(vtu, mesh)
    assert signed_sizes(read_vtu(vtu))[0] > 0.0
    su2 = scratch(f"orientation_{type_name}.su2")
    mm.write_mesh(su2, mesh)
    assert signed_sizes(grid_of_su2(su2))[0] > 0.0
    back = mm.read_mesh(su2)
    np.testing.assert_array_equal(back.cells[0][1], mesh.cells[0][1])


def test_classic_quadratic_wedge_is_positive_for_vtk():
    """A prism15 (written as VTK's classic quadratic wedge): vertices, then the midpoints of
    Gmsh's prism edges (0,1) (0,2) (0,3) (1,2) (1,4) (2,5) (3,4) (3,5) (4,5)."""
    vertices = np.array(CELLS_3D["prism6"][0], dtype=float)
    edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 4), (2, 5), (3, 4), (3, 5), (4, 5)]
    points = np.vstack([vertices, [(vertices[a] + vertices[b]) / 2 for a, b in edges]])
    mesh = mm.from_arrays(points, {"prism15": np.arange(15)[None, :]}, {})
    assert mm.quality_report(mesh)["invalid"] == 0
    vtu = scratch("orientation_prism15.vtu")
    mm.write_mesh(vtu, mesh)
    grid = read_vtu(vtu)
    assert grid.GetCellType(0) == vtk.VTK_QUADRATIC_WEDGE
    assert signed_sizes(grid)[0] > 0.0


@pytest.mark.parametrize("type_name", sorted(CELLS_3D))
def test_quadratic_cells_are_positive_for_vtk(type_name):
    # P2 through the curving pipeline: the base (z = 0) snapped onto a sphere so large that it
    # is that plane to 1e-6, the only way to name a curved group in 3D without a CAD file.
    curved, report = mm.curve_mesh(one_cell(type_name, CELLS_3D), method="none",
                                   geometry={"base": "sphere:0.5,0.5,-1e6,1e6"})
    assert curved.cells[0][0] != type_name
    assert report["invalid"] == 0
    vtu = scratch(f"orientation_{type_name}_p2.vtu")
    mm.write_mesh(vtu, curved)
    grid = read_vtu(vtu)
    assert grid.GetNumberOfCells() == 1
    assert signed_sizes(grid)[0] > 0.0
