"""Calibration of the terms whose constant is ``c = "auto"``, every reading alike.

One criterion, for conservative and non-conservative terms: the model's effective tensor
C_eff (``model.homogenize``: a patch of the model's lattice, its surface moved by each unit
homogeneous strain, its interior relaxed) has five deviatoric Kelvin moduli mu_k (each 2G
for the isotropic material); the constants c_i >= 0 minimise sum_k (mu_k / 2G - 1)^2.
Forces are linear in each c_i, so the patch stiffness is K = K_0 + sum_i c_i K_i, with K_i the
finite-difference Jacobian of term i at c = 1, taken once: each trial c costs one sparse
factorisation of the patch interior. The patch is 8 x 8 x 8 cells of the mesh's lattice
(``TetMesh.lattice``: scheme, seed and spacing), so that a lattice gets one c whatever the size
of the body; a mesh without a lattice is its own patch. The start is the same fit without
the relaxation (every node moved affinely), which is linear in c: non-negative least squares.
A term the fit sets to 0 stays in the model with c = 0 and is named in
``calibration_dropped``; all of them at 0 is an error.

The quadratic forms of the unit energies under homogeneous deviatoric strain
(:func:`strain_quadratic_form`) remain: the tests check each conservative term's closed form
with them.
"""
import numpy as np
from scipy.optimize import least_squares, nnls

from .static import JacobianPattern, jacobian
from .errors import CalibrationDroppedError, ModelError
from .homogenize import condensed_stiffness, kelvin_moduli
from .geometry import radius_ratio
from .mesh import SLIVER_RADIUS_RATIO, _first, box


def deviatoric_basis():
    """Five orthonormal (Frobenius) symmetric traceless 3x3 tensors."""
    s2 = np.sqrt(2.0)
    b = [np.diag([1.0, -1.0, 0.0]) / s2, np.diag([1.0, 1.0, -2.0]) / np.sqrt(6.0)]
    for i, j in ((0, 1), (1, 2), (0, 2)):
        d = np.zeros((3, 3))
        d[i, j] = d[j, i] = 1.0 / s2
        b.append(d)
    return np.array(b)


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


_DEV_STRAINS = deviatoric_basis()

PATCH_NODES = 9     # the calibration patch: 8 x 8 x 8 cells of the model's lattice
_FITTED = {}        # (lattice, terms, material) -> (coefficients, summary): one fit a process


def calibration_patch(mesh):
    """The patch C_eff is fitted on: 8 x 8 x 8 cells of ``mesh``'s lattice, or the mesh."""
    if mesh.lattice is None:
        return mesh
    scheme, seed, h = mesh.lattice
    n = PATCH_NODES
    return box(n, n, n, *((n - 1) * np.asarray(h)), scheme, seed)


def _signature(terms, material):
    """What a fit depends on besides the lattice: each term's class and parameters (not its
    ``scale``, which multiplies the term after the fit, else c = auto would undo it)."""
    return (tuple((type(t).__module__, type(t).__qualname__,
                   tuple(sorted((k, repr(v)) for k, v in t.p.items()))) for t in terms),
            material.E, material.nu)


def _stiffnesses(terms, patch, material):
    """-df/dx at rest on the patch: the sum of the fixed terms', and each auto term's at
    c = 1 (the same term built on the patch), every term at scale 1 (scale multiplies after
    the fit)."""
    from .terms import make_term
    pattern = JacobianPattern(patch)
    fixed, unit = None, []
    for t in terms:
        params = {**t.p, "c": 1.0} if t.calibrate else dict(t.p)
        on_patch = make_term(t.name, patch, material, **params)
        K = -jacobian(on_patch.forces, patch, patch.points, pattern).tocsc()
        if t.calibrate:
            unit.append(K)
        else:
            fixed = K if fixed is None else fixed + K
    return fixed, unit


def _affine_start(fixed, unit, patch, G):
    """The fit without relaxation (all nodes moved affinely, linear in c): NNLS of the
    deviatoric blocks against 2G I."""
    x = patch.points - patch.points.mean(axis=0)
    B = _DEV_STRAINS
    U = np.stack([(x @ e.T).ravel() for e in B], axis=1)            # (3n, 5)
    V = float(patch.volumes.sum())

    def block(K):
        return np.zeros((5, 5)) if K is None else U.T @ (K @ U) / V  # energy form: 2G I

    target = 2 * G * np.eye(5) - block(fixed)
    A = np.stack([block(K).ravel() for K in unit], axis=1)
    c, _ = nnls(A, target.ravel())
    return c


def calibrate(terms, mesh, material, cache=True):
    """Set ``coef`` of every term with ``calibrate`` true (see the module docstring); return
    the fit's summary: the patch, and the fitted deviatoric moduli over 2G (all 1 for an
    isotropic model) and bulk modulus over K. A lattice's fit is kept for the process
    (``cache`` False: fit again, to time it)."""
    auto = [t for t in terms if getattr(t, "calibrate", False)]
    if not auto:
        return {}
    key = (None if mesh.lattice is None or not cache
           else (mesh.lattice, _signature(terms, material)))
    if key in _FITTED:
        coefs, out = _FITTED[key]
    else:
        coefs, out = _fit(terms, auto, mesh, material)
        if key is not None:
            _FITTED[key] = (coefs, out)
    for t, c in zip(auto, coefs):
        t.coef = float(c)     # 0: the fit drops the term on this mesh (a finding, said in info)
    dropped = [t.name for t, c in zip(auto, coefs) if not c > 0]
    return {**out, **({"calibration_dropped": dropped} if dropped else {})}


def _fit(terms, auto, mesh, material):
    patch = calibration_patch(mesh)
    names = ", ".join(t.describe() for t in auto)
    thin = patch.slivers()
    if thin.size:
        ratio = radius_ratio(patch.points, patch.tets[thin]).min()
        raise ModelError(f"calibration of {names} refused: tetrahedra {_first(thin)} of the "
                         f"mesh are slivers (radius ratio down to {ratio:.3g}, below "
                         f"{SLIVER_RADIUS_RATIO:g}), whose stiffness would set c; re-mesh them, "
                         "or pass a number for c")
    fixed, unit = _stiffnesses(terms, patch, material)
    G = material.G

    def moduli(c):
        K = sum((ci * Ki for ci, Ki in zip(c, unit)), fixed if fixed is not None else 0)
        return kelvin_moduli(condensed_stiffness(K, patch, name=names))

    def residual(c):
        return moduli(c)[1] / (2 * G) - 1

    def solve(free, start):
        """The least-squares constants with those outside ``free`` held at 0."""
        def r(cf):
            c = np.zeros(len(unit))
            c[free] = cf
            return residual(c)
        fit = least_squares(r, np.maximum(start[free], 1e-3), bounds=(0.0, np.inf),
                            xtol=1e-14, ftol=1e-14, gtol=1e-14)
        c = np.zeros(len(unit))
        c[free] = np.where(fit.active_mask == -1, 0.0, fit.x)
        return c, float(np.sum(residual(c) ** 2))

    try:
        start = _affine_start(fixed, unit, patch, G)
        coefs, cost = solve(np.arange(len(unit)), start)
        # trf only approaches a bound: a constant left near 0 is tried at 0
        tiny = np.flatnonzero(coefs < 1e-4 * coefs.max())
        if tiny.size and tiny.size < len(unit):
            held, held_cost = solve(np.setdiff1d(np.arange(len(unit)), tiny), coefs)
            if held_cost <= cost * (1 + 1e-9) + 1e-24:
                coefs = held
    except ModelError as exc:
        raise ModelError(f"calibration of {names} failed: {exc}; pass a number for c") \
            from None
    if not np.any(coefs > 0):
        raise CalibrationDroppedError(f"calibration of {names} gave c = 0: no term adds to "
                                      "the deviatoric fit on this mesh; pass a number for c")
    bulk, mu = moduli(coefs)
    ratio = mu / (2 * G)
    if ratio.min() <= 0:
        raise ModelError(f"calibration of {names} gave a deviatoric modulus {ratio.min():.3g} "
                         "x 2G <= 0 (a mode with no shear stiffness): the model is unstable on "
                         "this mesh; pass a number for c")
    out = {"calibration_patch": ("the mesh itself" if patch is mesh else
                                 f"{PATCH_NODES - 1}^3 cells of its lattice"),
           "deviatoric_eig_min": float(ratio.min()), "deviatoric_eig_max": float(ratio.max()),
           "bulk_ratio": float(bulk / material.K)}
    return coefs, out
