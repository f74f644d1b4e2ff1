"""Boundary conditions: ``{node: (ux, uy, uz)}`` with None for a free component."""
import numpy as np

from .errors import ModelError


def merge(pairs):
    """One mapping from an iterable of ``(node, (ux, uy, uz))`` pairs, as node sets give them
    when they overlap (an edge in two faces): components combine, conflicting values are an
    error."""
    out = {}
    try:
        for node, comp in pairs:
            old = out.get(node, (None, None, None))
            if len(comp) != 3:
                raise ModelError(f"boundary condition on node {node}: give (ux, uy, uz) with "
                                 f"None for a free component, got {comp!r}")
            new = []
            for k, (a, b) in enumerate(zip(old, comp)):
                if a is not None and b is not None and a != b:
                    raise ModelError(f"conflicting values for node {node}, component "
                                     f"{'xyz'[k]}: {a!r} and {b!r}; give each component once")
                new.append(a if b is None else b)
            out[node] = tuple(new)
    except TypeError:
        raise ModelError("boundary conditions must be a mapping node -> (ux, uy, uz) or "
                         "(node, (ux, uy, uz)) pairs") from None
    return out


def bc_arrays(bc, n_nodes):
    """Mask (n, 3) of prescribed components and their displacement values (n, 3) [m].

    ``bc`` is a mapping node -> (ux, uy, uz), None for a free component, or an iterable of
    such pairs (see :func:`merge`)."""
    if not hasattr(bc, "items"):
        bc = merge(bc)
    mask = np.zeros((n_nodes, 3), dtype=bool)
    vals = np.zeros((n_nodes, 3))
    if not bc:
        return mask, vals
    nodes = np.array(list(bc.keys()))
    comps = np.empty((len(bc), 3), dtype=object)
    try:
        comps[:] = list(bc.values())
    except ValueError:
        bad = next(k for k, v in bc.items() if not hasattr(v, "__len__") or len(v) != 3)
        raise ModelError(f"boundary condition on node {bad}: give (ux, uy, uz) with None for a "
                         f"free component, got {bc[bad]!r}") from None
    if not np.issubdtype(nodes.dtype, np.integer) or nodes.min() < 0 or nodes.max() >= n_nodes:
        bad = next(k for k in bc if not (isinstance(k, (int, np.integer)) and 0 <= k < n_nodes))
        raise ModelError(f"boundary condition on node {bad!r}: nodes are 0..{n_nodes - 1}")
    given = comps != None  # noqa: E711 (elementwise on an object array)
    try:
        v = np.where(given, comps, 0.0).astype(np.float64)
    except (TypeError, ValueError):
        raise ModelError("boundary condition values must be numbers or None") from None
    if not np.isfinite(v).all():
        i, k = np.argwhere(~np.isfinite(v))[0]
        raise ModelError(f"boundary condition on node {nodes[i]}, component {'xyz'[k]}: "
                         f"value {v[i, k]!r} is not finite")
    mask[nodes] = given
    vals[nodes] = v
    return mask, vals


def path(bc_of_t, n_nodes, t0=0.0):
    """(mask, u_of_t): the components ``bc_of_t`` prescribes (at ``t0``) and a function of t
    giving their displacements (n, 3), through ``bc_of_t.arrays`` where it has one (no mapping
    rebuilt at every step), else ``bc_arrays``, refusing a set of prescribed components that
    changes with time."""
    mask, _ = bc_arrays(bc_of_t(t0), n_nodes)
    if hasattr(bc_of_t, "arrays"):
        def u_of_t(t):
            return bc_of_t.arrays(t, n_nodes)[1]
    else:
        def u_of_t(t):
            m, u = bc_arrays(bc_of_t(t), n_nodes)
            if not np.array_equal(m, mask):
                raise ModelError(f"bc_of_t({t:g}) prescribes other components than at t = "
                                 f"{t0:g}; the set of prescribed components must stay the same")
            return u
    return mask, u_of_t


def load_fractions(load_steps):
    """The load fractions of ``load_steps``: k / n for an int n, or the given increasing
    fractions in (0, 1] ending at 1 (steps of unequal size, e.g. to stop at measured states)."""
    if isinstance(load_steps, (int, np.integer)) and not isinstance(load_steps, bool):
        if load_steps < 1:
            raise ModelError(f"load_steps must be a positive integer, got {load_steps!r}")
        return np.arange(1, load_steps + 1) / load_steps
    try:
        f = np.asarray(load_steps, dtype=float).ravel()
    except (TypeError, ValueError):
        f = np.array([np.nan])
    if f.size == 0 or not np.all(np.isfinite(f)) or f[0] <= 0 or np.any(np.diff(f) <= 0) \
            or f[-1] != 1.0:
        raise ModelError(f"load_steps must be a positive integer or increasing fractions in "
                         f"(0, 1] ending at 1, got {load_steps!r}")
    return f


class Ramp:
    """A ``bc_of_t``: ``nodes`` move linearly to ``displacement`` (ux, uy, uz; None for free)
    over ``t_ramp`` seconds and then hold; ``fixed`` nodes stay at zero and ``held`` (a bc
    mapping) stays at its values throughout.

    Callable like any ``bc_of_t`` (t -> mapping); ``arrays`` and ``velocity`` give the
    integrator the prescribed state without rebuilding a mapping at every stage.
    """

    def __init__(self, nodes, displacement, t_ramp, fixed=(), held=None):
        if not t_ramp > 0:
            raise ModelError(f"t_ramp must be a positive time in seconds, got {t_ramp!r}")
        self.nodes, self.fixed = [int(i) for i in nodes], [int(i) for i in fixed]
        self.disp, self.t_ramp = tuple(displacement), float(t_ramp)
        self.held = dict(held or {})
        self._cache = None

    def scale(self, t):
        """The fraction of the displacement reached at t (0 before, 1 after the ramp)."""
        return min(max(t / self.t_ramp, 0.0), 1.0)

    def __call__(self, t):
        s = self.scale(t)
        out = [(i, (0.0, 0.0, 0.0)) for i in self.fixed] + list(self.held.items())
        out += [(i, tuple(None if d is None else s * d for d in self.disp)) for i in self.nodes]
        return merge(out)

    def parts(self, n_nodes):
        """(mask, start, moving) (n, 3): the prescribed components, their values at t = 0
        and the change over the ramp; the prescribed values at t are start + scale(t) moving."""
        if self._cache is None or self._cache[0] != n_nodes:
            mask, end = bc_arrays(self(self.t_ramp), n_nodes)
            _, start = bc_arrays(self(0.0), n_nodes)
            self._cache = (n_nodes, mask, start, end - start)
        return self._cache[1:]

    def arrays(self, t, n_nodes):
        """(mask, displacement) at time t, as bc_arrays(self(t), n_nodes) gives them."""
        mask, start, moving = self.parts(n_nodes)
        return mask, start + self.scale(t) * moving

    def velocity(self, t, n_nodes):
        """Prescribed velocity at t (the ramp's slope before t_ramp, zero after)."""
        _, _, moving = self.parts(n_nodes)
        return moving / self.t_ramp if 0.0 <= t < self.t_ramp else np.zeros_like(moving)


class Proportional(Ramp):
    """A ``bc_of_t`` whose every prescribed value grows in proportion, from zero at t = 0 to
    the mapping ``bc`` at ``t_ramp``, and then holds: a whole boundary condition ramped (a
    problem whose nodes move by different amounts)."""

    def __init__(self, bc, t_ramp):
        super().__init__((), (None, None, None), t_ramp)
        self.final = merge(bc.items() if hasattr(bc, "items") else bc)

    def __call__(self, t):
        s = self.scale(t)
        return {i: tuple(None if d is None else s * d for d in u) for i, u in self.final.items()}


def ramp(nodes, displacement, t_ramp, fixed=(), held=None):
    """Shorthand for :class:`Ramp`."""
    return Ramp(nodes, displacement, t_ramp, fixed, held)
