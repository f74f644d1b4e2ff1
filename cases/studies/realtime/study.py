"""The real-time study's runs: the paper's push on the 'five' cubes of the bench's real-time
family, each model's static equilibrium against FEM P1 on the same tetrahedra and against the
converged continuum, beside the wall time per simulated second `pbcm bench` measured for that
model there (``cases.tools.realtime_bench``: the same push, each model at its own step).

Nothing is timed here: every cost is the bench's, measured in one process on the machine the
bench names, so that the accuracy runs stay deterministic. The accuracy is computed where the
bench timed a model (and FEM P1 there): above the sizes where a model was over real time twice
in a row, neither is measured, since those sizes cannot be its reach."""
import math
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
from ...reporting import costs as bench_costs

BC = "clamped"                  # the paper's base
P1 = "fem-neohookean"           # FEM P1 with the continuum's law: the model-form twin
REF_MESH = ("six", 5)           # the continuum: neo-Hookean P2 on this cube, refined
REF_LEVELS, QUICK_REF_LEVELS = 2, 1
STATIC_RTOL = 1e-10


def statics_of(model):
    """The model whose static equilibrium ``model`` has: an implicit preset's is its explicit
    twin's (the same forces; backward Euler changes the dynamics only)."""
    return "fem-corotated" if model in IMPLICIT_STEP else model


def laws(quick):
    """One static solve each: the laws of the family's models."""
    return tuple(dict.fromkeys(statics_of(m) for m in bench_costs.family_models(quick)))


class CubePush:
    """The library's loading: the paper's push on the clamped 'five' cubes of the bench's
    real-time family, the continuum neo-Hookean P2 on a finer cube. A user's problem has the
    same methods (``cases.studies.realtime.problem.ProblemLoading``)."""

    bc = BC
    above_reach = True          # every timed size solved (the family steps by 1.5 at most)
    # how the report names the loading, its family, its timing and its force
    words = {"loading": "the paper's push on its cube", "load": "the push",
             "loads_detail": "the paper's push (1.7 mm on the 32 mm cube at 1.7 mm/s, clamped "
                             "base) on the 'five' cubes of its real-time family",
             "family": "the bench's real-time family (run `pbcm bench` on this machine)",
             "quick": "`pbcm run realtime` reads the bench's whole real-time family",
             "timer": "`pbcm bench`", "timing": "the bench", "blowup": "one stops the bench",
             "stops": "two sizes in a row over real time", "stopped": "at two smaller sizes in a row",
             "solved": "",
             "field": "the displacement field, which the push prescribes and a law's "
                      "stiffness hardly moves",
             "force": "top force", "force_detail": "the force the push needs (the top reaction)",
             "force_is": "the reaction the push needs",
             "question": "The question the paper leaves open",
             "inputs": "the Truth Cube study's",
             "force_why": "the push prescribes the top", "figure": "the paper's push",
             "glossary": "../glossary.md"}

    def sizes(self, quick):
        return bench_costs.sizes(quick)

    def mesh(self, tets):
        return bench_mesh(tets)

    def label(self, tets):
        return f"five-{tets}"

    def dirichlet(self, mesh):
        return P.static_bc(mesh, BC, P.PUSH_MM)

    def f_ext(self, mesh):
        return None

    def reference(self, s):
        """The continuum under the push and its error estimate (``reference``)."""
        return reference(s)

    def force_where(self, mesh):
        return top_where(mesh)

    def reference_force(self, result):
        return top_force(reference_mesh(), result.reaction)


@dataclass
class RealtimeSettings(MaterialSettings):
    """Material (the paper cube's) and the mode."""

    quick: bool = False
    loading = CubePush()

    @property
    def ref_levels(self):
        return QUICK_REF_LEVELS if self.quick else REF_LEVELS

    @property
    def units(self):
        """Work units a pool could share: each static solve of the quick family (the full
        run's count depends on the bench)."""
        return len(bench_costs.sizes(True)) * len(laws(True))

    def problem(self):
        return {**self.material_record(), "size_mm": P.SIZE_MM, "push_mm": P.PUSH_MM,
                "bc": BC, "reference": {"element": "P2",
                                        "mesh": f"{REF_MESH[0]} {REF_MESH[1]}^3",
                                        "refinements": self.ref_levels}}

    def describe(self):
        return {**self.problem(), "quick": self.quick,
                "models": list(bench_costs.family_models(self.quick))}


def cost_rows(bench, quick, sizes=None, models=None):
    """{(model, tets): the bench's real-time family row} (every model and size of the family;
    the quick run's two sizes whether or not the bench timed them); ``sizes`` and ``models``
    default the bench's family's."""
    got = {(r["model"], r["tets"]): r for r in (bench or {}).get("realtime_rows", [])}
    return {(m, t): got.get((m, t), {"model": m, "tets": t, "timed": False})
            for t in sizes or bench_costs.sizes(quick)
            for m in models or bench_costs.family_models(quick)}


def solved_pairs(costs, quick, above_reach=True):
    """The (law, tets) whose static equilibrium is solved: every law on the quick family; in
    the full run each law where the bench timed any model with its statics there (without
    ``above_reach``, only up to the largest size any of them was real time at in some
    round, or the smallest timed where none was: what its reach and the ranking read), and
    FEM P1 wherever another law is solved (the model-form twin)."""
    order = tuple(dict.fromkeys([statics_of(m) for m, _ in costs] + [P1]))
    if quick:
        return [(t, m) for t in sorted({t for _, t in costs}) for m in order]
    pairs = {(t, statics_of(m)) for (m, t), r in costs.items() if r.get("timed")}
    if not above_reach:
        pairs = {(t, law) for t, law in pairs if t <= _last_needed(costs, law)}
    pairs |= {(t, P1) for t, _ in pairs}
    return sorted(pairs, key=lambda p: (p[0], order.index(p[1])))


def _last_needed(costs, law):
    """The largest size at which a model with ``law``'s statics was real time in some timing
    round, or the smallest at which one was timed where none was."""
    timed = [(t, r) for (m, t), r in costs.items() if r.get("timed") and statics_of(m) == law]
    fast = [t for t, r in timed
            if min(r["wall_range"][0], (r.get("two_thread_range") or [math.inf])[0])
            <= bench_costs.REAL_TIME]
    return max(fast) if fast else min(t for t, _ in timed)


def reference_mesh():
    """The cube the continuum is solved on (refined ``ref_levels`` times)."""
    from model.mesh import cube
    return cube(REF_MESH[1], P.SIZE_MM * P.MM, REF_MESH[0])


def reference(s):
    """The continuum under the paper's push on the clamped cube, and its error estimate."""
    mesh = reference_mesh()
    return hyperelastic.converged(mesh, s.material, P.static_bc(mesh, BC, P.PUSH_MM),
                                  levels=s.ref_levels, mixed="auto")


def top_force(mesh, reaction):
    """The force the push needs [N]: the reaction on the cube's top nodes along the push
    (None where the model gives no forces)."""
    return force_along(reaction, top_where(mesh))


def top_where(mesh):
    """(the cube's top nodes, the push's axis): where the push's force is summed."""
    return P.boundary_sets(mesh, BC)[0], 1


def _solve(job):
    """One model's static equilibrium on one mesh (its prescribed displacements and loads
    given) with every tetrahedron upright: its displacement field [m] and the force summed
    over ``where`` (nodes, axis; None: no force), or why it failed."""
    model, mesh, material, dirichlet, f_ext, where = job
    try:
        pm = build(model, mesh, material)
        st, steps = solve_split(pm, dirichlet, f_ext=f_ext, splits=LOAD_SPLITS, upright=True,
                                rtol=STATIC_RTOL, stall=STALL)
    except FINDINGS as exc:
        return {"u": None, "failed": str(exc), "load_steps": None, "reaction": None}
    return {"u": st.u, "failed": None, "load_steps": steps,
            "reaction": force_along(st.reaction, where)}


def force_along(reaction, where):
    """The reaction summed over ``where`` (nodes, axis) [N]; None without ``where`` or where
    it is not finite."""
    from ...running.runner import reaction_along
    if where is None:
        return None
    value = float(reaction_along(reaction, where))
    return value if np.isfinite(value) else None


def _reference_at(s, meshes, store, progress):
    """{tets: the continuum at that mesh's nodes} and the reference's error estimate, each
    mesh's values kept under its own key (the family grows with the bench)."""
    keys = {t: key(kind="realtime-reference", **s.problem(), tets=t) for t in meshes}
    est_key = key(kind="realtime-reference", **s.problem(), what="estimate and top force")
    at = {t: store.get(k) for t, k in keys.items()}
    est = store.get(est_key)
    if est is None or any(v is None for v in at.values()):
        r = s.loading.reference(s)
        est = store.put(est_key, {"error_estimate": r.error_estimate,
                                  "reaction": s.loading.reference_force(r.result)})
        for t, v in at.items():
            if v is None:
                at[t] = store.put(keys[t], {"u": r.result.at(meshes[t].points)})
    progress.advance(1, "reference")
    return {t: v["u"] for t, v in at.items()}, est["error_estimate"], est["reaction"]


def run(s, workers=None, log=True, bench=None, store=OFF):
    """Every solved (size, law)'s errors, and each (model, size)'s row with the bench's cost
    beside its law's errors."""
    loading = s.loading
    costs = cost_rows(bench, s.quick, loading.sizes(s.quick), getattr(s, "models", None))
    jobs = solved_pairs(costs, s.quick, loading.above_reach)
    meshes = {t: loading.mesh(t) for t in sorted({t for t, _ in jobs})}
    with Progress("realtime", 1 + len(jobs), log=log) as progress:
        ref_at, estimate, force_c = _reference_at(s, meshes, store, progress)
        keys = [key(kind="realtime-run", **s.problem(), tets=t, model=m, top_force=True)
                for t, m in jobs]
        found = [store.get(k) for k in keys]
        todo = [i for i, f in enumerate(found) if f is None]
        progress.advance(len(jobs) - len(todo))
        made = dearest_first(_solve, [(jobs[i][1], meshes[jobs[i][0]], s.material,
                                       loading.dirichlet(meshes[jobs[i][0]]),
                                       loading.f_ext(meshes[jobs[i][0]]),
                                       loading.force_where(meshes[jobs[i][0]])) for i in todo],
                             workers, lambda i: progress.advance(1, " ".join(
                                 map(str, jobs[todo[i]]))), [jobs[i][0] for i in todo])
        for i, got in zip(todo, made):
            found[i] = store.put(keys[i], got)
    fields = dict(zip(jobs, found))
    rows = []
    for (m, t), cost in costs.items():
        law = statics_of(m)
        row = {"mesh": loading.label(t), "tets": t, "bc": loading.bc, "model": m, "law": law,
               "cost": cost, "accuracy": (t, law) in fields, "failed": None,
               "disp_rel_l2": None, "disp_form_rel_l2": None, "force_rel": None,
               "force_form_rel": None, "load_steps": None}
        if row["accuracy"]:
            got, p1 = fields[(t, law)], fields.get((t, P1))
            row.update(failed=got["failed"], load_steps=got["load_steps"])
            if got["u"] is not None:
                row.update(_errors(got["u"], None if p1 is None else p1["u"], ref_at[t],
                                   loading.dirichlet(meshes[t]), meshes[t].n_nodes))
                row.update(_force_errors(got["reaction"], None if p1 is None
                                         else p1["reaction"], force_c))
        rows.append(row)
    return jsonable({"runs": rows, "error_estimate": estimate, "top_force_n": force_c,
                     "machine": (bench or {}).get("realtime_machine")
                     or (bench or {}).get("machine")})


def _force_errors(f, f_p1, f_c):
    """The top force's distance from the continuum's (f - f_c) / |f_c| and its model-form
    error against FEM P1's (f - f_p1) / |f_c|, signed: what the displacement field, which the
    push prescribes, hardly sees (a law's stiffness)."""
    if f is None or not f_c:
        return {}
    return {"force_rel": M.finite("force_rel", (f - f_c) / abs(f_c)),
            "force_form_rel": None if f_p1 is None
            else M.finite("force_form_rel", (f - f_p1) / abs(f_c))}


def _errors(u, u_p1, u_c, dirichlet, n_nodes):
    """The distance from the continuum ``u_c`` (||u - u_c|| / ||u_c||) and the model-form
    error against FEM P1 (||u - u_p1|| / ||u_c||), over the components ``dirichlet`` leaves
    free."""
    free = free_components(dirichlet, n_nodes)
    scale = float(np.linalg.norm(np.asarray(u_c)[free]))
    form = None if u_p1 is None else float(np.linalg.norm((u - u_p1)[free])) / scale
    return {"disp_rel_l2": M.rel_l2(u, u_c, free),
            "disp_form_rel_l2": M.finite("disp_form_rel_l2", form) if form is not None
            else None}
