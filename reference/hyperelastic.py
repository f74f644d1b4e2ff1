"""Static compressible neo-Hookean elasticity with Newton iterations and load steps.

W = mu/2 (tr C - 3) - mu ln J + lam/2 (ln J)^2, the first Piola-Kirchhoff stress
P = mu (F - F^-T) + lam ln J F^-T; for large deformation and rotation, where linear FEM is
wrong by construction.
"""
from dataclasses import dataclass

import numpy as np
from skfem import BilinearForm, LinearForm, asm, condense
from skfem.helpers import ddot, det, eye, grad, inv, mul, transpose

from model.bc import bc_arrays
from model.errors import ConvergenceError, ModelError
from .fem import (cell_average, dirichlet_dofs, element_basis, lame, linear_solve,
                  refine_with_data, skfem_mesh, stress_measures)
from .linear import body_load, dof_component, transfer_to_nodes


def _kinematics(w):
    H = grad(w["u"])
    F = H + eye(np.ones_like(H[0, 0]), 3)
    J = det(F)
    if np.any(J <= 0):
        raise ConvergenceError("neo-Hookean: an element inverted (det F <= 0); use more load "
                               "steps")
    return F, J, transpose(inv(F))


def first_piola(lam, mu):
    def P(F, J, FinvT):
        return mu * (F - FinvT) + lam * np.log(J) * FinvT
    return P


def forms(lam, mu):
    P = first_piola(lam, mu)

    @LinearForm
    def internal(v, w):
        return ddot(P(*_kinematics(w)), grad(v))

    @BilinearForm
    def tangent(du, v, w):
        F, J, FinvT = _kinematics(w)
        dF = grad(du)
        dP = (mu * dF + (mu - lam * np.log(J)) * mul(FinvT, mul(transpose(dF), FinvT))
              + lam * ddot(FinvT, dF) * FinvT)
        return ddot(dP, grad(v))

    return internal, tangent, P


@dataclass
class HyperelasticResult:
    """``u`` (n, 3) [m]; ``stress`` (m, 3, 3) Cauchy stress per tetrahedron (volume average);
    ``von_mises``, ``max_shear``, ``pressure`` (m,); ``reaction`` (n, 3) [N]; ``iterations``."""

    u: np.ndarray
    stress: np.ndarray
    von_mises: np.ndarray
    max_shear: np.ndarray
    pressure: np.ndarray
    reaction: np.ndarray
    iterations: int
    info: dict


def solve(mesh, E, nu, dirichlet, body_force=None, element="P1", refine=0, dirichlet_fn=None,
          load_steps=1, rtol=1e-10, max_iter=30, on_step=None):
    """Neo-Hookean equilibrium: Newton in ``load_steps`` equal increments of the prescribed
    displacement and body force, each converged to max |residual| <= rtol * E h^2 (h the mean
    edge). Raises ConvergenceError otherwise. ``on_step(step, u, reaction)``, when given, is
    called after every converged step with the nodal displacement (n, 3) and reaction (n, 3)
    at that load (a force-displacement curve in one solve)."""
    lam, mu = lame(E, nu)
    mask, vals = bc_arrays(dirichlet, mesh.n_nodes)
    if not mask.any():
        raise ModelError("no Dirichlet condition: the problem is singular; prescribe nodes")
    coarse = skfem_mesh(mesh)
    if refine:
        raise ModelError("the neo-Hookean reference solves on the input mesh (refine=0); "
                         "pass a refined mesh instead")
    m, mask_f, vals_f, W = refine_with_data(coarse, mask, vals, dirichlet_fn, 0)
    basis = element_basis(m, element)
    D, x_D = dirichlet_dofs(basis, mask_f, vals_f, dirichlet_fn)
    internal, tangent, P = forms(lam, mu)
    f_body = body_load(basis, body_force) if body_force is not None else np.zeros(basis.N)
    comp = dof_component(basis)
    I = np.setdiff1d(np.arange(basis.N), D)
    h = np.linalg.norm(np.diff(m.p[:, m.edges], axis=1), axis=0).mean()
    floor = rtol * E * h * h
    u = np.zeros(basis.N)
    iters = 0
    for step in range(1, load_steps + 1):
        s = step / load_steps
        for _ in range(max_iter):
            w = {"u": basis.interpolate(u)}
            res = asm(internal, basis, **w) - s * f_body
            rn = np.abs(res[I]).max(initial=0.0)
            if rn <= floor and np.array_equal(u[D], s * x_D[D]):
                break
            # Newton step; its prescribed part carries the load increment (a tangent predictor,
            # so that the interior follows the boundary instead of inverting next to it)
            K = asm(tangent, basis, **w)
            A, b, du, II = condense(K, -res, x=np.where(np.isin(np.arange(basis.N), D),
                                                        s * x_D - u, 0.0), D=D)
            du[II], _ = linear_solve(A, b, basis.doflocs.T[II], comp[II])
            u = u + du
            u[D] = s * x_D[D]
            iters += 1
        else:
            raise ConvergenceError(f"neo-Hookean Newton did not converge in {max_iter} "
                                   f"iterations at load step {step}/{load_steps}: residual "
                                   f"{rn:.3e} N; increase load_steps")
        if on_step is not None:
            w = {"u": basis.interpolate(u)}
            on_step(step, u[basis.nodal_dofs[:, :mesh.n_nodes]].T,
                    transfer_to_nodes(basis, W, D, (asm(internal, basis, **w) - s * f_body)[D]))
    w = {"u": basis.interpolate(u)}
    reaction = transfer_to_nodes(basis, W, D, (asm(internal, basis, **w) - f_body)[D])
    F, J, FinvT = _kinematics(w)
    cauchy = np.einsum("ij...,kj...->ik...", P(F, J, FinvT), F) / J
    stress = np.moveaxis(cell_average(basis, cauchy), -1, 0)
    vm, tmax, p = stress_measures(stress)
    return HyperelasticResult(u=u[basis.nodal_dofs[:, :mesh.n_nodes]].T, stress=stress,
                              von_mises=vm, max_shear=tmax, pressure=p, reaction=reaction,
                              iterations=iters, info={"element": element,
                                                      "load_steps": load_steps})
