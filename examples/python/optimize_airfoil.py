#!/usr/bin/python3
"""Inverse design of an airfoil with scipy.optimize, the mesh warped by meshmotion.Warp.

Eight Hicks-Henne bumps (four on each side) move the airfoil's wall; the objective is the
distance of the warped volume mesh to a target mesh made with hidden bump amplitudes:

    I(a) = 1/2 sum_nodes |Xv(a) - Xv_target|^2

Its gradient is the chain dI/da = dXs/da^T . warp_derivative(dI/dXv): one reverse product per
iteration, whatever the number of design variables, as in an adjoint-based optimization. The
example checks that gradient against central finite differences, runs L-BFGS-B and checks
that it recovers the hidden amplitudes. Exit code 0 when it does.

    /usr/bin/python3 examples/python/optimize_airfoil.py [mesh.su2 [wall group]]

Without arguments it takes the NACA0012 of ../shared/data (su2_naca0012_inviscid_tri.su2),
or, where that folder is absent, a generated O-mesh around a NACA0012.
"""

import os
import pathlib
import sys

import numpy as np
import scipy.optimize

import meshmotion as mm


def naca0012_o_mesh(n_around=160, n_radial=40, farfield=20.0):
    """Quadrilaterals from a NACA0012 (chord 1) out to a circle, groups airfoil and farfield."""
    beta = np.linspace(0.0, 2.0 * np.pi, n_around, endpoint=False)
    x = 0.5 * (1.0 + np.cos(beta))  # cosine spacing, trailing edge at beta = 0
    half = 0.6 * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    wall = np.column_stack([x, np.where(beta < np.pi, half, -half)])
    centre = np.array([0.5, 0.0])
    circle = centre + farfield * np.column_stack([np.cos(beta), np.sin(beta)])
    s = (np.geomspace(1.0, 1.0 + 200.0, n_radial + 1) - 1.0) / 200.0  # clustered at the wall
    points = np.concatenate([(1.0 - t) * wall + t * circle for t in s])
    node = lambda j, i: j * n_around + i % n_around  # noqa: E731
    quads = np.array([[node(j, i), node(j + 1, i), node(j + 1, i + 1), node(j, i + 1)]
                      for j in range(n_radial) for i in range(n_around)], dtype=np.int64)
    ring = lambda j: np.array([[node(j, i), node(j, i + 1)] for i in range(n_around)], dtype=np.int64)  # noqa: E731
    return mm.from_arrays(points, {"quad4": quads}, {"airfoil": ("line2", ring(0)), "farfield": ("line2", ring(n_radial))})


def load(argv):
    if len(argv) > 1:
        return mm.read_mesh(argv[1], "fix_reversed"), (argv[2] if len(argv) > 2 else "airfoil")
    shared = pathlib.Path(os.environ.get("MESHMOTION_SHARED_DATA_DIR",
                                         pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "data"))
    file = shared / "su2_naca0012_inviscid_tri.su2"
    if file.exists():
        print(f"mesh: {file.resolve()}")
        return mm.read_mesh(str(file), "fix_reversed"), "airfoil"
    print(f"mesh: generated O-mesh ({file} not found)")
    return naca0012_o_mesh(), "airfoil"


def hicks_henne(xs, n_per_side=4):
    """The design map dXs/da: (n_design * dim, n_bumps), bumps moving y on one side each."""
    x, y = xs[:, 0], xs[:, 1]
    t = np.clip((x - x.min()) / (x.max() - x.min()), 0.0, 1.0)
    upper = y > 0.0
    peaks = np.linspace(0.2, 0.8, n_per_side)
    columns = []
    for side in (upper, ~upper):
        for peak in peaks:
            shape = np.sin(np.pi * t ** (np.log(0.5) / np.log(peak))) ** 3
            dy = np.where(side, shape, 0.0)
            columns.append(np.column_stack([np.zeros_like(dy), dy]).ravel())
    return np.column_stack(columns)


def main(argv):
    mesh, wall = load(argv)
    others = [g for g in mesh.groups if g != wall]
    # An optimizer's line search probes designs far from the answer, some folding cells: it needs
    # the smooth map and its exact gradient there, not the map with those cells repaired.
    warp = mm.Warp(mesh, design=[wall], fixed=others, support_radius=0.5, repair=False)
    xs0 = warp.surface_coordinates()
    basis = hicks_henne(xs0)
    print(f"{mesh.num_nodes} nodes, {len(xs0)} design nodes on '{wall}', {basis.shape[1]} design variables")

    def volume(a):
        warp.set_surface_coordinates(xs0 + (basis @ a).reshape(xs0.shape))
        return warp.warp()

    hidden = 0.004 * np.array([1.0, -0.5, 0.8, 0.3, -0.7, 0.4, -0.2, 0.6])
    target = volume(hidden).copy()

    def objective(a):
        r = volume(a) - target
        gradient = basis.T @ warp.warp_derivative(r).ravel()
        return 0.5 * float(np.sum(r * r)), gradient

    # The gradient against central finite differences at a random design.
    rng = np.random.default_rng(1)
    a = 0.002 * rng.standard_normal(basis.shape[1])
    _, g = objective(a)
    h = 1e-6
    fd = np.array([(objective(a + h * e)[0] - objective(a - h * e)[0]) / (2 * h) for e in np.eye(len(a))])
    gradient_error = np.abs(g - fd).max() / np.abs(fd).max()
    print(f"gradient vs finite differences: largest relative error {gradient_error:.2e}")
    warp_error = warp.verify_derivative()

    result = scipy.optimize.minimize(objective, np.zeros(basis.shape[1]), jac=True, method="L-BFGS-B",
                                     options={"ftol": 0.0, "gtol": 1e-14, "maxiter": 200})
    recovered = np.abs(result.x - hidden).max() / np.abs(hidden).max()
    print(f"L-BFGS-B: {result.nit} iterations, {result.nfev} warps, objective {result.fun:.3e}, "
          f"amplitudes recovered to {recovered:.2e} (relative)")
    final = mesh.copy()
    final.points = volume(result.x)
    quality = mm.quality_report(final, "jacobian")
    print(f"optimized mesh: min scaled Jacobian {quality['min']:.3f}, {quality['invalid']} invalid")
    ok = gradient_error < 1e-6 and warp_error < 1e-6 and recovered < 1e-4
    print("converged" if ok else "FAILED: the gradient or the recovered design is off")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
