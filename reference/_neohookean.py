"""Element kernels of the compressible neo-Hookean law (``model.material``: its energy and
stress, the ones the FEM term uses), displacement and mixed (u, p) forms.

    W(F) = mu/2 (F:F - 3) - mu ln J + lam/2 (ln J)^2
    P    = mu (F - F^-T) + lam ln J F^-T
    A_iJkL = dP_iJ / dF_kL = mu d_ik d_JL + (mu - lam ln J) Fi_Jk Fi_Li + lam Fi_Ji Fi_Lk

with Fi = F^-1. The mixed form replaces lam ln J by an independent pressure p (P1):

    Pi(u, p) = W_dev(F) + p ln J - p^2 / (2 lam),   W_dev = mu/2 (F:F - 3) - mu ln J,

whose stationarity in p gives p = lam ln J back, so both forms solve the same law; the mixed
one keeps P2 accurate as lam / mu grows (nu -> 1/2).

A local dof a of the vector basis carries component comp[a] and has the scalar gradient
grad[e, q, a] (as ``reference.assembly.scalar_gradients`` gives them); with
t_a = grad_a . Fi (t_a[m] = sum_J grad_a[J] Fi[J, m]):

    r_a     = sum_q P[comp_a] . grad_a dx
    K_ab    = sum_q (mu d_ik grad_a . grad_b + c t_a[k] t_b[i] + lam t_a[i] t_b[k]) dx
    K_ap    = sum_q t_a[comp_a] psi_m dx           (mixed: the u-p block)

with i = comp_a, k = comp_b, c = mu - lam ln J (mixed: c = mu - p, no lam term).
"""
import numpy as np
from numba import njit

from model.material import neohookean_energy, neohookean_stress


@njit(cache=True)
def _inverse3(F, Fi):
    """Fi = F^-1; returns det F."""
    det = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
           - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
           + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
    Fi[0, 0] = (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1]) / det
    Fi[0, 1] = (F[0, 2] * F[2, 1] - F[0, 1] * F[2, 2]) / det
    Fi[0, 2] = (F[0, 1] * F[1, 2] - F[0, 2] * F[1, 1]) / det
    Fi[1, 0] = (F[1, 2] * F[2, 0] - F[1, 0] * F[2, 2]) / det
    Fi[1, 1] = (F[0, 0] * F[2, 2] - F[0, 2] * F[2, 0]) / det
    Fi[1, 2] = (F[0, 2] * F[1, 0] - F[0, 0] * F[1, 2]) / det
    Fi[2, 0] = (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]) / det
    Fi[2, 1] = (F[0, 1] * F[2, 0] - F[0, 0] * F[2, 1]) / det
    Fi[2, 2] = (F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]) / det
    return det


@njit(cache=True)
def neohookean(grad, comp, dx, ue, psi, pe, lam, mu, mixed, tangent, r_u, r_p, k_uu, k_up,
               k_pp):
    """Residuals, tangent blocks and energy of every element; returns (energy, the first
    element found inverted or -1).

    grad (nel, nqp, nb, 3), comp (nb,), dx (nel, nqp): the vector basis; ue (nel, nb) the
    element displacements; psi (nel, nqp, npb) and pe (nel, npb) the pressure basis and
    element pressures (read when ``mixed``). Outputs, overwritten: r_u (nel, nb), r_p (nel,
    npb), and when ``tangent`` k_uu (nel, nb, nb), k_up (nel, nb, npb), k_pp (nel, npb, npb).
    """
    nel, nqp, nb = grad.shape[0], grad.shape[1], grad.shape[2]
    npb = psi.shape[2]
    F = np.empty((3, 3))
    Fi = np.empty((3, 3))
    t = np.empty((nb, 3))
    energy = 0.0
    for e in range(nel):
        r_u[e, :] = 0.0
        r_p[e, :] = 0.0
        if tangent:
            k_uu[e, :, :] = 0.0
            k_up[e, :, :] = 0.0
            k_pp[e, :, :] = 0.0
        for q in range(nqp):
            w = dx[e, q]
            for i in range(3):
                for J in range(3):
                    F[i, J] = 1.0 if i == J else 0.0
            for a in range(nb):
                for J in range(3):
                    F[comp[a], J] += ue[e, a] * grad[e, q, a, J]
            det = _inverse3(F, Fi)
            if not det > 0.0:
                return energy, e
            lnJ = np.log(det)
            I1 = 0.0
            for i in range(3):
                for J in range(3):
                    I1 += F[i, J] * F[i, J]
            p = 0.0
            if mixed:
                for m in range(npb):
                    p += pe[e, m] * psi[e, q, m]
                energy += (neohookean_energy(I1, lnJ, 0.0, mu) + p * lnJ
                           - 0.5 * p * p / lam) * w
                for m in range(npb):
                    r_p[e, m] += (lnJ - p / lam) * psi[e, q, m] * w
                ca, cb = mu, p - mu          # the law's stress with lam ln J read as p
            else:
                p = lam * lnJ
                energy += neohookean_energy(I1, lnJ, lam, mu) * w
                ca, cb = neohookean_stress(lnJ, lam, mu)
            # P = ca F + cb Fi^T
            for a in range(nb):
                i = comp[a]
                for m in range(3):
                    t[a, m] = (grad[e, q, a, 0] * Fi[0, m] + grad[e, q, a, 1] * Fi[1, m]
                               + grad[e, q, a, 2] * Fi[2, m])
                ga = grad[e, q, a]
                r_u[e, a] += (ca * (F[i, 0] * ga[0] + F[i, 1] * ga[1] + F[i, 2] * ga[2])
                              + cb * t[a, i]) * w
            if not tangent:
                continue
            c = mu - p
            geo = 0.0 if mixed else lam
            for a in range(nb):
                i = comp[a]
                ga = grad[e, q, a]
                for b in range(a, nb):
                    k = comp[b]
                    s = c * t[a, k] * t[b, i] + geo * t[a, i] * t[b, k]
                    if i == k:
                        gb = grad[e, q, b]
                        s += mu * (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2])
                    k_uu[e, a, b] += s * w
                if mixed:
                    for m in range(npb):
                        k_up[e, a, m] += t[a, i] * psi[e, q, m] * w
            if mixed:
                for m in range(npb):
                    for n in range(npb):
                        k_pp[e, m, n] -= psi[e, q, m] * psi[e, q, n] * w / lam
        if tangent:
            for a in range(nb):
                for b in range(a + 1, nb):
                    k_uu[e, b, a] = k_uu[e, a, b]
    return energy, -1
