"""The paper's experiment (section 4): a 32 mm cube, 5 x 5 x 5 nodes, the top pushed down
1.7 mm at 1.7 mm/s, measured against FEM for every mesh, boundary condition and model.

Millimetres stop at this file's edge: everything below the constants is in SI units.
"""
from dataclasses import dataclass, field
import statistics
import sys
import time

import numpy as np

from model import PRESETS, BlowUpError, Material, ModelError, build
from model.bc import Ramp, bc_arrays, merge
from model.mesh import cube
from model.terms.shear import Shear
from reference import linear
from . import metrics as M

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
                      "hold_max": 1.0, "quick": True, **kw})

    def describe(self):
        return {"E_Pa": self.E, "nu": self.nu, "rho_kg_m3": self.rho, "size_mm": SIZE_MM,
                "nodes_per_side": NODES_PER_SIDE, "push_mm": PUSH_MM,
                "speed_mm_s": SPEED_MM_S, "layers_mm": list(LAYERS_MM),
                "meshes": list(self.meshes), "bcs": list(self.bcs), "models": list(self.models),
                "p2_levels": self.p2_levels, "damping_1_s": self.damping,
                "rk4_safety": self.safety, "hold_max_s": self.hold_max,
                "rest_speed_fraction": self.rest_speed, "timing_steps": self.timing_steps,
                "timing_repeats": self.timing_repeats, "quick": self.quick,
                "shear_scale": self.shear_scale}


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


def uniform(field):
    return np.ptp(field) <= 1e-9 * max(np.abs(field).max(), 1e-300)


def build_model(name, mesh, mat, cfg):
    has_shear = any(t == "shear" for t, _ in PRESETS[name])
    extra = {"shear": {"scale": cfg.shear_scale}} if has_shear and cfg.shear_scale != 1 else {}
    return build(name, mesh, mat, **extra)


def dynamic_run(pm, mesh, bc, cfg):
    """RK4 as in the paper: the push over 1 s, then held until at rest (or hold_max)."""
    ramp = dynamic_bc(mesh, bc)
    t_push = ramp.t_ramp
    dt = pm.stable_dt(cfg.safety)
    t0 = time.perf_counter()
    rest = cfg.rest_speed * SPEED_MM_S * MM
    try:
        traj = pm.simulate(ramp, t_push, dt=dt, damping=cfg.damping, frames=21)
        ts, rs, x, v, t = list(traj.t), list(traj.reaction), traj.x[-1], traj.v, t_push
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
    return {"failed": None, "x": x, "t": np.array(ts),
            "reaction_y": -np.array(rs)[:, top, 1].sum(axis=1),
            "t_end": t, "at_rest": bool(np.abs(v).max() <= rest), "steps": steps,
            "dt": dt, "wall": wall, "max_speed": float(np.abs(v).max())}


def dynamic_metrics(dyn, mesh, st):
    """The dynamic run's metrics; None throughout (and the reason) when it blew up."""
    keys = ("dyn_vs_static_rel_l2", "dyn_at_rest", "dyn_t_end_s", "dyn_steps",
            "dyn_reaction_t_s", "dyn_reaction_n")
    out = {"dyn_failed": dyn["failed"], "dyn_dt_s": dyn["dt"], "dyn_wall_s": dyn["wall"]}
    if dyn["failed"]:
        return {**out, **{k: None for k in keys}}
    return {**out,
            "dyn_vs_static_rel_l2": M.rel_l2(dyn["x"] - mesh.points, st.u),
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
    """Median over repeats of the wall time of one RK4 step (the full integrator's step)."""
    ramp = dynamic_bc(mesh, bc)
    dt = pm.stable_dt(cfg.safety)
    times = []
    for _ in range(cfg.timing_repeats):
        t0 = time.perf_counter()
        pm.simulate(ramp, cfg.timing_steps * dt, dt=dt, damping=cfg.damping, frames=2)
        times.append((time.perf_counter() - t0) / cfg.timing_steps)
    return statistics.median(times)


def run(cfg, log=True):
    """Run every (mesh, bc, model); return the runs (metrics) and the fields for figures."""
    mat = cfg.material
    total = len(cfg.meshes) * len(cfg.bcs) * (len(cfg.models) + 1)
    done, t_start = 0, time.perf_counter()
    runs, fields = [], {}
    layers = [y * MM for y in LAYERS_MM]
    L = SIZE_MM * MM
    for mesh_name in cfg.meshes:
        mesh = make_mesh(mesh_name)
        probe = Shear(mesh, mat, reading="corner")  # the paper's max |tau| measure
        for bc in cfg.bcs:
            if log:
                progress(done, total, f"{mesh_name}/{bc}: FEM P1 and P2 references", t_start)
            sbc = static_bc(mesh, bc)
            p1 = linear.solve(mesh, mat.E, mat.nu, sbc, element="P1")
            conv = linear.converged(mesh, mat.E, mat.nu, sbc, levels=cfg.p2_levels)
            p2 = conv.result
            top = boundary_sets(mesh, bc)[0]
            fem_tau = probe.max_tau(mesh.points + p2.u)
            fem_profile = M.layer_profile(mesh.points, p2.u, layers, L)
            fields[(mesh_name, bc, "fem-p2")] = {"mesh": mesh, "u": p2.u, "max_tau": fem_tau,
                                                 "pressure": p2.pressure,
                                                 "von_mises": p2.von_mises}
            fem_reaction = float(-p2.reaction[top, 1].sum())
            done += 1
            for model_name in cfg.models:
                if log:
                    progress(done, total, f"{mesh_name}/{bc}/{model_name}", t_start)
                pm = build_model(model_name, mesh, mat, cfg)
                st = pm.solve_static(sbc)
                s = pm.tet_stress(st.x)
                dyn = dynamic_run(pm, mesh, bc, cfg)
                profile = M.layer_profile(mesh.points, st.u, layers, L)
                nft = pm.net_force_torque(mesh.points + p2.u)
                uniform_ref = uniform(fem_tau)
                r = {
                    "mesh": mesh_name, "bc": bc, "model": model_name,
                    "nodes": mesh.n_nodes, "tets": mesh.n_tets,
                    "disp_rel_l2_p1": M.rel_l2(st.u, p1.u),
                    "disp_max_rel_p1": M.max_rel(st.u, p1.u),
                    "disp_rel_l2_p2": M.rel_l2(st.u, p2.u),
                    "disp_max_rel_p2": M.max_rel(st.u, p2.u),
                    "reaction_n": M.finite("reaction", -st.reaction[top, 1].sum()),
                    "reaction_fem_p2_n": fem_reaction,
                    "reaction_ratio": M.finite("reaction_ratio",
                                               -st.reaction[top, 1].sum() / fem_reaction),
                    "reaction_rel_err": M.finite("reaction_rel_err", abs(
                        -st.reaction[top, 1].sum() / fem_reaction - 1)),
                    "stress_corr": None if uniform_ref else M.correlation(s["max_tau"], fem_tau),
                    "stress_rel_err": M.rel_l2(s["max_tau"], fem_tau),
                    "pressure_corr": (None if uniform(p2.pressure)
                                      else M.correlation(s["pressure"], p2.pressure)),
                    "pressure_rel_err": M.rel_l2(s["pressure"], p2.pressure),
                    "bulge_profile_mm": (profile / MM).tolist(),
                    "bulge_profile_fem_mm": (fem_profile / MM).tolist(),
                    "zigzag": M.zigzag(profile),
                    "zigzag_fem": M.zigzag(fem_profile),
                    "paper_pattern": M.paper_pattern(profile),
                    "paper_pattern_fem": M.paper_pattern(fem_profile),
                    "net_force_rel": M.finite("net_force", nft["force_rel"]),
                    "net_torque_rel": M.finite("net_torque", nft["torque_rel"]),
                    "static_residual_n": st.residual,
                    "growth_rate_1_s": growth_rate(pm, mesh, bc),
                    **dynamic_metrics(dyn, mesh, st),
                    "step_time_s": step_time(pm, mesh, bc, cfg),
                    "p2_error_estimate": conv.error_estimate,
                    "model_info": _jsonable(pm.info),
                }
                runs.append(r)
                fields[(mesh_name, bc, model_name)] = {"mesh": mesh, "u": st.u,
                                                       "max_tau": s["max_tau"],
                                                       "pressure": s["pressure"]}
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
