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
from ._kernels import cross, dot, gather, volume_gradient, volume_gradient_numpy
from .volume import FLAT
from ..errors import ModelError, DegenerateTetError

# (a, j, m, l): corner, tip, in-plane edge end, the other base vertex
COMBOS = np.array([(a, j, m, l) for a in range(4) for j in range(4) if j != a
                   for m in range(4) if m not in (a, j)
                   for l in range(4) if l not in (a, j, m)], dtype=np.int64)
# +1 when (a, m, l, j) is an even permutation of (0, 1, 2, 3)
_PARITY = np.array([round(np.linalg.det(np.eye(4)[[a, m, l, j]])) for a, j, m, l in COMBOS])
READINGS = {"corner": 0, "balanced": 1, "variational": 2}


@njit(cache=True, fastmath=True)
def _shear(x, tets, vol0, gamma0, G, coef, reading, out, gamma_out):
    """Strains of every tetrahedron into gamma_out (m, 24) and, unless reading < 0, the
    forces of ``reading`` added into out (n, 3). Returns the first flattened tetrahedron,
    or -1. Loops run corner a, tip j, then the two in-plane edges m of the base
    (a, m, l), so that edge vectors and the base normal are computed once."""
    n_tets = tets.shape[0]
    xt, ee, dV = np.empty((4, 3)), np.empty((3, 3)), np.empty((4, 3))
    ed, en, eu = np.empty((4, 3)), np.empty(4), np.empty((4, 3))  # edges from corner a
    c, ch, gc, gr = np.empty(3), np.empty(3), np.empty((4, 3)), np.empty((4, 3))
    ft = np.empty((4, 3))  # this tetrahedron's nodal forces, added to out once
    for t in range(n_tets):
        ft[:] = 0.0
        gather(x, tets, t, xt)
        V = volume_gradient(xt, ee, dV)
        if V <= FLAT * vol0[t]:
            return t
        s = 0
        for a in range(4):
            for b in range(4):
                for k in range(3):
                    ed[b, k] = xt[b, k] - xt[a, k]
                en[b] = np.sqrt(dot(ed[b], ed[b])) if b != a else 1.0
                for k in range(3):
                    eu[b, k] = ed[b, k] / en[b]
            for j in range(4):
                if j == a:
                    continue
                m0 = 0
                while m0 == a or m0 == j:
                    m0 += 1
                l0 = 6 - a - j - m0
                cross(ed[m0], ed[l0], c)
                cn = np.sqrt(dot(c, c))
                for k in range(3):
                    ch[k] = c[k] / cn
                if reading == 2:  # d|c|/dx, shared by both in-plane edges
                    cross(ed[l0], ch, gc[m0])
                    cross(ch, ed[m0], gc[l0])
                    for k in range(3):
                        gc[j, k] = 0.0
                        gc[a, k] = -(gc[m0, k] + gc[l0, k])
                for mm in range(2):
                    m = m0 if mm == 0 else l0
                    l = l0 if mm == 0 else m0
                    q = dot(ed[j], eu[m])
                    graw = q * cn / (6.0 * V)
                    gamma = graw - gamma0[t, s]
                    gamma_out[t, s] = gamma
                    s += 1
                    if reading < 0:
                        continue
                    tau_area = G * gamma * 0.5 * cn  # tau S_F
                    if reading == 0:      # corner: on a alone, paper factor 1/4
                        for k in range(3):
                            ft[a, k] += 0.25 * tau_area * eu[m, k]
                    elif reading == 1:    # balanced: on the tip, reaction over the base
                        for k in range(3):
                            f = tau_area * eu[m, k]
                            ft[j, k] -= f
                            ft[a, k] += f / 3.0
                            ft[m, k] += f / 3.0
                            ft[l, k] += f / 3.0
                    else:                 # variational: -dW/dx, W = (c/2) G V0 gamma^2
                        for k in range(3):
                            gr[j, k] = cn * eu[m, k] / (6.0 * V)
                            gr[m, k] = (cn * (ed[j, k] - q * eu[m, k]) / en[m]
                                        + q * gc[m, k]) / (6.0 * V)
                            gr[l, k] = q * gc[l, k] / (6.0 * V)
                            gr[a, k] = -(gr[j, k] + gr[m, k] + gr[l, k])
                        s_w = coef * G * vol0[t] * gamma
                        for i in range(4):
                            for k in range(3):
                                ft[i, k] -= s_w * (gr[i, k] - graw * dV[i, k] / V)
        if reading >= 0:
            for i in range(4):
                for k in range(3):
                    out[tets[t, i], k] += ft[i, k]
    return -1


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
        self._gam = np.empty((mesh.n_tets, 24))  # reused by every force evaluation
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
        self._run(x, -1, np.zeros((1, 3)), gam)
        return gam

    def max_tau(self, x):
        """Maximum |tau| = G max |gamma| per tetrahedron (the paper's Figure 1), material G."""
        return self.material.G * np.abs(self.strains(x)).max(axis=1)

    def _run(self, x, reading, out, gam):
        bad = _shear(np.ascontiguousarray(x, dtype=np.float64), self.mesh.tets, self.vol0,
                     self.gamma0, self.scale * self.G, self.coef or 0.0, reading, out, gam)
        if bad >= 0 and reading < 0:
            raise DegenerateTetError(f"tetrahedron {bad} is inverted or flattened", [bad])
        return bad

    def _kernel_forces(self, x, out):
        if self.reading == 2 and self.coef is None:
            raise ModelError("variational shear with c='auto' is not calibrated yet: "
                             "build the model with model.build, or pass a number for c")
        return self._run(x, self.reading, out, self._gam)

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

    def unit_energy(self, x):
        """Energy of the variational reading with c = 1 and scale 1: (1/2) G V0 sum gamma^2
        (what calibration fits, so that ``scale`` survives it)."""
        return float(0.5 * self.G * np.sum(self.vol0[:, None] * self.strains(x) ** 2))

    def energy(self, x):
        if not self.conservative:
            return super().energy(x)
        return self.scale * self.coef * self.unit_energy(x)
