"""Boundary conditions: ``{node: (ux, uy, uz)}`` with None for a free component."""
import numpy as np

from .errors import ModelError


def bc_arrays(bc, n_nodes):
    """Mask (n, 3) of prescribed components and their displacement values (n, 3) [m]."""
    if not hasattr(bc, "items"):
        raise ModelError(f"boundary conditions must be a mapping node -> (ux, uy, uz), "
                         f"got {type(bc).__name__}")
    mask = np.zeros((n_nodes, 3), dtype=bool)
    vals = np.zeros((n_nodes, 3))
    for node, comp in bc.items():
        if int(node) != node or not 0 <= node < n_nodes:
            raise ModelError(f"boundary condition on node {node!r}: nodes are 0..{n_nodes - 1}")
        if len(comp) != 3:
            raise ModelError(f"boundary condition on node {node}: give (ux, uy, uz) with None "
                             f"for a free component, got {comp!r}")
        for k, v in enumerate(comp):
            if v is None:
                continue
            if not np.isfinite(v):
                raise ModelError(f"boundary condition on node {node}, component {'xyz'[k]}: "
                                 f"value {v!r} is not finite")
            mask[node, k] = True
            vals[node, k] = v
    return mask, vals


def ramp(nodes, displacement, t_ramp, fixed=()):
    """A ``bc_of_t`` that moves ``nodes`` linearly to ``displacement`` (ux, uy, uz) over
    ``t_ramp`` seconds and then holds, with ``fixed`` nodes held at zero throughout."""
    nodes, fixed = [int(i) for i in nodes], [int(i) for i in fixed]
    disp = tuple(displacement)

    def bc_of_t(t):
        s = min(max(t / t_ramp, 0.0), 1.0)
        out = {i: (0.0, 0.0, 0.0) for i in fixed}
        out.update({i: tuple(None if d is None else s * d for d in disp) for i in nodes})
        return out

    return bc_of_t
