"""Warp: mesh warping for optimization loops, in the terms of IDWarp's USMesh.

    w = Warp("wing.su2", design=["wing"], symmetry=["symmetry"], fixed=["farfield"])
    Xs = w.surface_coordinates()          # (n_design, dim), design nodes ascending
    w.set_surface_coordinates(Xs + dXs)
    w.warp()                              # always from the reference mesh; setup reused
    Xv = w.volume_coordinates()           # (n_nodes, dim)
    dI_dXs = w.warp_derivative(dI_dXv)    # (n_design, dim), sized like the design surface

The design surface is the union of the design groups' nodes, in ascending node order, or in
the solver's own order after set_surface_order(nodes). Nodes of symmetry groups slide in
their plane, nodes of fixed groups stay; neither appears in the design surface.

Over MPI (mpi4py), every rank of `comm` builds the Warp together:

    w = Warp("wing.su2", design=["wing"], symmetry=["symmetry"], comm=MPI.COMM_WORLD)

Rank 0 reads the mesh (or takes the Mesh given there; the other ranks may pass None) and
resolves the groups on the whole mesh; METIS splits the cells over the ranks, or
`cell_ranks` (one rank per cell, on rank 0) does, as a solver's own partition. Each rank
then holds its part: `node_ids` gives the global id (node index in the whole mesh) of each
row of volume_coordinates() (owned nodes first, then ghosts shared with other ranks), and
the design surface of a rank is the design nodes it owns (`design_nodes`, global ids). Every
call that moves or differentiates is collective. warp_derivative(dI_dXv) reads the rows of
owned nodes (a ghost's row belongs to its owner) and returns this rank's rows of dI/dXs: the
ranks' rows together are the serial gradient. Methods: rbf, le and sle (PETSc), each with
its reverse derivative. The result equals the serial Warp's to round-off (RBF), to the PETSc
solve's tolerance (le, sle).
"""

import os as _os
import warnings as _warnings

import numpy as _np

from . import _core
from ._arrays import index_array, real_array


def _is_path(mesh):
    return isinstance(mesh, (str, bytes)) or hasattr(mesh, "__fspath__")


def same_file(a, b):
    """Whether the paths a and b name one existing file (by any path to it: a link, another
    spelling)."""
    try:
        return _os.path.samefile(a, b)
    except OSError:
        return False


def _read(mesh, orientation):
    if _is_path(mesh):
        mesh = _core.read_mesh(mesh, orientation)
    if not isinstance(mesh, (_core.Mesh2, _core.Mesh3)):
        raise _core.InputError("Warp: mesh must be a file name or a meshmotion mesh")
    return mesh


def _boundary_spec(mesh, design, symmetry, fixed):
    spec = _core.BoundarySpec2() if isinstance(mesh, _core.Mesh2) else _core.BoundarySpec3()
    for group in design:
        spec.prescribed(group)
    for group in symmetry:
        spec.sliding(group)
    for group in fixed:
        spec.fixed(group)
    return spec


def _design_nodes(boundary):
    # The prescribed entries are the design groups' nodes (a node shared with a symmetry or
    # fixed group included: prescribed wins), however the groups were named (a patch group, a
    # pattern).
    return _np.array([v for v, kind in zip(boundary.nodes, boundary.kinds) if kind == "prescribed"], dtype=_np.int64)


class Warp:
    def __init__(self, mesh, design, symmetry=(), fixed=(), method="rbf", orientation="fix_reversed", comm=None,
                 cell_ranks=None, **options):
        self._comm = comm
        self._source = mesh if _is_path(mesh) else None  # what write_mesh() must not replace unasked
        if not design:
            raise _core.InputError("Warp: give at least one design group")
        if comm is None:
            mesh = _read(mesh, orientation)
            boundary = _boundary_spec(mesh, design, symmetry, fixed).resolve(mesh)
            self._dim = 2 if isinstance(mesh, _core.Mesh2) else 3
            self._mesh = mesh
            self._ids = _np.arange(mesh.points.shape[0], dtype=_np.int64)
            self._num_owned = len(self._ids)
            self._design = _design_nodes(boundary)
            self._mover = (_core.Mover2 if self._dim == 2 else _core.Mover3)(method, **options)
            self._mover.setup(mesh, boundary)
        else:
            boundary = self._partition(mesh, design, symmetry, fixed, orientation, cell_ranks)
            self._mover = (_core.DistributedMover2 if self._dim == 2 else _core.DistributedMover3)(method, **options)
            self._mover.setup(self._part, boundary)
        self._owned = slice(0, self._num_owned)
        self._finish(boundary, method, _np.array(self._mesh.points, copy=True))

    @classmethod
    def from_partition(cls, comm, points, global_ids, owner, groups, design, symmetry=(), fixed=(), method="rbf",
                       **options):
        """A Warp on a solver's own partition, where no rank holds the whole mesh (collective).

        Each rank gives its local nodes in its own order: points (n_local, dim), their global
        ids (n_local,), the rank owning each (n_local,; every global node owned by one rank,
        a ghost listed on other ranks with the same id), and groups, a dict from group name to
        the local indices of that group's nodes on this rank (a group may be absent or empty
        on a rank). design, symmetry and fixed name groups as in Warp(); a symmetry group's
        plane is fitted to its nodes on every rank together. Rows of warp() and of
        warp_derivative's dI_dXv are the local nodes in the order given; a rank's design
        surface is the design nodes it owns, by ascending global id. RBF only (elasticity
        needs the cells: Warp(mesh, comm=...) partitions a mesh read on rank 0)."""
        self = cls.__new__(cls)
        self._source = None
        self._comm = comm
        _check_comm(comm)
        self._part = self._whole = self._mesh = None
        failure = None
        try:
            points = real_array(points, "Warp.from_partition: points")
            if points.ndim != 2 or points.shape[1] not in (2, 3):
                raise _core.InputError(f"Warp.from_partition: points must be (n_local, 2 or 3) (got {points.shape})")
            ids = index_array(global_ids, "Warp.from_partition: global_ids").astype(_np.int64)
            owner = index_array(owner, "Warp.from_partition: owner").astype(_np.int64)
            if len(ids) != len(points) or len(owner) != len(points):
                raise _core.InputError(f"Warp.from_partition: {len(points)} local nodes but {len(ids)} global ids and "
                                       f"{len(owner)} owners (expected one each)")
            local = {}
            for name, nodes in dict(groups).items():
                nodes = index_array(nodes, f"Warp.from_partition: group '{name}'")
                if len(nodes) and (nodes.min() < 0 or nodes.max() >= len(points)):
                    bad = int(nodes[(nodes < 0) | (nodes >= len(points))][0])
                    raise _core.InputError(f"Warp.from_partition: group '{name}' refers to local node {bad} (expected "
                                           f"0 to {len(points) - 1})")
                local[str(name)] = nodes
        except Exception as error:
            failure = (type(error).__name__, str(error))
        _raise_any(comm, failure)
        self._dim = _agree(comm, points.shape[1], "the points' dimension")
        if not design:
            raise _core.InputError("Warp: give at least one design group")
        known = set().union(*comm.allgather(sorted(local)))
        for name in list(design) + list(symmetry) + list(fixed):
            if name not in known:
                raise _core.InputError(f"Warp.from_partition: no group named '{name}' on any rank (known: "
                                       f"{', '.join(sorted(known)) or 'none'})")
            local.setdefault(name, _np.zeros(0, dtype=_np.int64))
        owned = owner == comm.Get_rank()
        spec = _core.BoundarySpec2() if self._dim == 2 else _core.BoundarySpec3()
        for group in design:
            spec.prescribed(group)
        for group in symmetry:
            spec.sliding(group, normal=_core.sliding_plane_normal(comm, group, points[local[group][owned[local[group]]]]))
        for group in fixed:
            spec.fixed(group)
        failure = None
        try:
            boundary = spec.resolve_nodes(points, {k: v.tolist() for k, v in local.items()})
        except Exception as error:
            failure = (type(error).__name__, str(error))
        _raise_any(comm, failure)
        self._mover = (_core.DistributedMover2 if self._dim == 2 else _core.DistributedMover3)(method, **options)
        self._mover.setup_partition(comm, points, ids.tolist(), owner.astype(_np.int32).tolist(), boundary)
        self._ids = ids.copy()
        self._owned = owned
        self._num_owned = int(owned.sum())
        mine = _np.array([v for v in _design_nodes(boundary) if owned[v]], dtype=_np.int64)
        self._design = mine[_np.argsort(ids[mine], kind="stable")]
        self._finish(boundary, method, points.copy())
        return self

    def _finish(self, boundary, method, reference):
        comm = self._comm
        self._boundary = boundary
        self._reference = reference
        self._columns = _np.array([boundary.column(int(v)) for v in self._design], dtype=_np.int64)
        self._order = _np.arange(len(self._design))  # user position -> design position
        if not self._mover.has_derivatives:
            self._derivative_note = f"method {method} has no derivatives" + (" over MPI" if comm is not None else "")
        else:
            self._derivative_note = None
        self._surface = self._reference[self._design].copy()
        self._input = _np.zeros((boundary.size, self._dim))
        self._displacement = _np.zeros_like(self._reference)
        self._volume = self._reference.copy()
        self._volume_view = self._volume.view()
        self._volume_view.flags.writeable = False
        if self.condition > CONDITION_WARNING and (comm is None or comm.Get_rank() == 0):
            _warnings.warn(f"Warp: the RBF system's condition number is at least {self.condition:.1e}: warp_derivative "
                           f"may carry relative rounding errors up to {self.condition * 2.2e-16:.0e} (a smaller "
                           "support_radius conditions it better; condition_limit thins compact kernels' systems "
                           "without partition_of_unity)",
                           RuntimeWarning, stacklevel=3)

    def _partition(self, mesh, design, symmetry, fixed, orientation, cell_ranks):
        """Rank 0 reads and resolves; every rank gets its part, its boundary entries and its
        owned design nodes. Returns this rank's boundary."""
        comm = self._comm
        _check_comm(comm)
        root = comm.Get_rank() == 0
        whole = whole_boundary = design_ids = None
        failure = None
        if root:
            try:
                whole = _read(mesh, orientation)
                whole_boundary = _boundary_spec(whole, design, symmetry, fixed).resolve(whole)
                design_ids = _design_nodes(whole_boundary)
                if cell_ranks is not None:
                    cell_ranks = index_array(cell_ranks, "Warp: cell_ranks").astype(_np.int32).tolist()
            except Exception as error:  # every rank raises what rank 0 found
                failure = (type(error).__name__, str(error))
        _raise_everywhere(comm, failure)
        self._dim = comm.bcast(2 if isinstance(whole, _core.Mesh2) else 3, root=0)
        self._whole = whole  # rank 0 writes the moved mesh from it
        Part = _core.DistributedMesh2 if self._dim == 2 else _core.DistributedMesh3
        self._part = Part.partition(comm, whole, cell_ranks if root else None)
        self._mesh = self._part.local
        self._ids = _np.array(self._part.global_ids)
        self._num_owned = self._part.num_owned
        boundary = self._part.distribute_boundary(whole_boundary)
        design_ids = comm.bcast(design_ids, root=0)
        owned = self._ids[:self._num_owned]
        where = _np.searchsorted(owned, design_ids)
        mine = where < len(owned)
        mine[mine] = owned[where[mine]] == design_ids[mine]
        self._design = where[mine]  # owned local nodes, by ascending global id
        return boundary

    @property
    def condition(self):
        """A lower bound of the interpolation system's condition number (RBF; 0 for methods
        without one, or before the system is factorized: with the default radius and each
        move's rigid part blended, at the first warp that needs it): rounding in
        warp_derivative grows by up to this factor."""
        return float(self._mover.stats["condition"])

    @property
    def boundary_solve(self):
        """Over MPI, where the RBF boundary system is solved: "replicated" (every rank),
        "petsc" (MUMPS across the ranks) or "patches" (partition_of_unity=True: each patch on one
        rank, nothing replicated); "none" for elasticity; None without MPI."""
        return self._mover.boundary_solve if self._comm is not None else None

    @property
    def dim(self):
        return self._dim

    @property
    def comm(self):
        return self._comm

    @property
    def design_nodes(self):
        """Node indices (over MPI: global ids of this rank's owned nodes) of the design surface, in
        the order of surface_coordinates()."""
        return self._ids[self._design[self._order]]

    @property
    def node_ids(self):
        """Per row of volume_coordinates(): the node's index in the whole mesh (a copy)."""
        return self._ids.copy()

    @property
    def num_owned(self):
        """Rows 0..num_owned-1 of volume_coordinates() are nodes this rank owns, the others ghosts
        (all of them without MPI). From a solver's partition: how many rows this rank owns, in
        the order it gave them (`owned` says which)."""
        return self._num_owned

    @property
    def owned(self):
        """Per row of volume_coordinates(): whether this rank owns the node (a copy)."""
        mask = _np.zeros(len(self._ids), dtype=bool)
        mask[self._owned] = True
        return mask

    @property
    def mesh(self):
        """The mesh moved (over MPI: this rank's part), in its reference position; None for a
        solver's own partition (from_partition), which gives no cells."""
        return self._mesh

    def set_surface_order(self, nodes):
        """Use the solver's own order of the design nodes (each of design_nodes exactly once)."""
        nodes = index_array(nodes, "set_surface_order")
        position = {int(v): k for k, v in enumerate(self._ids[self._design])}
        if len(nodes) != len(self._design) or len(set(nodes.tolist())) != len(nodes):
            raise _core.InputError(
                f"set_surface_order: expected each of the {len(self._design)} design nodes once (got {len(nodes)} nodes)")
        missing = [int(v) for v in nodes if int(v) not in position]
        if missing:
            raise _core.InputError(f"set_surface_order: node {missing[0]} is not on the design surface")
        self._order = _np.array([position[int(v)] for v in nodes], dtype=_np.int64)

    def surface_coordinates(self):
        """Absolute coordinates of the design surface, (n_design, dim)."""
        return self._surface[self._order].copy()

    def set_surface_coordinates(self, X):
        """New absolute coordinates of the design surface, (n_design, dim), finite."""
        X = real_array(X, "set_surface_coordinates")
        if X.shape != (len(self._design), self._dim):
            raise _core.InputError(
                f"set_surface_coordinates: expected shape ({len(self._design)}, {self._dim}) (got {X.shape})")
        if not _np.all(_np.isfinite(X)):
            raise _core.InputError("set_surface_coordinates: a coordinate is not finite")
        self._surface[self._order] = X

    def warp(self):
        """Moves the volume from the reference mesh to the current surface (setup reused) and
        returns the coordinates (n_nodes, dim) as a read-only view of the Warp's state: the next
        warp() overwrites it (volume_coordinates() or .copy() keeps one). No array of the
        volume's size is allocated per call."""
        self._input[self._columns] = self._surface - self._reference[self._design]
        self._mover.move_into(self._input, self._displacement)
        _np.add(self._reference, self._displacement, out=self._volume)
        return self._volume_view

    def volume_coordinates(self):
        """Coordinates of every node after the last warp(), (n_nodes, dim), a copy."""
        return self._volume.copy()

    def gather_volume_coordinates(self):
        """Coordinates of the whole mesh after the last warp(), in its node order: over MPI on
        rank 0 (None on the others; collective), else a copy."""
        if self._comm is None:
            return self._volume.copy()
        if self._part is not None:
            return self._part.gather_owned(self._volume)
        return _gather_owned(self._comm, self._ids[self._owned], self._volume[self._owned])

    def write_mesh(self, file, like=None, overwrite=False):
        """Writes the mesh at the last warp() (format by extension). Over MPI, collective: rank 0
        gathers the owned nodes and writes the whole mesh in its numbering. like: the CGNS file
        the mesh was read from, written again with the new coordinates (its structured blocks,
        BCs and solutions kept). The file the Warp was read from is replaced only with
        overwrite=True; `like` never is (by any path to either)."""
        from . import write_mesh as _write_mesh

        if like is not None and same_file(file, like):
            raise _core.InputError(f"write_mesh: {file} is the file given as like= (write the warped mesh elsewhere)")
        if not overwrite and self._source is not None and same_file(file, self._source):
            raise _core.InputError(f"write_mesh: {file} is the mesh this Warp was read from (give overwrite=True to "
                                   "replace it)")

        if self._comm is not None and self._part is None:
            raise _core.InputError("write_mesh: a Warp on a solver's own partition holds no cells to write; "
                                   "gather_volume_coordinates() gives the whole mesh's coordinates on rank 0")

        def _write(target, mesh):
            if like is None:
                _write_mesh(target, mesh)
            else:
                _core.write_cgns_coordinates(str(like), str(target), mesh)

        if self._comm is None:
            mesh = self._mesh.copy()
            mesh.points[:] = self._volume
            _write(file, mesh)
            return
        whole = self.gather_volume_coordinates()
        failure = None
        if whole is not None:
            saved = _np.array(self._whole.points, copy=True)
            try:
                self._whole.points[:] = whole
                _write(file, self._whole)
            except Exception as error:
                failure = (type(error).__name__, str(error))
            finally:
                self._whole.points[:] = saved
        _raise_everywhere(self._comm, failure)

    def warp_derivative(self, dI_dXv):
        """dI/dXs for dI/dXv (n_nodes, dim): one row per design node, in surface order."""
        if self._derivative_note:
            raise _core.InputError("warp_derivative: " + self._derivative_note)
        v = real_array(dI_dXv, "warp_derivative")
        if v.shape != self._reference.shape:
            raise _core.InputError(f"warp_derivative: expected shape {self._reference.shape} (got {v.shape})")
        g = self._mover.derivative_reverse(v)
        return g[self._columns][self._order]

    def warp_derivative_forward(self, dXs):
        """dXv for a change dXs (n_design, dim, surface order) of the design surface: J dXs,
        (n_nodes, dim). Over MPI, collective."""
        return self._through_map(dXs, "warp_derivative_forward")

    def velocity(self, dXs_dt):
        """The grid velocities (n_nodes, dim) an ALE solver needs for the design surface's
        velocities dXs_dt (n_design, dim, surface order): J dXs_dt through the map of the last
        warp, the rate of change of the warped coordinates (docs/python.md). Over MPI,
        collective."""
        return self._through_map(dXs_dt, "velocity")

    def _through_map(self, values, where):
        # The mover's map of the current warp, linear in the surface: never a move, which could
        # set the mover up again for a seed's size.
        if self._derivative_note:
            raise _core.InputError(where + ": " + self._derivative_note)
        w = real_array(values, where)
        if w.shape != (len(self._design), self._dim):
            raise _core.InputError(f"{where}: expected shape ({len(self._design)}, {self._dim}) (got {w.shape})")
        seed = _np.zeros_like(self._input)
        seed[self._columns[self._order]] = w
        return self._mover.velocity(seed)

    def verify_derivative(self, h=1e-6, seed=0, verbose=True):
        """Compares warp_derivative with central finite differences of I = <dI_dXv, Xv> along a
        random surface direction; prints and returns the relative error."""
        rng = _np.random.default_rng(seed + (self._comm.Get_rank() if self._comm is not None else 0))
        v = rng.standard_normal(self._reference.shape)
        direction = rng.standard_normal((len(self._design), self._dim))
        saved = self._surface.copy()
        base = self.surface_coordinates()
        scale = max(1.0, float(_np.abs(base).max()) if base.size else 0.0)
        if self._comm is not None:
            scale = self._comm.allreduce(scale, op=_max())
        self.set_surface_coordinates(base + h * scale * direction)
        plus = self._sum(v * self.warp())
        self.set_surface_coordinates(base - h * scale * direction)
        minus = self._sum(v * self.warp())
        self._surface = saved
        self.warp()
        finite_difference = (plus - minus) / (2.0 * h * scale)
        adjoint = self._sum(self.warp_derivative(v) * direction, owned_only=False)
        error = abs(adjoint - finite_difference) / max(abs(finite_difference), 1e-300)
        if verbose and (self._comm is None or self._comm.Get_rank() == 0):
            print(f"verify_derivative: adjoint {adjoint:.12e}, finite difference {finite_difference:.12e}, "
                  f"relative error {error:.3e}, condition >= {self.condition:.1e}")
        return error

    def _sum(self, terms, owned_only=True):
        """Σ of terms over the nodes (rows) each rank owns, over every rank."""
        local = float(_np.sum(terms[self._owned] if owned_only else terms))
        return local if self._comm is None else self._comm.allreduce(local)


#: Warp warns when the RBF system's condition estimate exceeds this: warp_derivative's
#: rounding may then reach 1e-4 of its values.
CONDITION_WARNING = 1e12


def _raise_everywhere(comm, failure):
    """Raises on every rank the error rank 0 caught, (class name, message), so that no rank goes
    on to a collective call the others never reach."""
    _raise_everywhere_from(comm.bcast(failure, root=0))


def _raise_any(comm, failure):
    """Raises on every rank the error of the first rank that caught one, (class name, message)."""
    failures = [f for f in comm.allgather(failure) if f is not None]
    _raise_everywhere_from(failures[0] if failures else None)


def _raise_everywhere_from(failure):
    if failure is not None:
        kind = getattr(_core, failure[0], None)
        raise (kind if isinstance(kind, type) and issubclass(kind, Exception) else RuntimeError)(failure[1])


def _check_comm(comm):
    if not (hasattr(comm, "py2f") and hasattr(comm, "bcast")):
        raise _core.InputError(f"Warp: comm must be an mpi4py communicator (got {type(comm).__name__})")
    if not getattr(_core, "have_mpi", False):
        raise _core.InputError("Warp: comm given but the module has no MPI: " + _core.mpi_missing)


def _agree(comm, value, what):
    """value, when every rank has the same; else InputError on every rank."""
    values = comm.allgather(value)
    if any(v != values[0] for v in values):
        raise _core.InputError(f"Warp.from_partition: the ranks disagree on {what} ({values})")
    return values[0]


def _gather_owned(comm, ids, values):
    """values (rows of the global nodes `ids` this rank owns) of every rank as one array in
    global order on rank 0 (None elsewhere); raises on every rank for a global node no rank
    owns or one owned twice."""
    ids = comm.gather(ids, root=0)
    values = comm.gather(values, root=0)
    out, failure = None, None
    if comm.Get_rank() == 0:
        ids, values = _np.concatenate(ids), _np.concatenate(values)
        count = int(ids.max()) + 1 if len(ids) else 0
        seen = _np.bincount(ids, minlength=count) if len(ids) else _np.zeros(0, dtype=_np.int64)
        if len(ids) and (ids.min() < 0 or (seen != 1).any()):
            bad = int(ids.min()) if ids.min() < 0 else int(_np.flatnonzero(seen != 1)[0])
            failure = ("InputError", f"gather_volume_coordinates: global node {bad} is owned by "
                                     f"{int(seen[bad]) if bad >= 0 else 0} ranks (expected ids 0..n-1, each owned once)")
        else:
            out = _np.empty((count, values.shape[1]))
            out[ids] = values
    _raise_everywhere(comm, failure)
    return out


def _max():
    from mpi4py import MPI
    return MPI.MAX
