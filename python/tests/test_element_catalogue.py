"""The element catalogue against Gmsh and VTK themselves (Debian python3-gmsh, python3-vtk9):
every type's reference nodes in Gmsh's order, the node order of every VTK Lagrange cell the
.vtu writer uses, at every order the library holds, and Gmsh's reading of written .msh files."""

import os
import pathlib

import numpy as np
import pytest

mm = pytest.importorskip("meshmotion", reason="the meshmotion module was not built (pybind11 absent?)")

GMSH_IDS = {
    "line2": 1, "line3": 8, "line4": 26, "line5": 27, "line6": 28, "line7": 62, "line8": 63, "line9": 64,
    "tri3": 2, "tri6": 9, "tri10": 21, "tri15": 23, "tri21": 25, "tri28": 42, "tri36": 43, "tri45": 44,
    "quad4": 3, "quad8": 16, "quad9": 10, "quad16": 36, "quad25": 37, "quad36": 38, "quad49": 47, "quad64": 48,
    "quad81": 49,
    "tet4": 4, "tet10": 11, "tet20": 29, "tet35": 30, "tet56": 31, "tet84": 71, "tet120": 72, "tet165": 73,
    "hex8": 5, "hex20": 17, "hex27": 12, "hex64": 92, "hex125": 93, "hex216": 94, "hex343": 95, "hex512": 96,
    "hex729": 97,
    "prism6": 6, "prism15": 18, "prism18": 13, "prism40": 90, "prism75": 91, "prism126": 106, "prism196": 107,
    "prism288": 108, "prism405": 109,
    "pyramid5": 7, "pyramid13": 19, "pyramid14": 14, "pyramid30": 118, "pyramid55": 119, "pyramid91": 120,
    "pyramid140": 121, "pyramid204": 122, "pyramid285": 123,
}
PRISM_ORDER = {"prism40": 3, "prism75": 4, "prism126": 5, "prism196": 6, "prism288": 7, "prism405": 8}
DIM = {"line": 1, "tri": 2, "quad": 2, "tet": 3, "hex": 3, "prism": 3, "pyramid": 3}


def family(type_name):
    return type_name.rstrip("0123456789")


def scratch(name):
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder / name


def test_the_catalogue_lists_every_order():
    assert set(GMSH_IDS) <= set(mm.element_types())


@pytest.fixture(scope="module")
def gmsh():
    module = pytest.importorskip("gmsh", reason="python3-gmsh is not installed")
    module.initialize()
    module.option.setNumber("General.Terminal", 0)
    yield module
    module.finalize()


def meshed_prism_nodes(gmsh, order):
    """Gmsh 4.8 cannot list the reference nodes of a prism past order 2 (getElementProperties
    fails on its face closure): mesh the reference prism itself at that order and read its one
    element."""
    gmsh.model.add(f"prism{order}")
    geo = gmsh.model.geo
    p = [geo.addPoint(*c) for c in [(0, 0, -1), (1, 0, -1), (0, 1, -1)]]
    lines = [geo.addLine(p[0], p[1]), geo.addLine(p[1], p[2]), geo.addLine(p[2], p[0])]
    surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    for line in lines:
        geo.mesh.setTransfiniteCurve(line, 2)
    geo.extrude([(2, surface)], 0, 0, 2, [1], recombine=True)
    geo.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 10)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 10)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(order)
    _, _, nodes = gmsh.model.mesh.getElements(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    where = {int(t): k for k, t in enumerate(tags)}
    coords = np.asarray(coords).reshape(-1, 3)
    element = nodes[0]
    gmsh.model.remove()
    return np.array([coords[where[int(t)]] for t in element])


@pytest.mark.parametrize("type_name", sorted(GMSH_IDS))
def test_reference_nodes_are_gmsh_s(gmsh, type_name):
    dim = DIM[family(type_name)]
    ours = mm.reference_nodes(type_name)
    try:
        _, gdim, _, count, coords, _ = gmsh.model.mesh.getElementProperties(GMSH_IDS[type_name])
        theirs = np.asarray(coords).reshape(count, gdim)
    except Exception:
        if type_name not in PRISM_ORDER:
            raise
        theirs = meshed_prism_nodes(gmsh, PRISM_ORDER[type_name])
    assert ours.shape[0] == theirs.shape[0]
    # The meshed prism's nodes come from Gmsh's geometry, to its own rounding.
    np.testing.assert_allclose(ours[:, :dim], theirs[:, :dim], atol=1e-10 if type_name in PRISM_ORDER else 1e-12)


def pyramid_lattice(n):
    """Points of the reference pyramid on n levels below the apex (the apex is singular)."""
    points = []
    for k in range(n):
        half, m = 1 - k / n, n - k
        points += [(half * (2 * i / m - 1), half * (2 * j / m - 1), k / n) for i in range(m + 1) for j in range(m + 1)]
    return np.array(points)


@pytest.mark.parametrize("order", [3, 4, 6])
def test_pyramid_jacobians_are_gmsh_s(gmsh, order):
    """Pyramids past order 2 with curved sides, meshed by Gmsh (between hexahedra and tetrahedra
    on a curved annulus): each cell's min det J over the straight cell's (the quality report's
    certified scaled Jacobian: a lower bound within 1e-4 of the minimum) against Gmsh's own det J
    on a 24-level lattice (getJacobians, its basis functions), an upper bound of it: the same
    distribution to that lattice's sampling gap. (Gmsh 4.8's AnalyseMeshQuality is no judge
    here: at order 4 it calls 16 of these pyramids invalid whose det J its own getJacobians finds
    positive everywhere, and it stops at prisms past order 2, as getJacobians does.)"""
    gmsh.model.add(f"pyramids{order}")
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0)  # meshed_prism_nodes() leaves them at 10
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)
    gmsh.merge(str(pathlib.Path(__file__).parents[2] / "tests" / "quality" / "data" / "prisms_pyramids.geo"))
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(order)
    file = scratch(f"pyramids_p{order}.msh")
    gmsh.write(str(file))
    gmsh_type = gmsh.model.mesh.getElementType("Pyramid", order)
    _, det, _ = gmsh.model.mesh.getJacobians(gmsh_type, pyramid_lattice(24).flatten().tolist())
    tags, nodes = gmsh.model.mesh.getElementsByType(gmsh_type)
    det = np.asarray(det).reshape(len(tags), -1)
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    where = {int(t): k for k, t in enumerate(node_tags)}
    coords = np.asarray(coords).reshape(-1, 3)
    straight = []
    for vertices in np.asarray(nodes).reshape(len(tags), -1)[:, :5]:
        x = coords[[where[int(t)] for t in vertices]]
        # The linear pyramid's Jacobian at its centroid (0, 0, 1/5), columns d/du, d/dv, d/dw.
        straight.append(np.linalg.det(np.column_stack([(-x[0] + x[1] + x[2] - x[3]) / 4, (-x[0] - x[1] + x[2] + x[3]) / 4,
                                                        x[4] - x[:4].sum(axis=0) / 4])))
    gmsh.model.remove()
    theirs = np.sort(det.min(axis=1) / np.array(straight))
    mesh = mm.read_mesh(file)
    values = mm.quality_report(mesh, "jacobian")["values"]
    counts = [len(connectivity) for _, connectivity in mesh.cells]
    block = [name.startswith("pyramid") for name, _ in mesh.cells].index(True)
    start = sum(counts[:block])
    ours = np.sort(values[start:start + counts[block]])
    assert len(ours) == len(theirs) > 0
    np.testing.assert_allclose(ours, theirs, atol=0.02)


# ---- VTK ----------------------------------------------------------------------------------

LAGRANGE = {"line": "vtkLagrangeCurve", "tri": "vtkLagrangeTriangle", "quad": "vtkLagrangeQuadrilateral",
            "tet": "vtkLagrangeTetra", "hex": "vtkLagrangeHexahedron", "prism": "vtkLagrangeWedge"}
VTK_TYPES = ["line3", "line4", "line5", "line6", "line9", "tri6", "tri10", "tri15", "tri21", "tri28", "tri36", "tri45",
             "quad9", "quad16", "quad25", "quad36", "quad49", "quad64", "quad81", "tet10", "tet20", "tet35", "tet56",
             "tet84", "tet120", "tet165", "hex27", "hex64", "hex125", "hex216", "hex729", "prism18", "prism40",
             "prism75", "prism126", "prism196", "prism405"]


def to_vtk_parametric(type_name, x):
    """Our reference coordinates in VTK's parametric space ([0, 1] where Gmsh's is [-1, 1])."""
    x = np.array(x, dtype=float)
    f = family(type_name)
    if f in ("line", "quad", "hex"):
        x[:, :DIM[f]] = (x[:, :DIM[f]] + 1) / 2
    if f == "prism":
        x[:, 2] = (x[:, 2] + 1) / 2
    return x


@pytest.mark.parametrize("type_name", VTK_TYPES)
def test_vtk_lagrange_order_is_vtk_s(type_name):
    vtk = pytest.importorskip("vtk", reason="python3-vtk9 is not installed")
    ours = mm.reference_nodes(type_name)
    n = ours.shape[0]
    order = mm.vtk_order(type_name, lagrange=True) or list(range(n))
    cell = getattr(vtk, LAGRANGE[family(type_name)])()
    cell.GetPointIds().SetNumberOfIds(n)
    cell.GetPoints().SetNumberOfPoints(n)
    p = {"quad": round(n ** 0.5) - 1, "hex": round(n ** (1 / 3)) - 1}.get(family(type_name))
    if family(type_name) == "quad":
        cell.SetOrder(p, p)
    elif family(type_name) == "hex":
        cell.SetOrder(p, p, p)
    elif family(type_name) == "prism":
        p = {18: 2, 40: 3, 75: 4, 126: 5, 196: 6, 288: 7, 405: 8}[n]
        cell.SetOrder(p, p, p, n)
    cell.Initialize()
    parametric = cell.GetParametricCoords()
    theirs = np.array([parametric[k] for k in range(3 * n)]).reshape(n, 3)
    expected = to_vtk_parametric(type_name, ours[order])
    if family(type_name) == "hex":
        # VTK 9.1 reads files older than version 2.2 (ours declare 1.0) with the vertical
        # edges (2,6) and (3,7) swapped, so the table holds them swapped: swap them back.
        k = 8 + 10 * (p - 1)
        expected[k:k + 2 * (p - 1)] = np.roll(expected[k:k + 2 * (p - 1)], p - 1, axis=0)
    np.testing.assert_allclose(expected, theirs, atol=1e-12)


AFFINE = np.array([[1.3, 0.2, 0.1], [-0.1, 0.9, 0.3], [0.2, -0.2, 1.1]])


def write_affine_cell(type_name, extension):
    """One cell of `type_name` on the affine image (AFFINE, + 0.5) of its reference element,
    written to a scratch file of `extension`: (file, its points)."""
    dim = DIM[family(type_name)]
    points = mm.reference_nodes(type_name)[:, :dim] @ AFFINE[:dim, :dim].T + 0.5
    file = scratch(f"catalogue_{type_name}{extension}")
    mm.write_mesh(file, mm.from_arrays(points, {type_name: np.arange(len(points))[None, :]}, {}))
    return file, points


@pytest.mark.parametrize("type_name", [t for t in VTK_TYPES if DIM[family(t)] >= 2])
def test_vtu_cells_past_order_2_read_back_through_vtk(type_name):
    """One cell of each type on an affine image of its reference element, written to .vtu and
    read by VTK: VTK's i-th point of the cell sits at the image of its i-th parametric point
    (the file's node order, the legacy hexahedron edges included, is VTK's)."""
    vtk = pytest.importorskip("vtk", reason="python3-vtk9 is not installed")
    dim = DIM[family(type_name)]
    vtu, points = write_affine_cell(type_name, ".vtu")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(vtu))
    reader.Update()
    cell = reader.GetOutput().GetCell(0)
    n = cell.GetNumberOfPoints()
    assert n == len(points)
    parametric = cell.GetParametricCoords()
    vtk_ref = np.array([parametric[k] for k in range(3 * n)]).reshape(n, 3)
    f = family(type_name)
    if f in ("quad", "hex"):
        vtk_ref[:, :dim] = vtk_ref[:, :dim] * 2 - 1
    if f == "prism":
        vtk_ref[:, 2] = vtk_ref[:, 2] * 2 - 1
    expected = vtk_ref[:, :dim] @ AFFINE[:dim, :dim].T + 0.5
    got = np.array([cell.GetPoints().GetPoint(k)[:dim] for k in range(n)])
    np.testing.assert_allclose(got, expected, atol=1e-12)


@pytest.mark.parametrize("type_name", ["tri6", "quad9", "tet10", "hex27", "tri10", "quad16", "tet20", "hex64"])
def test_cgns_cells_read_by_vtk(type_name):
    """One cell of each type CGNS holds past order 1, on an affine image of its reference element,
    written to .cgns and read by VTK's CGNS reader (its own CGNS-to-VTK orders, which SU2's CGNS
    reader shares for these types): VTK's i-th point of the cell is the image of our node
    vtk_order[i]. (Past order 3 VTK 9.1 reads no CGNS cell, nor a PYRA_30; for the PENTA_40 it
    starts the face (3, 1, 4, 6) at vertex 1 where SU2, Gmsh's rules and the SIDS start it at
    vertex 3, which the library follows: cgns_test.cpp pins those orders.)"""
    vtk = pytest.importorskip("vtk", reason="python3-vtk9 is not installed")
    if not mm.have_cgns:
        pytest.skip("meshmotion was built without the CGNS library")
    dim = DIM[family(type_name)]
    file, points = write_affine_cell(type_name, ".cgns")
    reader = vtk.vtkCGNSReader()
    reader.SetFileName(str(file))
    reader.EnableAllBases()
    reader.Update()
    blocks = reader.GetOutput().NewIterator()
    blocks.InitTraversal()
    grid = blocks.GetCurrentDataObject()
    cell = grid.GetCell(0)
    assert cell.GetNumberOfPoints() == len(points)
    got = np.array([grid.GetPoint(cell.GetPointId(k))[:dim] for k in range(len(points))])
    # VTK's quadratic cells are its classic ones, the cubic its Lagrange cells.
    order = mm.vtk_order(type_name, lagrange=type_name in ("tri10", "quad16", "tet20", "hex64")) or list(range(len(points)))
    np.testing.assert_allclose(got, points[order], atol=1e-12)


@pytest.mark.parametrize("type_name", [t for t in VTK_TYPES if DIM[family(t)] >= 2])
@pytest.mark.parametrize("mode", ["Binary", "Ascii"])
def test_vtu_written_by_vtk_reads_back(type_name, mode):
    """Our .vtu read by VTK and written again by VTK's own writer (file version 2.2, its
    hexahedron edge order, UInt32 headers) reads back into the same cell."""
    vtk = pytest.importorskip("vtk", reason="python3-vtk9 is not installed")
    dim = DIM[family(type_name)]
    points = mm.reference_nodes(type_name)[:, :dim] * 0.7 + 0.3
    mesh = mm.from_arrays(points, {type_name: np.arange(len(points))[None, :]}, {})
    ours = scratch(f"vtk_roundtrip_{type_name}.vtu")
    mm.write_mesh(ours, mesh)
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(ours))
    reader.Update()
    theirs = scratch(f"vtk_roundtrip_{type_name}_{mode}.vtu")
    writer = vtk.vtkXMLUnstructuredGridWriter()
    writer.SetFileName(str(theirs))
    writer.SetInputData(reader.GetOutput())
    getattr(writer, f"SetDataModeTo{mode}")()
    writer.SetCompressorTypeToNone()
    assert writer.Write() == 1
    back = mm.read_mesh(theirs)
    np.testing.assert_array_equal(back.points, mesh.points)
    assert back.cells[0][0] == type_name
    np.testing.assert_array_equal(back.cells[0][1], mesh.cells[0][1])


def gmsh_mesh_state(gmsh):
    """Each entity's physical groups and nodes (tags, coordinates, parameters), as Gmsh sees them."""
    state = {}
    for dim, tag in gmsh.model.getEntities():
        nodes, coords, params = gmsh.model.mesh.getNodes(dim, tag, includeBoundary=False, returnParametricCoord=True)
        state[(dim, tag)] = (list(gmsh.model.getPhysicalGroupsForEntity(dim, tag)), np.asarray(nodes), np.asarray(coords),
                             np.asarray(params))
    return state


@pytest.mark.parametrize("version", ["2.2", "4.1"])
def test_msh_written_back_keeps_gmsh_s_entities_and_parameters(gmsh, version):
    """A mesh Gmsh made on an OpenCASCADE model, saved with its nodes' parameters as 2.2
    ($ParametricNodes) or 4.1, read and written (4.1) by the library: Gmsh reads the written
    file with the entities, groups, nodes and parameters it reads from its own 4.1 file."""
    gmsh.model.add("sphere_in_box")
    occ = gmsh.model.occ
    occ.cut([(3, occ.addBox(-2, -2, -2, 4, 4, 4))], [(3, occ.addSphere(0, 0, 0, 0.5))])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [1], 1)
    for face in gmsh.model.getEntities(2):
        gmsh.model.addPhysicalGroup(2, [face[1]], 10 + face[1])
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.8)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.SaveParametric", 1)
    files = {}
    for v in ("2.2", "4.1"):
        gmsh.option.setNumber("Mesh.MshFileVersion", float(v))
        files[v] = scratch(f"gmsh_sphere_{v}.msh")
        gmsh.write(str(files[v]))
    gmsh.model.remove()

    ours_file = scratch(f"ours_sphere_from_{version}.msh")
    mm.write_mesh(ours_file, mm.read_mesh(files[version]))
    states = []
    for file in (files["4.1"], ours_file):
        gmsh.open(str(file))
        states.append(gmsh_mesh_state(gmsh))
        gmsh.model.remove()
    theirs, ours = states
    assert sum(len(s[1]) for s in theirs.values()) > 100
    for key, (groups, nodes, coords, params) in theirs.items():
        if len(nodes) == 0:  # an entity without nodes or elements need not be listed
            continue
        assert key in ours, key
        our_groups, our_nodes, our_coords, our_params = ours[key]
        assert groups == our_groups, key
        np.testing.assert_array_equal(nodes, our_nodes)
        np.testing.assert_array_equal(coords, our_coords)
        np.testing.assert_array_equal(params, our_params)
