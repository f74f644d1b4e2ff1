"""The paper cube's dynamics against FEM: the RK4 run against the FEM transient on the same
boundary motion, and the model's modes (linearised at rest) against FEM modes (issue 9).

Plain functions of arrays; the case module decides when to call them.
"""
import numpy as np

from model.bc import bc_arrays
from reference import dynamic, modal
from .. import metrics as M

N_MODES = 10            # non-rigid frequencies compared
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
    r = dynamic.solve(mesh, mat.E, mat.nu, mat.rho, motion, t_end, damping=cfg.damping,
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


def model_frequencies(pm, free):
    """Frequencies [Hz] of the model linearised at rest on the ``free`` components (a (3n,)
    mask), ascending, and the number of rigid (zero) modes. For a non-conservative reading
    the eigenvalues lambda of -M^-1 df/dx are complex: the frequency is |Re sqrt(lambda)| / 2 pi
    (its growth rate, Im, is the case's growth_rate)."""
    J = pm.jacobian(pm.mesh.points).toarray()[free][:, free]
    A = -J / np.repeat(pm.mass, 3)[free][:, None]
    lam = np.linalg.eigvals(A).astype(complex)
    scale = np.abs(lam).max()
    rigid = int((np.abs(lam) < RIGID_TOL * scale).sum())
    freq = np.sort(np.abs(np.sqrt(lam).real)) / (2 * np.pi)
    return freq, rigid


def modal_comparison(pm, mesh, static_bc, fem_free, fem_held):
    """``modal_rel_err`` (the first N_MODES frequencies with the case's constraints, largest
    relative error against FEM P2), ``modal_rel_err_free`` (free-free, after the rigid
    modes) and ``rigid_modes_free`` (6 for a model that resists every deformation)."""
    mask, _ = bc_arrays(static_bc, mesh.n_nodes)
    held, _ = model_frequencies(pm, ~mask.ravel())
    free, rigid = model_frequencies(pm, np.ones(3 * mesh.n_nodes, dtype=bool))
    free = free[rigid:rigid + N_MODES]
    return {"modal_rel_err": M.finite("modal_rel_err",
                                      np.abs(held[:N_MODES] / fem_held - 1).max()),
            "modal_rel_err_free": M.finite("modal_rel_err_free",
                                           np.abs(free / fem_free - 1).max()),
            "rigid_modes_free": rigid,
            "frequencies_hz": held[:N_MODES].tolist()}


def fem_modes(mesh, static_bc, cfg):
    """FEM P2 frequencies: the first N_MODES with the case's constraints (held at zero) and
    the first N_MODES non-rigid ones free-free."""
    mat = cfg.material
    zero = {i: tuple(None if c is None else 0.0 for c in comp) for i, comp in static_bc.items()}
    held = modal.frequencies(mesh, mat.E, mat.nu, mat.rho, zero, k=N_MODES).frequencies
    free = modal.frequencies(mesh, mat.E, mat.nu, mat.rho, {}, k=N_MODES + 6).frequencies[6:]
    return free, held
