"""The real-time study's runs: the paper's push on the five cube over the bench's mesh sizes,
each model's static equilibrium against FEM P1 on the same tetrahedra and against the converged
continuum, beside what `pbcm bench` measured that model to cost per simulated second there.

Nothing is timed here: every cost is the bench's (``cases.reporting.costs``), measured in one
process on the machine the bench names, so that the accuracy runs stay deterministic."""
from dataclasses import dataclass

import numpy as np

from model import build
from model.presets import IMPLICIT_STEP
from reference import hyperelastic
from ...framework import FINDINGS, LOAD_SPLITS, STALL, MaterialSettings, solve_split
from ...library import paper_cube as P
from ...library.common import bench_mesh
from ...measuring import metrics as M
from ...running.progress import Progress
from ...running.runner import free_components, jsonable
from ...running.store import OFF, key
from ...running.workers import dearest_first

# the bench's sizes from the paper's cube up (the same 'five' cubes it times); the accuracy is
# computed up to ACCURACY_TETS (a static Newton solve per model and size), the cost read at all
SIZES = (3.2e2, 1e3, 1e4, 1e5)
QUICK_SIZES = (3.2e2, 1e3)
ACCURACY_TETS = 2.5e4
BC = "clamped"                  # the paper's base
P1 = "fem-neohookean"           # FEM P1 with the continuum's law: the model-form twin
MODELS = ("pbcm-corner", "pbcm-balanced", "pbcm-variational", "msm", "fem-linear",
          "fem-corotated", P1, *IMPLICIT_STEP)
REF_MESH = ("six", 5)           # the continuum: neo-Hookean P2 on this cube, refined
REF_LEVELS, QUICK_REF_LEVELS = 2, 1
STATIC_RTOL = 1e-10


def statics_of(model):
    """The model whose static equilibrium ``model`` has: an implicit preset's is its explicit
    twin's (the same forces; backward Euler changes the dynamics only)."""
    return "fem-corotated" if model in IMPLICIT_STEP else model


@dataclass
class RealtimeSettings(MaterialSettings):
    """Material (the paper cube's) and the mode."""

    quick: bool = False

    @property
    def sizes(self):
        return QUICK_SIZES if self.quick else SIZES

    @property
    def ref_levels(self):
        return QUICK_REF_LEVELS if self.quick else REF_LEVELS

    @property
    def units(self):
        """Work units a pool could share: each explicit model's static solve per size whose
        accuracy is computed."""
        return len([t for t in self.sizes if t <= ACCURACY_TETS]) * len(
            {statics_of(m) for m in MODELS})

    def problem(self):
        return {**self.material_record(), "size_mm": P.SIZE_MM, "push_mm": P.PUSH_MM,
                "bc": BC, "sizes": [int(t) for t in self.sizes],
                "accuracy_tets": ACCURACY_TETS,
                "reference": {"element": "P2", "mesh": f"{REF_MESH[0]} {REF_MESH[1]}^3",
                              "refinements": self.ref_levels}}

    def describe(self):
        return {**self.problem(), "quick": self.quick, "models": list(MODELS)}


def meshes(s):
    """{tetrahedra: mesh} of the bench's 'five' cubes at the study's sizes."""
    return {m.n_tets: m for m in (bench_mesh(t) for t in s.sizes)}


def reference(s):
    """The continuum under the paper's push on the clamped cube, and its error estimate."""
    from model.mesh import cube
    mesh = cube(REF_MESH[1], P.SIZE_MM * P.MM, REF_MESH[0])
    return hyperelastic.converged(mesh, s.material, P.static_bc(mesh, BC, P.PUSH_MM),
                                  levels=s.ref_levels, mixed="auto")


def _solve(job):
    """One model's static equilibrium on one mesh: its displacement field [m], or why it
    failed."""
    model, mesh, s = job
    try:
        pm = build(model, mesh, s.material)
        st, steps = solve_split(pm, P.static_bc(mesh, BC, P.PUSH_MM), splits=LOAD_SPLITS,
                                rtol=STATIC_RTOL, stall=STALL)
    except FINDINGS as exc:
        return {"u": None, "failed": str(exc), "load_steps": None}
    return {"u": st.u, "failed": None, "load_steps": steps}


def run(s, workers=None, log=True, bench=None, store=OFF):
    """Every (size, model) run's errors where the size is at most ACCURACY_TETS (each
    explicit model's own static solve, the implicit presets reading their twin's), and the
    bench's cost per simulated second at every size."""
    from ...reporting import costs
    by_tets = meshes(s)
    solved = {t: m for t, m in by_tets.items() if t <= ACCURACY_TETS}
    own = sorted({statics_of(m) for m in MODELS})
    jobs = [(t, m) for t in solved for m in own]
    with Progress("realtime", 1 + len(jobs), log=log) as progress:
        ref_key = key(kind="realtime-reference", **s.problem())
        ref = store.get(ref_key)
        if ref is None:
            r = reference(s)
            ref = store.put(ref_key, {"at": {t: r.result.at(m.points) for t, m in solved.items()},
                                      "error_estimate": r.error_estimate})
        progress.advance(1, "reference")
        keys = [key(kind="realtime-run", **s.problem(), tets=t, model=m) for t, m in jobs]
        found = [store.get(k) for k in keys]
        todo = [i for i, f in enumerate(found) if f is None]
        progress.advance(len(jobs) - len(todo))
        made = dearest_first(_solve, [(jobs[i][1], solved[jobs[i][0]], s) for i in todo],
                             workers, lambda i: progress.advance(1, " ".join(
                                 map(str, jobs[todo[i]]))), [jobs[i][0] for i in todo])
        for i, got in zip(todo, made):
            found[i] = store.put(keys[i], got)
    fields = dict(zip(jobs, found))
    rows = []
    for t, mesh in by_tets.items():
        cost = {m: costs.per_simulated_second(bench, m, t) for m in MODELS}
        for m in MODELS:
            row = {"mesh": f"five-{t}", "tets": t, "nodes": mesh.n_nodes, "bc": BC,
                   "model": m, "realtime_factor": cost[m], "accuracy": t in solved,
                   "failed": None, "disp_rel_l2": None, "disp_form_rel_l2": None,
                   "load_steps": None}
            if t in solved:
                got, p1 = fields[(t, statics_of(m))], fields[(t, P1)]
                row.update(failed=got["failed"], load_steps=got["load_steps"])
                if got["u"] is not None:
                    row.update(_errors(got["u"], None if p1["u"] is None else p1["u"],
                                       ref["at"][t], mesh))
            rows.append(row)
    return jsonable({"runs": rows, "error_estimate": ref["error_estimate"],
                     "machine": (bench or {}).get("machine")})


def _errors(u, u_p1, u_c, mesh):
    """The distance from the continuum ``u_c`` (||u - u_c|| / ||u_c||) and the model-form
    error against FEM P1 (||u - u_p1|| / ||u_c||), over the free components."""
    free = free_components(P.static_bc(mesh, BC, P.PUSH_MM), mesh.n_nodes)
    scale = float(np.linalg.norm(np.asarray(u_c)[free]))
    form = None if u_p1 is None else float(np.linalg.norm((u - u_p1)[free])) / scale
    return {"disp_rel_l2": M.rel_l2(u, u_c, free),
            "disp_form_rel_l2": M.finite("disp_form_rel_l2", form) if form is not None
            else None}
