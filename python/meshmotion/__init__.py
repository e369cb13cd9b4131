"""meshmotion: mesh motion and curved-mesh generation for CFD, from Python.

Meshes hold their points as an (n, dim) float64 numpy view (no copy). Movers are built by
method name with typed keyword options, checked by the library's own parser. ``Warp`` is the
optimization-loop interface (design surfaces in, volume coordinates and their derivative out).
"""

from ._core import (  # noqa: F401  (re-exported)
    Error,
    InputError,
    InvalidMeshError,
    IoError,
    SolverError,
    __version__,
    element_types,
    find_extrusion,
    have_cgns,
    curve_options,
    mover_methods,
    mover_options,
    report_fields,
    num_threads,
    read_mesh,
    reference_nodes,
    set_num_threads,
    vtk_order,
)
from . import _core
from ._arrays import index_array, real_array
from .warp import Warp  # noqa: F401

import numpy as _np


def _dim_of(mesh):
    return 2 if isinstance(mesh, _core.Mesh2) else 3


def from_arrays(points, cells, groups=None):
    """A mesh from a solver's arrays.

    The arrays are copied into the mesh, converted exactly: points of any float (up to 64 bits) or
    integer dtype and any layout; cells and groups of any integer dtype (a float index is refused).

    points: (n, dim) reals; cells: {type name: (n_cells, nodes_per_cell) ints} or a list of
    (type name, array) pairs ("tri3", "quad4", "tet4", "hex8", "prism6", "pyramid5", P2 types);
    groups: {name: (facet type name, (n_facets, nodes_per_facet) ints)}, or a list of such
    pairs for a group of several facet types (a 3D wall of triangles and quadrilaterals).
    """
    points = real_array(points, "from_arrays: points")
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"from_arrays: points must have shape (n, 2) or (n, 3) (got {points.shape})")
    cell_list = [(t, index_array(a, f"from_arrays: cells {t}"))
                 for t, a in (cells.items() if isinstance(cells, dict) else cells)]
    group_list = []
    for name, value in (groups or {}).items():
        # One facet block per group, or several: [(facet type, facets), ...].
        for facet_type, facets in ([value] if isinstance(value[0], str) else value):
            group_list.append((name, facet_type, index_array(facets, f"from_arrays: group {name}")))
    build = _core._from_arrays2 if points.shape[1] == 2 else _core._from_arrays3
    return build(points, cell_list, group_list)


def write_mesh(file, mesh):
    """Writes a mesh by extension (.msh, .su2, .cgns, .vtu), through a temporary file."""
    _core.write_mesh(str(file), mesh)


def Boundary(dim):
    """Boundary conditions by group: moving(group, nodes, displacements), translating(group,
    t), prescribed(group), fixed(group), sliding(group); resolve(mesh)."""
    return _core.BoundarySpec2() if dim == 2 else _core.BoundarySpec3()


def Mover(method, dim, section=False, **options):
    """The mover `method` ("rbf", "sle", ...) in `dim` dimensions with typed keyword options.

    An unknown keyword raises InputError (a ValueError) naming the method's keys;
    mover_options(method) lists them with their defaults.

    section=True (dim 3): for a 2D case stored in 3D (one cell thick between two planes normal
    to a coordinate axis, as find_extrusion(mesh) tells), the method moves the 2D section and
    the front and the back take its displacement, with none along the axis, whatever the
    method; setup refuses another mesh, and conditions or displacements that are not
    two-dimensional.
    """
    if dim not in (2, 3):
        raise InputError(f"Mover: dim must be 2 or 3 (got {dim})")
    if section:
        if dim != 3:
            raise InputError("Mover: section=True moves a 2D case stored in 3D (give dim=3)")
        return _core._section_mover(method, **options)
    return (_core.Mover2 if dim == 2 else _core.Mover3)(method, **options)


def quality_report(mesh, metric="jacobian"):
    """The quality report of a mesh as a dict: min, max, mean, invalid, histogram, worst cells,
    and per cell (cell order) ``values`` (float64) and ``valid`` (bool) numpy arrays.

    metric: "jacobian" (certified scaled Jacobian, P1 and P2) or a Knupp metric ("shape",
    "size", "skew", "size_shape")."""
    return _core.quality_report(mesh, metric)


def curve_mesh(mesh, **options):
    """Curves a linear mesh into a certified P2 (P3, P4) mesh; returns (curved mesh, report dict).

    Keywords: geometry ({group: "spline" | "reconstruct" | "straight" | "bump" | "circle:X,Y,R" |
    "naca:XXXX[,CHORD,X0,Y0]" | "sphere:X,Y,Z,R"}, or a CAD file "MODEL.step" (.stp, .iges, .igs,
    .brep) for every group it fits, as the curve_mesh program chooses them; cad_groups=[...]
    names them, cad_tolerance sets the matching tolerance; the report then has on_model and
    cad_groups), and every key of curve_options(method):
    the pipeline's own (order, method, sliding, steps, strict, support_radius, untangle, ...)
    and the typed options of the method's mover (as in Mover()), each with its type, default
    and one line of doc. An unknown key is refused naming the known ones. strict=True raises
    InvalidMeshError when invalid cells remain; otherwise report["invalid"] counts them. The
    report's keys are report_fields("curve").
    """
    return _core.curve_mesh(mesh, **options)


from .meshio_bridge import from_meshio, to_meshio  # noqa: E402,F401  (re-exported)
