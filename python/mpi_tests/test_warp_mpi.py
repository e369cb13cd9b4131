"""Warp over MPI, run by ctest under mpiexec at 1 to 4 ranks: each rank's part of the warped mesh
and of the gradient equals the serial Warp's on the same mesh, which every rank also builds; the
solver's own partition gives the same; errors reach every rank."""

import os
import pathlib

import numpy as np
import pytest

mm = pytest.importorskip("meshmotion", reason="the meshmotion module was not built")
MPI = pytest.importorskip("mpi4py.MPI", reason="mpi4py is not installed (python3-mpi4py)")
if not mm._core.have_mpi:
    pytest.skip("the module was built without MPI: " + mm._core.mpi_missing, allow_module_level=True)

from meshes import box, bump, seed  # noqa: E402  (beside this file)

comm = MPI.COMM_WORLD


def pair(method="rbf", cell_ranks=None, **options):
    mesh = box()
    serial = mm.Warp(mesh, design=["wall"], symmetry=["symmetry"], fixed=["farfield"], method=method, **options)
    ranks = cell_ranks(mesh) if cell_ranks is not None and comm.rank == 0 else None
    parallel = mm.Warp(mesh if comm.rank == 0 else None, design=["wall"], symmetry=["symmetry"], fixed=["farfield"],
                       method=method, comm=comm, cell_ranks=ranks, **options)
    return serial, parallel


def warp_both(serial, parallel):
    serial.set_surface_coordinates(bump(serial.surface_coordinates()))
    parallel.set_surface_coordinates(bump(parallel.surface_coordinates()))
    return serial.warp(), parallel.warp()


def test_rbf_warp_and_gradient_equal_the_serial_ones():
    serial, parallel = pair(support_radius=0.7)
    ids = parallel.node_ids
    assert len(ids) == parallel.mesh.num_nodes and 0 < parallel.num_owned <= len(ids)
    # The design surface is split: each design node on exactly one rank.
    mine = parallel.design_nodes
    everyone = np.sort(np.concatenate(comm.allgather(mine)))
    np.testing.assert_array_equal(everyone, np.sort(serial.design_nodes))
    whole, part = warp_both(serial, parallel)
    moved = np.abs(whole - serial.mesh.points).max()
    assert moved > 0.01
    np.testing.assert_allclose(part, whole[ids], rtol=0, atol=1e-12 * moved)
    # Symmetry nodes stayed in their plane y = 0.
    symmetry = [i for i, g in enumerate(ids) if g in set(serial.mesh.group_nodes("symmetry"))]
    np.testing.assert_allclose(part[symmetry, 1], 0.0, atol=1e-15)
    # Gradient: this rank's rows are the serial gradient's rows of its design nodes.
    g_serial = serial.warp_derivative(seed(serial.node_ids))
    g_part = parallel.warp_derivative(seed(ids))
    row = {int(v): k for k, v in enumerate(serial.design_nodes)}
    expected = g_serial[[row[int(v)] for v in mine]] if len(mine) else np.zeros((0, 3))
    scale = np.abs(g_serial).max()
    np.testing.assert_allclose(g_part, expected, rtol=0, atol=1e-12 * scale)
    # Ghost rows of dI/dXv belong to their owners: changing them changes nothing.
    poked = seed(ids)
    poked[parallel.num_owned:] += 1.0
    np.testing.assert_array_equal(parallel.warp_derivative(poked), g_part)
    assert parallel.verify_derivative(verbose=False) < 1e-6


def test_the_default_radius_is_the_serial_one_where_the_memory_budget_binds():
    # No support_radius: each mover takes its default at setup, cut to max_memory_bytes; the
    # distributed one samples the serial mover's nodes by global id, whatever the partition.
    serial, parallel = pair(max_memory_bytes=5e5)
    whole, part = warp_both(serial, parallel)
    chosen = serial._mover.stats
    assert chosen["radius_reduced"] and chosen["support_radius"] > 0
    assert parallel._mover.stats["support_radius"] == chosen["support_radius"]
    assert parallel._mover.stats["radius_reduced"]
    np.testing.assert_allclose(part, whole[parallel.node_ids], rtol=0, atol=1e-12 * np.abs(whole - serial.mesh.points).max())


def test_warp_returns_a_read_only_view_of_local_coordinates():
    _, parallel = pair(support_radius=0.7)
    parallel.set_surface_coordinates(bump(parallel.surface_coordinates()))
    result = parallel.warp()
    with pytest.raises(ValueError):
        result[0, 0] = 1.0
    np.testing.assert_array_equal(parallel.volume_coordinates(), result)


def test_a_solvers_own_partition_gives_the_same_mesh():
    # Cells by slabs of x, ranks in reverse order: not what METIS would do.
    def slabs(mesh):
        cells = np.asarray(mesh.cells[0][1])
        x = np.asarray(mesh.points)[cells].mean(axis=1)[:, 0]
        return (comm.size - 1 - np.minimum((x / 1.4 * comm.size).astype(int), comm.size - 1)).astype(np.int64)

    serial, parallel = pair(support_radius=0.7, cell_ranks=slabs)
    whole, part = warp_both(serial, parallel)
    np.testing.assert_allclose(part, whole[parallel.node_ids], rtol=0, atol=1e-12)


def scattered_partition(mesh):
    """This rank's share of `mesh` as a solver might hold it, without the library's partition:
    node g owned by rank g % size, ghosts the nodes rank (g + 1) % size owns, all in a shuffled
    order; groups as local indices."""
    n = mesh.num_nodes
    ids = np.flatnonzero((np.arange(n) % comm.size == comm.rank) | ((np.arange(n) + 1) % comm.size == comm.rank))
    ids = np.random.default_rng(comm.rank).permutation(ids)
    local = {int(g): k for k, g in enumerate(ids)}
    groups = {name: [local[int(g)] for g in mesh.group_nodes(name) if int(g) in local]
              for name in ("wall", "symmetry", "farfield")}
    return np.asarray(mesh.points)[ids], ids, (ids % comm.size).astype(np.int32), groups


def test_a_partition_no_rank_holds_whole_gives_the_serial_warp_and_gradient():
    mesh = box()
    serial = mm.Warp(mesh, design=["wall"], symmetry=["symmetry"], fixed=["farfield"], support_radius=0.7)
    points, ids, owner, groups = scattered_partition(mesh)
    parallel = mm.Warp.from_partition(comm, points, ids, owner, groups, design=["wall"], symmetry=["symmetry"],
                                      fixed=["farfield"], support_radius=0.7)
    assert parallel.mesh is None and parallel.num_owned == int((owner == comm.rank).sum())
    np.testing.assert_array_equal(parallel.node_ids, ids)
    np.testing.assert_array_equal(parallel.owned, owner == comm.rank)
    mine = parallel.design_nodes
    assert np.all(np.diff(mine) > 0) and np.all(mine % comm.size == comm.rank)
    np.testing.assert_array_equal(np.sort(np.concatenate(comm.allgather(mine))), serial.design_nodes)
    whole, part = warp_both(serial, parallel)
    moved = np.abs(whole - serial.mesh.points).max()
    assert moved > 0.01
    # Rows in the order given, ghosts included; the symmetry plane fitted over every rank.
    np.testing.assert_allclose(part, whole[ids], rtol=0, atol=1e-12 * moved)
    gathered = parallel.gather_volume_coordinates()
    if comm.rank == 0:
        np.testing.assert_allclose(gathered, whole, rtol=0, atol=1e-12 * moved)
    else:
        assert gathered is None
    g_serial = serial.warp_derivative(seed(serial.node_ids))
    g_part = parallel.warp_derivative(seed(ids))
    row = {int(v): k for k, v in enumerate(serial.design_nodes)}
    expected = g_serial[[row[int(v)] for v in mine]] if len(mine) else np.zeros((0, 3))
    np.testing.assert_allclose(g_part, expected, rtol=0, atol=1e-12 * np.abs(g_serial).max())
    assert parallel.verify_derivative(verbose=False) < 1e-6
    with pytest.raises(mm.InputError, match="holds no cells"):
        parallel.write_mesh("unused.msh")


def test_partition_of_unity_keeps_each_patch_on_one_rank_with_the_serial_result():
    # No sliding group (a symmetry plane makes two systems per patch: replicated instead).
    mesh = box()
    options = dict(design=["wall"], fixed=["farfield", "symmetry"], support_radius=0.5, partition_of_unity=True,
                   patch_centres=12)
    serial = mm.Warp(mesh, **options)
    points, ids, owner, groups = scattered_partition(mesh)
    parallel = mm.Warp.from_partition(comm, points, ids, owner, groups, boundary_solve="patches", **options)
    assert parallel.boundary_solve == "patches"
    whole, part = warp_both(serial, parallel)
    moved = np.abs(whole - serial.mesh.points).max()
    assert moved > 0.01
    np.testing.assert_allclose(part, whole[ids], rtol=0, atol=1e-12 * moved)
    g_serial = serial.warp_derivative(seed(serial.node_ids))
    g_part = parallel.warp_derivative(seed(ids))
    row = {int(v): k for k, v in enumerate(serial.design_nodes)}
    mine = parallel.design_nodes
    expected = g_serial[[row[int(v)] for v in mine]] if len(mine) else np.zeros((0, 3))
    np.testing.assert_allclose(g_part, expected, rtol=0, atol=1e-12 * np.abs(g_serial).max())
    assert parallel.verify_derivative(verbose=False) < 1e-6
    # With a symmetry plane, the default (automatic) replicates and still equals the serial Warp.
    serial, parallel = pair(support_radius=0.5, partition_of_unity=True, patch_centres=12)
    assert parallel.boundary_solve == "replicated"
    whole, part = warp_both(serial, parallel)
    np.testing.assert_allclose(part, whole[parallel.node_ids], rtol=0, atol=1e-12 * np.abs(whole).max())


def test_a_partition_no_rank_holds_whole_is_refused_clearly():
    mesh = box(3, 3, 2)
    points, ids, owner, groups = scattered_partition(mesh)
    with pytest.raises(mm.InputError, match="no group named 'nowhere' on any rank"):
        mm.Warp.from_partition(comm, points, ids, owner, groups, design=["nowhere"])
    with pytest.raises(mm.InputError, match="rbf only"):
        mm.Warp.from_partition(comm, points, ids, owner, groups, design=["wall"], fixed=["farfield"], method="sle")
    # One rank's bad array raises on every rank, with that rank's message.
    bad = groups if comm.rank != comm.size - 1 else dict(groups, wall=[len(ids)])
    with pytest.raises(mm.InputError, match="group 'wall' refers to local node"):
        mm.Warp.from_partition(comm, points, ids, owner, bad, design=["wall"])
    with pytest.raises(mm.InputError, match="not planar"):
        mm.Warp.from_partition(comm, points, ids, owner, groups, design=["wall"], symmetry=["farfield"])
    if comm.size > 1:  # a node owned by two ranks
        with pytest.raises(mm.InputError, match="owned boundary node on two ranks"):
            mm.Warp.from_partition(comm, points, ids, np.full(len(ids), comm.rank, dtype=np.int32), groups,
                                   design=["wall"], fixed=["farfield"])


def test_elasticity_over_petsc_agrees_with_the_serial_solve_and_its_gradient():
    serial, parallel = pair(method="sle")
    whole, part = warp_both(serial, parallel)
    moved = np.abs(whole - serial.mesh.points).max()
    np.testing.assert_allclose(part, whole[parallel.node_ids], rtol=0, atol=1e-5 * moved)
    # The ranks' rows of dI/dXs are the serial gradient's, to the PETSc solve's tolerance.
    g_serial = serial.warp_derivative(seed(serial.node_ids))
    g_part = parallel.warp_derivative(seed(parallel.node_ids))
    row = {int(v): k for k, v in enumerate(serial.design_nodes)}
    mine = parallel.design_nodes
    expected = g_serial[[row[int(v)] for v in mine]] if len(mine) else np.zeros((0, 3))
    assert np.abs(g_serial).max() > 0
    np.testing.assert_allclose(g_part, expected, rtol=0, atol=1e-6 * np.abs(g_serial).max())


def test_write_mesh_gathers_the_whole_mesh_on_rank_0():
    serial, parallel = pair(support_radius=0.7)
    whole, _ = warp_both(serial, parallel)
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp")) / f"warp_mpi_{comm.size}"
    if comm.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
    comm.Barrier()
    parallel.write_mesh(folder / "moved.msh")
    if comm.rank == 0:
        back = mm.read_mesh(str(folder / "moved.msh"))
        np.testing.assert_allclose(back.points, whole, rtol=0, atol=1e-12)


def test_every_rank_raises_what_rank_0_finds():
    mesh = box(3, 3, 2)
    with pytest.raises(mm.InputError, match="nowhere"):
        mm.Warp(mesh if comm.rank == 0 else None, design=["nowhere"], comm=comm)
    with pytest.raises(mm.InputError, match="no distributed mover"):
        mm.Warp(mesh if comm.rank == 0 else None, design=["wall"], fixed=["farfield"], method="spring", comm=comm)
    with pytest.raises(mm.InputError, match="an mpi4py communicator"):
        mm.Warp(mesh, design=["wall"], comm="world")
