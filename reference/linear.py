"""Static linear elasticity with scikit-fem (P1 or P2, optionally on a refined mesh)."""
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq
from skfem import FacetBasis, LinearForm, asm, condense
from skfem.helpers import dot, sym_grad
from skfem.models.elasticity import linear_stress

from model.bc import bc_arrays
from model.errors import ModelError
from model.material import as_material
from .assembly import stiffness
from .discretisation import (INTORDER, dirichlet_dofs, dof_hats, element_basis, probe,
                             refine_with_data, skfem_mesh)
from .solvers import check_finite, linear_solve
from .stress import stress_measures, stress_on_input


@dataclass
class LinearResult:
    """Solution on the input mesh.

    ``u`` (n, 3) displacement at the mesh nodes [m]; ``stress`` (m, 3, 3) Cauchy stress per
    tetrahedron of the input mesh (its volume average: exact for P1, the centroid value for P2);
    ``stress_nodes`` (n, 3, 3) volume-weighted nodal average; ``von_mises``, ``max_shear``,
    ``pressure`` (m,) per tetrahedron [Pa]; ``reaction`` (n, 3) force the supports exert [N];
    ``energy`` strain energy [J]; ``info`` element, refinement, dofs and solver.
    """

    u: np.ndarray
    stress: np.ndarray
    stress_nodes: np.ndarray
    von_mises: np.ndarray
    max_shear: np.ndarray
    pressure: np.ndarray
    reaction: np.ndarray
    energy: float
    info: dict = field(default_factory=dict)
    basis: object = field(default=None, repr=False)
    dofs: np.ndarray = field(default=None, repr=False)

    def at(self, points):
        """The displacement (k, 3) of the finite-element solution at arbitrary ``points``
        (k, 3) inside the mesh (its basis functions evaluated there, not the nodal values
        interpolated): what compares a solution with results on another mesh."""
        return probe(self.basis, self.dofs, points)


@LinearForm
def _vector_load(v, w):
    return dot(w.load, v)


def _assemble_load(basis, value, name, normals=False):
    """The load vector of a force density ``value`` on ``basis``: a constant (3,) or a
    callable evaluated once at every quadrature point on plain ndarrays, ``value(points)``
    (or ``value(points, normals)`` on facets), points and normals (..., 3), returning
    (..., 3); writing into ``np.zeros_like(points)`` works."""
    x = np.moveaxis(np.array(basis.global_coordinates().value), 0, -1)   # (nel, nqp, 3)
    if callable(value):
        args = (x, np.moveaxis(np.array(basis.normals), 0, -1)) if normals else (x,)
        load = np.asarray(value(*args), dtype=float)
    else:
        load = np.broadcast_to(np.asarray(value, dtype=float), x.shape)
    if load.shape != x.shape:
        raise ModelError(f"{name} must give a (..., 3) force density for points of shape "
                         f"(..., 3), got shape {load.shape} for {x.shape}")
    if not np.isfinite(load).all():
        raise ModelError(f"{name} is not finite at some quadrature points")
    return asm(_vector_load, basis, load=np.moveaxis(load, -1, 0))


def body_load(basis, b):
    """Load vector of a body force density ``b`` [N/m^3]: (3,) or ``b(points) -> (..., 3)``."""
    return _assemble_load(basis, b, "body_force")


def traction_load(facet_basis, fn):
    """Load vector of a traction [Pa] ``fn(points, normals) -> (..., 3)`` on boundary facets."""
    return _assemble_load(facet_basis, fn, "traction", normals=True)


def solve(mesh, material, dirichlet, body_force=None, traction=None, element="P1", refine=0,
          dirichlet_fn=None, solver="auto"):
    """Linear elastic equilibrium on ``mesh`` (a model.mesh.TetMesh).

    Parameters
    ----------
    material : the model.material.Material (E [Pa], nu; rho is not read).
    dirichlet : mapping node -> (ux, uy, uz), None for a free component (as the model takes).
    body_force : (3,) force per unit volume [N/m^3], e.g. rho * g, or a callable
        ``points (..., 3) -> (..., 3)`` (plain ndarrays, evaluated once per quadrature point).
    traction : callable ``(points (..., 3), normals (..., 3)) -> (..., 3)`` [Pa] on the boundary
        facets (return zero where unloaded); plain ndarrays, so ``t = np.zeros_like(points);
        t[..., 1] = ...`` works.
    element : "P1" or "P2".
    refine : uniform refinements before solving; results come back on the input mesh.
    dirichlet_fn : ``points (k, 3) -> (k, 3)``, the prescribed displacement at new boundary
        points (P2 midpoints, refined nodes) on boundary facets whose three vertices are
        prescribed; NaN leaves a component free there (declare the prescribed surfaces this
        way when a free face lies between two of them, e.g. a body one element thick); linear
        interpolation when None (see ``reference.discretisation.prescribed_edges``).
    solver : "auto", "direct" or "amg" (see ``reference.solvers.linear_solve``).
    """
    lam, mu = as_material(material, "reference.linear.solve").lame
    n = mesh.n_nodes
    mask, vals = bc_arrays(dirichlet, n)
    if not mask.any():
        raise ModelError("no Dirichlet condition: the linear system is singular (rigid motions "
                         "are free); prescribe at least three non-collinear nodes")
    if int(refine) != refine or refine < 0:
        raise ModelError(f"refine must be a non-negative integer, got {refine!r}")
    coarse = skfem_mesh(mesh)
    m, mask_f, vals_f, W = refine_with_data(coarse, mask, vals, dirichlet_fn, refine)
    basis = element_basis(m, element)
    D, x_D = dirichlet_dofs(basis, mask_f, vals_f, dirichlet_fn)
    K = stiffness(basis, lam, mu)
    f = np.zeros(basis.N)
    if body_force is not None:
        f += body_load(basis, body_force)
    if traction is not None:
        fb = FacetBasis(m, basis.elem, intorder=INTORDER[element])
        f += traction_load(fb, traction)
    A, b, x, I = condense(K, f, x=x_D, D=D)
    xI, sinfo = linear_solve(A, b, basis.doflocs.T[I], dof_component(basis)[I], solver)
    x[I] = check_finite("displacement", xI)
    u_all = x
    # reactions: K u - f on the prescribed dofs, carried to the input nodes by the P1 hats
    reaction = transfer_to_nodes(basis, W, D, (K @ u_all - f)[D])
    u = u_all[basis.nodal_dofs[:, :n]].T
    # stress: volume average over each input tetrahedron of the solution's stress
    w = basis.interpolate(u_all)
    stress, vol = stress_on_input(basis, W, mesh, linear_stress(lam, mu)(sym_grad(w)))
    vm, tmax, p = stress_measures(stress)
    node_vol = np.zeros(n)
    np.add.at(node_vol, mesh.tets, vol[:, None])
    stress_nodes = np.zeros((n, 3, 3))
    np.add.at(stress_nodes, mesh.tets, (vol[:, None, None] * stress)[:, None])
    stress_nodes /= node_vol[:, None, None]
    return LinearResult(u=u, stress=stress, stress_nodes=stress_nodes, von_mises=vm,
                        max_shear=tmax, pressure=p, reaction=reaction,
                        energy=float(0.5 * u_all @ (K @ u_all)),
                        info={"element": element, "refine": int(refine), "dofs": int(basis.N),
                              **sinfo}, basis=basis, dofs=u_all)


def p1_stiffness(mesh, material):
    """The linear elastic P1 stiffness (3n x 3n, CSR) on ``mesh``'s own tetrahedra, its rows
    and columns node-major (u.ravel() of an (n, 3) field): the energy norm ||v||_K of the
    continuum's energy of a nodal field's P1 interpolant, v.K v = 2 x that energy."""
    lam, mu = as_material(material, "reference.linear.p1_stiffness").lame
    basis = element_basis(skfem_mesh(mesh), "P1")
    order = basis.nodal_dofs.T.ravel()
    return stiffness(basis, lam, mu)[order][:, order].tocsr()


def transfer_to_nodes(basis, W, dofs, values):
    """Carry forces on ``dofs`` to the input mesh's nodes with its P1 hat functions
    (preserves their sum and first moments; the identity for P1 without refinement)."""
    hats = dof_hats(basis, W)[dofs]
    comp = dof_component(basis)[dofs]
    return np.column_stack([hats[comp == k].T @ values[comp == k] for k in range(3)])


def dof_component(basis):
    """The displacement component (0, 1, 2) each dof of a vector basis carries."""
    comp = np.empty(basis.N, dtype=int)
    for k in range(3):
        comp[basis.nodal_dofs[k]] = k
        if basis.edge_dofs.size:
            comp[basis.edge_dofs[k]] = k
    return comp


@dataclass
class ConvergedResult:
    """The finest P2 solution (``result``) of a refinement sequence, evaluated on the input
    mesh, with the reference's own error estimate: ``levels`` the refinements solved,
    ``increments`` relative nodal L2 change between successive levels and ``rate`` its observed
    order; ``energy_increments`` and ``energy_rate`` the same for the strain energy;
    ``error_estimate`` the larger of the two Richardson estimates of the finest level's relative
    error (the last increment where no rate can be observed). The energy keeps the estimate
    honest where every input node is prescribed and the nodal values cannot move."""

    result: LinearResult
    levels: list
    increments: list
    rate: float
    error_estimate: float
    energy_increments: list = field(default_factory=list)
    energy_rate: float = float("nan")


def richardson(increments, h=None):
    """(observed order, estimated error of the finest level) from the relative changes
    between successive levels at spacings ``h`` (descending; default: each level halves h).
    The order p solves (h1^p - h2^p) / (h2^p - h3^p) = inc[-2] / inc[-1] over the last three
    levels (log2 of the ratio when h halves); the estimate is inc[-1] h3^p / (h2^p - h3^p),
    or the last change itself where no order above 0.5 is observed."""
    inc = increments
    # no rate from a change that is exactly zero (an exact solution: the uniform sliding cube)
    rate = float("nan")
    h1, h2, h3 = (4.0, 2.0, 1.0) if h is None else (float(x) for x in h[-3:])
    if len(inc) > 1 and inc[-1] > 0 and inc[-2] > 0:
        ratio = inc[-2] / inc[-1]
        if np.isclose(h1 / h2, h2 / h3, rtol=1e-12):
            rate = float(np.log(ratio) / np.log(h2 / h3))
        else:
            def gap(p):
                return (h1**p - h2**p) / (h2**p - h3**p) - ratio
            if gap(0.05) * gap(20.0) < 0:
                rate = float(brentq(gap, 0.05, 20.0, xtol=1e-12))
    if np.isfinite(rate) and rate > 0.5:
        return rate, float(inc[-1] * h3**rate / (h2**rate - h3**rate))
    return rate, float(inc[-1])


def estimate(sols, h=None):
    """The one error estimate of every converged FEM reference: of the finest of solutions
    ``sols`` (each with ``u`` at common points and ``energy``) at spacings ``h`` (default:
    halving), the larger of the Richardson estimates from the relative changes of the
    displacement and of the energy, with those changes and orders:
    (estimate, increments, rate, energy increments, energy rate). The energy keeps the
    estimate honest where the compared points are all prescribed and cannot move."""
    norm = max(np.linalg.norm(sols[-1].u), 1e-300)
    inc = [float(np.linalg.norm(b.u - a.u) / norm) for a, b in zip(sols, sols[1:])]
    scale = max(abs(sols[-1].energy), 1e-300)
    inc_e = [abs(b.energy - a.energy) / scale for a, b in zip(sols, sols[1:])]
    rate, est = richardson(inc, h)
    rate_e, est_e = richardson(inc_e, h)
    return max(est, est_e), inc, rate, inc_e, rate_e


def converged(mesh, material, dirichlet, levels=2, **kw):
    """Solve with P2 on ``mesh`` refined 0..levels times and estimate the error of the finest;
    ``material`` the model.material.Material, ``kw`` as :func:`solve` takes them."""
    material = as_material(material, "reference.linear.converged")
    if levels < 1:
        raise ModelError(f"converged needs levels >= 1 to estimate its error, got {levels}")
    return converged_from([solve(mesh, material, dirichlet, element="P2", refine=k, **kw)
                           for k in range(levels + 1)])


def converged_from(sols):
    """The ConvergedResult of solutions on the mesh refined 0, 1, ... times (each with ``u``
    at the input nodes and ``energy``): the finest, with :func:`estimate`."""
    est, inc, rate, inc_e, rate_e = estimate(sols)
    return ConvergedResult(result=sols[-1], levels=list(range(len(sols))), increments=inc,
                           rate=rate, error_estimate=est, energy_increments=inc_e,
                           energy_rate=rate_e)
