"""IDWarp's USMesh on meshmotion's Warp: a MACH-Aero, MPhys or DAFoam script switches by one import.

    from meshmotion.idwarp import USMesh        # instead of: from idwarp import USMesh
    mesh = USMesh(options={"gridFile": "wing.cgns", "fileType": "CGNS",
                           "symmetrySurfaces": ["sym"]}, comm=MPI.COMM_WORLD)

The calls keep IDWarp's names, shapes and orderings: surface arrays are (N, 3), volume grids
flat (3 N) as IDWarp returns them. Each rank holds a part of the mesh (Warp(comm=...)); the
surface is the solver's (setSurfaceDefinition: points on any rank, repeated where the solver
repeats them) or, by default, every node of the specified surfaces on rank 0. A decomposed
OpenFOAM case is read as DAFoam runs it: each rank its own processor folder, none the whole
mesh, the solver's nodes that folder's points. A surface node
given several times takes the mean of its copies, so each copy's row of getdXs() is the
gradient divided by the number of copies: the directional derivative along any change of the
points is the sum of the rows' products, as finite differences give it.

Options: IDWarp's names. gridFile and fileType (CGNS, OpenFOAM, SU2; PLOT3D is refused);
specifiedSurfaces (the design groups; default every group not a symmetry surface and not named
like a far field, inlet or outlet); symmetrySurfaces (groups sliding in their plane);
symmetryPlanes ([[point, normal], ...]: every group lying in one of them slides); restartFile is
refused (a setup takes seconds); the inverse-distance options (aExp, bExp, LdefFact, alpha,
errTol, evalMode, symmTol, useRotations, zeroCornerRotations, cornerAngle, bucketSize) are
accepted with a warning: RBF or elasticity replaces the method they tune. meshmotion's own
choices go in options["meshmotion"], a dict of Warp keywords (method, support_radius, ...).
"""

import os
import warnings

import numpy as _np

from . import _core
from ._arrays import index_array, real_array
from .warp import Warp, _raise_any, _raise_everywhere, same_file

_FILE_TYPES = ("CGNS", "OpenFOAM", "SU2")
_INVERSE_DISTANCE_OPTIONS = ("aExp", "bExp", "LdefFact", "alpha", "errTol", "evalMode", "symmTol", "useRotations",
                             "zeroCornerRotations", "cornerAngle", "bucketSize")
_KNOWN = ("gridFile", "fileType", "specifiedSurfaces", "symmetrySurfaces", "symmetryPlanes", "restartFile",
          "meshmotion") + _INVERSE_DISTANCE_OPTIONS
_NOT_WALLS = ("far", "inlet", "outlet", "inflow", "outflow", "freestream")
# OpenFOAM patch types that are no surface of the mesh: interfaces between processors or periodic
# halves, and the planes of a 2D case.
_NOT_SURFACES = ("processor", "processorCyclic", "cyclic", "cyclicAMI", "empty", "wedge")


def _to_directory(comm, ids, num_global):
    """Sends each of `ids` (global ids 0..num_global-1) to the rank keeping its range of a
    directory spread over the ranks by id range (collective). Returns each id's directory rank
    and, per rank, the ids it sent here."""
    p = comm.size
    where = _np.minimum(ids * p // max(num_global, 1), p - 1)
    return where, comm.alltoall([ids[where == r] for r in range(p)])


class _Route:
    """Rows of node fields between the ranks that ask for global nodes (`wanted`, any order,
    repeats allowed) and the ranks that own them (`owned`, sorted global ids of this rank).
    The owner of an id is found through a directory spread over the ranks by id range."""

    def __init__(self, comm, wanted, owned, num_global, what):
        p = comm.size
        wanted = _np.asarray(wanted, dtype=_np.int64)
        owned = _np.asarray(owned, dtype=_np.int64)
        bad = wanted[(wanted < 0) | (wanted >= num_global)]
        if len(bad):
            raise _core.InputError(f"{what}: node index {int(bad[0])} on rank {comm.rank} is outside 0..{num_global - 1}")

        _, registered = _to_directory(comm, owned, num_global)
        ids = _np.concatenate(registered)
        ranks = _np.concatenate([_np.full(len(a), r, dtype=_np.int64) for r, a in enumerate(registered)])
        order = _np.argsort(ids)
        ids, ranks = ids[order], ranks[order]
        asked, queries = _to_directory(comm, wanted, num_global)
        answers = []
        for q in queries:
            at = _np.minimum(_np.searchsorted(ids, q), max(len(ids) - 1, 0))
            known = (ids[at] == q) if len(ids) else _np.zeros(len(q), dtype=bool)
            answers.append(_np.where(known, ranks[at] if len(ids) else 0, -1))
        replies = comm.alltoall(answers)
        owner = _np.empty(len(wanted), dtype=_np.int64)
        for r in range(p):
            owner[asked == r] = replies[r]
        if (owner < 0).any():
            raise _core.InputError(f"{what}: node {int(wanted[owner < 0][0])} on rank {comm.rank} is not one of the "
                                   "nodes it may refer to")
        self._positions = [_np.flatnonzero(owner == r) for r in range(p)]
        requests = comm.alltoall([wanted[pos] for pos in self._positions])
        self._rows = [_np.searchsorted(owned, q) for q in requests]  # owned rows each rank asks for
        self._comm = comm
        self._size = len(wanted)

    def fetch(self, values):
        """Rows of the wanted nodes from their owners' `values` (n_owned, k)."""
        parts = self._comm.alltoall([values[rows] for rows in self._rows])
        out = _np.empty((self._size,) + values.shape[1:])
        for pos, part in zip(self._positions, parts):
            out[pos] = part
        return out

    def add_to_owners(self, values, owned_count):
        """Σ of the rows given for each owned node (values: one row per wanted node)."""
        parts = self._comm.alltoall([values[pos] for pos in self._positions])
        out = _np.zeros((owned_count,) + values.shape[1:])
        for rows, part in zip(self._rows, parts):
            _np.add.at(out, rows, part)
        return out


class USMesh:
    def __init__(self, options=None, comm=None, debug=False):
        if options is None:
            raise _core.InputError("USMesh: options is not optional (give at least gridFile)")
        if not getattr(_core, "have_mpi", False):
            raise _core.InputError("USMesh needs MPI: " + _core.mpi_missing)
        from mpi4py import MPI
        self.comm = comm if comm is not None else MPI.COMM_WORLD
        unknown = sorted(set(options) - set(_KNOWN))
        if unknown:
            raise _core.InputError(f"USMesh: unknown option '{unknown[0]}' (expected one of {', '.join(_KNOWN)})")
        ignored = [key for key in _INVERSE_DISTANCE_OPTIONS if key in options]
        if ignored and self.comm.rank == 0:
            warnings.warn(f"USMesh: {', '.join(ignored)} tune IDWarp's inverse-distance method and are ignored: "
                          "meshmotion warps by RBF or elasticity (options['meshmotion'])", stacklevel=2)
        if options.get("restartFile") is not None:
            raise _core.InputError("USMesh: restartFile is not supported (meshmotion's setup is computed, not restarted)")
        self.fileType = options.get("fileType", "CGNS")
        if self.fileType not in _FILE_TYPES:
            raise _core.InputError(f"USMesh: fileType '{self.fileType}' is not supported (expected one of "
                                   f"{', '.join(_FILE_TYPES)})")
        self.gridFile = options.get("gridFile")
        if not self.gridFile:
            raise _core.InputError("USMesh: the option gridFile is required")
        self._options = dict(options)
        self._solver = None
        self._dXs = None
        grid = str(self.gridFile)
        self._decomposed = self.fileType == "OpenFOAM" and self.comm.size > 1 and os.path.isdir(os.path.join(grid, "processor0"))
        if self._decomposed:
            surface = self._read_processors(options)
        else:
            surface = self._read_on_rank_0(options)
        if self._warp.dim != 3:
            raise _core.InputError("USMesh: the mesh is 2D (IDWarp's arrays are 3D; use meshmotion.Warp)")
        owned = _np.flatnonzero(self._warp.owned)
        ids = self._warp.node_ids
        self._owned_rows = owned[_np.argsort(ids[owned], kind="stable")]  # owned rows by ascending global id
        self._owned = ids[self._owned_rows]
        self._design = self._warp.design_nodes  # this rank's owned design nodes, ascending
        self._reference = self._warp.surface_coordinates()
        self._surface = None  # global id of each surface point of this rank
        self._define(*surface())
        if self._decomposed:  # the solver's nodes are this rank's processor points, in their order
            self.setExternalMeshIndices(ids)

    def _read_on_rank_0(self, options):
        """Rank 0 reads the grid; the Warp partitions it. Returns the internal surface's maker:
        every design node on rank 0, with the design facets."""
        whole, groups = None, None
        failure = None
        if self.comm.rank == 0:
            try:
                whole = _core.read_mesh(str(self.gridFile), "fix_reversed")
                groups = _surfaces([g for g, (dim, _) in whole.group_tags.items() if dim == whole.dim - 1], options,
                                   _lies_in_mesh(whole))
            except Exception as error:  # every rank raises what rank 0 found
                failure = (type(error).__name__, str(error))
        _raise_everywhere(self.comm, failure)
        design, symmetry = self.comm.bcast(groups, root=0)
        self._warp = Warp(whole, design=design, symmetry=symmetry, comm=self.comm, **dict(options.get("meshmotion", {})))

        def surface():
            everyone = self.comm.gather(self._design, root=0)
            if self.comm.rank == 0:
                ids = _np.sort(_np.concatenate(everyone))
                return (ids,) + _facets_of(whole, design, ids)
            return _np.zeros(0, dtype=_np.int64), _np.zeros(0, dtype=_np.intc), _np.zeros(0, dtype=_np.intc)
        return surface

    def _read_processors(self, options):
        """A decomposed OpenFOAM case, as IDWarp and DAFoam read it: each rank its own processor
        folder (points in OpenFOAM's order, global ids from pointProcAddressing); no rank holds
        the whole mesh. Returns the internal surface's maker: each rank's faces of the design
        patches."""
        comm, grid = self.comm, str(self.gridFile)
        local, failure = None, None
        try:
            count = sum(1 for d in os.listdir(grid) if d.startswith("processor") and d[9:].isdigit())
            if count != comm.size:
                raise _core.InputError(f"USMesh: {grid} is decomposed into {count} processor folders for {comm.size} ranks "
                                       "(run as many ranks as folders)")
            local = _core.read_foam_processor(os.path.join(grid, f"processor{comm.rank}"))
        except Exception as error:
            failure = (type(error).__name__, str(error))
        _raise_any(comm, failure)
        points, ids = local["points"], local["global_ids"]
        patches = [p for p in local["patches"] if p["type"] not in _NOT_SURFACES]
        groups = {p["name"]: _np.unique(p["conn"]) for p in patches}
        names = list(dict.fromkeys(name for names in comm.allgather([p["name"] for p in patches]) for name in names))
        design, symmetry = _surfaces(names, options, _lies_in_partition(comm, points, groups))
        self._warp = Warp.from_partition(comm, points, ids, _lowest_holders(comm, ids), groups, design=design,
                                         symmetry=symmetry, **dict(options.get("meshmotion", {})))

        def surface():
            chosen = [p for p in patches if p["name"] in design]
            conn = _np.concatenate([p["conn"] for p in chosen]) if chosen else _np.zeros(0, dtype=_np.int64)
            sizes = _np.concatenate([p["sizes"] for p in chosen]) if chosen else _np.zeros(0, dtype=_np.int64)
            surface_ids = _np.unique(ids[conn])
            return surface_ids, _np.searchsorted(surface_ids, ids[conn]).astype(_np.intc), sizes.astype(_np.intc)
        return surface

    # The surface -----------------------------------------------------------------------------
    def _define(self, ids, conn, sizes):
        self._surface = ids
        self._conn, self._faceSizes = conn, sizes
        self._route = _Route(self.comm, ids, self._design, self._num_global(), "USMesh surface")
        self._copies = self._route.add_to_owners(_np.ones((len(ids), 1)), len(self._design))
        self._points = self._route.fetch(self._reference)

    def _num_global(self):
        return self.comm.allreduce(int(self._warp.num_owned))

    def setSurfaceDefinition(self, pts, conn, faceSizes, cgnsBlockID=None):
        """The solver's surface: this rank's points (M, 3), each on a design node of the mesh
        (repeats allowed, on any rank), and its faces (conn flat, faceSizes) for
        getSurfaceConnectivity."""
        pts = real_array(pts, "setSurfaceDefinition: pts").reshape(-1, 3)
        all_ids = _np.concatenate(self.comm.allgather(self._design))
        all_points = _np.concatenate(self.comm.allgather(self._reference)).reshape(-1, 3)
        ids = _match(pts, all_ids, all_points, self.comm.rank)
        self._define(ids, _np.asarray(conn, dtype=_np.intc).ravel(), _np.asarray(faceSizes, dtype=_np.intc).ravel())

    def getSurfaceConnectivity(self):
        """(conn, faceSizes) of this rank's surface points: conn flat, indices into them."""
        return self._conn.copy(), self._faceSizes.copy()

    def getSurfaceCoordinates(self):
        """This rank's surface points, (N, 3) (N may be 0)."""
        return self._points.copy()

    def setSurfaceCoordinates(self, coordinates):
        """New positions of this rank's surface points, (N, 3) as getSurfaceCoordinates()."""
        x = real_array(coordinates, "setSurfaceCoordinates")
        if x.shape != self._points.shape:
            raise _core.InputError(f"setSurfaceCoordinates: expected shape {self._points.shape} on rank {self.comm.rank} "
                                   f"(got {x.shape})")
        if not _np.all(_np.isfinite(x)):
            raise _core.InputError(f"setSurfaceCoordinates: a coordinate on rank {self.comm.rank} is not finite")
        self._points = x.copy()
        total = self._route.add_to_owners(x, len(self._design))
        given = self._copies[:, 0] > 0
        surface = self._reference.copy()
        surface[given] = total[given] / self._copies[given]
        self._warp.set_surface_coordinates(surface)

    # The volume ------------------------------------------------------------------------------
    def setExternalMeshIndices(self, ind):
        """The solver's nodes on this rank, as 0-based indices of the grid file's nodes."""
        ind = index_array(ind, "setExternalMeshIndices").ravel()
        self._solver = _Route(self.comm, ind, self._owned, self._num_global(), "setExternalMeshIndices")

    def warpMesh(self):
        """Warps the volume to the surface set (collective)."""
        self._warp.warp()

    def getWarpGrid(self):
        """This rank's nodes of the warp's own partition, flat (3 n)."""
        return self._warp.volume_coordinates().ravel()

    def getSolverGrid(self):
        """The solver's nodes (setExternalMeshIndices), flat (3 n), after the last warpMesh."""
        owned = self._warp.volume_coordinates()[self._owned_rows]
        return self._solver_route("getSolverGrid").fetch(owned).ravel()

    def getCommonGrid(self):
        """The whole grid in the file's order on rank 0 (None elsewhere), flat (3 n)."""
        whole = self._warp.gather_volume_coordinates()
        return None if whole is None else whole.ravel()

    def writeGrid(self, fileName=None):
        """Writes the warped grid (collective). A .cgns grid file is written again with the new
        coordinates (structured blocks, BCs and solutions kept); other names by extension. The
        grid file itself is not overwritten."""
        if fileName is None:
            raise _core.InputError("writeGrid: give a file name (the grid file itself is not overwritten)")
        if self._decomposed:
            raise _core.InputError("writeGrid: a decomposed OpenFOAM case is written by its solver (getSolverGrid gives "
                                   "this rank's points in its processor folder's order)")
        if same_file(fileName, self.gridFile):
            raise _core.InputError(f"writeGrid: {fileName} is the grid file (write the warped grid elsewhere)")
        same_format = str(self.gridFile).endswith(".cgns") and str(fileName).endswith(".cgns")
        self._warp.write_mesh(fileName, like=self.gridFile if same_format else None)

    # Derivatives -----------------------------------------------------------------------------
    def warpDeriv(self, dXv, solverVec=True):
        """dI/dXs for dI/dXv (the solver's nodes when solverVec, else the warp grid's), kept for
        getdXs(). Collective."""
        seed = real_array(dXv, "warpDeriv").reshape(-1, 3)
        local = _np.zeros((len(self._warp.node_ids), 3))
        if solverVec:
            local[self._owned_rows] = self._solver_route("warpDeriv").add_to_owners(seed, len(self._owned_rows))
        else:
            if seed.shape != local.shape:
                raise _core.InputError(f"warpDeriv: expected {local.size} values on rank {self.comm.rank} (got {seed.size})")
            local[:] = seed
        g = self._warp.warp_derivative(local)
        share = _np.divide(g, self._copies, out=_np.zeros_like(g), where=self._copies > 0)
        self._dXs = self._route.fetch(share)

    def getdXs(self):
        """The last warpDeriv's result, (N, 3) as getSurfaceCoordinates()."""
        if self._dXs is None:
            raise _core.InputError("getdXs: call warpDeriv first")
        return self._dXs.copy()

    def warpDerivFwd(self, dXs, solverVec=True):
        """J dXs for a change of this rank's surface points (N, 3): the volume's change, flat,
        on the solver's nodes when solverVec, else on the warp grid's. Collective."""
        w = real_array(dXs, "warpDerivFwd").reshape(-1, 3)
        if w.shape != self._points.shape:
            raise _core.InputError(f"warpDerivFwd: expected shape {self._points.shape} on rank {self.comm.rank} (got {w.shape})")
        total = self._route.add_to_owners(w, len(self._design))
        mean = _np.divide(total, self._copies, out=_np.zeros_like(total), where=self._copies > 0)
        dXv = self._warp.warp_derivative_forward(mean)
        if solverVec:
            return self._solver_route("warpDerivFwd").fetch(dXv[self._owned_rows]).ravel()
        return dXv.ravel()

    def verifyWarpDeriv(self, dXv=None, solverVec=True, dofStart=0, dofEnd=10, h=1e-6, randomSeed=314):
        """Compares warpDeriv with central differences of <dXv, Xv> along a random change of the
        surface; prints (rank 0) and returns the relative error. Collective."""
        rng = _np.random.default_rng(randomSeed + self.comm.rank)
        solver = solverVec and self._solver is not None
        grid = self.getSolverGrid if solver else self.getWarpGrid
        if dXv is None:
            dXv = rng.standard_normal(grid().shape)
        dXv = real_array(dXv, "verifyWarpDeriv").ravel()
        if not solver:
            dXv = dXv.reshape(-1, 3).copy()
            dXv[~self._warp.owned] = 0.0  # a ghost's row belongs to its owner
            dXv = dXv.ravel()
        direction = rng.standard_normal(self._points.shape)
        base = self._points.copy()
        values = []
        for step in (h, -h):
            self.setSurfaceCoordinates(base + step * direction)
            self.warpMesh()
            values.append(self.comm.allreduce(float(dXv @ grid())))
        self.setSurfaceCoordinates(base)
        self.warpMesh()
        finite_difference = (values[0] - values[1]) / (2 * h)
        self.warpDeriv(dXv, solverVec=solver)
        adjoint = self.comm.allreduce(float(_np.sum(self.getdXs() * direction)))
        error = abs(adjoint - finite_difference) / max(abs(finite_difference), 1e-300)
        if self.comm.rank == 0:
            print(f"verifyWarpDeriv: adjoint {adjoint:.12e}, finite difference {finite_difference:.12e}, "
                  f"relative error {error:.3e}")
        return error

    def getOption(self, name):
        return self._options.get(name)

    def _solver_route(self, where):
        if self._solver is None:
            raise _core.InputError(f"{where}: call setExternalMeshIndices first (the solver's node indices)")
        return self._solver


def _surfaces(groups, options, lies_in):
    """(design groups, sliding groups) among the surface groups `groups` for IDWarp's options;
    lies_in(group, point, unit normal) says whether a group lies in a plane (collective where
    the mesh is)."""
    symmetry = list(options.get("symmetrySurfaces") or [])
    for point, normal in options.get("symmetryPlanes") or []:
        point, normal = _np.asarray(point, dtype=float), _np.asarray(normal, dtype=float)
        normal = normal / _np.linalg.norm(normal)
        lying = [g for g in groups if g not in symmetry and lies_in(g, point, normal)]
        if not lying:
            raise _core.InputError(f"USMesh: no group lies in the symmetry plane through {point.tolist()} with normal "
                                   f"{normal.tolist()} (groups: {', '.join(groups)})")
        symmetry += lying
    for g in symmetry:
        if g not in groups:
            raise _core.InputError(f"USMesh: symmetry surface '{g}' is not a group of the mesh ({', '.join(groups)})")
    design = options.get("specifiedSurfaces")
    if design is None:
        design = [g for g in groups if g not in symmetry and not any(word in g.lower() for word in _NOT_WALLS)]
    return list(design), symmetry


def _lies_in_mesh(mesh):
    """_surfaces' plane test on a whole mesh: every node of the group within 1e-6 of its size."""
    size = float(_np.ptp(mesh.points, axis=0).max())

    def lies_in(group, point, normal):
        nodes = mesh.groups[group]
        return bool(len(nodes)) and _np.abs((mesh.points[nodes] - point) @ normal).max() <= 1e-6 * size
    return lies_in


def _lies_in_partition(comm, points, groups):
    """_surfaces' plane test on each rank's nodes of a group (collective), as _lies_in_mesh."""
    from mpi4py import MPI
    corners = _np.array(comm.allgather(_np.vstack([points.min(axis=0), points.max(axis=0)]) if len(points)
                                       else _np.full((2, 3), _np.nan)))
    size = float((_np.nanmax(corners[:, 1], axis=0) - _np.nanmin(corners[:, 0], axis=0)).max())

    def lies_in(group, point, normal):
        nodes = groups.get(group, ())
        off = float(_np.abs((points[nodes] - point) @ normal).max()) if len(nodes) else 0.0
        return comm.allreduce(len(nodes)) > 0 and comm.allreduce(off, op=MPI.MAX) <= 1e-6 * size
    return lies_in


def _lowest_holders(comm, ids):
    """The owner of each of this rank's global `ids`: the lowest rank holding it, found through a
    directory spread over the ranks by id range (collective)."""
    from mpi4py import MPI
    num_global = comm.allreduce(int(ids.max()) + 1 if len(ids) else 0, op=MPI.MAX)
    directory, sent = _to_directory(comm, ids, num_global)
    every = _np.concatenate(sent)
    senders = _np.concatenate([_np.full(len(a), r, dtype=_np.int32) for r, a in enumerate(sent)])
    order = _np.lexsort((senders, every))
    known, first = _np.unique(every[order], return_index=True)
    lowest = senders[order][first]
    replies = comm.alltoall([lowest[_np.searchsorted(known, a)] for a in sent])
    owner = _np.empty(len(ids), dtype=_np.int32)
    for r in range(comm.size):
        owner[directory == r] = replies[r]
    return owner


def _facets_of(mesh, design, ids):
    """The design groups' facets as (conn flat, faceSizes), indices into `ids` (sorted)."""
    tags = {mesh.group_tags[g][1] for g in design}
    conn, sizes = [], []
    for _, facets, facet_tags in mesh.facets:
        chosen = _np.asarray(facets)[_np.isin(facet_tags, list(tags))]
        conn.append(_np.searchsorted(ids, chosen).ravel())
        sizes.append(_np.full(len(chosen), chosen.shape[1]))
    return (_np.concatenate(conn).astype(_np.intc) if conn else _np.zeros(0, dtype=_np.intc),
            _np.concatenate(sizes).astype(_np.intc) if sizes else _np.zeros(0, dtype=_np.intc))


def _match(pts, ids, points, rank):
    """The design node (global id) at each of `pts`, within 1e-9 of the surface's size."""
    if len(pts) == 0:
        return _np.zeros(0, dtype=_np.int64)
    from scipy.spatial import cKDTree
    distance, at = cKDTree(points).query(pts)
    tolerance = 1e-9 * max(float(_np.ptp(points, axis=0).max()), 1e-300)
    far = _np.flatnonzero(distance > tolerance)
    if len(far):
        raise _core.InputError(f"setSurfaceDefinition: point {int(far[0])} on rank {rank} ({pts[far[0]].tolist()}) is "
                               f"{distance[far[0]]:.3g} from the nearest node of the specified surfaces")
    return ids[at]
