"""Manufactured solutions for the references' verification: a smooth field that is not a
polynomial (a sum of plane waves, sines with phases), the body force and the boundary traction
that make it the exact solution of linear or neo-Hookean elasticity, the FEM solve of that
problem and the L2 error of the solution against the field, integrated on the solution's mesh.

    u(x) = sum_j a_j sin(k_j . x + phi_j)
    H_ijk = d2 u_i / dx_j dx_k = -sum_j a_ji k_jj k_jk sin(k_j . x + phi_j)

The body force is b = -div S(grad u), S the material's stress (the Cauchy stress of linear
elasticity; the first Piola-Kirchhoff stress of the neo-Hookean solid, on the reference
configuration), and the traction S(grad u) n on the faces that are not prescribed (a dead load
per reference area). Each divergence is worked out from H in closed form (below) and tested
against a finite-difference divergence of the stress.
"""
from dataclasses import dataclass

import numpy as np
from skfem import Basis, Functional

from model.errors import ModelError
from model.material import Material, as_material, neohookean_stress


@dataclass(frozen=True)
class PlaneWaves:
    """``amplitudes`` (J, 3) [m], ``wavevectors`` (J, 3) [1/m], ``phases`` (J,)."""

    amplitudes: np.ndarray
    wavevectors: np.ndarray
    phases: np.ndarray

    def _arg(self, x):
        return np.einsum("...i,ji->...j", np.asarray(x, float), self.wavevectors) + self.phases

    def u(self, x):
        """The displacement (..., 3) at points ``x`` (..., 3)."""
        return np.einsum("...j,ji->...i", np.sin(self._arg(x)), self.amplitudes)

    def grad(self, x):
        """du_i / dx_k (..., 3, 3)."""
        return np.einsum("...j,ji,jk->...ik", np.cos(self._arg(x)), self.amplitudes,
                         self.wavevectors)

    def hessian(self, x):
        """d2 u_i / dx_j dx_k (..., 3, 3, 3)."""
        k = self.wavevectors
        return -np.einsum("...w,wi,wj,wk->...ijk", np.sin(self._arg(x)), self.amplitudes, k, k)


@dataclass(frozen=True)
class LinearElastic:
    """sigma = lam tr(eps) I + 2 mu eps; div sigma_i = (lam + mu) H_kki + mu H_ijj."""

    lam: float
    mu: float

    def stress(self, g):
        eps = 0.5 * (g + np.swapaxes(g, -1, -2))
        return (self.lam * np.trace(eps, axis1=-2, axis2=-1)[..., None, None] * np.eye(3)
                + 2 * self.mu * eps)

    def divergence(self, g, H):
        return ((self.lam + self.mu) * np.einsum("...kki->...i", H)
                + self.mu * np.einsum("...ijj->...i", H))


@dataclass(frozen=True)
class NeoHookean:
    """P = mu F + (lam ln J - mu) F^-T (the energy ``reference.hyperelastic`` solves), F = I + g.
    With d(F^-1)_Ji / dX_K = -F^-1_Ja H_abK F^-1_bi and d ln J / dX_K = F^-1_ba H_abK:
    div P_i = mu H_iJJ + lam F^-1_ba H_abJ F^-1_Ji - (lam ln J - mu) F^-1_Ja H_abJ F^-1_bi."""

    lam: float
    mu: float

    def _kinematics(self, g):
        F = np.eye(3) + g
        J = np.linalg.det(F)
        if np.any(J <= 0):
            raise ModelError("the manufactured field inverts the material (det F <= 0): "
                             "take a smaller amplitude")
        return F, np.linalg.inv(F), np.log(J)

    def stress(self, g):
        F, Fi, lnJ = self._kinematics(g)
        a, b = neohookean_stress(lnJ, self.lam, self.mu)     # P = a F + b F^-T, the one law
        return a * F + np.asarray(b)[..., None, None] * np.swapaxes(Fi, -1, -2)

    def divergence(self, g, H):
        _, Fi, lnJ = self._kinematics(g)
        a, b = neohookean_stress(lnJ, self.lam, self.mu)
        dlnJ = np.einsum("...ba,...abJ->...J", Fi, H)
        dFiT = -np.einsum("...Ja,...abJ,...bi->...i", Fi, H, Fi)
        # d(a F)/dX with a constant, d(b F^-T)/dX with db = lam dlnJ
        return (a * np.einsum("...iJJ->...i", H)
                + self.lam * np.einsum("...J,...Ji->...i", dlnJ, Fi)
                + np.asarray(b)[..., None] * dFiT)


MATERIALS = {"linear": LinearElastic, "neo-Hookean": NeoHookean}


@dataclass(frozen=True)
class Manufactured:
    """A field and a material: the loads that make the field the exact solution."""

    field: PlaneWaves
    law: object               # LinearElastic or NeoHookean, at the material's constants
    material: Material

    def stress(self, x):
        return self.law.stress(self.field.grad(x))

    def body_force(self, x):
        """b(x) = -div S(u) [N/m^3] at points (..., 3), as the references take it."""
        return -self.law.divergence(self.field.grad(x), self.field.hessian(x))

    def traction(self, x, n):
        """t(x, n) = S(u) n [Pa] at boundary points and normals (..., 3)."""
        return np.einsum("...ik,...k->...i", self.stress(x), np.asarray(n, float))


def manufactured(field, law, material):
    """The problem of ``field`` for the law ``law`` ("linear" or "neo-Hookean") of the
    Material ``material``."""
    material = as_material(material, "reference.manufactured.manufactured")
    if law not in MATERIALS:
        raise ModelError(f"unknown law {law!r}: choose one of {sorted(MATERIALS)}")
    return Manufactured(field, MATERIALS[law](*material.lame), material)


def waves(size, amplitude=1e-3):
    """The field the verification uses on a cube of side ``size`` [m]: three plane waves of
    about one wavelength across the cube, in three directions, with phases, amplitude
    ``amplitude`` x size (the largest strain is about 3.5 ``amplitude``). No component is a
    polynomial, none vanishes on a face."""
    k = np.pi / size
    return PlaneWaves(
        amplitudes=amplitude * size * np.array([[1.0, 0.4, -0.3], [-0.2, 0.8, 0.5],
                                                [0.3, -0.6, 0.9]]),
        wavevectors=k * np.array([[0.9, 0.3, 0.2], [-0.2, 0.7, 0.5], [0.4, -0.3, 0.8]]),
        phases=np.array([0.3, 1.1, -0.7]))


def l2_error(basis, dofs, exact, intorder=6):
    """(||u_h - u||_L2, ||u||_L2) over the solution's mesh, with quadrature of order
    ``intorder`` (above the element's, so that the error is the element's)."""
    if intorder < 2:
        raise ModelError(f"intorder must be at least 2, got {intorder}")
    fine = Basis(basis.mesh, basis.elem, intorder=intorder)
    uh = fine.interpolate(dofs)

    @Functional
    def err(w):
        d = w["uh"] - np.moveaxis(exact(np.moveaxis(w.x, 0, -1)), -1, 0)
        return np.sum(d * d, axis=0)

    @Functional
    def norm(w):
        e = np.moveaxis(exact(np.moveaxis(w.x, 0, -1)), -1, 0)
        return np.sum(e * e, axis=0)
    return float(np.sqrt(err.assemble(fine, uh=uh))), float(np.sqrt(norm.assemble(fine)))




def prescribed_faces(points, size, faces="xyz"):
    """Mask of ``points`` on the faces ``faces`` of the cube [0, size]^3: a lower-case axis is
    its face at 0, an upper-case one its face at ``size``."""
    p = np.asarray(points, float)
    on = np.zeros(p.shape[:-1], bool)
    tol = 1e-9 * size
    for ax in faces:
        c = "xyz".index(ax.lower())
        on |= np.abs(p[..., c] - (size if ax.isupper() else 0.0)) < tol
    return on


def solve(mesh, problem, size, element="P1", mixed=False, faces="xyz", load_steps=1,
          start=None):
    """The FEM solution of ``problem`` (a Manufactured) on ``mesh``, the cube [0, size]^3: the
    field prescribed on ``faces``, its traction on the others, its body force inside; linear
    FEM for the linear material, Newton in ``load_steps`` for the neo-Hookean one
    (displacement form, or Taylor-Hood P2/P1 when ``mixed``), or from ``start``, the result
    on a coarser mesh of the same cube (``reference.hyperelastic.solve``'s nested iteration:
    the same solution to Newton's tolerance in fewer iterations).
    Returns (||u_h - u|| / ||u|| in L2, the result)."""
    from . import hyperelastic, linear
    u = problem.field.u
    on = prescribed_faces(mesh.points, size, faces)
    if not on.any():
        raise ModelError(f"no node of the mesh lies on the faces {faces!r} of the cube of "
                         f"side {size} m: pass the mesh of that cube")
    bc = {int(i): tuple(u(mesh.points[i])) for i in np.flatnonzero(on)}

    def dirichlet_fn(p):
        return np.where(prescribed_faces(p, size, faces)[:, None], u(p), np.nan)
    kw = dict(body_force=problem.body_force, traction=problem.traction, element=element,
              dirichlet_fn=dirichlet_fn)
    if isinstance(problem.law, LinearElastic):
        if mixed:
            raise ModelError("the linear reference has no mixed form: pass mixed=False")
        res = linear.solve(mesh, problem.material, bc, **kw)
    else:
        res = hyperelastic.solve(mesh, problem.material, bc, mixed=mixed,
                                 load_steps=load_steps, start=start, **kw)
    e, n = l2_error(res.basis, res.dofs[:res.basis.N], u)
    return e / n, res


__all__ = ["PlaneWaves", "LinearElastic", "NeoHookean", "Manufactured", "manufactured",
           "waves", "l2_error", "prescribed_faces", "solve"]
