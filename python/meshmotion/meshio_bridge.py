"""The bridge to meshio (Debian python3-meshio): meshes to and from meshio.Mesh, so that any
format meshio knows can be read and written. Cell blocks go in VTK's node order."""

import numpy as _np

from . import _core
from ._core import InputError


# meshio's cell type names, and ours. meshio keeps VTK's node order for quadratic cells.
_MESHIO_TYPES = {
    "line2": "line", "line3": "line3", "tri3": "triangle", "tri6": "triangle6", "quad4": "quad",
    "quad8": "quad8", "quad9": "quad9", "tet4": "tetra", "tet10": "tetra10", "hex8": "hexahedron",
    "hex20": "hexahedron20", "hex27": "hexahedron27", "prism6": "wedge", "prism15": "wedge15",
    "prism18": "wedge18", "pyramid5": "pyramid", "pyramid13": "pyramid13", "pyramid14": "pyramid14",
}
_FROM_MESHIO = {v: k for k, v in _MESHIO_TYPES.items()}
_TYPE_DIM = {"line": 1, "tri": 2, "quad": 2, "tet": 3, "hex": 3, "prism": 3, "pyramid": 3}


def _type_dim(type_name):
    return _TYPE_DIM[type_name.rstrip("0123456789")]


def _vtk_order(type_name):
    order = _core.vtk_order(type_name)
    return _np.asarray(order, dtype=_np.int64) if order else None


def to_meshio(mesh):
    """The mesh as a meshio.Mesh (Debian python3-meshio): cells then boundary facets as cell
    blocks in VTK's node order, each named group as a cell set over the facet blocks, and the
    group tags as cell data "meshmotion:tag". meshio then writes any format it knows."""
    import meshio

    cells, sets_blocks = [], []
    for type_name, conn in list(mesh.cells) + [(t, c) for t, c, _ in mesh.facets]:
        if type_name not in _MESHIO_TYPES:
            raise InputError(f"to_meshio: {type_name} elements have no meshio counterpart here (orders 1 and 2 only; "
                             "write .msh or .vtu for higher orders)")
    for type_name, conn in mesh.cells:
        order = _vtk_order(type_name)
        cells.append((_MESHIO_TYPES[type_name], conn[:, order] if order is not None else conn.copy()))
        sets_blocks.append(None)
    for type_name, conn, tags in mesh.facets:
        order = _vtk_order(type_name)
        cells.append((_MESHIO_TYPES[type_name], conn[:, order] if order is not None else conn.copy()))
        sets_blocks.append(_np.asarray(tags))
    cell_sets = {}
    for name, (dim, tag) in mesh.group_tags.items():
        cell_sets[name] = [
            _np.zeros(0, dtype=_np.int64) if tags is None else _np.flatnonzero(tags == tag) for tags in sets_blocks
        ]
    tag_data = [_np.zeros(len(c[1]), dtype=_np.int32) if t is None else t.astype(_np.int32) for c, t in zip(cells, sets_blocks)]
    return meshio.Mesh(_np.array(mesh.points), cells, cell_sets=cell_sets, cell_data={"meshmotion:tag": tag_data})


def from_meshio(m, dim=None):
    """A mesh from a meshio.Mesh: its cells of the highest dimension (or `dim`), and named
    groups from its cell sets, or from Gmsh's physical tags (cell data "gmsh:physical" with
    field_data names), over its facet blocks. Sets of cells of other dimensions are not
    groups and are left out. Points with a nonzero z in a 2D mesh are refused."""
    blocks = []
    for block in m.cells:
        if block.type not in _FROM_MESHIO:
            if block.type == "vertex":
                continue
            raise InputError(f"from_meshio: cell type '{block.type}' is not supported (expected one of {sorted(_FROM_MESHIO)})")
        blocks.append((_FROM_MESHIO[block.type], _np.asarray(block.data, dtype=_np.int64)))
    if not blocks:
        raise InputError("from_meshio: the mesh has no cells")
    if dim is None:
        dim = max(_type_dim(t) for t, _ in blocks)
    if dim not in (2, 3):
        raise InputError(f"from_meshio: expected a 2D or 3D mesh (got cells of dimension {dim})")
    points = _np.asarray(m.points, dtype=_np.float64)
    if points.shape[1] == 3 and dim == 2:
        if _np.any(points[:, 2] != 0.0):
            raise InputError("from_meshio: a 2D mesh must lie in the plane z = 0 (a point has z != 0)")
        points = points[:, :2]
    in_our_order = []
    for type_name, conn in blocks:
        order = _vtk_order(type_name)
        if order is not None:
            ours = _np.empty_like(conn)
            ours[:, order] = conn
            conn = ours
        in_our_order.append((type_name, conn))
    cells = [(t, c) for t, c in in_our_order if _type_dim(t) == dim]
    # Groups: cell sets over facet blocks, else Gmsh's physical tags.
    facet_block = [k for k, (t, _) in enumerate(in_our_order) if _type_dim(t) == dim - 1]
    selections = {}
    if m.cell_sets:
        for name, per_block in m.cell_sets.items():
            parts = [(k, _np.asarray(per_block[k], dtype=_np.int64)) for k in facet_block if len(per_block[k])]
            if parts:
                selections[name] = parts
    elif "gmsh:physical" in m.cell_data:
        tags = m.cell_data["gmsh:physical"]
        for name, (tag, tag_dim) in ((n, (int(v[0]), int(v[1]))) for n, v in m.field_data.items()):
            if tag_dim != dim - 1:
                continue
            parts = [(k, _np.flatnonzero(_np.asarray(tags[k]) == tag)) for k in facet_block]
            parts = [(k, p) for k, p in parts if len(p)]
            if parts:
                selections[name] = parts
    groups = []
    for name, parts in selections.items():
        for k, rows in parts:
            groups.append((name, in_our_order[k][0], in_our_order[k][1][rows]))
    build = _core._from_arrays2 if dim == 2 else _core._from_arrays3
    return build(_np.ascontiguousarray(points), cells, groups)
