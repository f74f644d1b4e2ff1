"""Metrics comparing a model's state with a reference (docs/model.md "What is compared").

Every function returns plain floats or arrays and raises MetricError rather than return NaN.
"""
import numpy as np

from model.errors import PbcmError


PATTERN_TOL = 1e-6  # second differences below this fraction of the profile count as zero
ALTERNATION_CLEAR = 0.01   # an alternation below 1 % of the mean lateral displacement is not clear
# a patch test passes below this displacement error: the linear regime (strains of 1e-4)
# leaves a geometrically nonlinear model about 5e-5 off the linear field (fem-neohookean), a
# consistency error is 1e-3 and above
PATCH_TOL = 1e-3
RANK_TOL = 1e-8     # singular values below this (unit columns) count as zero: rounding, not shape


class MetricError(PbcmError, ArithmeticError):
    """A metric could not be computed (NaN, empty set, zero reference)."""


def finite(name, value):
    """``value`` if every entry is finite, else a MetricError naming the metric."""
    a = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(a)):
        raise MetricError(f"metric {name!r} is not finite ({value!r}): the run behind it failed")
    return float(a) if a.ndim == 0 else a


def _nonzero(name, ref):
    if not ref > 0:
        raise MetricError(f"metric {name!r}: the reference is zero, the relative error is "
                          "undefined")
    return ref


def rel_l2(u, ref, free=None):
    """||u - ref|| / ||ref|| over the nodal components ``free`` ((n, 3) bool; all when None):
    the prescribed ones, equal in model and reference, would only dilute the error."""
    d, r = _masked(u, ref, free)
    return finite("rel_l2", np.linalg.norm(d) / _nonzero("rel_l2", np.linalg.norm(r)))


def max_rel(u, ref, free=None):
    """max_i |u_i - ref_i| / max_i |ref_i| (nodal vector norms of the ``free`` components)."""
    d, r = _masked(u, ref, free)
    num = np.linalg.norm(d, axis=1).max()
    return finite("max_rel", num / _nonzero("max_rel", np.linalg.norm(r, axis=1).max()))


def _masked(u, ref, free):
    """(u - ref, ref), zero on the components outside ``free``."""
    d, r = np.asarray(u, float) - ref, np.asarray(ref, float)
    if free is None:
        return d, r
    free = np.asarray(free, bool)
    if free.shape != r.shape:
        raise MetricError(f"free-component mask of shape {free.shape} for a field of shape "
                          f"{r.shape}")
    return np.where(free, d, 0.0), np.where(free, r, 0.0)


def energy_rel(u, ref, K):
    """||u - ref||_K / ||ref||_K: the error in the energy norm of the stiffness K (3n x 3n,
    node-major components: u.ravel()), the continuum's measure of a displacement error."""
    d = (np.asarray(u, float) - ref).ravel()
    r = np.asarray(ref, float).ravel()
    ref_energy = _nonzero("energy_rel", float(r @ (K @ r)))
    return finite("energy_rel", np.sqrt(max(float(d @ (K @ d)), 0.0) / ref_energy))


def node_patch_average(mesh, per_tet):
    """The volume-weighted average over each node's tetrahedra of a per-tetrahedron field
    (m, ...) -> (n, ...), as FEM's nodal stress is averaged."""
    per_tet = np.asarray(per_tet, float)
    V = mesh.volumes
    tail = per_tet.shape[1:]
    acc = np.zeros((mesh.n_nodes,) + tail)
    w = np.zeros(mesh.n_nodes)
    for k in range(4):
        np.add.at(acc, mesh.tets[:, k], V.reshape((-1,) + (1,) * len(tail)) * per_tet)
        np.add.at(w, mesh.tets[:, k], V)
    return acc / w.reshape((-1,) + (1,) * len(tail))


def tensor_rel_l2(a, ref):
    """sqrt(sum_i |a_i - ref_i|_F^2) / sqrt(sum_i |ref_i|_F^2) over a field of tensors."""
    a, ref = np.asarray(a, float), np.asarray(ref, float)
    return finite("tensor_rel_l2", np.linalg.norm(a - ref)
                  / _nonzero("tensor_rel_l2", np.linalg.norm(ref)))


def von_mises(sigma):
    """The von Mises stress of each tensor of (k, 3, 3)."""
    s = np.asarray(sigma, float)
    dev = s - np.trace(s, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    return np.sqrt(1.5 * np.einsum("kij,kij->k", dev, dev))


def correlation(a, b):
    """Pearson correlation of two per-tetrahedron fields."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.std() == 0 or b.std() == 0:
        raise MetricError("correlation of a constant field is undefined")
    return finite("correlation", np.corrcoef(a, b)[0, 1])


def layer_profile(points, u, layers, size, tol=None):
    """Mean outward lateral displacement of the side-face nodes of each y-layer of a cube
    [0, size]^3 (a node on an edge counts once per face it lies on)."""
    tol = 1e-6 * size if tol is None else tol
    out = []
    for y in layers:
        in_layer = np.abs(points[:, 1] - y) <= tol
        vals = []
        for axis in (0, 2):
            for side, normal in ((0.0, -1.0), (size, 1.0)):
                on = in_layer & (np.abs(points[:, axis] - side) <= tol)
                vals.append(normal * u[on, axis])
        vals = np.concatenate(vals)
        if vals.size == 0:
            raise MetricError(f"no side-face node in the layer y = {y}")
        out.append(vals.mean())
    return finite("layer_profile", np.array(out))


def side_line_profiles(points, u, layers, size, tol=None):
    """Outward lateral displacement along each vertical line of side-face nodes of a cube
    [0, size]^3: one row per line (a face and a node position across it, taken from the
    first layer; an edge line counts once per face, as in :func:`layer_profile`), one column
    per y-layer, so that on a lattice the rows' mean is the layer profile. Raises where a
    line lacks a node in some layer (a mesh without vertical lines of nodes)."""
    tol = 1e-6 * size if tol is None else tol
    layers = np.asarray(layers, float)
    rows = []
    for axis in (0, 2):
        across = 2 - axis
        for side, normal in ((0.0, -1.0), (size, 1.0)):
            on_face = np.abs(points[:, axis] - side) <= tol
            first = on_face & (np.abs(points[:, 1] - layers[0]) <= tol)
            for t in np.sort(points[first, across]):
                on_line = on_face & (np.abs(points[:, across] - t) <= tol)
                row = []
                for y in layers:
                    at = np.flatnonzero(on_line & (np.abs(points[:, 1] - y) <= tol))
                    if at.size != 1:
                        raise MetricError(
                            f"no single side-face node at y = {y:.6g} on the line "
                            f"{'xz'[axis // 2]} = {side:.6g}, {'xz'[across // 2]} = {t:.6g}: "
                            "the mesh has no vertical lines of nodes on its side faces")
                    row.append(normal * u[at[0], axis])
                rows.append(row)
    if not rows:
        raise MetricError("no side-face node in the first layer")
    return finite("side_line_profiles", np.array(rows))


def line_alternations(lines, reference, free=None):
    """The signature of :func:`alternation` of each row of ``lines`` (:func:`side_line_profiles`)
    [their unit], read with the weights of the layer profile ``reference`` (one weighting for
    every line, so the rows' mean is the layer profile's signature); None where those layers
    leave no signature."""
    lines, r = np.atleast_2d(np.asarray(lines, float)), np.asarray(reference, float)
    if lines.shape[1] != r.size:
        raise MetricError(f"line_alternations: {lines.shape[1]} layers per line against a "
                          f"reference of {r.size}")
    keep = np.ones(r.size, bool) if free is None else np.asarray(free, bool)
    w = nyquist_weights(r[keep], np.flatnonzero(keep))
    if w is None:
        return None
    return finite("line_alternations_mm", lines[:, keep] @ w)


def alternation(profile, reference, free=None):
    """The period-2 (Nyquist) component of a layer profile, the pattern's own signature:
    ``beta`` [the profiles' unit] of the fit over the ``free`` layers (those whose lateral
    motion nothing prescribes; all when None; they must be consecutive),

        profile_k = alpha reference_k + s_k + beta (-1)^k,

    s a smooth part, read with the weights of :func:`nyquist_weights`, and ``beta`` over the
    reference's mean |profile| (``relative``). The weights are blind to the reference at any
    scale and to polynomials up to degree 2 (EXACT_DEGREE) and read a pure
    (-1)^k pattern as its amplitude: the continuum against itself and a parabolic barrel score
    0 to round-off; of every other smooth field (a bulge or an end layer of two layer spacings
    or wider) they read the least their layers allow (a Gaussian of standard deviation 2
    layers: below 3e-3 of its height on 7 free layers, 3e-4 on 9, 2e-5 on 15 and 17), but
    little on five, where one direction is left to reduce the leak along (the paper's own
    view: it cannot tell a smooth bump from an alternation). +beta puts the layers of even
    index from the base out (the ends and the middle layer of five: the paper's sign). (None,
    None) where the free layers leave no signature (three free layers of a clamped five-layer
    cube)."""
    b, r = np.asarray(profile, float), np.asarray(reference, float)
    if b.shape != r.shape or b.ndim != 1 or b.size < 3:
        raise MetricError(f"alternation needs two profiles of the same three or more layers, "
                          f"got shapes {b.shape} and {r.shape}")
    scale = np.abs(r).mean()
    if scale == 0:
        raise MetricError("alternation: the reference's layer profile is zero, so no relative "
                          "amplitude exists; compare a loaded case")
    keep = np.ones(b.size, bool) if free is None else np.asarray(free, bool)
    k = np.flatnonzero(keep)
    if k.size and np.any(np.diff(k) != 1):
        raise MetricError("alternation: the free layers must be consecutive, got "
                          f"{keep.astype(int).tolist()}")
    w = nyquist_weights(r[keep], k)
    if w is None:
        return None, None
    beta = float(w @ b[keep])
    return finite("alternation_mm", beta), finite("alternation_rel", beta / scale)


# the smooth fields the signature's weights are designed to be blind to (in layer spacings):
# Gaussian bulges of these standard deviations centred anywhere from two of them before the
# first free layer to two after the last, and end layers decaying over these lengths
SMOOTH_WIDTHS = (2.0, 2.5, 3.0, 4.0, 6.0, 8.0, 12.0, 24.0)
SMOOTH_DECAYS = (2.0, 3.0, 4.0)
SMOOTH_STEP = 0.25      # the Gaussians' centres, this fraction of a layer spacing apart
EXACT_DEGREE = 2        # polynomials up to this degree (a parabolic barrel) read 0 exactly


def smooth_family(k):
    """The design fields of :func:`nyquist_weights` on the consecutive layers ``k``, one per
    row, each scaled to a largest |value| of 1: the Gaussians of SMOOTH_WIDTHS, the end
    layers of SMOOTH_DECAYS (at the first layer, the last, both alike and opposite) and the
    half-sine barrel vanishing one layer outside them."""
    k = np.asarray(k, float)
    first, last = k[0], k[-1]
    rows = [np.exp(-(k - c) ** 2 / (2 * s * s)) for s in SMOOTH_WIDTHS
            for c in np.arange(first - 2 * s, last + 2 * s + 1e-9, SMOOTH_STEP)]
    for d in SMOOTH_DECAYS:
        base, top = np.exp(-(k - first) / d), np.exp(-(last - k) / d)
        rows += [base, top, base + top, base - top]
    rows.append(np.sin(np.pi * (k - first + 1) / (last - first + 2)))
    a = np.array(rows)
    return a / np.abs(a).max(axis=1, keepdims=True)


def nyquist_weights(reference, k):
    """The weights w of :func:`alternation` on the layers ``k`` (consecutive indices): of the
    weightings blind to ``reference`` and to the polynomials up to EXACT_DEGREE with
    w . (-1)^k = 1, the one whose scores on :func:`smooth_family` have the
    least sum of squares (a minimum-leakage filter: the smooth part is whatever varies over
    two layer spacings or more, not a polynomial the layers happen to span); None where
    (-1)^k lies in the span of what the weights must be blind to."""
    k = np.asarray(k, float)
    n = len(k)
    alt = (-1.0) ** k
    x = np.linspace(-1.0, 1.0, n) if n > 1 else np.zeros(1)
    exact = np.column_stack([reference, np.polynomial.legendre.legvander(x, EXACT_DEGREE)])
    exact = exact / np.linalg.norm(exact, axis=0)          # unit columns: ranks at RANK_TOL
    u, sv, _ = np.linalg.svd(exact, full_matrices=True)
    rank = int((sv > RANK_TOL * sv[0]).sum())
    null = u[:, rank:]                 # every weighting blind to the exact fields
    a = null.T @ alt
    if np.linalg.norm(a) <= 1e3 * RANK_TOL * np.linalg.norm(alt):
        return None                    # (-1)^k is exact-smooth on these layers
    s = smooth_family(k) @ null
    gram = s.T @ s
    # a ridge at round-off keeps the solve defined where the family spans fewer directions
    gram += 1e-12 * np.trace(gram) / len(gram) * np.eye(len(gram))
    z = np.linalg.solve(gram, a)
    return null @ (z / (a @ z))


def paper_pattern(profile):
    """True when the middle layer and the ends bulge relative to their neighbours while the
    quarter layers neck (the paper's section 5): second differences above PATTERN_TOL of the
    profile, positive at the quarter layers and negative at the middle (five layers)."""
    b = np.asarray(profile, float)
    if b.size != 5:
        raise MetricError("the paper's pattern is defined on five layers")
    d2 = b[:-2] - 2 * b[1:-1] + b[2:]
    tol = PATTERN_TOL * np.abs(b).max()  # rounding noise on a uniform profile is no pattern
    return bool(d2[0] > tol and d2[1] < -tol and d2[2] > tol)


MAC_MIN = 0.8          # a model mode pairs with reference modes whose span holds this much of it


def mac(a, B):
    """The subspace modal assurance criterion of the mode shape ``a`` (3n,) against the span of
    the columns of ``B`` (3n, k): ||P a||^2 / ||a||^2 with P the orthogonal projector onto
    it; for one column the classic |a . b|^2 / (|a|^2 |b|^2). Complex shapes (a
    non-conservative model's) are compared by their modulus."""
    Q, _ = np.linalg.qr(np.asarray(B, dtype=complex).reshape(len(a), -1))
    a = np.asarray(a, dtype=complex)
    return float(np.linalg.norm(Q.conj().T @ a) ** 2 / np.vdot(a, a).real)


def spanned(a, B, mac_min=MAC_MIN):
    """The fewest columns of ``B`` (best single MAC first) whose span holds ``mac_min`` of the
    shape ``a``; None when all of them together do not (a shape the reference lacks)."""
    a = np.asarray(a, dtype=complex) / np.linalg.norm(a)
    single = np.abs(a.conj() @ B) ** 2 / np.linalg.norm(B, axis=0) ** 2
    order = np.argsort(-single, kind="stable")
    Q, _ = np.linalg.qr(B[:, order])     # its first k columns span the best k
    held = np.cumsum(np.abs(Q.conj().T @ a) ** 2)
    return list(order[:np.argmax(held >= mac_min) + 1]) if held[-1] >= mac_min else None


def pair_modes(f_model, v_model, f_ref, v_ref, mac_min=MAC_MIN, count=None, mass=None):
    """Pair reference modes with model modes by shape: [(i_ref, j_model)] and the unpaired
    reference indices among the first ``count`` (default all). ``f_*`` ascending frequencies,
    ``v_*`` (k, 3n) shapes, node by node; ``mass`` (n,) nodal masses weight the comparison
    (the modes' own inner product: unweighted, the few light corner and surface nodes would
    count as much as the heavy inner ones). Reference modes past ``count`` only complete a
    group that ``count`` would cut.

    Individual reference shapes are only defined up to mixing with those of near frequency:
    the cube's symmetry makes pairs and triples, which an irregular mesh splits by a few %,
    and a model's own error mixes modes further apart (FEM P1 on the 5-node cube: up to 20 %
    apart). So each model mode is explained by the fewest reference modes whose span holds
    ``mac_min`` of its shape (``spanned``), and each reference mode by the fewest model modes
    (both ways: a degenerate model space may come as any, even non-orthogonal, basis);
    the modes one mode needs jointly form one group with it (transitively), and a group
    pairs its reference modes with the model modes it explains, the best matching first, in
    frequency order. A model mode no set of reference modes explains (a spurious shape)
    pairs with none, instead of shifting every later frequency; a reference mode its group
    finds no model mode for is unpaired."""
    w = 1.0 if mass is None else np.sqrt(np.repeat(np.asarray(mass, float), 3))
    vm, B = np.asarray(v_model, complex) * w, (np.asarray(v_ref, complex) * w).T
    nr = len(f_ref)
    root = list(range(nr + len(f_model)))   # union-find: reference modes, then model modes

    def find(i):
        while root[i] != i:
            i = root[i]
        return i

    def join(a, others):
        for b in others:
            root[find(b)] = find(a)
    spans = {j: s for j in range(len(f_model)) if (s := spanned(vm[j], B, mac_min))}
    for j, s in spans.items():
        join(nr + j, s)
    for i in range(nr):
        join(i, [nr + j for j in spanned(B[:, i], vm.T, mac_min) or []])
    pairs, unpaired = [], []
    for g in sorted({find(i) for i in range(nr)}):
        c = [i for i in range(nr) if find(i) == g]
        fit = sorted((j for j in spans if find(nr + j) == g), key=lambda j: -mac(vm[j], B[:, c]))
        chosen = sorted(fit[:len(c)], key=lambda j: (f_model[j], j))
        pairs += list(zip(c, chosen))
        unpaired += c[len(chosen):]
    pairs.sort()
    if count is not None:
        pairs = [(i, j) for i, j in pairs if i < count]
        unpaired = [i for i in unpaired if i < count]
    return pairs, sorted(unpaired)
