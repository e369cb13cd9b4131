"""Tests of the Python layer: numpy views without copies, typed keyword options refused as the
C++ parser refuses them, exact interpolation at the boundary, derivatives against finite
differences, the Warp class, errors mapped to Python exceptions."""

import os
import pathlib
import warnings

import numpy as np
import pytest

mm = pytest.importorskip("meshmotion", reason="the meshmotion module was not built (pybind11 absent?)")


def grid(nx=8, ny=6, size=1.0):
    """A structured square of quadrilaterals with groups bottom, top, left, right."""
    x, y = np.meshgrid(np.linspace(0.0, size, nx + 1), np.linspace(0.0, size, ny + 1), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel()])
    node = lambda i, j: i * (ny + 1) + j  # noqa: E731
    quads = [[node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)] for i in range(nx) for j in range(ny)]
    lines = lambda pairs: np.array(pairs, dtype=np.int64)  # noqa: E731
    groups = {
        "bottom": ("line2", lines([[node(i, 0), node(i + 1, 0)] for i in range(nx)])),
        "top": ("line2", lines([[node(i, ny), node(i + 1, ny)] for i in range(nx)])),
        "left": ("line2", lines([[node(0, j), node(0, j + 1)] for j in range(ny)])),
        "right": ("line2", lines([[node(nx, j), node(nx, j + 1)] for j in range(ny)])),
    }
    return mm.from_arrays(points, {"quad4": np.array(quads)}, groups)


def scratch(name):
    folder = pathlib.Path(os.environ.get("MESHMOTION_TEST_TMP_DIR", "/tmp"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder / name


def test_points_are_a_view_without_copy():
    mesh = grid()
    p = mesh.points
    assert p.shape == (mesh.num_nodes, 2) and p.dtype == np.float64 and p.flags["C_CONTIGUOUS"]
    p[3, 1] = 7.5
    assert mesh.points[3, 1] == 7.5  # the same memory
    assert np.shares_memory(p, mesh.points)
    name, quads = mesh.cells[0]
    assert name == "quad4" and quads.shape == (mesh.num_cells, 4) and quads.dtype == np.int64
    assert sorted(mesh.groups) == ["bottom", "left", "right", "top"]
    assert list(mesh.groups["bottom"]) == list(range(0, mesh.num_nodes, 7))


def test_summary_is_mesh_infos_from_its_description():
    summary = grid().summary()
    assert list(summary) == mm.report_fields("summary")
    assert summary["cells"] == {"quad4": 48} and summary["facets"] == {"line2": 28}
    assert summary["bbox_min"] == [0.0, 0.0] and summary["bbox_max"] == [1.0, 1.0]
    assert [g["name"] for g in summary["groups"]] == ["bottom", "top", "left", "right"]
    assert summary["groups"][0]["nodes"] == 9 and summary["orientation"] == "positive"


def test_write_and_read_back(tmp_path=None):
    mesh = grid()
    file = scratch("python_grid.msh")
    mm.write_mesh(file, mesh)
    back = mm.read_mesh(str(file))
    assert isinstance(back, mm._core.Mesh2)
    np.testing.assert_array_equal(back.points, mesh.points)
    np.testing.assert_array_equal(back.cells[0][1], mesh.cells[0][1])
    assert back.groups.keys() == mesh.groups.keys()


def test_typed_options_refused_like_the_cpp_parser():
    with pytest.raises(ValueError, match="did you mean 'support_radius'"):
        mm.Mover("rbf", 2, suport_radius=0.5)
    with pytest.raises(mm.InputError, match="poisson_ratio"):
        mm.Mover("rbf", 2, poisson_ratio=0.3)
    with pytest.raises(ValueError, match="finite number"):
        mm.Mover("rbf", 2, support_radius=float("nan"))
    with pytest.raises(ValueError, match="wendland"):
        mm.Mover("rbf", 2, kernel="wendland3")
    with pytest.raises(ValueError, match="unknown mover method"):
        mm.Mover("rfb", 2)
    assert ("support_radius", "0") in mm.mover_options("rbf")  # 0: from the boundary at setup
    mm.Mover("sle", 3, poisson_ratio=0.4, solver="cg_jacobi", tolerance=1e-9)


def test_rbf_moves_the_boundary_exactly_and_into_a_callers_array():
    mesh = grid()
    spec = mm.Boundary(2).prescribed("bottom").fixed("top").sliding("left").sliding("right")
    b = spec.resolve(mesh)
    d = np.zeros((b.size, 2))
    bottom = mesh.groups["bottom"]
    ramp = np.column_stack([np.zeros(len(bottom)), 0.05 * mesh.points[bottom, 0]])
    b.scatter(list(bottom), ramp, d)
    mover = mm.Mover("rbf", 2, support_radius=0.6)
    mover.setup(mesh, b)
    u = mover.move(d)
    np.testing.assert_allclose(u[bottom], ramp, rtol=0, atol=1e-15)
    assert np.all(u[mesh.groups["top"]] == 0.0)
    out = np.full((mesh.num_nodes, 2), -1.0)
    mover.move_into(d, out)
    np.testing.assert_array_equal(out, u)
    assert mover.stats["moves"] == 2


def test_the_default_radius_follows_the_mesh_scale():
    # The same mesh in metres and in millimetres, moved with the defaults, moves alike.
    moved = []
    for size in (1.0, 1000.0):
        mesh = grid(size=size)
        b = mm.Boundary(2).prescribed("bottom").fixed("top").sliding("left").sliding("right").resolve(mesh)
        bottom = mesh.groups["bottom"]
        d = np.zeros((b.size, 2))
        b.scatter(list(bottom), np.column_stack([np.zeros(len(bottom)), 0.2 * mesh.points[bottom, 0]]), d)
        mover = mm.Mover("rbf", 2)
        mover.setup(mesh, b)
        moved.append(mover.move(d) / size)
    np.testing.assert_allclose(moved[1], moved[0], rtol=0, atol=1e-12)


def slab(nx=8, ny=6, thickness=0.05):
    """grid() extruded one cell thick along z: hexahedra, the lateral groups as quadrilaterals
    and the front and back as one group, as an OpenFOAM 2D case stores it."""
    flat = grid(nx, ny)
    n = flat.num_nodes
    points = np.vstack([np.column_stack([flat.points, np.zeros(n)]), np.column_stack([flat.points, np.full(n, thickness)])])
    node = lambda i, j: i * (ny + 1) + j  # noqa: E731
    quads = np.array([[node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)] for i in range(nx) for j in range(ny)])
    lateral = lambda pairs: ("quad4", np.array([[a, b, b + n, a + n] for a, b in pairs]))  # noqa: E731
    groups = {
        "bottom": lateral([(node(i, 0), node(i + 1, 0)) for i in range(nx)]),
        "top": lateral([(node(i, ny), node(i + 1, ny)) for i in range(nx)]),
        "frontAndBack": ("quad4", np.vstack([quads[:, ::-1], quads + n])),
    }
    return mm.from_arrays(points, {"hex8": np.hstack([quads, quads + n])}, groups)


def test_a_2d_case_stored_in_3d_moves_as_its_section():
    mesh = slab()
    assert mm.find_extrusion(mesh) == {"axis": 2, "front": 0.0, "back": 0.05, "plane_groups": ["frontAndBack"]}
    tet = mm.from_arrays([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], {"tet4": [[0, 1, 2, 3]]})
    assert mm.find_extrusion(tet) is None
    b = mm.Boundary(3).translating("top", [0.1, -0.05, 0.0]).fixed("bottom").resolve(mesh)
    d = np.zeros((b.size, 3))
    top = mesh.groups["top"]
    b.scatter(list(top), np.tile([0.1, -0.05, 0.0], (len(top), 1)), d)
    n = mesh.num_nodes // 2
    for method in ("le", "dgrbf", "rbf"):
        mover = mm.Mover(method, 3, section=True)
        mover.setup(mesh, b)
        u = mover.move(d)
        assert np.all(u[:, 2] == 0.0), method
        np.testing.assert_array_equal(u[:n], u[n:])
    # The 3D elasticity moves the front and back off their planes.
    mover = mm.Mover("le", 3)
    mover.setup(mesh, b)
    assert np.abs(mover.move(d)[:, 2]).max() > 1e-6
    with pytest.raises(mm.InputError, match="not two-dimensional"):
        mover = mm.Mover("le", 3, section=True)
        mover.setup(mesh, mm.Boundary(3).translating("top", [0.1, 0.0, 0.01]).fixed("bottom").resolve(mesh))
    with pytest.raises(mm.InputError, match="give dim=3"):
        mm.Mover("le", 2, section=True)


def test_tps_gets_the_polynomial_it_needs():
    # Without the polynomial the thin plate spline's system is ill-posed: a rotated boundary
    # gave a scaled Jacobian of -230 and no error. It is always added: the rotation is exact.
    mesh = grid()
    b = mm.Boundary(2).prescribed("bottom").prescribed("top").prescribed("left").prescribed("right").resolve(mesh)
    c, angle = np.array([0.5, 0.5]), 0.4
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    rotated = lambda x: (x - c) @ turn.T + c - x  # noqa: E731
    d = np.zeros((b.size, 2))
    nodes = sorted(set().union(*(set(mesh.groups[g]) for g in ("bottom", "top", "left", "right"))))
    b.scatter(nodes, rotated(mesh.points[nodes]), d)
    for polynomial in (False, True):
        mover = mm.Mover("rbf", 2, kernel="tps", polynomial=polynomial)
        mover.setup(mesh, b)
        np.testing.assert_allclose(mover.move(d), rotated(mesh.points), rtol=0, atol=1e-9)


def test_bad_arrays_are_refused():
    mesh = grid()
    b = mm.Boundary(2).prescribed("bottom").fixed("top").resolve(mesh)
    mover = mm.Mover("rbf", 2, support_radius=0.6)
    mover.setup(mesh, b)
    with pytest.raises(ValueError, match="float64"):
        mover.move(np.zeros((b.size, 2), dtype=np.float32))
    with pytest.raises(ValueError, match="shape"):
        mover.move(np.zeros((b.size, 3)))
    with pytest.raises(ValueError, match="C-contiguous"):
        mover.move(np.zeros((2, b.size)).T)
    with pytest.raises(ValueError, match="not finite"):
        d = np.zeros((b.size, 2))
        d[0, 0] = np.nan
        mover.move(d)
    with pytest.raises(ValueError):
        mover.move_into(np.zeros((b.size, 2)), np.zeros((3, 2)))


def test_copied_arrays_convert_exactly_or_are_refused_and_views_are_read_only():
    mesh = grid()
    points = mesh.points.copy()
    quads = mesh.cells[0][1].copy()
    # Copied arrays: float32 coordinates and int32 indices, in Fortran order, convert exactly.
    p32 = np.asfortranarray(points.astype(np.float32))
    again = mm.from_arrays(p32, {"quad4": np.asfortranarray(quads.astype(np.int32))})
    assert np.array_equal(again.points, p32.astype(np.float64))
    assert np.array_equal(again.cells[0][1], quads)
    # What would lose something is refused: a float index, a complex coordinate.
    with pytest.raises(mm.InputError, match="float index is not rounded"):
        mm.from_arrays(points, {"quad4": quads + 0.7})
    with pytest.raises(mm.InputError, match="expected real numbers"):
        mm.from_arrays(points + 0j, {"quad4": quads})
    with pytest.raises(mm.InputError, match="beyond 2\\*\\*53"):
        mm.from_arrays(np.full((4, 2), 2**60, dtype=np.int64), {"quad4": np.array([[0, 1, 2, 3]])})
    # The connectivity views cannot be written: an index out of range never reaches a loop.
    view = mesh.cells[0][1]
    assert not view.flags.writeable
    with pytest.raises(ValueError):
        view[0, 0] = 10**9
    assert not mesh.facets[0][1].flags.writeable


LINEAR_METHODS = ["rbf", "spring", "torsion", "le", "sle", "dgm", "idgm", "dgrbf"]


@pytest.mark.parametrize("method", LINEAR_METHODS)
def test_derivatives_match_finite_differences_and_each_other(method):
    mesh = grid()
    b = mm.Boundary(2).prescribed("bottom").fixed("top").sliding("left").resolve(mesh)
    mover = mm.Mover(method, 2, **({"support_radius": 0.6} if method == "rbf" else {}))
    mover.setup(mesh, b)
    assert mover.has_derivatives
    rng = np.random.default_rng(7)
    d = 1e-3 * rng.standard_normal((b.size, 2))
    w = rng.standard_normal((b.size, 2))
    for k, kind in enumerate(b.kinds):
        if kind != "prescribed":
            d[k] = w[k] = 0.0
    h = 1e-4
    fd = (mover.move(d + h * w) - mover.move(d - h * w)) / (2 * h)
    np.testing.assert_allclose(mover.derivative_forward(w), fd, rtol=0, atol=1e-9 * np.abs(fd).max())
    v = rng.standard_normal((mesh.num_nodes, 2))
    jtv = mover.derivative_reverse(v)
    assert jtv.shape == (b.size, 2)
    assert abs(np.sum(v * mover.derivative_forward(w)) - np.sum(jtv * w)) < 1e-10 * np.abs(v).sum()
    sliding = [k for k, kind in enumerate(b.kinds) if kind == "sliding"]
    assert np.all(jtv[sliding] == 0.0)


def test_movers_without_derivatives_say_so():
    mesh = grid()
    b = mm.Boundary(2).prescribed("bottom").fixed("top").resolve(mesh)
    mover = mm.Mover("nle", 2)
    mover.setup(mesh, b)
    assert not mover.has_derivatives
    with pytest.raises(ValueError, match="no derivatives"):
        mover.derivative_reverse(np.zeros((mesh.num_nodes, 2)))


def test_warp_in_an_optimization_loop():
    mesh = grid()
    w = mm.Warp(mesh, design=["bottom"], symmetry=["left", "right"], fixed=["top"], support_radius=0.6)
    xs = w.surface_coordinates()
    assert xs.shape == (len(mesh.groups["bottom"]), 2)
    bump = xs.copy()
    bump[:, 1] += 0.02 * np.sin(np.pi * xs[:, 0])
    w.set_surface_coordinates(bump)
    first = w.warp().copy()
    w.set_surface_coordinates(bump)
    np.testing.assert_array_equal(w.warp(), first)  # always from the reference
    np.testing.assert_allclose(w.volume_coordinates()[w.design_nodes], bump, atol=1e-15)
    assert w.verify_derivative(verbose=False) < 1e-6
    g = w.warp_derivative(np.ones((mesh.num_nodes, 2)))
    assert g.shape == xs.shape  # sized like the design surface, no sliding or fixed rows
    # The solver's own order of the design nodes.
    order = w.design_nodes[::-1].copy()
    w.set_surface_order(order)
    np.testing.assert_array_equal(w.design_nodes, order)
    np.testing.assert_array_equal(w.surface_coordinates(), bump[::-1])
    with pytest.raises(ValueError, match="design surface"):
        w.set_surface_order(np.concatenate([order[:-1], [mesh.groups["top"][3]]]))
    with pytest.raises(ValueError, match="shape"):
        w.set_surface_coordinates(bump[:-1])


def test_warp_never_writes_over_its_input_unasked():
    # The mesh file a Warp was read from, by any path to it, is replaced only with
    # overwrite=True; the file given as like= never is.
    source = scratch("python_warp_source.msh")
    mm.write_mesh(source, grid())
    link = scratch("python_warp_source_link.msh")
    if os.path.lexists(link):
        os.remove(link)
    os.symlink(source, link)
    w = mm.Warp(str(source), design=["bottom"], fixed=["top"], support_radius=0.6)
    xs = w.surface_coordinates()
    w.set_surface_coordinates(xs + [0.0, 0.01])
    w.warp()
    before = pathlib.Path(source).read_bytes()
    for target in (source, link):
        with pytest.raises(mm.InputError, match="overwrite=True"):
            w.write_mesh(target)
    assert pathlib.Path(source).read_bytes() == before
    other = scratch("python_warp_other.msh")
    mm.write_mesh(other, grid())
    with pytest.raises(mm.InputError, match="like="):
        w.write_mesh(other, like=other)
    w.write_mesh(source, overwrite=True)
    np.testing.assert_allclose(mm.read_mesh(str(source)).points, w.volume_coordinates(), rtol=0, atol=1e-12)


def test_warp_takes_groups_named_by_patterns_as_openfoam_names_patches():
    mesh = grid()
    by_name = mm.Warp(mesh, design=["bottom"], symmetry=["left", "right"], fixed=["top"], support_radius=0.6)
    by_pattern = mm.Warp(mesh, design=["bot.*"], symmetry=["(left|right)"], fixed=["t[o]p"], support_radius=0.6)
    np.testing.assert_array_equal(by_pattern.design_nodes, by_name.design_nodes)
    bump = by_name.surface_coordinates().copy()
    bump[:, 1] += 0.02 * np.sin(np.pi * bump[:, 0])
    by_name.set_surface_coordinates(bump)
    by_pattern.set_surface_coordinates(bump)
    np.testing.assert_array_equal(by_pattern.warp(), by_name.warp())
    with pytest.raises(ValueError, match="no group named 'inlet.[*]'"):
        mm.Warp(mesh, design=["inlet.*"], fixed=["top"])


def test_warp_reports_its_conditioning_and_warns_when_gradients_lose_digits():
    mesh = grid()
    conditions = []
    for radius in (0.6, 3.0):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a well-conditioned Warp warns of nothing
            conditions.append(mm.Warp(mesh, design=["bottom"], fixed=["top"], support_radius=radius).condition)
    assert 1.0 <= conditions[0] < conditions[1]
    with pytest.warns(RuntimeWarning, match="condition number is at least"):
        w = mm.Warp(mesh, design=["bottom"], fixed=["top"], support_radius=2000.0, condition_limit=0.0)
    assert w.condition > mm.warp.CONDITION_WARNING
    # By default such a system is thinned: its condition within the limit, nothing to warn of,
    # the gradient agreeing with finite differences.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        thinned = mm.Warp(mesh, design=["bottom"], fixed=["top"], support_radius=2000.0)
    assert thinned.condition <= 1e10
    assert thinned._mover.stats["thinned_centres"] > 0
    assert thinned.verify_derivative(verbose=False) < 1e-6
    assert mm.Warp(mesh, design=["bottom"], fixed=["top"], method="le").condition == 0.0


def test_warp_returns_a_read_only_view_and_allocates_no_volume_array():
    import tracemalloc

    mesh = grid(60, 40)
    w = mm.Warp(mesh, design=["bottom"], fixed=["top", "left", "right"], support_radius=0.6)
    xs = w.surface_coordinates()
    xs[:, 1] += 0.01 * np.sin(np.pi * xs[:, 0])
    w.set_surface_coordinates(xs)
    result = w.warp()
    with pytest.raises(ValueError):
        result[0, 0] = 5.0  # the Warp's state, not the caller's to edit
    kept = w.volume_coordinates()
    kept[0, 0] = 5.0  # a copy: the Warp does not see it
    assert w.volume_coordinates()[0, 0] == 0.0
    tracemalloc.start()
    w.warp()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < mesh.num_nodes * 2 * 8 // 4, f"warp() allocated {peak} bytes in Python for {mesh.num_nodes} nodes"


def test_errors_map_to_python_exceptions():
    with pytest.raises(OSError):
        mm.read_mesh("/no/such/mesh.msh")
    with pytest.raises(ValueError, match="unknown mesh format"):
        mm.read_mesh("mesh.cgnx")
    bad = scratch("python_bad.su2")
    bad.write_text("NDIME= 2\nNELEM= x\n")
    with pytest.raises(mm.InputError, match="python_bad.su2:2"):
        mm.read_mesh(str(bad))
    assert issubclass(mm.InputError, ValueError) and issubclass(mm.IoError, OSError)
    assert issubclass(mm.SolverError, RuntimeError)
    # Error is the base of every one of them, as docs/python.md says.
    for kind in (mm.InputError, mm.IoError, mm.SolverError, mm.InvalidMeshError):
        assert issubclass(kind, mm.Error), kind
    with pytest.raises(mm.Error):
        mm.read_mesh("/no/such/mesh.msh")


def test_an_absurd_omp_num_threads_is_refused_at_import():
    import subprocess
    import sys

    env = dict(os.environ, OMP_NUM_THREADS="100000")
    run = subprocess.run([sys.executable, "-c", "import meshmotion"], env=env, capture_output=True, text=True)
    assert run.returncode != 0
    assert "OMP_NUM_THREADS=100000: more than 1024 threads" in run.stderr


def test_reversed_mesh_is_reoriented_at_read_time():
    file = scratch("python_clockwise.su2")
    file.write_text("NDIME= 2\nNELEM= 2\n5 0 2 1 0\n5 0 3 2 1\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\n"
                    "NMARK= 1\nMARKER_TAG= wall\nMARKER_ELEMS= 1\n3 0 1\n")
    assert mm.quality_report(mm.read_mesh(str(file)))["invalid"] == 2
    assert mm.quality_report(mm.read_mesh(str(file), "fix_reversed"))["invalid"] == 0
    with pytest.raises(ValueError, match="negatively oriented"):
        mm.read_mesh(str(file), "require_positive")


def test_real_mesh_from_shared_data():
    folder = pathlib.Path(os.environ.get("MESHMOTION_SHARED_DATA_DIR", ""))
    file = folder / "su2_naca0012_inviscid_tri.su2"
    if not file.exists():
        pytest.skip(f"{file} not found (../shared/data is absent here)")
    mesh = mm.read_mesh(str(file))
    assert mesh.points.shape[1] == 2 and mesh.num_cells > 0
    wall = [g for g in mesh.groups if g.lower() in ("airfoil", "wall")]
    assert wall, f"no wall group among {list(mesh.groups)}"
    w = mm.Warp(mesh, design=wall, fixed=[g for g in mesh.groups if g not in wall], support_radius=0.5)
    assert w.verify_derivative(verbose=False) < 1e-6


def annulus(n_around=48, n_radial=8, inner=0.5, outer=2.0):
    """Quadrilaterals between two circles, groups "wall" (inner) and "farfield" (outer)."""
    t = np.linspace(0.0, 2.0 * np.pi, n_around, endpoint=False)
    r = inner * (outer / inner) ** np.linspace(0.0, 1.0, n_radial + 1)
    points = np.column_stack([np.outer(r, np.cos(t)).ravel(), np.outer(r, np.sin(t)).ravel()])
    node = lambda j, i: j * n_around + i % n_around  # noqa: E731
    quads = np.array([[node(j, i), node(j + 1, i), node(j + 1, i + 1), node(j, i + 1)]
                      for j in range(n_radial) for i in range(n_around)], dtype=np.int64)
    ring = lambda j: np.array([[node(j, i), node(j, i + 1)] for i in range(n_around)], dtype=np.int64)  # noqa: E731
    return mm.from_arrays(points, {"quad4": quads}, {"wall": ("line2", ring(0)), "farfield": ("line2", ring(n_radial))})


def test_a_mover_set_up_once_follows_a_whole_boundary_turning_56_degrees():
    # As a time loop uses it: set up on the reference with no displacement, moved from the
    # reference ten times. Each move's rigid part (turn and translation) is blended in first,
    # and the default radius grows with what it leaves (held at the setup's and interpolating
    # the whole motion, the ring folded at the last steps).
    mesh = annulus()
    b = mm.Boundary(2).prescribed("wall").prescribed("farfield").resolve(mesh)
    x = mesh.points[b.nodes]
    mover = mm.Mover("rbf", 2)
    mover.setup(mesh, b)
    for step in range(1, 11):
        s = 0.1 * step
        turn = s * (np.radians(56.0) + 0.15 * np.cos(2.0 * np.arctan2(x[:, 1], x[:, 0])))
        sx, sy = 1.16 ** s * x[:, 0], 1.16 ** -s * x[:, 1]
        target = np.column_stack([np.cos(turn) * sx - np.sin(turn) * sy + s * 0.31 * 2.0, np.sin(turn) * sx + np.cos(turn) * sy])
        moved = mm.from_arrays(mesh.points + mover.move(target - x), {"quad4": mesh.cells[0][1]}, {})
        report = mm.quality_report(moved, "scaled_jacobian")
        assert report["invalid"] == 0 and report["min"] > 0.5, (step, report["min"])
        # The move's time split: its solves and what it set up again, within the move.
        stats = mover.stats
        assert stats["solve_seconds"] > 0.0 and stats["rebuild_seconds"] >= 0.0
        assert stats["solve_seconds"] + stats["rebuild_seconds"] <= stats["move_seconds"]
    assert mover.stats["moves"] == 10
    assert mover.stats["rigid_part"]
    assert mover.stats["radius_growths"] <= 4
    # The grid velocity of a uniform boundary velocity through the last move's map.
    v = np.tile([0.5, -0.25], (b.size, 1))
    u = mover.velocity(v)
    assert u.shape == mesh.points.shape
    np.testing.assert_allclose(u[b.nodes], v, rtol=0, atol=1e-12)
    np.testing.assert_allclose(u, mover.derivative_forward(v), rtol=0, atol=0)
    with pytest.raises(mm.InputError, match="not linear"):
        nonlinear = mm.Mover("nle", 2)
        nonlinear.setup(mesh, b)
        nonlinear.velocity(v)


def test_quality_report_has_per_cell_arrays():
    mesh = grid()
    report = mm.quality_report(mesh, "jacobian")
    assert report["values"].shape == (mesh.num_cells,) and report["valid"].dtype == np.bool_
    np.testing.assert_allclose(report["values"], 1.0, rtol=0, atol=1e-14)  # squares
    mesh.points[mesh.cells[0][1][5]] = mesh.points[mesh.cells[0][1][5]][[1, 0, 3, 2]]  # fold cell 5's corners
    folded = mm.quality_report(mesh, "jacobian")
    assert not folded["valid"][5] and folded["invalid"] >= 1
    assert folded["values"].min() == folded["min"]


def test_curve_mesh_at_order_3_and_4():
    mesh = annulus()
    for order, cell in ((3, "quad16"), (4, "quad25")):
        curved, report = mm.curve_mesh(mesh, order=order, geometry={"wall": "circle:0,0,0.5"})
        assert curved.cells[0][0] == cell and report["invalid"] == 0
        wall = curved.groups["wall"]
        np.testing.assert_allclose(np.linalg.norm(curved.points[wall], axis=1), 0.5, rtol=0, atol=1e-12)
        assert set(report["untangle"]) >= {"cells_below", "invalid_after", "min_after"}
        assert "untangle" in report["seconds"]
        with pytest.raises(ValueError, match="no meshio counterpart"):
            mm.to_meshio(curved)
    with pytest.raises(ValueError, match=r"option 'order': 9 is out of range \(expected 2 to 8\)"):
        mm.curve_mesh(mesh, order=9)
    # The rounds raising the worst cells never lower the minimum; none leaves it as it was.
    _, raised = mm.curve_mesh(mesh, order=3, geometry={"wall": "circle:0,0,0.5"})
    _, plain = mm.curve_mesh(mesh, order=3, geometry={"wall": "circle:0,0,0.5"}, raise_rounds=0)
    assert plain["untangle"]["raise_rounds"] == 0
    assert raised["quality"]["min"] >= plain["quality"]["min"]
    assert (raised["untangle"]["raise_rounds"] > 0) == (raised["quality"]["min"] > plain["quality"]["min"])
    with pytest.raises(ValueError, match="raise_rounds"):
        mm.curve_mesh(mesh, raise_rounds=-1)


def test_curve_mesh_on_a_cad_model_takes_the_programs_policy(tmp_path):
    # A disk's hole in a square, as Gmsh's OpenCASCADE kernel builds, writes (BREP) and meshes
    # it: the wall goes onto the model's circle, the square (the model's lines alone) stays
    # straight, as curve_mesh --geometry MODEL.brep decides (geometry_on_cad()).
    if not mm._core.have_cad:
        pytest.skip("the module was built without the CAD component (libocct-*-dev)")
    gmsh = pytest.importorskip("gmsh", reason="python3-gmsh is not installed")
    model, mesh_file = tmp_path / "hole.brep", tmp_path / "hole.msh"
    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        square = gmsh.model.occ.addRectangle(-2, -2, 0, 4, 4)
        hole = gmsh.model.occ.addDisk(0, 0, 0, 0.5, 0.5)
        (surface,), _ = gmsh.model.occ.cut([(2, square)], [(2, hole)])
        gmsh.model.occ.synchronize()
        gmsh.write(str(model))
        curves = [c for _, c in gmsh.model.getBoundary([surface])]
        circle = [c for c in curves if abs(gmsh.model.occ.getMass(1, abs(c)) - np.pi) < 1e-6]
        for dim, tags, name in ((1, [abs(c) for c in circle], "wall"), (1, [abs(c) for c in curves if c not in circle], "farfield"),
                                (2, [surface[1]], "fluid")):
            gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(mesh_file))
    finally:
        gmsh.finalize()
    curved, report = mm.curve_mesh(mm.read_mesh(str(mesh_file)), geometry=str(model), order=3)
    assert report["on_model"] == ["wall"] and "wall" in report["cad_groups"]
    assert report["invalid"] == 0
    wall = curved.group_nodes("wall")
    np.testing.assert_allclose(np.linalg.norm(curved.points[wall], axis=1), 0.5, atol=1e-9)
    assert len(wall) == 3 * len(mm.read_mesh(str(mesh_file)).group_nodes("wall"))  # P3: two nodes an edge
    with pytest.raises(ValueError, match="cad_groups and cad_tolerance go with"):
        mm.curve_mesh(curved, cad_tolerance=1e-6)


def test_curve_mesh_puts_the_high_order_nodes_on_the_circle():
    mesh = annulus()
    curved, report = mm.curve_mesh(mesh, geometry={"wall": "circle:0,0,0.5"})
    assert curved.cells[0][0] == "quad9" and report["num_linear_nodes"] == mesh.num_nodes
    # The linear nodes keep their numbers; the wall's vertices were on the circle and stay.
    linear_wall = mesh.groups["wall"]
    np.testing.assert_array_equal(curved.points[linear_wall], mesh.points[linear_wall])
    assert np.abs(curved.points[: mesh.num_nodes] - mesh.points).max() < 1e-3
    wall = curved.groups["wall"]
    np.testing.assert_allclose(np.linalg.norm(curved.points[wall], axis=1), 0.5, rtol=0, atol=1e-12)
    assert report["invalid"] == 0 and report["quality"]["min"] > 0.5
    # The geometric certificate: the wall's facets, sampled inside, are on the circle.
    distance = {w["group"]: w for w in report["geometry_distance"]}
    assert distance["wall"]["geometry"] == "projection" and distance["wall"]["facets"] == len(wall) // 2
    assert distance["wall"]["max_node_distance"] < 1e-12 and 0 < distance["wall"]["max_distance"] < 1e-3
    assert report["off_geometry"] == 0
    with pytest.raises(ValueError, match="did you mean 'support_radius'"):
        mm.curve_mesh(mesh, suport_radius=0.3)
    with pytest.raises(ValueError, match="circle:X,Y,R"):
        mm.curve_mesh(mesh, geometry={"wall": "circle:0,0"})
    with pytest.raises(ValueError, match="expected a finite number"):
        mm.curve_mesh(mesh, support_radius="big")
    with pytest.raises(ValueError, match="expected a finite number"):
        mm.curve_mesh(mesh, support_radius=True)
    with pytest.raises(ValueError, match="'method': expected a string"):
        mm.curve_mesh(mesh, method=5)
    with pytest.raises(ValueError, match="'sliding': expected a list of names"):
        mm.curve_mesh(mesh, sliding="wall")
    # The movers' keywords go by the same descriptions.
    with pytest.raises(ValueError, match="'kernel': expected one of .*wendland2.* as a string"):
        mm.Mover("rbf", 2, kernel=2)
    with pytest.raises(ValueError, match="expects a dict"):
        mm.curve_mesh(mesh, geometry="circle:0,0,0.5")
    with pytest.raises(ValueError, match="unknown option 'kernel' for curve_mesh with method 'blend'"):
        mm.curve_mesh(mesh, method="blend", kernel="wendland4")
    _, sle = mm.curve_mesh(mesh, method="sle", geometry={"wall": "circle:0,0,0.5"}, poisson_ratio=0.3)
    assert sle["method"] == "sle" and sle["invalid"] == 0


def test_facets_and_group_tags():
    mesh = grid()
    facets = {t: (conn, tags) for t, conn, tags in mesh.facets}
    conn, tags = facets["line2"]
    assert conn.shape == (28, 2) and tags.shape == (28,)
    tag_of = {name: tag for name, (dim, tag) in mesh.group_tags.items()}
    assert all(dim == 1 for dim, _ in mesh.group_tags.values())
    bottom = conn[tags == tag_of["bottom"]]
    assert sorted(set(bottom.ravel())) == list(mesh.groups["bottom"])


def test_a_group_of_several_facet_types_keeps_one_name():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]], dtype=float)
    tets = np.array([[0, 1, 2, 3], [1, 4, 2, 3]])
    mesh = mm.from_arrays(points, {"tet4": tets}, {"base": [("tri3", np.array([[0, 2, 1], [1, 2, 4]]))]})
    assert list(mesh.groups) == ["base"] and list(mesh.groups["base"]) == [0, 1, 2, 4]


@pytest.mark.parametrize("extension", [".msh", ".su2", ".vtu"])
def test_every_format_writes(extension):
    mesh = annulus()
    file = scratch("python_annulus" + extension)
    mm.write_mesh(file, mesh)
    assert file.stat().st_size > 0
    if extension != ".vtu":  # .vtu is written for viewing, not read back
        back = mm.read_mesh(file)
        np.testing.assert_allclose(back.points, mesh.points, rtol=1e-15)
        assert sorted(back.groups) == sorted(mesh.groups)


def test_meshio_round_trip():
    meshio = pytest.importorskip("meshio", reason="python3-meshio is not installed")
    mesh = annulus()
    curved, _ = mm.curve_mesh(mesh, geometry={"wall": "circle:0,0,0.5"})
    for m in (mesh, curved):
        io = mm.to_meshio(m)
        assert isinstance(io, meshio.Mesh) and set(io.cell_sets) == {"wall", "farfield"}
        back = mm.from_meshio(io)
        np.testing.assert_array_equal(back.points, m.points)
        for (t1, c1), (t2, c2) in zip(back.cells, m.cells):
            assert t1 == t2
            np.testing.assert_array_equal(c1, c2)
        for g in m.groups:
            np.testing.assert_array_equal(back.groups[g], m.groups[g])
    # Through a file meshio writes in VTK's order: the quad9's certified quality survives.
    file = scratch("python_meshio.vtu")
    mm.to_meshio(curved).write(file)
    again = mm.from_meshio(meshio.read(file))
    assert mm.quality_report(again)["min"] == pytest.approx(mm.quality_report(curved)["min"], rel=1e-12)
    with pytest.raises(ValueError, match="z = 0"):
        mm.from_meshio(meshio.Mesh(np.array([[0, 0, 1.0], [1, 0, 0], [0, 1, 0]]), [("triangle", np.array([[0, 1, 2]]))]))
    with pytest.raises(ValueError, match="not supported"):
        mm.from_meshio(meshio.Mesh(np.zeros((3, 3)), [("polygon", np.array([[0, 1, 2]]))]))


def test_curve_mesh_keywords_and_report_come_from_one_description():
    # Every keyword curve_options() lists is taken with its default, and the report holds
    # exactly the fields of its description (with the mover's stats per step).
    options = mm.curve_options("rbf")
    keys = [o["key"] for o in options]
    assert len(keys) == len(set(keys)) and {"order", "raise_rounds", "kernel", "sliding"} <= set(keys)
    for o in options:
        assert set(o) == {"key", "type", "default", "doc", "details"} and o["doc"]
    # The one description of an option holds its whole doc: a line, then the details.
    radius = next(o for o in options if o["key"] == "support_radii")
    assert "nonsymmetric" in radius["details"] and "nonsymmetric" not in radius["doc"]
    assert "blending_factor" in [o["key"] for o in mm.curve_options()]
    circle = {"wall": "circle:0,0,0.5"}
    _, report = mm.curve_mesh(annulus(), geometry=circle, method="rbf", raise_rounds=1, midpoint="parameter",
                              sliding=[], support_radius_factor=3.5)
    assert list(report) == mm.report_fields("curve")
    assert list(report["quality"]) == mm.report_fields("quality")
    assert list(report["untangle"]) == mm.report_fields("untangle")
    assert all(list(s) == mm.report_fields("mover_stats") for s in report["mover_steps"])
    assert report["support_radius_limited"] is False and "wall" in report["curved_groups"]
    assert report["layers"] and set(report["layers"][0]) >= {"group", "thickness"}
    with pytest.raises(ValueError, match="unknown report"):
        mm.report_fields("nothing")


def test_two_level_rbf_from_python_interpolates_with_exact_gradients():
    # levels="two": a coarse subset of the boundary carries the radius, every boundary node
    # what it leaves (docs/interpolation.md); the default for a boundary of more than
    # two_level_centres nodes.
    mesh = grid(40, 30)
    w = mm.Warp(mesh, design=["bottom"], fixed=["top"], levels="two")
    assert w.verify_derivative(verbose=False) < 1e-6
    assert 0 < w._mover.stats["coarse_centres"] < 82 / 2  # of the bottom's and the top's 82 nodes
    automatic = mm.Warp(mesh, design=["bottom"], fixed=["top"], two_level_centres=50)
    assert automatic.verify_derivative(verbose=False) < 1e-6
    assert automatic._mover.stats["coarse_centres"] == w._mover.stats["coarse_centres"]
    with pytest.raises(mm.InputError, match="levels=two.*polynomial"):
        mm.Warp(mesh, design=["bottom"], fixed=["top"], levels="two", polynomial=True)
