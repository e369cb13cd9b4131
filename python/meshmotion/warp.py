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
"""

import numpy as _np

from . import _core
from ._arrays import index_array, real_array


class Warp:
    def __init__(self, mesh, design, symmetry=(), fixed=(), method="rbf", orientation="fix_reversed", **options):
        if isinstance(mesh, (str, bytes)) or hasattr(mesh, "__fspath__"):
            mesh = _core.read_mesh(mesh, orientation)
        if not isinstance(mesh, (_core.Mesh2, _core.Mesh3)):
            raise _core.InputError("Warp: mesh must be a file name or a meshmotion mesh")
        if not design:
            raise _core.InputError("Warp: give at least one design group")
        self._dim = 2 if isinstance(mesh, _core.Mesh2) else 3
        self._mesh = mesh
        self._reference = _np.array(mesh.points, copy=True)
        spec = _core.BoundarySpec2() if self._dim == 2 else _core.BoundarySpec3()
        for group in design:
            spec.prescribed(group)
        for group in symmetry:
            spec.sliding(group)
        for group in fixed:
            spec.fixed(group)
        self._boundary = spec.resolve(mesh)
        nodes = set()
        for group in design:
            nodes.update(mesh.group_nodes(group))
        self._design = _np.array(sorted(nodes), dtype=_np.int64)
        self._columns = _np.array([self._boundary.column(int(v)) for v in self._design], dtype=_np.int64)
        self._order = _np.arange(len(self._design))  # user position -> design position
        self._mover = (_core.Mover2 if self._dim == 2 else _core.Mover3)(method, **options)
        self._mover.setup(mesh, self._boundary)
        if not self._mover.has_derivatives:
            self._derivative_note = f"method {method} has no derivatives"
        else:
            self._derivative_note = None
        self._surface = self._reference[self._design].copy()
        self._volume = self._reference.copy()
        self._input = _np.zeros((self._boundary.size, self._dim))

    @property
    def dim(self):
        return self._dim

    @property
    def design_nodes(self):
        """Node indices of the design surface, in the order of surface_coordinates()."""
        return self._design[self._order].copy()

    def set_surface_order(self, nodes):
        """Use the solver's own order of the design nodes (each design node exactly once)."""
        nodes = index_array(nodes, "set_surface_order")
        position = {int(v): k for k, v in enumerate(self._design)}
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
        """Moves the volume from the reference mesh to the current surface (setup reused)."""
        self._input[:] = 0.0
        self._input[self._columns] = self._surface - self._reference[self._design]
        self._volume = self._reference + self._mover.move(self._input)
        return self._volume

    def volume_coordinates(self):
        """Coordinates of every node after the last warp(), (n_nodes, dim)."""
        return self._volume.copy()

    def warp_derivative(self, dI_dXv):
        """dI/dXs for dI/dXv (n_nodes, dim): one row per design node, in surface order."""
        if self._derivative_note:
            raise _core.InputError("warp_derivative: " + self._derivative_note)
        v = real_array(dI_dXv, "warp_derivative")
        if v.shape != self._reference.shape:
            raise _core.InputError(f"warp_derivative: expected shape {self._reference.shape} (got {v.shape})")
        g = self._mover.derivative_reverse(v)
        return g[self._columns][self._order]

    def verify_derivative(self, h=1e-6, seed=0, verbose=True):
        """Compares warp_derivative with central finite differences of I = <dI_dXv, Xv> along a
        random surface direction; prints and returns the relative error."""
        rng = _np.random.default_rng(seed)
        v = rng.standard_normal(self._reference.shape)
        direction = rng.standard_normal((len(self._design), self._dim))
        saved = self._surface.copy()
        base = self.surface_coordinates()
        scale = max(1.0, float(_np.abs(base).max()))
        self.set_surface_coordinates(base + h * scale * direction)
        plus = float(_np.sum(v * self.warp()))
        self.set_surface_coordinates(base - h * scale * direction)
        minus = float(_np.sum(v * self.warp()))
        self._surface = saved
        self.warp()
        finite_difference = (plus - minus) / (2.0 * h * scale)
        adjoint = float(_np.sum(self.warp_derivative(v) * direction))
        error = abs(adjoint - finite_difference) / max(abs(finite_difference), 1e-300)
        if verbose:
            print(f"verify_derivative: adjoint {adjoint:.12e}, finite difference {finite_difference:.12e}, "
                  f"relative error {error:.3e}")
        return error
