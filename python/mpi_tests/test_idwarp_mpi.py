"""meshmotion.idwarp.USMesh under mpiexec at 1 to 4 ranks: IDWarp's call sequence on a 3D mesh
with a symmetry plane, the solver holding its nodes in its own partition (not the warp's), gives
the serial Warp's grid, a gradient that central differences confirm, and IDWarp's shapes."""

import os
import pathlib
import shutil
import warnings

import numpy as np
import pytest

mm = pytest.importorskip("meshmotion", reason="the meshmotion module was not built")
MPI = pytest.importorskip("mpi4py.MPI", reason="mpi4py is not installed (python3-mpi4py)")
pytest.importorskip("scipy", reason="setSurfaceDefinition matches points with scipy (python3-scipy)")
if not mm._core.have_mpi:
    pytest.skip("the module was built without MPI: " + mm._core.mpi_missing, allow_module_level=True)

from meshmotion.idwarp import USMesh  # noqa: E402
from meshes import box, bump, cgns_zone_types, structured_cgns  # noqa: E402  (beside this file)

comm = MPI.COMM_WORLD


@pytest.fixture(scope="module")
def grid_file():
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp")) / f"idwarp_{comm.size}"
    path = folder / ("box.cgns" if mm.have_cgns else "box.su2")  # unstructured CGNS, as ADflow's grids
    if comm.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
        mm.write_mesh(path, box())
    comm.Barrier()
    return path


def options(grid_file, **more):
    o = {"gridFile": str(grid_file), "fileType": "CGNS" if grid_file.suffix == ".cgns" else "SU2",
         "specifiedSurfaces": ["wall"], "symmetrySurfaces": ["symmetry"],
         "meshmotion": {"support_radius": 0.7}}
    o.update(more)
    return o


def solver_indices(n):
    """A solver's partition unlike METIS's: every comm.size-th node, and a few of the next
    rank's as ghosts (a node on two ranks)."""
    mine = np.arange(comm.rank, n, comm.size)
    return np.concatenate([mine, (mine[:3] + 1) % n])


def serial_warp(grid_file):
    w = mm.Warp(str(grid_file), design=["wall"], symmetry=["symmetry"], support_radius=0.7)
    w.set_surface_coordinates(bump(w.surface_coordinates()))
    return w, w.warp().copy()


def test_idwarps_call_sequence_gives_the_serial_grid_and_gradient(grid_file):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = USMesh(options=options(grid_file, LdefFact=100.0, aExp=3.0), comm=comm)
    if comm.rank == 0:
        assert any("LdefFact" in str(w.message) for w in caught)
    serial, expected = serial_warp(grid_file)
    n = serial.mesh.num_nodes
    ind = solver_indices(n)
    mesh.setExternalMeshIndices(ind)
    xs = mesh.getSurfaceCoordinates()
    assert xs.ndim == 2 and xs.shape[1] == 3
    # The internal surface: every design node on rank 0, with its triangles.
    assert len(xs) == (len(serial.design_nodes) if comm.rank == 0 else 0)
    conn, sizes = mesh.getSurfaceConnectivity()
    assert sizes.sum() == len(conn) and (comm.rank > 0 or (len(sizes) > 0 and conn.max() < len(xs)))
    mesh.setSurfaceCoordinates(bump(xs))
    mesh.warpMesh()
    grid = mesh.getSolverGrid()
    assert grid.shape == (3 * len(ind),)
    np.testing.assert_allclose(grid.reshape(-1, 3), expected[ind], rtol=0, atol=1e-12)
    # warpDeriv then getdXs: rank 0's rows are the serial gradient for dI/dXv summed over the
    # solver's ranks (a node on two ranks counts twice).
    dXv = np.sin(np.arange(3 * len(ind)) + 0.1 * comm.rank)
    mesh.warpDeriv(dXv)
    dXs = mesh.getdXs()
    assert dXs.shape == xs.shape
    whole = np.zeros((n, 3))
    for index, values in comm.allgather((ind, dXv.reshape(-1, 3))):
        np.add.at(whole, index, values)
    if comm.rank == 0:
        g = serial.warp_derivative(whole)
        np.testing.assert_allclose(dXs, g, rtol=0, atol=1e-12 * np.abs(g).max())
    assert mesh.verifyWarpDeriv(h=1e-6) < 1e-6
    # Forward: J dXs against the difference of two warps (the RBF warp is linear in the surface).
    direction = np.cos(np.arange(xs.size)).reshape(xs.shape)
    forward = mesh.warpDerivFwd(direction)
    base = mesh.getSolverGrid()
    mesh.setSurfaceCoordinates(bump(xs) + 1e-3 * direction)
    mesh.warpMesh()
    np.testing.assert_allclose(forward, (mesh.getSolverGrid() - base) / 1e-3, rtol=0, atol=1e-9)


def test_a_solvers_surface_with_repeated_points(grid_file):
    mesh = USMesh(options=options(grid_file), comm=comm)
    serial, expected = serial_warp(grid_file)
    design = serial.mesh.points[serial.design_nodes]
    # Each rank gives every other design node, the ranks overlapping: most points are on two ranks.
    pts = design[(np.arange(len(design)) + comm.rank) % 2 == 0]
    if comm.rank == 0:
        pts = np.concatenate([pts, design[1::2]])  # every node on some rank
    mesh.setSurfaceDefinition(pts, np.zeros(0, dtype=int), np.zeros(0, dtype=int))
    np.testing.assert_allclose(mesh.getSurfaceCoordinates(), pts, rtol=0, atol=0)
    mesh.setExternalMeshIndices(np.arange(serial.mesh.num_nodes))
    mesh.setSurfaceCoordinates(bump(pts))
    mesh.warpMesh()
    np.testing.assert_allclose(mesh.getSolverGrid().reshape(-1, 3), expected, rtol=0, atol=1e-12)
    assert mesh.verifyWarpDeriv(solverVec=False) < 1e-6
    with pytest.raises(mm.InputError, match="nearest node of the specified surfaces"):
        mesh.setSurfaceDefinition(pts + 0.01, np.zeros(0, dtype=int), np.zeros(0, dtype=int))


def test_write_grid_and_the_options_refused(grid_file):
    mesh = USMesh(options=options(grid_file), comm=comm)
    mesh.setSurfaceCoordinates(bump(mesh.getSurfaceCoordinates()))
    mesh.warpMesh()
    with pytest.raises(mm.InputError, match="is the grid file"):
        mesh.writeGrid(str(grid_file))
    out = grid_file.with_name("warped" + grid_file.suffix)
    mesh.writeGrid(str(out))
    common = mesh.getCommonGrid()  # collective
    if comm.rank == 0:
        _, expected = serial_warp(grid_file)
        np.testing.assert_allclose(mm.read_mesh(str(out)).points, expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(common.reshape(-1, 3), expected, rtol=0, atol=1e-12)
    else:
        assert common is None
    with pytest.raises(mm.InputError, match="restartFile"):
        USMesh(options=options(grid_file, restartFile="r.dat"), comm=comm)
    with pytest.raises(mm.InputError, match="PLOT3D"):
        USMesh(options=options(grid_file, fileType="PLOT3D"), comm=comm)
    with pytest.raises(mm.InputError, match="unknown option 'warpType'"):
        USMesh(options=options(grid_file, warpType="x"), comm=comm)
    with pytest.raises(mm.InputError, match="setExternalMeshIndices first"):
        USMesh(options=options(grid_file), comm=comm).getSolverGrid()


def test_symmetry_planes_find_their_groups(grid_file):
    by_plane = USMesh(options=options(grid_file, symmetrySurfaces=None, symmetryPlanes=[[[0, 0, 0], [0, 1, 0]]]), comm=comm)
    by_plane.setSurfaceCoordinates(bump(by_plane.getSurfaceCoordinates()))
    by_plane.warpMesh()
    _, expected = serial_warp(grid_file)
    whole = by_plane.getCommonGrid()
    if comm.rank == 0:
        np.testing.assert_allclose(whole.reshape(-1, 3), expected, rtol=0, atol=1e-12)
    with pytest.raises(mm.InputError, match="no group lies in the symmetry plane"):
        USMesh(options=options(grid_file, symmetrySurfaces=None, symmetryPlanes=[[[0, 0.5, 0], [0, 1, 0]]]), comm=comm)


def test_a_structured_multiblock_cgns_grid():
    if not mm.have_cgns:
        pytest.skip("the module was built without CGNS (libcgns-dev)")
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp")) / f"idwarp_structured_{comm.size}"
    path = folder / "blocks.cgns"
    written = None
    if comm.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
        written = structured_cgns(path)
    if not comm.bcast(written, root=0):
        pytest.skip("the CGNS library could not be loaded to write the structured grid")
    mesh = USMesh(options={"gridFile": str(path), "fileType": "CGNS", "specifiedSurfaces": ["wall"],
                           "symmetrySurfaces": ["symmetry"], "meshmotion": {"support_radius": 0.7}}, comm=comm)
    serial = mm.Warp(str(path), design=["wall"], symmetry=["symmetry"], support_radius=0.7)
    assert serial.mesh.num_nodes == 7 * 6 * 5  # the blocks' shared face read once
    assert serial.mesh.num_cells == 2 * 3 * 5 * 4
    serial.set_surface_coordinates(bump(serial.surface_coordinates()))
    expected = serial.warp()
    ind = solver_indices(serial.mesh.num_nodes)
    mesh.setExternalMeshIndices(ind)
    mesh.setSurfaceCoordinates(bump(mesh.getSurfaceCoordinates()))
    mesh.warpMesh()
    np.testing.assert_allclose(mesh.getSolverGrid().reshape(-1, 3), expected[ind], rtol=0, atol=1e-12)
    assert mesh.verifyWarpDeriv() < 1e-6
    mesh.writeGrid(str(folder / "warped.cgns"))  # the grid file again, its blocks kept
    if comm.rank == 0:
        assert cgns_zone_types(folder / "warped.cgns") == ["Structured", "Structured"]
        np.testing.assert_allclose(mm.read_mesh(str(folder / "warped.cgns")).points, expected, rtol=0, atol=1e-12)


def test_an_openfoam_cases_zones_are_not_design_surfaces():
    """Without specifiedSurfaces the design surfaces are the case's patches not named like a far
    field: a cell zone, a group of nodes, is none of them."""
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp")) / f"idwarp_foam_{comm.size}"
    if comm.rank == 0:
        shutil.rmtree(folder, ignore_errors=True)
        mm.write_mesh(str(folder), box())  # a new OpenFOAM case
        (folder / "constant" / "polyMesh" / "cellZones").write_text(
            "FoamFile { version 2.0; format ascii; class regIOobject; object cellZones; }\n"
            "1\n(core { type cellZone; cellLabels List<label> 3(0 1 2); })\n")
    comm.Barrier()
    assert mm.read_mesh(str(folder)).group_tags["core"][0] == 0
    base = {"gridFile": str(folder), "fileType": "OpenFOAM", "symmetrySurfaces": ["symmetry"],
            "meshmotion": {"support_radius": 0.7}}
    by_default = USMesh(options=base, comm=comm).getSurfaceCoordinates()
    named = USMesh(options=dict(base, specifiedSurfaces=["wall"]), comm=comm).getSurfaceCoordinates()
    assert by_default.shape == named.shape
    assert np.array_equal(by_default, named)


def decomposed_case(name, parts):
    """The box as an OpenFOAM case decomposed by decomposePar into `parts` processor folders (on
    rank 0; None everywhere without OpenFOAM's tools)."""
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp")) / f"{name}_{comm.size}"
    tool = shutil.which("decomposePar")
    if comm.rank == 0 and tool is not None:
        import subprocess
        shutil.rmtree(folder, ignore_errors=True)
        mm.write_mesh(str(folder), box())
        header = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"
        (folder / "system").mkdir(exist_ok=True)
        (folder / "system" / "controlDict").write_text(header % "controlDict" + "application none; startFrom startTime; "
                                                       "startTime 0; stopAt endTime; endTime 1; deltaT 1; "
                                                       "writeControl timeStep; writeInterval 1;\n")
        (folder / "system" / "decomposeParDict").write_text(header % "decomposeParDict" +
                                                            f"numberOfSubdomains {parts};\nmethod simple;\n"
                                                            f"simpleCoeffs {{ n ({parts} 1 1); delta 0.001; }}\n")
        script = "decomposePar -force"
        bashrc = "/usr/share/openfoam/etc/bashrc"  # Debian's OpenFOAM finds its etc files through it
        if os.path.isfile(bashrc):
            script = f"source {bashrc} >/dev/null 2>&1; {script}"
        subprocess.run(["bash", "-c", script], cwd=folder, check=True, capture_output=True)
    comm.Barrier()
    return folder if tool is not None else None


def test_a_decomposed_openfoam_case_is_read_by_each_rank_as_dafoam_runs_it():
    folder = decomposed_case("idwarp_decomposed", comm.size)
    if folder is None:
        pytest.skip("OpenFOAM's decomposePar is not installed (apt-get install openfoam)")
    base = {"gridFile": str(folder), "fileType": "OpenFOAM", "specifiedSurfaces": ["wall"],
            "symmetrySurfaces": ["symmetry"], "meshmotion": {"support_radius": 0.7}}
    mesh = USMesh(options=base, comm=comm)
    serial, expected = serial_warp(folder)
    if comm.size > 1:  # each rank holds its processor folder's points, in their order
        mine = mm._core.read_foam_processor(str(folder / f"processor{comm.rank}"))
        address = mine["global_ids"]
        np.testing.assert_array_equal(mesh.getSolverGrid().reshape(-1, 3), mine["points"])
        with pytest.raises(mm.InputError, match="written by its solver"):
            mesh.writeGrid(str(folder / "moved.msh"))
    else:  # one rank reads the whole case; the solver's nodes are given as for any grid
        address = np.arange(serial.mesh.num_nodes)
        mesh.setExternalMeshIndices(address)
    xs = mesh.getSurfaceCoordinates()
    # Every rank's surface is its faces of the wall: together, each wall node at least once.
    distinct = np.unique(np.round(np.concatenate(comm.allgather(xs)), 12), axis=0)
    assert len(distinct) == len(serial.design_nodes)
    mesh.setSurfaceCoordinates(bump(xs))
    mesh.warpMesh()
    np.testing.assert_allclose(mesh.getSolverGrid().reshape(-1, 3), expected[address], rtol=0, atol=1e-12)
    # The gradient: a surface point on several ranks gets its share on each, so a change given by
    # position sees the serial gradient.
    dXv = np.sin(np.arange(3 * len(address)) + 0.1 * comm.rank)
    mesh.warpDeriv(dXv)
    whole = np.zeros((serial.mesh.num_nodes, 3))
    for index, values in comm.allgather((address, dXv.reshape(-1, 3))):
        np.add.at(whole, index, values)
    g = serial.warp_derivative(whole)
    along = lambda x: np.column_stack([np.cos(x[:, 0]), np.sin(x[:, 1]), x[:, 2]])  # noqa: E731
    directional = comm.allreduce(float(np.sum(mesh.getdXs() * along(xs))))
    serial_directional = float(np.sum(g * along(serial.mesh.points[serial.design_nodes])))
    assert abs(directional - serial_directional) <= 1e-12 * np.abs(g).sum()
    assert mesh.verifyWarpDeriv(h=1e-6) < 1e-6


def test_a_case_decomposed_for_another_rank_count_is_refused():
    if comm.size == 1:
        pytest.skip("one rank reads the whole case")
    folder = decomposed_case("idwarp_decomposed_other", comm.size + 1)
    if folder is None:
        pytest.skip("OpenFOAM's decomposePar is not installed (apt-get install openfoam)")
    with pytest.raises(mm.InputError, match=f"{comm.size + 1} processor folders for {comm.size} ranks"):
        USMesh(options={"gridFile": str(folder), "fileType": "OpenFOAM", "specifiedSurfaces": ["wall"]}, comm=comm)
