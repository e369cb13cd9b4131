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
    mover_methods,
    mover_options,
    num_threads,
    read_mesh,
    set_num_threads,
)
from . import _core
from .warp import Warp  # noqa: F401

import numpy as _np


def _dim_of(mesh):
    return 2 if isinstance(mesh, _core.Mesh2) else 3


def from_arrays(points, cells, groups=None):
    """A mesh from a solver's arrays.

    points: (n, dim) float64; cells: {type name: (n_cells, nodes_per_cell) ints} or a list of
    (type name, array) pairs ("tri3", "quad4", "tet4", "hex8", "prism6", "pyramid5", P2 types);
    groups: {name: (facet type name, (n_facets, nodes_per_facet) ints)}.
    """
    points = _np.ascontiguousarray(points, dtype=_np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"from_arrays: points must have shape (n, 2) or (n, 3) (got {points.shape})")
    cell_list = list(cells.items()) if isinstance(cells, dict) else list(cells)
    group_list = [(name, facet_type, facets) for name, (facet_type, facets) in (groups or {}).items()]
    build = _core._from_arrays2 if points.shape[1] == 2 else _core._from_arrays3
    return build(points, cell_list, group_list)


def write_mesh(file, mesh):
    """Writes a mesh by extension (.msh, .su2, .vtu), through a temporary file."""
    _core.write_mesh(str(file), mesh)


def Boundary(dim):
    """Boundary conditions by group: moving(group, nodes, displacements), translating(group,
    t), prescribed(group), fixed(group), sliding(group); resolve(mesh)."""
    return _core.BoundarySpec2() if dim == 2 else _core.BoundarySpec3()


def Mover(method, dim, **options):
    """The mover `method` ("rbf", "sle", ...) in `dim` dimensions with typed keyword options.

    An unknown keyword raises InputError (a ValueError) naming the method's keys;
    mover_options(method) lists them with their defaults.
    """
    if dim not in (2, 3):
        raise InputError(f"Mover: dim must be 2 or 3 (got {dim})")
    return (_core.Mover2 if dim == 2 else _core.Mover3)(method, **options)


def quality_report(mesh, metric="jacobian"):
    """The quality report of a mesh as a dict (min, mean, invalid, histogram, worst cells)."""
    return _core.quality_report(mesh, metric)
