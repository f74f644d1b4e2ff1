"""The paper cube's dynamics against FEM: the RK4 run against the FEM transient on the same
boundary motion, and the model's modes (linearised at rest) against FEM modes.

Plain functions of arrays; the case module decides when to call them.
"""
import numpy as np

from model.bc import bc_arrays
from reference import dynamic, modal
from ..measuring import metrics as M

N_MODES = 10            # non-rigid frequencies compared
# modes past them, to complete a group of mixed modes the tenth one cuts: FEM P1 mixes the
# 8th to 10th P2 modes with the 13th and 14th (unstructured mesh, clamped base)
CLUSTER_EXTRA = 4
RIGID_TOL = 1e-8        # |lambda| below this fraction of the largest is a rigid (zero) mode
HOLD_CHECK = 0.1        # the particle run checks for rest every 0.1 s of hold: so does FEM


def fem_transient(mesh, motion, top, cfg, rest_speed, element="P2"):
    """The FEM transient (consistent mass, the case's damping) over the push and the longest
    hold, exact in time (``reference.dynamic`` method "modal": no step error, and no cost
    growing with the mesh's thinnest tetrahedron): frames every 10 ms, the top reaction, the
    state at the end of the push and the time to rest (checked every HOLD_CHECK s after the
    push, as the particle run does)."""
    mat = cfg.material
    t_push = motion.t_ramp
    t_end = t_push + cfg.hold_max
    r = dynamic.solve(mesh, mat, motion, t_end, damping=cfg.damping,
                      element=element, mass="consistent", frames=int(round(t_end / 0.01)) + 1,
                      method="modal")
    speed = np.abs(r.v).max(axis=(1, 2))
    checks = [t for t in np.arange(t_push, t_end + 1e-9, HOLD_CHECK)]
    rest = next((t for t in checks if speed[np.argmin(abs(r.t - t))] <= rest_speed), None)
    return {"t": r.t, "reaction_y": -r.reaction[:, top, 1].sum(axis=1),
            "u_push": r.u[np.argmin(abs(r.t - t_push))], "rest_time_s": rest,
            "element": element}


def compare_transient(dyn, fem, mesh):
    """``reaction_time_rel_l2`` (the model's top reaction at its frames against the FEM
    transient interpolated there, over push and hold), ``disp_end_push_rel_l2`` and
    ``rest_time_s`` (None where the run never came to rest)."""
    r_fem = np.interp(dyn["t"], fem["t"], fem["reaction_y"])
    return {"reaction_time_rel_l2": M.rel_l2(dyn["reaction_y"], r_fem),
            "disp_end_push_rel_l2": M.rel_l2(dyn["x_push"] - mesh.points, fem["u_push"]),
            "rest_time_s": dyn["t_end"] if dyn["at_rest"] else None}


def model_frequencies(pm, free, shapes=False):
    """Frequencies [Hz] of the model linearised at rest on the ``free`` components (a (3n,)
    mask), ascending, and the number of rigid (zero) modes; with ``shapes`` also the mode
    shapes (k, 3n), zero on the held components. For a non-conservative reading the
    eigenvalues lambda of -M^-1 df/dx are complex: the frequency is |Re sqrt(lambda)| / 2 pi
    (its growth rate, Im, is the case's growth_rate)."""
    J = pm.jacobian(pm.mesh.points).toarray()[free][:, free]
    A = -J / np.repeat(pm.mass, 3)[free][:, None]
    if shapes:
        lam, vecs = np.linalg.eig(A)
    else:
        lam, vecs = np.linalg.eigvals(A), None
    lam = lam.astype(complex)
    scale = np.abs(lam).max()
    rigid = int((np.abs(lam) < RIGID_TOL * scale).sum())
    freq = np.abs(np.sqrt(lam).real) / (2 * np.pi)
    order = np.argsort(freq, kind="stable")
    if not shapes:
        return freq[order], rigid
    full = np.zeros((len(lam), free.size), dtype=complex)
    full[:, free] = vecs[:, order].T
    return freq[order], full, rigid


def paired_errors(freq, shapes, fem_freq, fem_shapes, name, mass=None):
    """The largest and the median relative frequency error of the model modes paired by
    shape with the first N_MODES FEM modes (``metrics.pair_modes``; FEM modes past them only
    complete a group of mixed modes; ``mass`` (n,) weights the shapes; None and None when no
    mode pairs: a finding, every FEM mode unpaired) and how many of them found no partner."""
    pairs, unpaired = M.pair_modes(freq, shapes, fem_freq, fem_shapes, count=N_MODES,
                                   mass=mass)
    if not pairs:
        return None, None, len(unpaired)
    err = np.array([abs(freq[j] / fem_freq[i] - 1) for i, j in pairs])
    return M.finite(name, err.max()), M.finite(name, np.median(err)), len(unpaired)


def first_modes(pm, free, rigid_expected=None):
    """The model's first 3 N_MODES non-rigid (frequencies, shapes) and its rigid count: the
    candidates the first N_MODES FEM modes are paired with."""
    freq, shapes, rigid = model_frequencies(pm, free, shapes=True)
    skip = rigid if rigid_expected is None else rigid_expected
    return freq[skip:skip + 3 * N_MODES], shapes[skip:skip + 3 * N_MODES], rigid


def modal_comparison(pm, mesh, static_bc, fem_free, fem_held):
    """``modal_rel_err`` (the first N_MODES FEM modes with the case's constraints, each paired
    with the model mode of the same shape: the largest relative frequency error),
    ``modal_rel_err_free`` (free-free, after the rigid modes), ``modes_unpaired`` (FEM modes of
    either set without a partner), ``modes_unpaired_held`` (those of the held set alone) and ``rigid_modes_free`` (6 for a model that resists every
    deformation). ``fem_*`` are (frequencies, shapes (k, 3n)); ``fem_held`` None: the case's
    constraints pose no modal problem (their metrics None)."""
    free, free_v, rigid = first_modes(pm, np.ones(3 * mesh.n_nodes, dtype=bool))
    err_free, _, lost = paired_errors(free, free_v, *fem_free, "modal_rel_err_free",
                                     mass=pm.mass)
    out = {"modal_rel_err": None, "modal_rel_err_free": err_free,
           "rigid_modes_free": rigid, "frequencies_hz": None, "modes_unpaired_held": None}
    if fem_held is not None:
        mask, _ = bc_arrays(static_bc, mesh.n_nodes)
        held, held_v, _ = first_modes(pm, ~mask.ravel(), rigid_expected=0)
        err_held, _, lost_held = paired_errors(held, held_v, *fem_held, "modal_rel_err",
                                               mass=pm.mass)
        lost += lost_held
        out.update(modal_rel_err=err_held, frequencies_hz=held[:N_MODES].tolist(),
                   modes_unpaired_held=lost_held)
    return {**out, "modes_unpaired": lost}


def fem_frequencies(mesh, material, dirichlet, refine=0, skip=0):
    """FEM P2 modes (consistent mass) on ``refine`` refinements of the mesh: the N_MODES
    after the first ``skip`` (the rigid ones free-free) and CLUSTER_EXTRA more (which complete
    a group of mixed modes the N_MODES-th cuts) as (frequencies, shapes (k, 3n) at the mesh
    nodes), and each of the N_MODES frequencies' refinement estimate, its relative change over
    the last refinement (None without one: ``refine`` 0)."""
    def solve(level):
        r = modal.frequencies(mesh, material, dirichlet,
                              k=N_MODES + CLUSTER_EXTRA + skip, refine=level)
        return r.frequencies[skip:], r.modes[skip:].reshape(N_MODES + CLUSTER_EXTRA, -1)
    freq, shapes = solve(refine)
    each = (np.abs(solve(refine - 1)[0][:N_MODES] / freq[:N_MODES] - 1) if refine >= 1
            else None)
    return (freq, shapes), each


def fem_modes(mesh, static_bc, cfg, held=True, refine=0):
    """FEM P2 modes on ``refine`` refinements, each set ((frequencies, shapes), estimates) as
    ``fem_frequencies`` gives it: the first N_MODES non-rigid ones free-free and (``held``;
    else None) the first N_MODES with the case's constraints (held at zero)."""
    free = fem_frequencies(mesh, cfg.material, {}, refine, skip=6)
    if not held:
        return free, None
    zero = {i: tuple(None if c is None else 0.0 for c in comp) for i, comp in static_bc.items()}
    return free, fem_frequencies(mesh, cfg.material, zero, refine)
