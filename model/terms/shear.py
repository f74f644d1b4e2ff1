"""Shear term, the paper's equations 4 and 5 (docs/model.md "Shear strain" and "Shear force").

At corner a of a tetrahedron, tip j, base face F = (a, m, l) with in-plane edge m:

    gamma(a, j, m) = (d . e) / (d . n) - [the same at rest],   d = x_j - x_a,
    e = (x_m - x_a) / |x_m - x_a|,  n the unit normal of F towards j.

With c = (x_m - x_a) x (x_l - x_a) (|c| = 2 S_F) the height is d . n = 6 V / |c|, so
gamma = (d . e) |c| / (6 V) - gamma_0: 24 strains per tetrahedron, tau = G gamma.

Readings of the force (``reading``):

Every reading takes tau = c G gamma, c the factor ``c`` (1: the paper's literal constant;
"auto": calibrated alike for all three, :mod:`model.calibrate`).

* ``corner``   f_a += (1/4) tau S_F e, on corner a alone (literal eq. 5). The sign is the one
  that restores: gamma grows when the tip moves along +e relative to a, and moving a along +e
  undoes that (checked in tests/test_terms.py). Momentum is not conserved.
* ``balanced`` f_j -= tau S_F e on the tip, its reaction split equally on a, m, l.
* ``variational`` f = -dW/dx with W = (c/2) G V0 sum gamma^2, every derivative taken.
"""
import numpy as np

from . import CalibratedTerm, Fused, Term, register
from ._kernels import COMBOS, volume_gradient_numpy
from ._blocks import blocked, blocked_tets
from ._shear_kernels import (shear_balanced, shear_balanced_range, shear_balanced_reference,
                             shear_corner, shear_corner_range, shear_corner_reference,
                             shear_strains, shear_variational, shear_variational_range,
                             shear_variational_reference)
from ._threads import split_of
from ..errors import ModelError, DegenerateTetError

# the six edges p < q of a tetrahedron, in the order of the kernels' rest lengths
PAIRS = np.array([(p, q) for p in range(4) for q in range(p + 1, 4)])
# +1 when (a, m, l, j) is an even permutation of (0, 1, 2, 3)
_PARITY = np.array([round(np.linalg.det(np.eye(4)[[a, m, l, j]])) for a, j, m, l in COMBOS])
READINGS = {"corner": 0, "balanced": 1, "variational": 2}

# One kernel per reading, written out combination by combination by _shear_codegen.py (whose
# docstrings carry each reading's derivation): the edges d_ab, squared lengths l_ab, face
# vectors c_j and 6V once per tetrahedron, then the 24 strains
#     gamma_s = D / L_am * |c_j| / (6V) - gamma0_s,   D = d_aj . d_am = (l_aj + l_am - l_jm) / 2.
# The kernels run over blocks of tetrahedra (model/terms/_blocks.py); the references, the same
# maths tetrahedron by tetrahedron, are what the tests hold them to.
KERNELS = {0: shear_corner, 1: shear_balanced, 2: shear_variational}
RANGE = {0: shear_corner_range, 1: shear_balanced_range, 2: shear_variational_range}
REFERENCE = {0: shear_corner_reference, 1: shear_balanced_reference,
             2: shear_variational_reference}


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
class Shear(CalibratedTerm):
    """Shear stresses from the 24 corner shear strains of each tetrahedron (paper eqs. 4-5).

    Parameters
    ----------
    reading : ``corner`` | ``balanced`` | ``variational`` (see the module docstring).
    c : the factor on G, for every reading: ``"auto"`` (fitted by :func:`model.build` so that
        the deviatoric moduli of the model's effective tensor are closest to 2G, see
        :mod:`model.calibrate`) or a number (1: the paper's literal constant).
    """

    name = "shear"
    checks_inversion = True
    params = {"reading": "variational", "c": "auto"}
    fit_constant = "c"

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)   # c, coef, G, vol0
        if self.p["reading"] not in READINGS:
            raise ModelError(f"shear reading {self.p['reading']!r} unknown; choose one of "
                             f"{', '.join(READINGS)}")
        self.reading = READINGS[self.p["reading"]]
        # only the variational reading's forces are its energy's gradient
        self.conservative = self.p["reading"] == "variational"
        # the corner reading's forces do not sum to zero; the balanced reading's do, but
        # their torques do not (docs/model.md "Shear force")
        self.momentum = self.p["reading"] != "corner"
        self.angular_momentum = self.p["reading"] == "variational"
        self.gamma0 = np.zeros((mesh.n_tets, 24))
        self.gamma0 = self.strains(mesh.points)
        # the kernels' data in the blocked layout (model/terms/_blocks.py): the rest squared
        # edge lengths, from which a block computes gamma0 (a quarter of its bytes to stream)
        d = mesh.points[mesh.tets[:, PAIRS[:, 1]]] - mesh.points[mesh.tets[:, PAIRS[:, 0]]]
        self._blocked = (blocked_tets(mesh.tets), mesh.n_tets, blocked(self.vol0),
                         blocked(np.einsum("tpk,tpk->tp", d, d)))

    def describe(self):
        return f"shear/{self.p['reading']}"

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

    def kernel_args(self, k, K=0.0):
        return KERNELS[self.reading], (*self._blocked, self.G * k, K)

    def fuse(self, other):
        """The volume term's forces in the shear kernel's pass (its 6V and face vectors are
        the shear's own; the flattening test is the same), or None for another term."""
        if other.name != "volume" or other.mesh is not self.mesh:
            return None
        return Fused(self, other, lambda: self.kernel_args(self.scale * self.coef, other.K),
                     lambda fused: self._split().kernel(RANGE[self.reading], fused.kernel()[1]))

    def _split(self):
        return split_of(self, self._blocked[0], self.mesh.n_tets, self.mesh.n_nodes)

    def _factor(self):
        """The kernels' factor G c scale (kernel_args's, for the reference kernels)."""
        return self.G * (self.scale * self.coef)

    def reference_kernel(self):
        self.kernel()        # the same checks
        return REFERENCE[self.reading], (self.mesh.tets, self.vol0, self.gamma0, self._factor())

    def threaded_kernel(self):
        return self._split().kernel(RANGE[self.reading], self.kernel()[1])

    def forces_numpy(self, x):
        tets = self.mesh.tets
        gam, area, e, V = strains_numpy(x, tets, self.gamma0)
        tau_area = (self.scale * self.coef * self.G * gam * area)[..., None] * e  # (m, 24, 3)
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

    def energy(self, x):
        """The variational reading's energy (CalibratedTerm's: unit_energy, (1/2) G V0 sum
        gamma^2, what calibration fits for every reading, times scale and c); the other
        readings' forces have none."""
        if not self.conservative:
            return Term.energy(self, x)
        return super().energy(x)
