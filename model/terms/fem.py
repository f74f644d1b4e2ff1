"""Explicit FEM baselines (docs/model.md "Explicit FEM baselines"): constant-strain tetrahedra with
F = Ds Dm^-1 and nodal forces f = -V0 P(F) Dm^-T, driven by the same RK4 as the particle
model. What a simulation engineer would pick instead, at the same cost budget.

* ``fem_linear``: small strain, eps = sym(F) - I, P = sigma = lam tr(eps) I + 2 mu eps;
  W = V0 (mu eps:eps + lam/2 tr(eps)^2). Linear in x: its statics are linear FEM P1.
* ``fem_corotated``: the rotation R of F = R S (polar decomposition) removed,
  W = V0 (mu |S - I|^2 + lam/2 tr(S - I)^2), P = R (2 mu (S - I) + lam tr(S - I) I). This is
  the warped stiffness of M. Mueller and M. Gross, "Interactive virtual materials", Graphics
  Interface 2004 (SOFA's TetrahedronFEMForceField, method "large", uses a polar or QR
  rotation), which with the polar R is the exact gradient of W (A. McAdams et al.,
  "Efficient elasticity for character skinning with contact and collisions", SIGGRAPH 2011).
* ``fem_neohookean``: W = V0 (mu/2 (tr C - 3) - mu ln J + lam/2 (ln J)^2),
  P = mu (F - F^-T) + lam ln J F^-T, the law of ``reference.hyperelastic``.

All three are conservative, conserve momentum and need no calibration.
"""
import numpy as np
from numba import njit

from . import Term, register
from ..material import neohookean_energy, neohookean_stress
from ._blocks import B, FAST, FLAG, INLINED, OPTIONS, OUT, SCRATCH, ahead, blocked, blocked_tets, first_flat, \
    gather, scatter, scatter_routed
from ._constant_strain import RestShape
from ._kernels import (add_piola_forces, cofactor, cross, deformation_gradient,
                       dot, lin, piola_forces_numpy,
                       sub)
from ._threads import split_of
from .volume import FLAT


@njit(cache=True, inline="always")
def linear_piola(F, lam, mu):
    """P = 2 mu eps + lam tr(eps) I, eps = sym(F) - I."""
    s = lam * (F[0][0] + F[1][1] + F[2][2] - 3.0) - 2.0 * mu
    return ((2.0 * mu * F[0][0] + s, mu * (F[0][1] + F[1][0]), mu * (F[0][2] + F[2][0])),
            (mu * (F[1][0] + F[0][1]), 2.0 * mu * F[1][1] + s, mu * (F[1][2] + F[2][1])),
            (mu * (F[2][0] + F[0][2]), mu * (F[2][1] + F[1][2]), 2.0 * mu * F[2][2] + s))


@njit(cache=True, fastmath=True)
def linear_forces(x, tets, Dinv, vol0, lam, mu, out):
    """Small-strain constant-strain tetrahedra; returns the first flattened one, or -1."""
    for t in range(tets.shape[0]):
        F, J = deformation_gradient(x, tets, t, Dinv)
        if J <= FLAT:
            return t
        add_piola_forces(linear_piola(F, lam, mu), Dinv, vol0, tets, t, out)
    return -1


@njit(inline="always", fastmath=FAST, error_model="numpy")
def lane_gradient(s, p, i):
    """F = Ds Dm^-1 of lane i of a block (corners in s, Dm^-1 row by row in p) and its
    flattening margin det F - FLAT."""
    x0 = (s[i], s[B + i], s[2 * B + i])
    e1 = sub((s[3 * B + i], s[4 * B + i], s[5 * B + i]), x0)
    e2 = sub((s[6 * B + i], s[7 * B + i], s[8 * B + i]), x0)
    e3 = sub((s[9 * B + i], s[10 * B + i], s[11 * B + i]), x0)
    r0, r1, r2 = ((p[i], p[B + i], p[2 * B + i]), (p[3 * B + i], p[4 * B + i], p[5 * B + i]),
                  (p[6 * B + i], p[7 * B + i], p[8 * B + i]))
    F = (lin(e1[0], r0, 1.0, lin(e2[0], r1, e3[0], r2)),
         lin(e1[1], r0, 1.0, lin(e2[1], r1, e3[1], r2)),
         lin(e1[2], r0, 1.0, lin(e2[2], r1, e3[2], r2)))
    return F, dot(F[0], cross(F[1], F[2])) - FLAT


@njit(inline="always", fastmath=FAST, error_model="numpy")
def lane_forces(s, p, i, P):
    """The forces -V0 P Dm^-T of lane i into the block's output rows of s: corners 1..3
    -V0 P (row c of Dm^-1), corner 0 minus their sum."""
    v = p[9 * B + i]
    f0 = (0.0, 0.0, 0.0)
    for c in range(3):
        rc = (p[3 * c * B + i], p[(3 * c + 1) * B + i], p[(3 * c + 2) * B + i])
        f = (-v * dot(P[0], rc), -v * dot(P[1], rc), -v * dot(P[2], rc))
        for k in range(3):
            s[OUT + (3 * c + 3 + k) * B + i] = f[k]
        f0 = sub(f0, f)
    for k in range(3):
        s[OUT + k * B + i] = f0[k]


@njit(**INLINED)
def linear_block(s, blk, data, lam, mu):
    """Small-strain forces of block blk's lanes (``data``: Dm^-1 and V0 per tetrahedron in
    the blocked layout, as the co-rotated block's); returns the count of lanes with
    det F <= FLAT."""
    p = data[blk * 10 * B:(blk + 1) * 10 * B]
    n_flat = 0
    for i in range(B):
        F, margin = lane_gradient(s, p, i)
        s[FLAG + i] = margin
        n_flat += margin <= 0.0
        lane_forces(s, p, i, linear_piola(F, lam, mu))
    return n_flat


@njit(**INLINED)
def neohookean_block(s, blk, data, lam, mu):
    """Neo-Hookean forces of block blk's lanes (as :func:`linear_block`); a flattened lane's
    stress is not used (its log is taken of a clamped J)."""
    p = data[blk * 10 * B:(blk + 1) * 10 * B]
    n_flat = 0
    for i in range(B):
        F, margin = lane_gradient(s, p, i)
        s[FLAG + i] = margin
        n_flat += margin <= 0.0
        J = max(margin + FLAT, FLAT)
        lane_forces(s, p, i, neohookean_piola(F, J, lam, mu))
    return n_flat


@njit(cache=True, inline="always")
def polar_rotation(F):
    """R of F = R S by Newton's iteration R <- (R + R^-T) / 2 from R = F (det F > 0):
    quadratic convergence, stopped at 1e-14 or 30 iterations."""
    R = F
    for _ in range(30):
        C = cofactor(R)
        h = 0.5 / dot(R[0], C[0])                           # R^-T = cof(R) / det R
        Rn = (lin(0.5, R[0], h, C[0]), lin(0.5, R[1], h, C[1]), lin(0.5, R[2], h, C[2]))
        d0, d1, d2 = sub(Rn[0], R[0]), sub(Rn[1], R[1]), sub(Rn[2], R[2])
        change = max(abs(d0[0]), abs(d0[1]), abs(d0[2]), abs(d1[0]), abs(d1[1]), abs(d1[2]),
                     abs(d2[0]), abs(d2[1]), abs(d2[2]))
        R = Rn
        if change < 1e-14:
            break
    return R


POLAR = 19 * B     # the co-rotated block's own scratch: F (9 rows), R (9 rows), converged


@njit(**INLINED)
def corotated_block(s, r, blk, data, lam, mu):
    """Co-rotated forces of block blk's lanes (model/terms/_blocks.py): ``data`` holds each
    tetrahedron's Dm^-1 (row by row) and V0 in the blocked layout, F = Ds Dm^-1, P = 2 mu
    (F - R) + lam tr(R^T F - I) R, f_c = -V0 P (row c of Dm^-1) on corners 1..3 and minus
    their sum on corner 0. The polar rotation is :func:`polar_rotation`'s iteration run on all
    lanes at once: a lane that has converged keeps its R (the same R, lane by lane, as the
    tetrahedron-by-tetrahedron loop), and the block stops when every lane has. Returns the
    count of lanes with det F <= FLAT (which are not iterated)."""
    p = data[blk * 10 * B:(blk + 1) * 10 * B]
    n_flat = 0
    for i in range(B):
        F, margin = lane_gradient(s, p, i)
        s[FLAG + i] = margin
        n_flat += margin <= 0.0
        for a in range(3):
            for b in range(3):
                r[(3 * a + b) * B + i] = F[a][b]
                r[(9 + 3 * a + b) * B + i] = F[a][b]
        r[18 * B + i] = 1.0 if margin <= 0.0 else 0.0
    for _ in range(30):
        active = 0
        for i in range(B):
            R = ((r[9 * B + i], r[10 * B + i], r[11 * B + i]),
                 (r[12 * B + i], r[13 * B + i], r[14 * B + i]),
                 (r[15 * B + i], r[16 * B + i], r[17 * B + i]))
            C = cofactor(R)
            h = 0.5 / dot(R[0], C[0])
            Rn = (lin(0.5, R[0], h, C[0]), lin(0.5, R[1], h, C[1]), lin(0.5, R[2], h, C[2]))
            d0, d1, d2 = sub(Rn[0], R[0]), sub(Rn[1], R[1]), sub(Rn[2], R[2])
            change = max(abs(d0[0]), abs(d0[1]), abs(d0[2]), abs(d1[0]), abs(d1[1]),
                         abs(d1[2]), abs(d2[0]), abs(d2[1]), abs(d2[2]))
            keep = r[18 * B + i] > 0.0
            for a in range(3):
                for b in range(3):
                    r[(9 + 3 * a + b) * B + i] = R[a][b] if keep else Rn[a][b]
            done = keep or change < 1e-14
            r[18 * B + i] = 1.0 if done else 0.0
            active += not done
        if active == 0:
            break
    for i in range(B):
        F = ((r[i], r[B + i], r[2 * B + i]), (r[3 * B + i], r[4 * B + i], r[5 * B + i]),
             (r[6 * B + i], r[7 * B + i], r[8 * B + i]))
        R = ((r[9 * B + i], r[10 * B + i], r[11 * B + i]),
             (r[12 * B + i], r[13 * B + i], r[14 * B + i]),
             (r[15 * B + i], r[16 * B + i], r[17 * B + i]))
        tr = dot(R[0], F[0]) + dot(R[1], F[1]) + dot(R[2], F[2]) - 3.0    # tr(R^T F - I)
        P = (lin(2.0 * mu, F[0], lam * tr - 2.0 * mu, R[0]),
             lin(2.0 * mu, F[1], lam * tr - 2.0 * mu, R[1]),
             lin(2.0 * mu, F[2], lam * tr - 2.0 * mu, R[2]))
        lane_forces(s, p, i, P)
    return n_flat


LINEAR, COROTATED, NEOHOOKEAN = 0, 1, 2     # the laws of the constant-strain kernels


@njit(**INLINED)
def law_block(s, r, blk, data, lam, mu, law):
    """Block blk's lanes under ``law`` (LINEAR, COROTATED or NEOHOOKEAN)."""
    if law == LINEAR:
        return linear_block(s, blk, data, lam, mu)
    if law == COROTATED:
        return corotated_block(s, r, blk, data, lam, mu)
    return neohookean_block(s, blk, data, lam, mu)


@njit(**OPTIONS)
def constant_strain_forces(x, tb, m, data, lam, mu, law, out):
    """Constant-strain tetrahedra under ``law``, block by block; returns the first one with
    det F <= FLAT, or -1."""
    s = np.empty(SCRATCH)
    r = np.empty(POLAR)
    nb = (m + B - 1) // B
    for blk in range(nb):
        ahead(tb, blk, nb)
        ahead(data, blk, nb)
        gather(x, tb, blk, s)
        if law_block(s, r, blk, data, lam, mu, law) > 0:
            return first_flat(s, blk, m)
        scatter(out, tb, blk, m, s)
    return -1


@njit(**OPTIONS)
def constant_strain_range(x, tb, m, data, lam, mu, law, first, stop, late, route, buf, out):
    """constant_strain_forces over the blocks [first, stop), the forces of routed corners into
    buf (the threaded mode's twin: model.terms._threads.SplitBlocks)."""
    s = np.empty(SCRATCH)
    r = np.empty(POLAR)
    nb = (m + B - 1) // B
    for blk in range(first, stop):
        ahead(tb, blk, nb)
        ahead(data, blk, nb)
        gather(x, tb, blk, s)
        if law_block(s, r, blk, data, lam, mu, law) > 0:
            return first_flat(s, blk, m)
        if late[blk]:
            scatter_routed(out, tb, blk, m, s, route, buf)
        else:
            scatter(out, tb, blk, m, s)
    return -1


@njit(cache=True, fastmath=True)
def corotated_forces_reference(x, tets, Dinv, vol0, lam, mu, out):
    """Co-rotated constant-strain tetrahedra; returns the first flattened one, or -1.
    Tetrahedron by tetrahedron (the reference of ``constant_strain_forces``)."""
    for t in range(tets.shape[0]):
        F, J = deformation_gradient(x, tets, t, Dinv)
        if J <= FLAT:
            return t
        R = polar_rotation(F)
        tr = dot(R[0], F[0]) + dot(R[1], F[1]) + dot(R[2], F[2]) - 3.0    # tr(R^T F - I)
        # P = 2 mu (F - R) + lam tr(S - I) R
        P = (lin(2.0 * mu, F[0], lam * tr - 2.0 * mu, R[0]),
             lin(2.0 * mu, F[1], lam * tr - 2.0 * mu, R[1]),
             lin(2.0 * mu, F[2], lam * tr - 2.0 * mu, R[2]))
        add_piola_forces(P, Dinv, vol0, tets, t, out)
    return -1


@njit(cache=True, inline="always")
def neohookean_piola(F, J, lam, mu):
    """P = m F + b F^-T of the compressible neo-Hookean law (F^-T = cof(F) / J)."""
    m, b = neohookean_stress(np.log(J), lam, mu)
    a = b / J
    C = cofactor(F)
    return (lin(m, F[0], a, C[0]), lin(m, F[1], a, C[1]), lin(m, F[2], a, C[2]))


@njit(cache=True, fastmath=True)
def neohookean_forces(x, tets, Dinv, vol0, lam, mu, out):
    """Compressible neo-Hookean constant-strain tetrahedra; returns the first one with
    det F <= FLAT, or -1."""
    for t in range(tets.shape[0]):
        F, J = deformation_gradient(x, tets, t, Dinv)
        if J <= FLAT:
            return t
        add_piola_forces(neohookean_piola(F, J, lam, mu), Dinv, vol0, tets, t, out)
    return -1


class _ConstantStrain(RestShape, Term):
    """What the three baselines share: Dm^-1 and F (``RestShape``), V0, the Lame constants,
    and the kernels' data in the blocked layout (Dm^-1 row by row and V0, 10 per
    tetrahedron). A law gives its blocked kernel, its threaded twin and its
    tetrahedron-by-tetrahedron reference."""

    conservative = True
    law = None            # LINEAR, COROTATED or NEOHOOKEAN
    _reference = None     # the law's tetrahedron-by-tetrahedron kernel

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        self.vol0 = mesh.volumes
        self.lam, self.mu = self.scale * material.lam, self.scale * material.G
        self._blocked = (blocked_tets(mesh.tets), mesh.n_tets, blocked(
            np.concatenate([self.Dinv.reshape(-1, 9), self.vol0[:, None]], axis=1)))

    def kernel(self):
        return constant_strain_forces, (*self._blocked, self.lam, self.mu, self.law)

    def threaded_kernel(self):
        return split_of(self, self._blocked[0], self.mesh.n_tets, self.mesh.n_nodes).kernel(
            constant_strain_range, self.kernel()[1])

    def reference_kernel(self):
        return type(self)._reference, (self.mesh.tets, self.Dinv, self.vol0, self.lam,
                                       self.mu)

    def forces_numpy(self, x):
        return piola_forces_numpy(self.piola(self.F(x)), self.Dinv, self.vol0, self.mesh.tets,
                                  self.mesh.n_nodes)

    def tangent(self, x):
        """d f / d x (sparse, 3n x 3n) in closed form: the law's dP/dF (``stress_tangent``)
        assembled over the tetrahedra; what a Newton solve or an implicit step factorises,
        at the cost of a few force evaluations instead of a coloured finite difference's
        hundred."""
        return self.assemble_tangent(self.stress_tangent(self.F(x)), self.vol0)

    def energy(self, x):
        return float(np.sum(self.vol0 * self.energy_density(self.F(x))))


@register
class FemLinear(_ConstantStrain):
    """Small-strain linear elastic tetrahedra."""

    name = "fem_linear"
    # small strain: a finite rotation strains it, so its forces neither turn with the body
    # nor keep the torque zero
    rotation_invariant = False
    angular_momentum = False

    law = LINEAR
    _reference = staticmethod(linear_forces)

    def _eps(self, F):
        return 0.5 * (F + np.transpose(F, (0, 2, 1))) - np.eye(3)

    def piola(self, F):
        eps = self._eps(F)
        tr = np.trace(eps, axis1=1, axis2=2)[:, None, None]
        return self.lam * tr * np.eye(3) + 2 * self.mu * eps

    def energy_density(self, F):
        eps = self._eps(F)
        return self.mu * np.sum(eps**2, axis=(1, 2)) + 0.5 * self.lam * np.trace(
            eps, axis1=1, axis2=2)**2

    def stress_tangent(self, F):
        """dP_ij / dF_kl = lam d_ij d_kl + mu (d_ik d_jl + d_il d_jk), the same everywhere."""
        d = np.eye(3)
        C = (self.lam * np.einsum("ij,kl->ijkl", d, d)
             + self.mu * (np.einsum("ik,jl->ijkl", d, d) + np.einsum("il,jk->ijkl", d, d)))
        return np.broadcast_to(C, (len(F), 3, 3, 3, 3))


LEVI_CIVITA = np.zeros((3, 3, 3))
LEVI_CIVITA[0, 1, 2] = LEVI_CIVITA[1, 2, 0] = LEVI_CIVITA[2, 0, 1] = 1.0
LEVI_CIVITA[0, 2, 1] = LEVI_CIVITA[2, 1, 0] = LEVI_CIVITA[1, 0, 2] = -1.0


def polar_numpy(F):
    """R and S of F = R S for a stack of F, by the SVD."""
    U, _, Vt = np.linalg.svd(F)
    R = U @ Vt
    return R, np.transpose(R, (0, 2, 1)) @ F


@register
class FemCorotated(_ConstantStrain):
    """Co-rotated linear tetrahedra (polar rotation)."""

    name = "fem_corotated"

    law = COROTATED
    _reference = staticmethod(corotated_forces_reference)

    def piola(self, F):
        R, S = polar_numpy(F)
        tr = (np.trace(S, axis1=1, axis2=2) - 3)[:, None, None]
        return 2 * self.mu * (F - R) + self.lam * tr * R

    def energy_density(self, F):
        _, S = polar_numpy(F)
        E = S - np.eye(3)
        return self.mu * np.sum(E**2, axis=(1, 2)) + 0.5 * self.lam * np.trace(
            E, axis1=1, axis2=2)**2

    def stress_tangent(self, F):
        """dP/dF of P = 2 mu (F - R) + lam (tr S - 3) R, F = R S: along dF = E_km,
        dR = R [w]x with w = 2 (tr S I - S)^-1 a, a the axial vector of skew(R^T dF)
        (a_p = -1/2 e_imp R_ki: the skew part of R^T dF = [w]x S + dS), and d tr S = R_km."""
        R, S = polar_numpy(F)
        trS = np.trace(S, axis1=1, axis2=2)
        A = np.linalg.inv(trS[:, None, None] * np.eye(3) - S)
        a = -0.5 * np.einsum("imp,tki->tpkm", LEVI_CIVITA, R)
        w = 2.0 * np.einsum("tqp,tpkm->tqkm", A, a)
        dR = -np.einsum("til,ljq,tqkm->tijkm", R, LEVI_CIVITA, w, optimize=True)
        d = np.eye(3)
        return (2 * self.mu * (np.einsum("ik,jm->ijkm", d, d)[None] - dR)
                + self.lam * (np.einsum("tij,tkm->tijkm", R, R)
                              + (trS - 3)[:, None, None, None, None] * dR))


@register
class FemNeoHookean(_ConstantStrain):
    """Compressible neo-Hookean tetrahedra."""

    name = "fem_neohookean"
    law = NEOHOOKEAN
    _reference = staticmethod(neohookean_forces)

    def piola(self, F):
        m, b = neohookean_stress(np.log(np.linalg.det(F)), self.lam, self.mu)
        FinvT = np.transpose(np.linalg.inv(F), (0, 2, 1))
        return m * F + b[:, None, None] * FinvT

    def energy_density(self, F):
        return neohookean_energy(np.einsum("tij,tij->t", F, F), np.log(np.linalg.det(F)),
                                 self.lam, self.mu)

    def stress_tangent(self, F):
        """dP/dF of P = a F + b F^-T (a = mu, b = lam ln J - mu): a d_ik d_jl
        - b Finv_li Finv_jk + lam Finv_ji Finv_lk."""
        a, b = neohookean_stress(np.log(np.linalg.det(F)), self.lam, self.mu)
        Fi = np.linalg.inv(F)
        d = np.eye(3)
        return (a * np.einsum("ik,jl->ijkl", d, d)[None]
                - b[:, None, None, None, None] * np.einsum("tli,tjk->tijkl", Fi, Fi)
                + self.lam * np.einsum("tji,tlk->tijkl", Fi, Fi))
