"""Plumbing shared by the FEM references: the scikit-fem mesh of a TetMesh, refinement that
carries Dirichlet data along, element choice, Dirichlet dofs, linear solvers, stress measures.

Physics lives in the modules that use it (linear.py, hyperelastic.py, modal.py); the mesh and
the boundary-condition format come from ``model``, nothing else does.
"""
import collections
import contextlib
import hashlib
import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from skfem import Basis, ElementTetP1, ElementTetP2, ElementVector, MeshTet

from model.errors import ConvergenceError, MaterialError, ModelError
from model.material import poisson_message
from .assembly import elasticity_matrix

ELEMENTS = {"P1": ElementTetP1, "P2": ElementTetP2}
INTORDER = {"P1": 1, "P2": 2}  # exact for the stiffness, and for a constant body force
# "auto" uses scipy's direct solver up to this many unknowns and AMG-CG beyond: where the two
# cost the same on the P1 and P2 cubes of `python -m cases.tools.fem_scaling --solvers` (direct/AMG
# time 0.9-1.3 at 2 200-4 000 unknowns, 1.6 at 6 600, 3 at 14 700, 12-16 at 47 000; README)
DIRECT_MAX_DOFS = 4_000
# GMRES iterations a mixed-form tangent is given on the last one's factorisation before it is
# factorised itself (SaddleSolver)
REUSE_ITERATIONS = 20
# peak memory of that direct solve of a P2 cube with 101 277 unknowns, measured: 5.8 GiB (245 s)
DIRECT_BYTES_AT_1E5 = 5.8 * 2**30
# where the default aggregation stagnates ("auto"), a system up to this many unknowns goes to the
# direct solver rather than to the second aggregation: such systems are slender, bending
# bodies whose LU fills little (the quick cantilever's neo-Hookean Newton step on five refined
# once, 47 808 unknowns: direct 5.5 s, evolution-strength AMG-CG 38 s after the stagnated try)
DIRECT_AFTER_STAGNATION_DOFS = 60_000
# tried in order: the default (cheap to set up), then one that converges on thin slabs
AMG_SETTINGS = (("default aggregation", {}),
                ("evolution strength, energy prolongation",
                 {"strength": "evolution", "smooth": "energy"}))


def spd_factor(A):
    """Sparse LU of a symmetric positive definite matrix, ordered as one: minimum degree on
    A + A^T with the diagonal pivots kept (SuperLU's symmetric mode). For the FEM transient,
    factored once and solved at every step: on the P2 cube's matrix it fills half what the
    default column ordering does and solves 2x faster (0.14 against 0.29 ms, 1 509 unknowns).
    The direct static solves use it too: on the slender cantilever's P2 systems it factors
    2.4 to 10 times faster than the default column ordering (bcc refined once, 104 640
    unknowns: 69 against 234 s), the time of a full report's references."""
    return splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                options={"SymmetricMode": True})


# the last few stiffness matrices assembled, by mesh, element and Lame constants: a case solves
# one mesh under several boundary conditions (reference.assembly: 1 s for the 206 000 P2
# unknowns of the paper cube's bcc mesh refined twice, where scikit-fem's asm took 12 s)
_STIFFNESS = collections.OrderedDict()
STIFFNESS_CACHE = 4


def stiffness(basis, lam, mu):
    """The linear elastic stiffness matrix (CSR) of ``basis``, reused when the same mesh,
    element and constants were assembled recently (the arrays are compared by content).
    Callers must not modify it."""
    m = basis.mesh
    key = (hashlib.blake2b(np.ascontiguousarray(m.p).tobytes()
                           + np.ascontiguousarray(m.t).tobytes(), digest_size=16).digest(),
           type(basis.elem).__name__, type(basis.elem.elem).__name__, basis.X.shape,
           float(lam), float(mu))
    if key in _STIFFNESS:
        _STIFFNESS.move_to_end(key)
        return _STIFFNESS[key]
    K = elasticity_matrix(basis, lam, mu)
    _STIFFNESS[key] = K
    while len(_STIFFNESS) > STIFFNESS_CACHE:
        _STIFFNESS.popitem(last=False)
    return K


def lame(E, nu):
    """(lambda, mu) after checking E > 0 and -1 < nu < 0.5."""
    if not (np.isfinite(E) and E > 0):
        raise MaterialError(f"Young's modulus E must be a finite number > 0 Pa, got {E!r}")
    if not np.isfinite(nu):
        raise MaterialError(f"Poisson's ratio nu must be a finite number, got {nu!r}")
    if not -1.0 < nu < 0.5:
        raise MaterialError(poisson_message(nu))
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def skfem_mesh(mesh):
    return MeshTet(np.ascontiguousarray(mesh.points.T), np.ascontiguousarray(mesh.tets.T))


class Region:
    """A prescribed displacement declared by geometry: ``fn(points (k, 3)) -> (k, 3)``, NaN
    where a component is free. Given as ``dirichlet_fn``, it decides every new boundary point
    of a refinement or a P2 midpoint by where it lies, whatever its facet's vertices: a
    punch declared this way is the same patch on every mesh, resolved ever finer as the
    reference refines (a plain ``dirichlet_fn`` only fills in facets whose vertices are all
    prescribed, so a patch would be the mesh's polygon of prescribed nodes)."""

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, points):
        return self.fn(points)


def prescribed_edges(m, mask, vals, dirichlet_fn):
    """Which edges' new points (refined vertices, P2 midpoints) are prescribed, and to what.

    An edge is prescribed in component k when it lies on a boundary facet whose three vertices
    are all prescribed in k: a free face stays free even where two of its vertices are held.
    The value is ``dirichlet_fn(midpoint)`` when given (NaN there leaves the component free:
    how a caller keeps free a face that lies between two prescribed surfaces, e.g. the sides
    of a body one element thick), else the mean of the edge's two ends. A :class:`Region`
    decides every boundary edge by its midpoint alone.
    Returns (n_edges, 3) mask and values.
    """
    bf = m.boundary_facets()
    e = m.edges
    edge_mask = np.zeros((m.edges.shape[1], 3), dtype=bool)
    if isinstance(dirichlet_fn, Region):
        on = np.unique(m.f2e[:, bf].ravel())                  # every boundary edge
        given = _given(dirichlet_fn, 0.5 * (m.p[:, e[0, on]] + m.p[:, e[1, on]]).T)
        edge_mask[on] = ~np.isnan(given)
        edge_vals = np.zeros((m.edges.shape[1], 3))
        edge_vals[on] = np.where(edge_mask[on], given, 0.0)
        return edge_mask, edge_vals
    full = mask[m.facets[:, bf]].all(axis=0)                 # (n boundary facets, 3)
    for k in range(3):
        edge_mask[m.f2e[:, bf[full[:, k]]].ravel(), k] = True
    edge_vals = np.where(edge_mask, 0.5 * (vals[e[0]] + vals[e[1]]), 0.0)
    cand = np.flatnonzero(edge_mask.any(axis=1))
    if dirichlet_fn is not None and cand.size:
        given = _given(dirichlet_fn, 0.5 * (m.p[:, e[0, cand]] + m.p[:, e[1, cand]]).T)
        edge_mask[cand] &= ~np.isnan(given)
        edge_vals[cand] = np.where(edge_mask[cand], given, 0.0)
    return edge_mask, edge_vals


def _given(dirichlet_fn, points):
    given = np.asarray(dirichlet_fn(points), dtype=float)
    if given.shape != points.shape:
        raise ModelError(f"dirichlet_fn must return a {points.shape} array for "
                         f"{points.shape} points, got shape {given.shape}")
    return given


SNAP_BITS = 20      # the refinement's diagonal choice is taken on coordinates in 2^-20 of the size


def refined(m):
    """``m`` refined once (each tetrahedron into 8, the middle octahedron cut along its
    shortest diagonal), the diagonals chosen on the coordinates snapped to a 2^-SNAP_BITS grid
    of the mesh's size: a lattice's equal diagonals then tie exactly and are split alike on
    every processor and under any perturbation far below the grid, where the float lengths
    would let round-off pick (and move the reference at its discretisation error). The new
    points are the exact midpoints of the given coordinates."""
    size = float(np.ptp(m.p, axis=1).max()) or 1.0
    q = size * 2.0 ** -SNAP_BITS
    lo = m.p.min(axis=1, keepdims=True)
    snapped = type(m)(np.round((m.p - lo) / q), m.t).refined()
    p = np.hstack((m.p, m.p[:, m.edges].mean(axis=1)))
    return type(m)(p, snapped.t)


def refine_with_data(m, mask, vals, dirichlet_fn, levels):
    """Refine ``levels`` times, carrying the Dirichlet data to the new vertices (see
    :func:`prescribed_edges`).

    Also returns W (sparse, fine nodes x input nodes): the input mesh's P1 hat functions at
    every fine node, built as the mean of the two parents' rows (hats are linear on edges).
    """
    W = sp.identity(m.nvertices, format="csr")
    for _ in range(levels):
        nm, nv = prescribed_edges(m, mask, vals, dirichlet_fn)
        n_old = m.nvertices
        W = sp.vstack([W, 0.5 * (W[m.edges[0]] + W[m.edges[1]])], format="csr")
        m = refined(m)
        assert m.nvertices == n_old + len(nm)  # new vertices are the old edges' midpoints
        mask, vals = np.vstack([mask, nm]), np.vstack([vals, nv])
    return m, mask, vals, W


def dof_hats(basis, W):
    """Sparse (N dofs x input nodes): the input mesh's P1 hats at every dof's location
    (vertex dofs take their node's row of W, P2 edge dofs the mean of their ends' rows)."""
    H = W
    dofs = [basis.nodal_dofs]
    if basis.edge_dofs.size:
        e = basis.mesh.edges
        H = sp.vstack([W, 0.5 * (W[e[0]] + W[e[1]])], format="csr")
        dofs.append(basis.edge_dofs)
    dof_index = np.concatenate([np.concatenate([d[k] for d in dofs]) for k in range(3)])
    place = sp.csr_matrix((np.ones(len(dof_index)), (dof_index, np.arange(len(dof_index)))),
                          shape=(basis.N, len(dof_index)))
    return place @ sp.vstack([H, H, H], format="csr")


def element_basis(m, element, intorder=None):
    if element not in ELEMENTS:
        raise ModelError(f"element must be one of {', '.join(ELEMENTS)}, got {element!r}")
    return Basis(m, ElementVector(ELEMENTS[element]()), intorder=intorder or INTORDER[element])


def dirichlet_dofs(basis, mask, vals, dirichlet_fn):
    """Prescribed dof indices and the full vector of their values. For P2 the midpoint dofs
    follow :func:`prescribed_edges`."""
    D = [basis.nodal_dofs.T[mask]]
    x = np.zeros(basis.N)
    x[basis.nodal_dofs.T[mask]] = vals[mask]
    if basis.edge_dofs.size:
        em, ev = prescribed_edges(basis.mesh, mask, vals, dirichlet_fn)
        dofs = basis.edge_dofs.T
        D.append(dofs[em])
        x[dofs[em]] = ev[em]
    return np.concatenate(D), x


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
    tangents go to the direct solver at once, rather than stagnating again first (the quick
    cantilever's neo-Hookean reference: the stagnated AMG tries were 40 % of its time). Its
    AMG hierarchy is not lent to the next tangent: on the quick indentation's 88 941
    unknowns CG then took 200-300 iterations instead of under 100, twice the time."""

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


def cell_average(basis, field):
    """Volume average per element of a quadrature field (..., nel, nqp)."""
    return np.einsum("...eq,eq->...e", field, basis.dx) / basis.dx.sum(axis=1)


def parent_of(m_fine, W, coarse_tets):
    """Index of the input tetrahedron containing each fine one: the input nodes whose hats do
    not vanish on a fine tetrahedron are exactly its parent's four vertices."""
    if m_fine.nelements == len(coarse_tets):
        return np.arange(len(coarse_tets))
    S = (W[m_fine.t[0]] + W[m_fine.t[1]] + W[m_fine.t[2]] + W[m_fine.t[3]]).tocsr()
    S.sort_indices()
    if not np.all(np.diff(S.indptr) == 4):
        raise AssertionError("a refined tetrahedron straddles two input tetrahedra")
    def key(t):  # one opaque, consistently ordered scalar per row of four node indices
        return np.ascontiguousarray(t, dtype=np.int64).view(np.dtype((np.void, 32))).ravel()

    fine_key = key(S.indices.reshape(-1, 4))
    coarse_key = key(np.sort(coarse_tets, axis=1))
    order = np.argsort(coarse_key)
    return order[np.searchsorted(coarse_key[order], fine_key)]


def stress_on_input(basis, W, mesh, sigma):
    """The volume average over each input tetrahedron of a quadrature stress field sigma
    (3, 3, nel, nqp) on the (possibly refined) ``basis``: (m, 3, 3), and the input volumes."""
    sig_fine = np.moveaxis(cell_average(basis, sigma), -1, 0)         # (m_fine, 3, 3)
    vol_fine = basis.dx.sum(axis=1)
    parent = parent_of(basis.mesh, W, mesh.tets)
    vol = np.bincount(parent, weights=vol_fine, minlength=mesh.n_tets)
    stress = np.stack([np.bincount(parent, weights=vol_fine * sig_fine[:, i, j],
                                   minlength=mesh.n_tets)
                       for i in range(3) for j in range(3)], axis=1).reshape(-1, 3, 3)
    return stress / vol[:, None, None], vol


def probe(basis, dofs, points):
    """The vector field ``dofs`` of ``basis`` at arbitrary ``points`` (k, 3) inside the mesh:
    its basis functions evaluated there (k, 3), not nodal values interpolated."""
    pts = np.asarray(points, dtype=float)
    values = basis.probes(np.ascontiguousarray(pts.T)) @ dofs
    return check_finite("displacement at the probed points",
                        values.reshape(3, len(pts)).T.copy())


def saddle_factor(A, b, accept=1e-8):
    """Factorise the symmetric indefinite tangent of the mixed (u, p) form, [K B; B^T -C]
    with K and C = M / lambda positive definite, and solve it for ``b``: ``(factor, x)``. A
    quasi-definite matrix has an LDL^T factorisation in every symmetric ordering (Vanderbei
    1995), so SuperLU runs with minimum degree on A + A^T and the diagonal pivots only (3.2 s
    on 17 850 unknowns, where a 1 % pivoting threshold took 147 s and the default ordering
    10 s). Where the tangent has lost definiteness and the residual shows it (relative
    residual above ``accept``), it factorises again with partial pivoting."""
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
    afresh only where GMRES does not reach ``rtol`` in REUSE_ITERATIONS iterations (the
    truth-cube's bonded reference: 23 factorisations were 16 of its 23 s). The same
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


def stress_measures(sigma):
    """von Mises, maximum shear (sigma_1 - sigma_3) / 2 and pressure -tr/3 of (m, 3, 3)."""
    eig = np.linalg.eigvalsh(sigma)
    dev = sigma - np.trace(sigma, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    return (np.sqrt(1.5 * np.einsum("mij,mij->m", dev, dev)),
            0.5 * (eig[:, -1] - eig[:, 0]), -np.trace(sigma, axis1=1, axis2=2) / 3)


def check_finite(name, a):
    if not np.all(np.isfinite(a)):
        raise ConvergenceError(f"{name} is not finite: the solve failed (singular system?)")
    return a
