"""Shear term, the paper's equations 4 and 5 (MODEL.md "Shear strain" and "Shear force").

At corner a of a tetrahedron, tip j, base face F = (a, m, l) with in-plane edge m:

    gamma(a, j, m) = (d . e) / (d . n) - [the same at rest],   d = x_j - x_a,
    e = (x_m - x_a) / |x_m - x_a|,  n the unit normal of F towards j.

With c = (x_m - x_a) x (x_l - x_a) (|c| = 2 S_F) the height is d . n = 6 V / |c|, so
gamma = (d . e) |c| / (6 V) - gamma_0: 24 strains per tetrahedron, tau = G gamma.

Readings of the force (``reading``):

* ``corner``   f_a += (1/4) tau S_F e, on corner a alone (literal eq. 5). The sign is the one
  that restores: gamma grows when the tip moves along +e relative to a, and moving a along +e
  undoes that (checked in tests/test_terms.py). Momentum is not conserved.
* ``balanced`` f_j -= tau S_F e on the tip, its reaction split equally on a, m, l.
* ``variational`` f = -dW/dx with W = (c/2) G V0 sum gamma^2, every derivative taken.
"""
import numpy as np
from numba import njit

from . import Term, register
from ._kernels import (FACE, apply_laplacian, cross, dot, scatter, tet_frame,
                       volume_gradient_numpy)
from .volume import FLAT
from ..errors import ModelError, DegenerateTetError

# (a, j, m, l): corner, tip, in-plane edge end, the other base vertex
COMBOS = np.array([(a, j, m, l) for a in range(4) for j in range(4) if j != a
                   for m in range(4) if m not in (a, j)
                   for l in range(4) if l not in (a, j, m)], dtype=np.int64)
# +1 when (a, m, l, j) is an even permutation of (0, 1, 2, 3)
_PARITY = np.array([round(np.linalg.det(np.eye(4)[[a, m, l, j]])) for a, j, m, l in COMBOS])
READINGS = {"corner": 0, "balanced": 1, "variational": 2}


# Every kernel below works on one tetrahedron at a time: the edges d[a, b], 6V, the face
# vectors c[j] (|c[j]| = 2 S_j) and the lengths L once, then the 24 strains
#     gamma_s = q |c_j| / (6V) - gamma0_s,   q = d[a, j] . d[a, m] / L[a, m].
# The forces of the corner and balanced readings and the q-part of the variational gradient
# are sums of coefficients times edges x_b - x_a: they are gathered in a 4 x 4 matrix M and
# applied once (apply_laplacian).


@njit(cache=True, fastmath=True)
def shear_strains(x, tets, gamma0, gamma_out):
    """The 24 strains of every tetrahedron into gamma_out (m, 24); returns the first
    flattened tetrahedron (6V <= 0), or -1."""
    d, c, cn, iL = np.empty((4, 4, 3)), np.empty((4, 3)), np.empty(4), np.empty((4, 4))
    for t in range(tets.shape[0]):
        V6 = tet_frame(x, tets, t, d, c, cn, iL)
        if V6 <= 0.0:
            return t
        for j in range(4):
            cn[j] /= V6                  # 1 / height over the face opposite j
        for s in range(24):
            a, j, m = COMBOS[s, 0], COMBOS[s, 1], COMBOS[s, 2]
            gamma_out[t, s] = dot(d[a, j], d[a, m]) * iL[a, m] * cn[j] - gamma0[t, s]
    return -1


@njit(cache=True, fastmath=True)
def shear_corner(x, tets, vol0, gamma0, G, out):
    """Literal eq. 5: f_a += (1/4) tau S_F e, tau = G gamma, S_F = |c_j| / 2, e = d[a, m] / L."""
    d, c, cn, iL = np.empty((4, 4, 3)), np.empty((4, 3)), np.empty(4), np.empty((4, 4))
    M, ft = np.empty((4, 4)), np.empty((4, 3))
    for t in range(tets.shape[0]):
        V6 = tet_frame(x, tets, t, d, c, cn, iL)
        if V6 <= FLAT * 6.0 * vol0[t]:
            return t
        iV6 = 1.0 / V6
        M[:] = 0.0
        for s in range(24):
            a, j, m = COMBOS[s, 0], COMBOS[s, 1], COMBOS[s, 2]
            gamma = dot(d[a, j], d[a, m]) * iL[a, m] * cn[j] * iV6 - gamma0[t, s]
            w = 0.125 * G * gamma * cn[j] * iL[a, m]   # (1/4) tau S_F / L on the edge a -> m
            M[a, m] += w
            M[a, a] -= w
        ft[:] = 0.0
        apply_laplacian(M, d, ft)
        scatter(tets, t, ft, out)
    return -1


@njit(cache=True, fastmath=True)
def shear_balanced(x, tets, vol0, gamma0, G, out):
    """f_j -= tau S_F e on the tip, + tau S_F e / 3 on each base vertex a, m, l."""
    d, c, cn, iL = np.empty((4, 4, 3)), np.empty((4, 3)), np.empty(4), np.empty((4, 4))
    M, ft = np.empty((4, 4)), np.empty((4, 3))
    for t in range(tets.shape[0]):
        V6 = tet_frame(x, tets, t, d, c, cn, iL)
        if V6 <= FLAT * 6.0 * vol0[t]:
            return t
        iV6 = 1.0 / V6
        M[:] = 0.0
        for s in range(24):
            a, j, m, l = COMBOS[s, 0], COMBOS[s, 1], COMBOS[s, 2], COMBOS[s, 3]
            gamma = dot(d[a, j], d[a, m]) * iL[a, m] * cn[j] * iV6 - gamma0[t, s]
            w = 0.5 * G * gamma * cn[j] * iL[a, m]     # tau S_F / L on the edge a -> m
            for i in range(4):                         # f_i += coef_i (x_m - x_a)
                coef = -w if i == j else w / 3.0
                M[i, m] += coef
                M[i, a] -= coef
        ft[:] = 0.0
        apply_laplacian(M, d, ft)
        scatter(tets, t, ft, out)
    return -1


@njit(cache=True, fastmath=True)
def shear_variational(x, tets, vol0, gamma0, cG, out):
    """f = -dW/dx, W = (c/2) G V0 sum_s gamma_s^2 (cG = c G). With w_s = c G V0 gamma_s:

        dW = sum_s w_s [ |c_j|/(6V) dq + q/(6V) d|c_j| - gamma_raw d(6V)/(6V) ],
        dq = d(d_aj . d_am) / L_am - q dL_am / L_am.
    """
    d, c, cn, iL = np.empty((4, 4, 3)), np.empty((4, 3)), np.empty(4), np.empty((4, 4))
    M, ft, B, ch, g = np.empty((4, 4)), np.empty((4, 3)), np.empty(4), np.empty(3), np.empty(3)
    for t in range(tets.shape[0]):
        V6 = tet_frame(x, tets, t, d, c, cn, iL)
        if V6 <= FLAT * 6.0 * vol0[t]:
            return t
        iV6, cGV0 = 1.0 / V6, cG * vol0[t]
        M[:] = 0.0      # -dW from dq, as coefficients of edges
        B[:] = 0.0      # dW / d|c_j|
        A = 0.0         # dW / d(6V)
        for s in range(24):
            a, j, m = COMBOS[s, 0], COMBOS[s, 1], COMBOS[s, 2]
            q = dot(d[a, j], d[a, m]) * iL[a, m]
            raw = q * cn[j] * iV6
            w = cGV0 * (raw - gamma0[t, s])
            A -= w * raw * iV6
            B[j] += w * q * iV6
            k = w * cn[j] * iV6 * iL[a, m]              # dW/dD for D = d_aj . d_am
            # -k dD: f_j -= k d_am, f_m -= k d_aj, f_a += k (d_am + d_aj)
            M[j, m] -= k
            M[j, a] += k
            M[m, j] -= k
            M[m, a] += k
            M[a, m] += k
            M[a, j] += k
            M[a, a] -= 2.0 * k
            # -dW/dL_am = k q: f_m += r d_am, f_a -= r d_am, r = k q / L
            r = k * q * iL[a, m]
            M[m, m] += r
            M[m, a] -= r
            M[a, m] -= r
            M[a, a] += r
        ft[:] = 0.0
        apply_laplacian(M, d, ft)
        for j in range(4):
            # -A d(6V)/dx_j = -A c[j]; -B_j d|c_j|/dx over the face (a, m, l) of c_j
            a, m, l = FACE[j, 0], FACE[j, 1], FACE[j, 2]
            for k in range(3):
                ft[j, k] -= A * c[j, k]
                ch[k] = B[j] * c[j, k] / cn[j]   # B_j c_hat
            cross(d[a, l], ch, g)      # d|c|/dx_m = d_al x c_hat
            for k in range(3):
                ft[m, k] -= g[k]
                ft[a, k] += g[k]
            cross(ch, d[a, m], g)      # d|c|/dx_l = c_hat x d_am
            for k in range(3):
                ft[l, k] -= g[k]
                ft[a, k] += g[k]
        scatter(tets, t, ft, out)
    return -1


KERNELS = {0: shear_corner, 1: shear_balanced, 2: shear_variational}


def strains_numpy(x, tets, gamma0):
    """Plain-numpy strains (m, 24), with S_F (m, 24), e (m, 24, 3) and the volumes."""
    V, _ = volume_gradient_numpy(x, tets)
    gam, area, evec = (np.empty((len(tets), 24)), np.empty((len(tets), 24)),
                       np.empty((len(tets), 24, 3)))
    for s, (a, j, m, l) in enumerate(COMBOS):
        xa = x[tets[:, a]]
        u, w, d = x[tets[:, m]] - xa, x[tets[:, l]] - xa, x[tets[:, j]] - xa
        cn = np.linalg.norm(np.cross(u, w), axis=1)
        e = u / np.linalg.norm(u, axis=1)[:, None]
        # unit normal of F towards j: the orientation of (a, m, l, j) fixes the side
        n = _PARITY[s] * np.cross(u, w) / cn[:, None]
        height = np.einsum("ij,ij->i", d, n)
        gam[:, s] = np.einsum("ij,ij->i", d, e) / height - gamma0[:, s]
        area[:, s], evec[:, s] = 0.5 * cn, e
    return gam, area, evec, V


@register
class Shear(Term):
    """Shear stresses from the 24 corner shear strains of each tetrahedron (paper eqs. 4-5).

    Parameters
    ----------
    reading : ``corner`` | ``balanced`` | ``variational`` (see the module docstring).
    c : calibration of ``variational``: ``"auto"`` (fitted by :func:`model.build` so that a
        homogeneous deviatoric strain gives G |dev eps|^2 per unit volume) or a number.
    """

    name = "shear"
    checks_inversion = True
    params = {"reading": "variational", "c": "auto"}

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        if self.p["reading"] not in READINGS:
            raise ModelError(f"shear reading {self.p['reading']!r} unknown; choose one of "
                             f"{', '.join(READINGS)}")
        self.reading = READINGS[self.p["reading"]]
        self.conservative = self.p["reading"] == "variational"
        c = self.p["c"]
        if c != "auto" and not (isinstance(c, (int, float)) and np.isfinite(c) and c > 0):
            raise ModelError(f"shear c must be 'auto' or a positive number, got {c!r}")
        self.coef = None if c == "auto" else float(c)
        self.calibrate = self.conservative and c == "auto"
        self.G = material.G  # scale multiplies forces and energy after calibration
        self.vol0 = mesh.volumes
        self.gamma0 = np.zeros((mesh.n_tets, 24))
        self.gamma0 = self.strains(mesh.points)

    def describe(self):
        return f"shear/{self.p['reading']}"

    def info(self):
        out = super().info()
        if self.conservative:
            out["c"] = self.coef
        return out

    def strains(self, x):
        """The 24 shear strains (m, 24) at positions x."""
        gam = np.empty((self.mesh.n_tets, 24))
        bad = shear_strains(np.ascontiguousarray(x, dtype=np.float64), self.mesh.tets,
                            self.gamma0, gam)
        if bad >= 0:
            raise DegenerateTetError(f"tetrahedron {bad} is inverted or flattened", [bad])
        return gam

    def max_tau(self, x):
        """Maximum |tau| = G max |gamma| per tetrahedron (the paper's Figure 1), material G."""
        return self.material.G * np.abs(self.strains(x)).max(axis=1)

    def kernel(self):
        if self.reading == 2 and self.coef is None:
            raise ModelError("variational shear with c='auto' is not calibrated yet: "
                             "build the model with model.build, or pass a number for c")
        k = self.scale * self.G * (self.coef if self.reading == 2 else 1.0)
        return KERNELS[self.reading], (self.mesh.tets, self.vol0, self.gamma0, k)

    def forces_numpy(self, x):
        tets = self.mesh.tets
        gam, area, e, V = strains_numpy(x, tets, self.gamma0)
        tau_area = (self.scale * self.G * gam * area)[..., None] * e  # (m, 24, 3)
        out = np.zeros_like(x)
        a, j, m, l = COMBOS.T
        if self.reading == 0:
            np.add.at(out, tets[:, a], 0.25 * tau_area)
        elif self.reading == 1:
            np.add.at(out, tets[:, j], -tau_area)
            for base in (a, m, l):
                np.add.at(out, tets[:, base], tau_area / 3.0)
        else:
            # gradient of gamma by its definition q |c| / (6 V), one combination at a time
            _, dV = volume_gradient_numpy(x, tets)
            for s, (a, j, m, l) in enumerate(COMBOS):
                xa = x[tets[:, a]]
                u, w, d = x[tets[:, m]] - xa, x[tets[:, l]] - xa, x[tets[:, j]] - xa
                c = np.cross(u, w)
                cn = np.linalg.norm(c, axis=1)[:, None]
                un = np.linalg.norm(u, axis=1)[:, None]
                ev = u / un
                q = np.einsum("ij,ij->i", d, ev)[:, None]
                graw = q * cn / (6 * V[:, None])
                dq = {j: ev, m: (d - q * ev) / un}
                dq[a] = -(dq[j] + dq[m])
                dc = {m: np.cross(w, c / cn), l: np.cross(c / cn, u)}
                dc[a] = -(dc[m] + dc[l])
                coef = (self.scale * self.coef * self.G * self.vol0 * gam[:, s])[:, None]
                for i in (a, j, m, l):
                    grad = (cn * dq.get(i, 0.0) + q * dc.get(i, 0.0)) / (6 * V[:, None]) \
                        - graw * dV[:, i] / V[:, None]
                    np.add.at(out, tets[:, i], -coef * grad)
        return out

    def calibration_residuals(self, x, rows):
        """The strains gamma (r, 24) of the tetrahedra ``rows`` and their weights G V0 / 2:
        unit_energy = sum w gamma^2."""
        tets, g0 = self.mesh.tets[rows], self.gamma0[rows]
        gam = np.empty(g0.shape)
        bad = shear_strains(np.ascontiguousarray(x, dtype=np.float64), tets, g0, gam)
        if bad >= 0:
            raise DegenerateTetError(f"tetrahedron {bad} is inverted or flattened", [bad])
        return gam, 0.5 * self.G * self.vol0[rows]

    def unit_energy(self, x):
        """Energy of the variational reading with c = 1 and scale 1: (1/2) G V0 sum gamma^2
        (what calibration fits, so that ``scale`` survives it)."""
        return float(0.5 * self.G * np.sum(self.vol0[:, None] * self.strains(x) ** 2))

    def energy(self, x):
        if not self.conservative:
            return super().energy(x)
        return self.scale * self.coef * self.unit_energy(x)
