"""Quasi-static equilibrium: Newton on the free components with a coloured finite-difference
Jacobian, so it needs no energy and serves the non-conservative readings too."""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.sparse.linalg import splu

from .bc import bc_arrays, load_fractions
from .errors import ConvergenceError, DegenerateTetError, ModelError
from .ordering import nested_dissection


# the default force tolerance: max free-node residual <= RTOL * E h^2
RTOL = 1e-9


def node_adjacency(mesh):
    """Sparse boolean node-node adjacency through shared tetrahedra (self included)."""
    rows = np.repeat(mesh.tets, 4, axis=1).ravel()
    cols = np.tile(mesh.tets, (1, 4)).ravel()
    return sp.csr_matrix((np.ones(len(rows), dtype=bool), (rows, cols)),
                         shape=(mesh.n_nodes,) * 2)


def colour_nodes(adjacency):
    """Greedy colouring in which two nodes of one colour share no neighbour, so perturbing all
    of a colour at once leaves every force row touched by at most one of them: each node in
    turn takes the smallest colour no node within two edges has taken."""
    dist2 = (adjacency.astype(np.int32) @ adjacency.astype(np.int32)).tocsr()
    return _greedy_colours(dist2.indptr, dist2.indices, adjacency.shape[0])


@njit(cache=True)
def _greedy_colours(indptr, indices, n):
    colour = np.full(n, -1, np.int64)
    taken_by = np.full(n + 1, -1, np.int64)     # taken_by[c] == i: c is taken near node i
    for i in range(n):
        for p in range(indptr[i], indptr[i + 1]):
            c = colour[indices[p]]
            if c >= 0:
                taken_by[c] = i
        c = 0
        while taken_by[c] == i:
            c += 1
        colour[i] = c
    return colour


class JacobianPattern:
    """What the finite-difference Jacobian needs of the mesh alone, built once per model: the
    node colours, the step, and for each (colour, component) the rows, columns and the
    gather that places the force differences in the sparse matrix."""

    def __init__(self, mesh, rel_step=1e-6):
        adj = node_adjacency(mesh)
        colour = colour_nodes(adj)
        self.h = rel_step * mesh.mean_edge
        self.n = 3 * mesh.n_nodes
        self.groups = []
        for c in range(colour.max() + 1):
            nodes = np.flatnonzero(colour == c)
            nbs = [adj.indices[adj.indptr[q]:adj.indptr[q + 1]] for q in nodes]
            nb = np.concatenate(nbs)
            owner = np.repeat(nodes, [len(b) for b in nbs])
            rows = (3 * nb[:, None] + np.arange(3)).ravel()
            for k in range(3):
                self.groups.append((nodes, k, rows, np.repeat(3 * owner + k, 3), nb))


def jacobian(forces, mesh, x, pattern=None):
    """Sparse d forces / d x (3n x 3n) by central differences over node colours."""
    p = pattern or JacobianPattern(mesh)
    rows, cols, vals = [], [], []
    for nodes, k, r, c, nb in p.groups:
        xp, xm = x.copy(), x.copy()
        xp[nodes, k] += p.h
        xm[nodes, k] -= p.h
        df = (forces(xp) - forces(xm)) / (2 * p.h)
        rows.append(r)
        cols.append(c)
        vals.append(df[nb].ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(p.n, p.n))


@dataclass
class StaticResult:
    """``x`` positions, ``u`` displacements, ``reaction`` (n, 3) support forces on the prescribed
    components (zero elsewhere), ``residual`` max free-node force norm [N] reached, ``tol`` the
    stated tolerance [N], ``iterations`` Newton iterations over all load steps, ``jacobians``
    how many of them formed and factorised a Jacobian (the rest were chord steps): the
    solve's cost."""

    x: np.ndarray
    u: np.ndarray
    reaction: np.ndarray
    residual: float
    tol: float
    iterations: int
    jacobians: int = 0


# a chord step (the last factorised Jacobian again) is kept when it divides the residual by
# this much; otherwise the Jacobian is formed and factorised afresh (a full Newton step)
CHORD_GAIN = 10.0
# a full Newton step is taken even where it raises the residual, by less than GROWTH times (its
# residual is second order in the step, and the next step then converges, where a
# backtracking search can take tens of Jacobians); where WATCH more iterations have not brought the
# residual below the one before it, the solve returns there and backtracks for the rest of the
# load step (a watchdog, Chamberlain et al. 1982). A step that raises it more has left Newton's
# basin (the same model under the cantilever case's 1000 times larger load: from 4e-5 N to
# 6.4 N) and could land on an equilibrium off the load path, which a static solve must follow
WATCH = 2
GROWTH = 1e3


def factorise(J, order=None):
    """Sparse LU of the Newton matrix, ordered for a structurally symmetric matrix (diagonal
    pivots preferred, 1 % threshold so that the non-symmetric Jacobians of the corner and
    balanced readings still pivot where they must): in the permutation ``order`` where given
    (a nested dissection), else by minimum degree on J + J^T (faster than the default column
    ordering on the convergence study's meshes)."""
    if order is None:
        return splu(J.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01,
                    options={"SymmetricMode": True})
    return _Permuted(splu(J.tocsr()[order][:, order].tocsc(), permc_spec="NATURAL",
                          diag_pivot_thresh=0.01, options={"SymmetricMode": True}), order)


class _Permuted:
    """The factors of J[order][:, order], solving J x = b."""

    def __init__(self, lu, order):
        self.lu, self.order = lu, order
        self.L, self.U = lu.L, lu.U

    def solve(self, b):
        x = np.empty_like(b)
        x[self.order] = self.lu.solve(b[self.order])
        return x


# from this many unknowns the first Newton matrix of a solve is also factorised in nested
# dissection order, and the sparser factors' ordering kept (on the 17-node cubes: 1.7-2.4
# times faster on six, bcc and the unmirrored five split, a little slower on the mirrored five)
DISSECT_FROM = 3000


class Factoriser:
    """``factorise`` for the Newton matrices of one solve, whose unknowns sit at ``coords``:
    the first factorised by minimum degree and, from DISSECT_FROM unknowns, by nested
    dissection too; the ordering whose factors hold fewer entries is kept for the rest (a
    choice by counts, so the same on every run)."""

    def __init__(self, coords):
        self.coords, self.order, self.chosen = coords, None, False

    def __call__(self, J):
        if self.chosen:
            return factorise(J, self.order)
        self.chosen = True
        lu = factorise(J)
        if J.shape[0] < DISSECT_FROM:
            return lu
        order = nested_dissection(J, self.coords)
        nd = factorise(J, order)
        if nd.L.nnz + nd.U.nnz < lu.L.nnz + lu.U.nnz:
            self.order, lu = order, nd
        return lu


def force_scale(model):
    """E h^2 with h the mean edge length: the size of a nodal force at unit strain [N]."""
    h = model.mesh.mean_edge
    return model.material.E * h * h


def _full_step(x, du, s, free, residual):
    """``(x + du, its residual)``, None where a tetrahedron inverts or a force is not
    finite."""
    xt = x.copy()
    xt.ravel()[free] += du
    try:
        rt = residual(xt, s)
    except DegenerateTetError:
        return None
    return (xt, rt) if np.all(np.isfinite(rt)) else None


SHORTEST_STEP = 1e-3     # a Newton step is backtracked down to this fraction of its length


def _backtracked(x, du, rn, s, free, residual):
    """``x + alpha du`` and its residual, alpha halved from 1 until the largest free residual
    falls below ``rn`` (or alpha below SHORTEST_STEP). Where even the shortest step inverts a
    tetrahedron the Newton direction leaves the admissible states at this load: a
    ConvergenceError, so that a caller may split the load more finely."""
    alpha = 1.0
    while True:
        xt = x.copy()
        xt.ravel()[free] += alpha * du
        try:
            rt = residual(xt, s)
            if np.abs(rt[free]).max() < rn or alpha < SHORTEST_STEP:
                return xt, rt
        except DegenerateTetError as exc:
            if alpha < SHORTEST_STEP:
                raise ConvergenceError(
                    f"{exc}: every Newton step down to {SHORTEST_STEP:g} of its length inverts "
                    "it at this load; increase load_steps") from exc
        alpha *= 0.5


def _predicted(x, r, before, last, s, free, residual):
    """The start of a load step: the last two converged states ``before`` and ``last``
    (load, positions) extrapolated linearly to the load ``s``, prescribed components kept
    from ``x``, where its residual is below that of ``x`` (the last state with the
    boundary moved alone, whose residual is first order in the increment); else ``(x, r)``."""
    (s0, x0), (s1, x1) = before, last
    xp = x1 + (s - s1) / (s1 - s0) * (x1 - x0)
    fixed = ~free.reshape(x.shape)
    xp[fixed] = x[fixed]
    try:
        rp = residual(xp, s)
    except DegenerateTetError:
        return x, r
    if np.abs(rp[free]).max(initial=0.0) < np.abs(r[free]).max(initial=0.0):
        return xp, rp
    return x, r


def solve(model, bc, f_ext=None, rtol=RTOL, max_iter=50, load_steps=1, on_step=None,
          stall=None):
    """Solve f_int(x) + f_ext = 0 on the free components, prescribed ones set from ``bc``.

    Newton in ``load_steps`` equal increments of the prescribed displacement and of ``f_ext``
    (or at the load fractions ``load_steps`` lists, see ``model.bc.load_fractions``), each
    started from the last two equilibria extrapolated to its load (:func:`_predicted`);
    ``on_step(step, x)``, when given, is called with the positions after every converged
    step; converged when the largest free-node residual is below ``rtol * E h^2``. A step
    first tries the last factorised Jacobian (a chord step) and keeps it when it divides the
    residual by CHORD_GAIN, which saves the finite-difference Jacobian and its factorisation
    in the last iterations. A full Newton step is kept where it raises the residual less than
    GROWTH times, under a watchdog (WATCH); otherwise, and for the rest of a step whose watch
    failed, the step is halved until the residual falls. Raises ConvergenceError otherwise,
    and, where ``stall`` is given, as soon as ``stall`` Newton iterations in a row have not
    halved the load step's residual (a stalled step: on a large mesh each of its iterations
    factorises a Newton matrix, and a caller splitting the load learns it sooner).
    """
    mesh = model.mesh
    mask, vals = bc_arrays(bc, mesh.n_nodes)
    if not mask.any():
        raise ModelError("no prescribed component: the static problem is singular "
                         "(rigid motions are free); fix or prescribe some nodes")
    f_ext = np.zeros_like(mesh.points) if f_ext is None else np.asarray(f_ext, dtype=float)
    free = ~mask.ravel()
    tol = rtol * force_scale(model)
    x = mesh.points.copy()
    iters = jacobians = 0
    lu = None
    factorised = Factoriser(np.repeat(mesh.points, 3, axis=0)[free])

    def residual(x, s):
        return (model.forces(x) + s * f_ext).ravel()

    fractions = load_fractions(load_steps)
    load_steps = len(fractions)
    # the last two converged states (the first is the rest state, exact at load 0)
    before, s_last, x_last = None, 0.0, mesh.points.copy()
    for step, s in enumerate(fractions, start=1):
        x[mask] = mesh.points[mask] + s * vals[mask]
        try:
            r = residual(x, s)
        except DegenerateTetError as exc:
            raise ConvergenceError(
                f"load step {step}/{load_steps} starts from an inverted or flattened "
                f"tetrahedron {exc.tets[0]}: the prescribed increment is too large for the "
                "mesh; increase load_steps") from exc
        if before is not None:
            x, r = _predicted(x, r, before, (s_last, x_last), s, free, residual)
        anchor, watched, monotone = None, 0, False
        mark, since = np.inf, 0     # the residual last halved to, and iterations since
        for _ in range(max_iter):
            rn = np.abs(r[free]).max(initial=0.0)
            if rn <= tol:
                break
            if rn <= 0.5 * mark:
                mark, since = rn, 0
            elif stall is not None and since >= stall:
                raise ConvergenceError(
                    f"static solve stalled at load step {step}/{load_steps}: {stall} Newton "
                    f"iterations did not halve the residual {mark:.3e} N (tol {tol:.3e} N); "
                    "increase load_steps")
            since += 1
            if anchor is not None:
                if rn < anchor[2]:
                    anchor = None
                elif watched == WATCH:  # the full step did not pay off: back, and backtrack
                    (x, r, rn), anchor, monotone = anchor, None, True
                else:
                    watched += 1
            if lu is not None:      # near the solution the last Jacobian still contracts
                xt = x.copy()
                xt.ravel()[free] += lu.solve(-r[free])
                try:
                    rt = residual(xt, s)
                    if np.abs(rt[free]).max() * CHORD_GAIN < rn:
                        x, r = xt, rt
                        iters += 1
                        continue
                except DegenerateTetError:
                    pass
            lu = factorised(model.jacobian(x).tocsc()[free][:, free])
            jacobians += 1
            du = lu.solve(-r[free])
            if not monotone and anchor is None:
                full = _full_step(x, du, s, free, residual)
                rf = np.inf if full is None else np.abs(full[1][free]).max()
                if rf < GROWTH * rn:
                    if rf >= rn:
                        anchor, watched = (x, r, rn), 0
                    x, r = full
                    iters += 1
                    continue
            x, r = _backtracked(x, du, rn, s, free, residual)
            iters += 1
        else:
            raise ConvergenceError(
                f"static solve did not converge in {max_iter} Newton iterations at load step "
                f"{step}/{load_steps}: residual {rn:.3e} N > tol {tol:.3e} N; increase "
                "load_steps or max_iter")
        before, s_last = (s_last, x_last), s
        x_last = x.copy()
        if on_step is not None:
            on_step(step, x.copy())
    reaction = np.where(mask, -r.reshape(-1, 3), 0.0)
    return StaticResult(x=x, u=x - mesh.points, reaction=reaction,
                        residual=float(np.abs(r[free]).max(initial=0.0)), tol=tol,
                        iterations=iters, jacobians=jacobians)
