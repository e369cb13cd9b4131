"""The meshes and fields the MPI tests share: each a function of position or global id only, so
that every rank computes its own part as the serial run computes the whole."""

import numpy as np

import meshmotion as mm


def box(nx=7, ny=5, nz=4):
    """Tetrahedra filling [0, 1.4] x [0, 1] x [0, 0.8], six per hexahedron; groups wall (z = 0,
    the design surface), symmetry (y = 0), farfield (the other four sides)."""
    xs, ys, zs = np.linspace(0, 1.4, nx + 1), np.linspace(0, 1.0, ny + 1), np.linspace(0, 0.8, nz + 1)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    points = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    node = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k  # noqa: E731
    tets = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                c = [node(i + a, j + b, k + d) for d in (0, 1) for b in (0, 1) for a in (0, 1)]
                # The Kuhn split of the cube along its 0-7 diagonal: six positive tetrahedra.
                for p, q in ((1, 3), (3, 2), (2, 6), (6, 4), (4, 5), (5, 1)):
                    tets.append([c[0], c[p], c[q], c[7]])
    tets = np.array(tets)
    # Orient each tetrahedron positively.
    e = points[tets[:, 1:]] - points[tets[:, :1]]
    negative = np.einsum("ij,ij->i", np.cross(e[:, 0], e[:, 1]), e[:, 2]) < 0
    tets[negative, 1], tets[negative, 2] = tets[negative, 2].copy(), tets[negative, 1].copy()
    faces = np.sort(np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]], tets[:, [1, 2, 3]]]), axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    outer = unique[counts == 1]
    centre = points[outer].mean(axis=1)
    groups = {
        "wall": ("tri3", outer[np.isclose(centre[:, 2], 0.0)]),
        "symmetry": ("tri3", outer[np.isclose(centre[:, 1], 0.0)]),
        "farfield": ("tri3", outer[~np.isclose(centre[:, 2], 0.0) & ~np.isclose(centre[:, 1], 0.0)]),
    }
    return mm.from_arrays(points, {"tet4": tets}, groups)


def bump(xs):
    """The design surface's new position: a bump on the wall, a function of position only, so
    that every rank moves its own nodes as the serial Warp moves all of them."""
    out = xs.copy()
    out[:, 2] += 0.05 * np.sin(np.pi * xs[:, 0] / 1.4) * np.sin(np.pi * xs[:, 1])
    out[:, 0] += 0.02 * xs[:, 1]
    return out


def seed(ids):
    """dI/dXv as a function of the global node id, the same on every rank."""
    return np.column_stack([np.sin(ids), np.cos(0.7 * ids), np.sin(1.3 * ids + 0.2)])


def structured_cgns(path):
    """Writes the box of box() as two structured CGNS blocks meeting at x = 0.7 (4 x 6 x 5
    vertices each), with vertex-range BCs wall (k = 1) and symmetry (j = 1) on both, through
    the CGNS library itself (ctypes), as a multiblock grid generator would. Returns False when
    the library cannot be loaded."""
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("cgns")
    if name is None:
        return False
    try:
        cg = ctypes.CDLL(name)
    except OSError:
        return False
    size_t = ctypes.c_int  # cgsize_t: Debian builds CGNS without 64-bit sizes (cgnstypes.h)
    mode_write, structured, real_double, bc_wall, bc_symmetry, point_range = 1, 2, 4, 20, 16, 4
    fn, base = ctypes.c_int(), ctypes.c_int()

    def ok(code, what):
        if code != 0:
            raise RuntimeError(f"CGNS {what} failed ({code})")

    ok(cg.cg_open(str(path).encode(), mode_write, ctypes.byref(fn)), "cg_open")
    ok(cg.cg_base_write(fn, b"Base", 3, 3, ctypes.byref(base)), "cg_base_write")
    n = (4, 6, 5)
    for block, x0 in ((b"upstream", 0.0), (b"downstream", 0.7)):
        size = (size_t * 9)(*n, *(v - 1 for v in n), 0, 0, 0)
        zone = ctypes.c_int()
        ok(cg.cg_zone_write(fn, base, block, size, structured, ctypes.byref(zone)), "cg_zone_write")
        k, j, i = np.meshgrid(np.linspace(0, 0.8, n[2]), np.linspace(0, 1.0, n[1]), np.linspace(x0, x0 + 0.7, n[0]),
                              indexing="ij")
        for coordinate, values in ((b"CoordinateX", i), (b"CoordinateY", j), (b"CoordinateZ", k)):
            data = np.ascontiguousarray(values.ravel(), dtype=np.float64)  # i fastest
            index = ctypes.c_int()
            ok(cg.cg_coord_write(fn, base, zone, real_double, coordinate, data.ctypes.data_as(ctypes.c_void_p),
                                 ctypes.byref(index)), "cg_coord_write")
        for bc, kind, corners in ((b"wall", bc_wall, (1, 1, 1, n[0], n[1], 1)),
                                  (b"symmetry", bc_symmetry, (1, 1, 1, n[0], 1, n[2]))):
            points = (size_t * 6)(*corners)
            index = ctypes.c_int()
            ok(cg.cg_boco_write(fn, base, zone, bc, kind, point_range, 2, points, ctypes.byref(index)), "cg_boco_write")
    ok(cg.cg_close(fn), "cg_close")
    return True


def cgns_zone_types(path):
    """The type of each zone of a CGNS file ("Structured", "Unstructured"), read through the CGNS
    library (ctypes)."""
    import ctypes
    import ctypes.util

    cg = ctypes.CDLL(ctypes.util.find_library("cgns"))
    fn, count = ctypes.c_int(), ctypes.c_int()
    if cg.cg_open(str(path).encode(), 0, ctypes.byref(fn)) != 0:
        raise RuntimeError(f"cg_open {path} failed")
    cg.cg_nzones(fn, 1, ctypes.byref(count))
    types = []
    for zone in range(1, count.value + 1):
        kind = ctypes.c_int()
        cg.cg_zone_type(fn, 1, zone, ctypes.byref(kind))
        types.append({2: "Structured", 3: "Unstructured"}.get(kind.value, str(kind.value)))
    cg.cg_close(fn)
    return types
