"""The paper's experiment (section 4): a 32 mm cube, 5 x 5 x 5 nodes, the top pushed down
1.7 mm at 1.7 mm/s, measured against FEM for every mesh, boundary condition and model.

Millimetres stop at this file's edge: everything below the constants is in SI units.
"""
from dataclasses import dataclass, field
import statistics
import sys
import time

import numpy as np

from model import PRESETS, BlowUpError, Material, ModelError, PbcmError, build
from model.bc import Ramp, bc_arrays, merge
from model.mesh import cube
from model.terms.shear import Shear
from reference import linear
from . import metrics as M
from . import transient

SIZE_MM = 32.0
NODES_PER_SIDE = 5
PUSH_MM = 1.7
SPEED_MM_S = 1.7
LAYERS_MM = (0.0, 8.0, 16.0, 24.0, 32.0)
MESHES = ("five", "six", "bcc", "unstructured")
QUICK_MESHES = ("five", "six")
BCS = ("clamped", "sliding")
MODELS = tuple(PRESETS)

MM = 1e-3


@dataclass
class Config:
    """What one run of the case does. Defaults follow the paper where it says something and
    MODEL.md where it does not (E, nu, rho: the paper gives none)."""

    E: float = 10e3
    nu: float = 0.45
    rho: float = 1000.0
    meshes: tuple = MESHES
    bcs: tuple = BCS
    models: tuple = MODELS
    p2_levels: int = 2            # refinements of the converged P2 reference
    transient_element: str = "P2"  # element of the FEM transient (quick: P1, 10x cheaper)
    damping: float = 50.0         # mass damping zeta [1/s] (the paper gives none)
    safety: float = 0.8           # RK4 step = safety * min h / c_p
    hold_max: float = 2.0         # longest hold after the push [s]
    rest_speed: float = 1e-3      # at rest: every node slower than this fraction of the push speed
    timing_steps: int = 20        # RK4 steps per timing repeat
    timing_repeats: int = 7
    quick: bool = False
    shear_scale: float = 1.0      # testing knob: scales every shear term (1 = the model)
    material: Material = field(init=False)

    def __post_init__(self):
        self.material = Material(E=self.E, nu=self.nu, rho=self.rho)

    @classmethod
    def quick_config(cls, **kw):
        return cls(**{"meshes": QUICK_MESHES, "p2_levels": 1, "timing_repeats": 3,
                      "transient_element": "P1",
                      "hold_max": 1.0, "quick": True, **kw})

    def problem(self):
        """The parameters that define the problem the metrics answer (what a bound was
        measured at): material, geometry, loading, damping, step and reference resolution.
        Selections (meshes, models) and timing repeats are not part of it."""
        return {"E_Pa": self.E, "nu": self.nu, "rho_kg_m3": self.rho, "size_mm": SIZE_MM,
                "nodes_per_side": NODES_PER_SIDE, "push_mm": PUSH_MM,
                "speed_mm_s": SPEED_MM_S, "layers_mm": list(LAYERS_MM),
                "p2_levels": self.p2_levels, "transient_element": self.transient_element,
                "damping_1_s": self.damping, "rk4_safety": self.safety,
                "hold_max_s": self.hold_max, "rest_speed_fraction": self.rest_speed}

    def describe(self):
        """Everything the run was given: the problem, the selection and the run settings."""
        return {**self.problem(),
                "meshes": list(self.meshes), "bcs": list(self.bcs), "models": list(self.models),
                "timing_steps": self.timing_steps, "timing_repeats": self.timing_repeats,
                "quick": self.quick, "shear_scale": self.shear_scale}


def make_mesh(name):
    return cube(NODES_PER_SIDE, SIZE_MM * MM, name)


def boundary_sets(mesh, bc):
    """(driven, held): the top nodes, moved in y; and the mapping that holds the rest.

    ``clamped``: bottom fully fixed, top fully prescribed. ``sliding``: only y prescribed at top
    and bottom; the origin pinned and the node at (L, 0, 0) held in z remove rigid motions."""
    L = SIZE_MM * MM
    top, bottom = mesh.nodes_on_plane("y", L), mesh.nodes_on_plane("y", 0.0)
    if bc == "clamped":
        return top, (0.0, None, 0.0), {int(i): (0.0, 0.0, 0.0) for i in bottom}
    if bc != "sliding":
        raise ModelError(f"unknown boundary condition {bc!r}; choose from {', '.join(BCS)}")
    held = [(int(i), (None, 0.0, None)) for i in bottom]
    origin = mesh.nodes_where(lambda p: np.all(np.abs(p) < 1e-9, axis=1))[0]
    corner_x = mesh.nodes_where(lambda p: (np.abs(p[:, 0] - L) < 1e-9) & (np.abs(p[:, 1]) < 1e-9)
                                & (np.abs(p[:, 2]) < 1e-9))[0]
    held += [(int(origin), (0.0, 0.0, 0.0)), (int(corner_x), (None, 0.0, 0.0))]
    return top, (None, None, None), merge(held)


def static_bc(mesh, bc):
    top, lateral, held = boundary_sets(mesh, bc)
    out = dict(held)
    out.update({int(i): (lateral[0], -PUSH_MM * MM, lateral[2]) for i in top})
    return out


def dynamic_bc(mesh, bc):
    top, lateral, held = boundary_sets(mesh, bc)
    return Ramp(top, (lateral[0], -PUSH_MM * MM, lateral[2]), PUSH_MM / SPEED_MM_S, held=held)


def progress(done, total, label, t0):
    """One line per step on stderr: the progress bar of a long run."""
    width = 24
    filled = int(width * done / total)
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} "
                     f"{time.perf_counter() - t0:6.1f} s  {label:<48}")
    if done == total:
        sys.stderr.write("\n")
    sys.stderr.flush()


# a reference field that varies by less than this fraction of its size is uniform: its
# variation is the iterative solver's (relative residual 1e-10 gives about 1e-9 here), and a
# correlation with it would correlate with solver noise (the sliding cube's pressure)
UNIFORM_TOL = 1e-6


def uniform(field):
    """True when a reference field is constant to the solver's accuracy (UNIFORM_TOL)."""
    return np.ptp(field) <= UNIFORM_TOL * max(np.abs(field).max(), 1e-300)


def build_model(name, mesh, mat, cfg):
    has_shear = any(t == "shear" for t, _ in PRESETS[name])
    extra = {"shear": {"scale": cfg.shear_scale}} if has_shear and cfg.shear_scale != 1 else {}
    return build(name, mesh, mat, **extra)


def dynamic_run(pm, mesh, bc, cfg, dt_scale=1.0):
    """RK4 as in the paper: the push over 1 s, then held until at rest (or hold_max), at the
    case's step times ``dt_scale``."""
    ramp = dynamic_bc(mesh, bc)
    t_push = ramp.t_ramp
    dt = pm.stable_dt(cfg.safety) * dt_scale
    t0 = time.perf_counter()
    rest = cfg.rest_speed * SPEED_MM_S * MM
    try:
        traj = pm.simulate(ramp, t_push, dt=dt, damping=cfg.damping, frames=21)
        ts, rs, x, v, t = list(traj.t), list(traj.reaction), traj.x[-1], traj.v, t_push
        x_push = x
        steps = traj.steps
        while t < t_push + cfg.hold_max - 1e-12 and np.abs(v).max() > rest:
            chunk = pm.simulate(ramp, t + 0.1, dt=dt, damping=cfg.damping, frames=3, x0=x,
                                v0=v, t0=t)
            ts += list(chunk.t[1:])
            rs += list(chunk.reaction[1:])
            x, v, t, steps = chunk.x[-1], chunk.v, t + 0.1, steps + chunk.steps
    except BlowUpError as exc:
        # a finding about the model (see the stability metric), not a crash of the suite
        return {"failed": str(exc), "wall": time.perf_counter() - t0, "dt": dt}
    wall = time.perf_counter() - t0
    top = ramp.nodes
    return {"failed": None, "x": x, "x_push": x_push, "t": np.array(ts),
            "reaction_y": -np.array(rs)[:, top, 1].sum(axis=1),
            "t_end": t, "at_rest": bool(np.abs(v).max() <= rest), "steps": steps,
            "dt": dt, "wall": wall, "max_speed": float(np.abs(v).max())}


def dynamic_metrics(dyn, mesh, st, fem):
    """The dynamic run's metrics, against the static solution and the FEM transient ``fem``;
    None throughout (and the reason) when it blew up. The distance to the static equilibrium
    is None when the static solve failed."""
    keys = ("dyn_vs_static_rel_l2", "dyn_at_rest", "dyn_t_end_s", "dyn_steps",
            "dyn_reaction_t_s", "dyn_reaction_n", "reaction_time_rel_l2",
            "disp_end_push_rel_l2", "rest_time_s")
    out = {"dyn_failed": dyn["failed"], "dyn_dt_s": dyn["dt"], "dyn_wall_s": dyn["wall"]}
    if dyn["failed"]:
        return {**out, **{k: None for k in keys}}
    return {**out, **transient.compare_transient(dyn, fem, mesh),
            "dyn_vs_static_rel_l2": None if st is None else M.rel_l2(dyn["x"] - mesh.points, st.u),
            "dyn_at_rest": dyn["at_rest"], "dyn_t_end_s": dyn["t_end"],
            "dyn_steps": dyn["steps"], "dyn_reaction_t_s": dyn["t"].tolist(),
            "dyn_reaction_n": M.finite("dyn_reaction", dyn["reaction_y"]).tolist()}


def growth_rate(pm, mesh, bc):
    """Largest exponential growth rate [1/s] of the undamped model linearised at rest with the
    case's constraints: max Re sqrt(lambda) over the eigenvalues lambda of M^-1 df/dx on the
    free components. Zero (to rounding) for a conservative model; positive means flutter, which
    mass damping zeta only suppresses when zeta / 2 exceeds it."""
    mask, _ = bc_arrays(static_bc(mesh, bc), mesh.n_nodes)
    free = ~mask.ravel()
    A = pm.jacobian(mesh.points).toarray()[free][:, free] / np.repeat(pm.mass, 3)[free][:, None]
    lam = np.linalg.eigvals(A).astype(complex)
    rate = float(np.sqrt(lam).real.max())
    scale = float(np.sqrt(np.abs(lam).max()))
    return rate if rate > 1e-7 * scale else 0.0


def step_time(pm, mesh, bc, cfg):
    """Median over repeats of the wall time of one RK4 step of the full integrator, and the
    state it was timed in: the paper's push ("push"); where the push blows up within the
    timed steps, the same steps with the boundary held at rest ("rest": a step costs the same
    arithmetic whatever the state); where even that blows up (rounding at rest amplified by an
    unstable reading), None and "failed: " with the reason."""
    top, _, held = boundary_sets(mesh, bc)
    dt = pm.stable_dt(cfg.safety)
    failures = []
    for state, motion in (("push", dynamic_bc(mesh, bc)),
                          ("rest", Ramp(top, (0.0, 0.0, 0.0), 1.0, held=held))):
        try:
            return _median_step(pm, motion, dt, cfg), state
        except BlowUpError as exc:
            failures.append(f"{state}: {exc}")
    return None, "failed: " + "; ".join(failures)


def _median_step(pm, motion, dt, cfg):
    times = []
    for _ in range(cfg.timing_repeats):
        t0 = time.perf_counter()
        pm.simulate(motion, cfg.timing_steps * dt, dt=dt, damping=cfg.damping, frames=2)
        times.append((time.perf_counter() - t0) / cfg.timing_steps)
    return statistics.median(times)


# the metrics of the static solution; None when the static solve failed
STATIC_KEYS = ("disp_rel_l2_p1", "disp_max_rel_p1", "disp_rel_l2_p2", "disp_max_rel_p2",
               "reaction_n", "reaction_ratio", "reaction_rel_err", "stress_corr",
               "stress_rel_err", "pressure_corr", "pressure_rel_err", "bulge_profile_mm",
               "zigzag", "paper_pattern", "static_residual_n")


class Reference:
    """The FEM side of one (mesh, bc): P1 on the mesh, converged P2, and what the metrics need."""

    def __init__(self, mesh, bc, cfg, probe):
        mat = cfg.material
        self.layers, self.L = [y * MM for y in LAYERS_MM], SIZE_MM * MM
        self.sbc = static_bc(mesh, bc)
        self.p1 = linear.solve(mesh, mat.E, mat.nu, self.sbc, element="P1")
        self.conv = linear.converged(mesh, mat.E, mat.nu, self.sbc, levels=cfg.p2_levels)
        self.p2 = self.conv.result
        self.top = boundary_sets(mesh, bc)[0]
        self.tau = probe.max_tau(mesh.points + self.p2.u)
        self.profile = M.layer_profile(mesh.points, self.p2.u, self.layers, self.L)
        self.reaction = float(-self.p2.reaction[self.top, 1].sum())
        rest = cfg.rest_speed * SPEED_MM_S * MM
        self.transient = transient.fem_transient(mesh, dynamic_bc(mesh, bc), self.top, cfg, rest,
                                                 element=cfg.transient_element)
        self.modes_free, self.modes_held = transient.fem_modes(mesh, self.sbc, cfg)


def static_metrics(pm, st, mesh, ref):
    """The static solution against the references (MODEL.md "What is compared")."""
    s = pm.tet_stress(st.x)
    profile = M.layer_profile(mesh.points, st.u, ref.layers, ref.L)
    reaction = M.finite("reaction", -st.reaction[ref.top, 1].sum())
    return {
        "disp_rel_l2_p1": M.rel_l2(st.u, ref.p1.u),
        "disp_max_rel_p1": M.max_rel(st.u, ref.p1.u),
        "disp_rel_l2_p2": M.rel_l2(st.u, ref.p2.u),
        "disp_max_rel_p2": M.max_rel(st.u, ref.p2.u),
        "reaction_n": reaction,
        "reaction_ratio": M.finite("reaction_ratio", reaction / ref.reaction),
        "reaction_rel_err": M.finite("reaction_rel_err", abs(reaction / ref.reaction - 1)),
        "stress_corr": None if uniform(ref.tau) else M.correlation(s["max_tau"], ref.tau),
        "stress_rel_err": M.rel_l2(s["max_tau"], ref.tau),
        "pressure_corr": (None if uniform(ref.p2.pressure)
                          else M.correlation(s["pressure"], ref.p2.pressure)),
        "pressure_rel_err": M.rel_l2(s["pressure"], ref.p2.pressure),
        "bulge_profile_mm": (profile / MM).tolist(),
        "zigzag": M.zigzag(profile),
        "paper_pattern": M.paper_pattern(profile),
        "static_residual_n": st.residual,
    }, s


def model_run(mesh_name, mesh, bc, model_name, cfg, ref):
    """One (mesh, bc, model): its metrics and its fields for the figures (None when the static
    solve failed). A failure of a phase (static, dynamic, timing) is recorded in that phase's
    ``*_failed`` entry, its metrics are None, and the other phases still run."""
    r = {"mesh": mesh_name, "bc": bc, "model": model_name,
         "nodes": mesh.n_nodes, "tets": mesh.n_tets,
         "reaction_fem_p2_n": ref.reaction,
         "bulge_profile_fem_mm": (ref.profile / MM).tolist(),
         "zigzag_fem": M.zigzag(ref.profile), "paper_pattern_fem": M.paper_pattern(ref.profile),
         "p2_error_estimate": ref.conv.error_estimate,
         "rest_time_fem_s": ref.transient["rest_time_s"]}
    pm = build_model(model_name, mesh, cfg.material, cfg)
    st, fields = None, None
    try:
        st = pm.solve_static(ref.sbc)
        values, s = static_metrics(pm, st, mesh, ref)
        r.update(values, static_failed=None)
        fields = {"mesh": mesh, "u": st.u, "max_tau": s["max_tau"], "pressure": s["pressure"]}
    except PbcmError as exc:   # no equilibrium found, or a metric undefined: a finding
        r.update({k: None for k in STATIC_KEYS}, static_failed=str(exc))
        st = None
    nft = pm.net_force_torque(mesh.points + ref.p2.u)
    r.update(net_force_rel=M.finite("net_force", nft["force_rel"]),
             net_torque_rel=M.finite("net_torque", nft["torque_rel"]),
             growth_rate_1_s=growth_rate(pm, mesh, bc))
    r.update(dynamic_metrics(dynamic_run(pm, mesh, bc, cfg), mesh, st, ref.transient))
    r["dyn_failed_dt4"] = dynamic_run(pm, mesh, bc, cfg, dt_scale=0.25)["failed"]
    r["verdict_changes_dt4"] = (r["dyn_failed"] is None) != (r["dyn_failed_dt4"] is None)
    r.update(transient.modal_comparison(pm, mesh, ref.sbc, ref.modes_free, ref.modes_held))
    r["step_time_s"], r["step_time_state"] = step_time(pm, mesh, bc, cfg)
    r["model_info"] = _jsonable(pm.info)
    return r, fields


def run(cfg, log=True):
    """Run every (mesh, bc, model); return the runs (metrics) and the fields for figures."""
    total = len(cfg.meshes) * len(cfg.bcs) * (len(cfg.models) + 1)
    done, t_start = 0, time.perf_counter()
    runs, fields = [], {}
    for mesh_name in cfg.meshes:
        mesh = make_mesh(mesh_name)
        probe = Shear(mesh, cfg.material, reading="corner")  # the paper's max |tau| measure
        for bc in cfg.bcs:
            if log:
                progress(done, total, f"{mesh_name}/{bc}: FEM P1 and P2 references", t_start)
            ref = Reference(mesh, bc, cfg, probe)
            fields[(mesh_name, bc, "fem-p2")] = {"mesh": mesh, "u": ref.p2.u, "max_tau": ref.tau,
                                                 "pressure": ref.p2.pressure,
                                                 "von_mises": ref.p2.von_mises,
                                                 "transient": ref.transient}
            done += 1
            for model_name in cfg.models:
                if log:
                    progress(done, total, f"{mesh_name}/{bc}/{model_name}", t_start)
                r, f = model_run(mesh_name, mesh, bc, model_name, cfg, ref)
                runs.append(r)
                if f is not None:
                    fields[(mesh_name, bc, model_name)] = f
                done += 1
    if log:
        progress(total, total, "done", t_start)
    return runs, fields


def _jsonable(d):
    if isinstance(d, dict):
        return {k: _jsonable(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [_jsonable(v) for v in d]
    if isinstance(d, (np.floating, np.integer)):
        return d.item()
    return d
