"""Calibration of auto-scaled energy terms against the isotropic deviatoric energy.

A term whose coefficient is ``"auto"`` writes its energy with coefficient 1 as a weighted sum
of squared strain measures, ``unit_energy(x) = sum_t w_t sum_k r_tk(x)^2`` with r = 0 at rest,
and offers ``calibration_residuals(x, rows)`` -> (r, w) for the tetrahedra ``rows``. Under a
homogeneous strain eps = sum_p a_p D_p over the orthonormal deviatoric basis D_p its energy is
a^T Q a + O(|a|^3) with Q = sum_t w_t J_t^T J_t, J_t = dr_t/da (central differences). The
coefficients c_i >= 0 are fitted jointly by non-negative least squares so that sum_i c_i Q_i
is closest (Frobenius) to G V I, the energy G |dev eps|^2 V. A term the fit sets to 0 (it only
moves the sum away from the target on this mesh) stays in the model with c = 0 and is named in
``calibration_dropped``; all of them at 0 is an error.
"""
import numpy as np
from scipy.optimize import nnls

from .errors import ModelError


def deviatoric_basis():
    """Five orthonormal (Frobenius) symmetric traceless 3x3 tensors."""
    s2 = np.sqrt(2.0)
    b = [np.diag([1.0, -1.0, 0.0]) / s2, np.diag([1.0, 1.0, -2.0]) / np.sqrt(6.0)]
    for i, j in ((0, 1), (1, 2), (0, 2)):
        d = np.zeros((3, 3))
        d[i, j] = d[j, i] = 1.0 / s2
        b.append(d)
    return np.array(b)


def quadratic_form(energy, points, basis, delta=1e-4):
    """Q with energy(X + delta eps X) = delta^2 a^T Q a + O(delta^4) (symmetric differences)
    from whole energies: slower than :func:`strain_quadratic_form`, the tests' check of it."""
    centred = points - points.mean(axis=0)

    def w(eps):
        return 0.5 * (energy(points + centred @ eps.T) + energy(points - centred @ eps.T))

    nb = len(basis)
    Q = np.empty((nb, nb))
    for k in range(nb):
        Q[k, k] = w(delta * basis[k]) / delta**2
    for k in range(nb):
        for l in range(k + 1, nb):
            Q[k, l] = Q[l, k] = 0.5 * (w(delta * (basis[k] + basis[l])) / delta**2
                                       - Q[k, k] - Q[l, l])
    return Q


def strain_quadratic_form(term, points, basis, delta=1e-4, chunk=1 << 16):
    """Q (p, p) of ``term``'s unit energy, from its strain measures by central differences,
    a chunk of tetrahedra at a time (memory stays at about chunk x 24 x p doubles)."""
    centred = points - points.mean(axis=0)
    moved = [(points + delta * centred @ B.T, points - delta * centred @ B.T) for B in basis]
    Q = np.zeros((len(basis), len(basis)))
    for start in range(0, term.mesh.n_tets, chunk):
        rows = slice(start, start + chunk)
        A = None    # sqrt(w_t) dr_tk/da_p as columns p, so that Q = A^T A (one BLAS product)
        for p, (plus, minus) in enumerate(moved):
            r_plus, w = term.calibration_residuals(plus, rows)
            r_minus, _ = term.calibration_residuals(minus, rows)
            col = (r_plus - r_minus).reshape(len(w), -1) * (np.sqrt(w) / (2 * delta))[:, None]
            if A is None:
                A = np.empty((col.size, len(basis)), order="F")
            A[:, p] = col.ravel()
        Q += A.T @ A
    return Q


def calibrate(terms, mesh, G):
    """Set ``coef`` of every term with ``calibrate`` true; return the fit's summary."""
    auto = [t for t in terms if getattr(t, "calibrate", False)]
    if not auto:
        return {}
    basis = deviatoric_basis()
    Qs = [strain_quadratic_form(t, mesh.points, basis) for t in auto]
    target = G * mesh.volumes.sum() * np.eye(len(basis))
    coefs, _ = nnls(np.stack([q.ravel() for q in Qs], axis=1), target.ravel())
    if not np.any(coefs > 0):
        raise ModelError(f"calibration of {', '.join(t.describe() for t in auto)} gave c = 0: "
                         "no term adds to the deviatoric fit on this mesh; pass a number for c")
    for t, c in zip(auto, coefs):
        t.coef = float(c)     # 0: the fit drops the term on this mesh (a finding, said in info)
    fitted = sum(c * q for c, q in zip(coefs, Qs)) / target[0, 0]
    eig = np.linalg.eigvalsh(fitted)
    # eigenvalues of the fitted deviatoric stiffness over G: all 1 for an isotropic model
    out = {"deviatoric_eig_min": float(eig.min()), "deviatoric_eig_max": float(eig.max())}
    dropped = [t.name for t, c in zip(auto, coefs) if not c > 0]
    if dropped:
        out["calibration_dropped"] = dropped
    return out
