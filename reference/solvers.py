"""The linear solvers of the FEM references: a sparse LU ordered for symmetric matrices, the
static solve (direct or AMG-preconditioned CG, with what it falls back on and the direct solver's
memory estimate), the tangents of a Newton solve, and the mixed form's saddle-point tangents.
"""
import contextlib
import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from model.errors import ConvergenceError, ModelError

# "auto" uses scipy's direct solver up to this many unknowns and AMG-CG beyond: where the two
# cost about the same on the P1 and P2 cubes of `python -m cases.tools.fem_scaling --solvers`
DIRECT_MAX_DOFS = 4_000
# GMRES iterations a mixed-form tangent is given on the last one's factorisation before it is
# factorised itself (SaddleSolver)
REUSE_ITERATIONS = 20
# peak memory of that direct solve of a P2 cube with 101 277 unknowns, measured
DIRECT_BYTES_AT_1E5 = 5.8 * 2**30
# where the default aggregation stagnates ("auto"), a system up to this many unknowns goes to the
# direct solver rather than to the second aggregation: such systems are slender, bending
# bodies whose LU fills little, which the direct solver factors faster than evolution-strength
# AMG-CG converges
DIRECT_AFTER_STAGNATION_DOFS = 60_000
# tried in order: the default (cheap to set up), then one that converges on thin slabs
AMG_SETTINGS = (("default aggregation", {}),
                ("evolution strength, energy prolongation",
                 {"strength": "evolution", "smooth": "energy"}))


def spd_factor(A):
    """Sparse LU of a symmetric positive definite matrix, ordered as one: minimum degree on
    A + A^T with the diagonal pivots kept (SuperLU's symmetric mode). For the FEM transient,
    factored once and solved at every step: it fills less than the default column ordering
    and solves faster; the direct static solves use it too, where it factors the slender
    cantilever's P2 systems several times faster than the default column ordering."""
    return splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                options={"SymmetricMode": True})


def rigid_modes(points, comp):
    """Six rigid-body modes (N, 6) of dofs at ``points`` (N, 3) carrying component ``comp``."""
    c = points - points.mean(axis=0)
    B = np.zeros((len(points), 6))
    B[np.arange(len(points)), comp] = 1.0
    # rotations about z, x, y: (-y, x, 0), (0, -z, y), (z, 0, -x)
    for col, (a, b) in zip((3, 4, 5), ((0, 1), (1, 2), (2, 0))):
        B[comp == a, col] = -c[comp == a, b]
        B[comp == b, col] = c[comp == b, a]
    return B


def linear_solve(A, b, doflocs, comp, solver="auto", rtol=1e-10, accept=1e-8):
    """Solve the SPD system A x = b to a relative residual ||b - A x|| / ||b|| <= ``rtol``
    (AMG-CG: or <= ``accept`` where rounding stops it short of ``rtol``).

    ``solver``: "direct" (scipy's sparse LU), "amg" (CG preconditioned by pyamg smoothed
    aggregation with the rigid-body modes as near-null space) or "auto": direct up to
    DIRECT_MAX_DOFS unknowns, AMG-CG beyond. CG runs until it converges or stagnates, with no
    fixed iteration count; if it stagnates with the default aggregation, "auto" solves directly
    up to DIRECT_AFTER_STAGNATION_DOFS unknowns (where the memory fits) and otherwise starts
    again with evolution strength and energy-minimising prolongation (what thin,
    bending-dominated bodies need); if that stagnates too, "auto" falls back to the direct solver when its estimated
    memory fits in the memory available, and otherwise a ConvergenceError advises
    ``solver="direct"``. ``doflocs`` (N, 3) and ``comp`` (N,) locate each unknown.
    """
    n = A.shape[0]
    if solver not in ("auto", "direct", "amg"):
        raise ModelError(f"solver must be 'auto', 'direct' or 'amg', got {solver!r}")
    if solver == "direct" or (solver == "auto" and n <= DIRECT_MAX_DOFS):
        return spd_factor(A).solve(b), {"solver": "direct", "iterations": 0}
    import pyamg

    A = A.tocsr()
    B = rigid_modes(doflocs, comp)
    tried, x, total = [], np.zeros_like(b), 0
    for name, settings in AMG_SETTINGS:
        with _seeded_numpy_random():
            ml = pyamg.smoothed_aggregation_solver(A, B=B, symmetry="symmetric", **settings)
            x, iterations, rel = _cg_until_stagnant(ml, A, b, x, rtol)
        total += iterations
        tried.append(f"{name}: relative residual {rel:.2e} after {iterations} iterations")
        if rel <= rtol:
            return x, {"solver": f"amg-cg ({name})", "iterations": total, "residual": float(rel)}
        if (solver == "auto" and n <= DIRECT_AFTER_STAGNATION_DOFS
                and direct_memory_estimate(n) < 0.5 * available_memory()):
            return spd_factor(A).solve(b), {"solver": f"direct ({name} stagnated)",
                                           "iterations": total, "amg": tried}
    if rel <= accept:   # both stagnated close to rtol: the rounding floor of this system
        return x, {"solver": f"amg-cg ({name})", "iterations": total, "residual": float(rel)}
    need, have = direct_memory_estimate(n), available_memory()
    if solver == "auto" and need < 0.5 * have:
        return spd_factor(A).solve(b), {"solver": "direct (AMG-CG stagnated)", "iterations": 0,
                                       "amg": tried}
    why = ("solver=\"amg\" was asked" if solver == "amg" else
           f"the direct solver's estimated {need / 2**30:.1f} GiB is more than half the "
           f"{have / 2**30:.1f} GiB available")
    raise ConvergenceError(
        f"AMG-preconditioned CG stagnated on {n} unknowns ({'; '.join(tried)}) and {why}; pass "
        "solver=\"direct\" to try the direct solver, or check that enough Dirichlet conditions "
        "hold the body")


class NewtonSolver:
    """:func:`linear_solve` over the tangents of one Newton solve (one sparsity, spectra that
    change little): once the default AMG stagnated and the direct solver took over, the later
    tangents go to the direct solver at once, rather than stagnating again first. Its AMG
    hierarchy is not lent to the next tangent: a hierarchy built for another tangent
    preconditions this one worse, and CG takes more iterations."""

    def __init__(self, solver="auto"):
        self.solver = solver
        self.cg_iterations = 0

    def __call__(self, A, b, doflocs, comp, rtol=1e-10):
        """:func:`linear_solve` to ``rtol`` (an inexact Newton's forcing term)."""
        x, info = linear_solve(A, b, doflocs, comp, self.solver, rtol=rtol)
        self.cg_iterations += info["iterations"]
        if self.solver == "auto" and info["solver"].startswith("direct ("):
            self.solver = "direct"
        return x, info


@contextlib.contextmanager
def _seeded_numpy_random(seed=0):
    """pyamg estimates spectral radii from numpy's global random generator: seed it for the
    solve (same inputs, same outputs to the last bit) and give the caller's state back."""
    state = np.random.get_state()
    np.random.seed(seed)
    try:
        yield
    finally:
        np.random.set_state(state)


def _cg_until_stagnant(ml, A, b, x, rtol, chunk=100, gain=10.0):
    """AMG-preconditioned CG from ``x`` in chunks of ``chunk`` iterations, each continuing
    from the last iterate, until the relative residual ||b - A x|| / ||b|| reaches ``rtol`` or
    a chunk fails to divide it by ``gain`` (a preconditioner this weak is not worth more
    iterations). Returns (x, iterations, relative residual)."""
    bn = max(np.linalg.norm(b), 1e-300)
    iterations, rel = 0, np.linalg.norm(b - A @ x) / bn
    while True:
        history = []                      # the residual of each iteration: how many it took
        with warnings.catch_warnings():   # CG's "indefinite ... aborting": a stagnation here
            warnings.simplefilter("ignore", UserWarning)
            x_new = ml.solve(b, x0=x, tol=0.1 * rtol, accel="cg", maxiter=chunk,
                             residuals=history)
        iterations += max(len(history) - 1, 0)
        rel_new = np.linalg.norm(b - A @ x_new) / bn
        if rel_new <= rtol:
            return x_new, iterations, rel_new
        if not np.isfinite(rel_new) or rel_new > rel / gain:   # stagnating or diverging
            return (x_new, iterations, rel_new) if rel_new < rel else (x, iterations, rel)
        x, rel = x_new, rel_new


def direct_memory_estimate(n):
    """Bytes the direct solver may need for n unknowns: the peak measured on a P2 cube
    (DIRECT_BYTES_AT_1E5) scaled as n^(5/3), the fill of a 3-D sparse LU; thin bodies need
    less, so this errs on the safe side."""
    return DIRECT_BYTES_AT_1E5 * (n / 1e5) ** (5 / 3)


def available_memory():
    """MemAvailable of /proc/meminfo in bytes (0 where unknown: no direct fallback)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def saddle_factor(A, b, accept=1e-8):
    """Factorise the symmetric indefinite tangent of the mixed (u, p) form, [K B; B^T -C]
    with K and C = M / lambda positive definite, and solve it for ``b``: ``(factor, x)``. A
    quasi-definite matrix has an LDL^T factorisation in every symmetric ordering (Vanderbei
    1995), so SuperLU runs with minimum degree on A + A^T and the diagonal pivots only (far
    faster than a pivoting threshold or the default ordering). Where the tangent has lost
    definiteness and the residual shows it (relative residual above ``accept``), it
    factorises again with partial pivoting."""
    A = sp.csc_matrix(A)
    lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
              options={"SymmetricMode": True})
    x = lu.solve(b)
    bn = max(np.linalg.norm(b), 1e-300)
    if not np.all(np.isfinite(x)) or np.linalg.norm(A @ x - b) > accept * bn:
        lu = splu(A)
        x = lu.solve(b)
    return lu, check_finite("the mixed Newton step", x)


class SaddleSolver:
    """The mixed form's tangents of one Newton solve, each to a relative residual ``rtol``
    (an inexact Newton's forcing term): the last factorisation preconditions GMRES on the
    next tangent, which differs from it by one Newton update, and a tangent is factorised
    afresh only where GMRES does not reach ``rtol`` in REUSE_ITERATIONS iterations
    (factorisations were most of the truth-cube's bonded reference's time). The same
    interface as :class:`NewtonSolver`; the dof locations are not needed."""

    def __init__(self):
        self.lu = None
        self.factorisations = 0
        self.krylov_iterations = 0

    def __call__(self, A, b, doflocs=None, comp=None, rtol=1e-10):
        from scipy.sparse.linalg import LinearOperator, gmres
        A = sp.csc_matrix(A)
        bn = max(np.linalg.norm(b), 1e-300)
        if self.lu is not None:
            count = []
            x, _ = gmres(A, b, rtol=0.5 * rtol, atol=0.0, restart=REUSE_ITERATIONS, maxiter=1,
                         M=LinearOperator(A.shape, matvec=self.lu.solve, dtype=float),
                         callback=count.append, callback_type="pr_norm")
            self.krylov_iterations += len(count)
            if np.all(np.isfinite(x)) and np.linalg.norm(A @ x - b) <= rtol * bn:
                return x, {"solver": "gmres", "iterations": len(count)}
        self.lu, x = saddle_factor(A, b)
        self.factorisations += 1
        return x, {"solver": "direct", "iterations": 0}


def check_finite(name, a):
    if not np.all(np.isfinite(a)):
        raise ConvergenceError(f"{name} is not finite: the solve failed (singular system?)")
    return a
