"""The engines study's runs: the Newton engine's solvers (model.simulators.newton) on the bar,
the cube and the cantilever of the case library, each at its default settings and, for the
iterative solvers, up a ladder of iteration counts, beside FEM P1 on the same tetrahedra, through
the cases' own runner (the same references, the same error model as every model).

The bar is the library's block settling under its own weight (``self-weight``, sliding base: a
prismatic bar whose closed form is exact), the cube the paper's (``paper-cube``, clamped base),
the cantilever ``cantilever`` (clamped). Each runs on its quick-mode meshes and references (the
engines' single precision and run-to-rest tolerance, 1e-3, are coarser than those references'
estimates), on the 'five' split in the quick run and on 'five' and 'six' in the full run."""
from dataclasses import dataclass

import numpy as np

from model.simulators.newton import LADDER, SOLVERS, installed, ladder_models
from ...framework import MaterialSettings
from ...measuring.error_model import P1_FINITE, P1_LINEAR, at_load, decomposed, u_num
from ...running.runner import jsonable, run as run_case
from ...running.store import OFF

CASE_NAMES = {"self-weight": "the bar", "paper-cube": "the cube", "cantilever": "the cantilever"}
BCS = {"self-weight": "sliding", "paper-cube": "clamped", "cantilever": "clamped"}
QUICK_RUNGS = 2       # the quick run's iterative solvers: the first two rungs of their ladders
MESHES, QUICK_MESHES = ("five", "six"), ("five",)
CONVERGED = 0.01      # within this fraction of its own answer at the ladder's top
MATCH = 0.05          # "matches FEM P1": a model-form error at most this


@dataclass
class EngineSettings(MaterialSettings):
    """The material (every case's, as the extensions study gives it) and the mode."""

    quick: bool = False

    @property
    def ladder(self):
        return {k: v[:QUICK_RUNGS] if self.quick else v for k, v in LADDER.items()}

    @property
    def meshes(self):
        return QUICK_MESHES if self.quick else MESHES

    def models(self):
        """Every engine model run: the semi-implicit solver, each iterative one up its ladder."""
        return ladder_models(QUICK_RUNGS if self.quick else None)

    def case_settings(self):
        from ...registry import CASES
        return {name: CASES[name].settings(
            quick=True, models=(*self.models(), P1_LINEAR, P1_FINITE), meshes=self.meshes,
            bcs=(BCS[name],), E=self.E, nu=self.nu, rho=self.rho) for name in CASE_NAMES}

    @property
    def units(self):
        return sum(c.units for c in self.case_settings().values())

    def problem(self):
        return {**self.material_record(),
                "cases": {n: c.problem() for n, c in self.case_settings().items()},
                "bcs": BCS, "ladder": {k: list(v) for k, v in self.ladder.items()},
                "meshes": list(self.meshes)}

    def describe(self):
        return {**self.problem(), "quick": self.quick, "models": list(self.models())}


def mesh_sizes(s):
    """{case: {mesh: tetrahedra}} of the meshes the study runs each case on (``s.meshes``, the
    cases' quick meshes): each case's own mesh builder under the study's settings of it, so
    known from the recorded problem without running anything."""
    from ...registry import CASES
    return {name: {m: CASES[name].mesh(m, cfg).n_tets for m in s.meshes}
            for name, cfg in s.case_settings().items()}


def solver_of(model):
    """(solver, iterations or None) of an engine model's name."""
    for solver in SOLVERS:
        if model == solver or model.startswith(solver + "("):
            if solver not in LADDER:
                return solver, None
            n = LADDER[solver][0]
            if "iterations=" in model:
                n = int(model.split("iterations=")[1].split(",")[0].rstrip(")"))
            return solver, n
    return None, None


def case_rows(case, runs):
    """Each run's quantity, model-form, discretisation and total errors (signed, relative to
    the continuum's |Q_c|) in the linear regime and at the case's load."""
    rows = []
    for q, regime in ((case.decomposed, "linear regime"), (at_load(case.decomposed), "at the load")):
        if q is None or q not in case.decompositions():
            continue
        # the reference's u_num: its estimate and the continuum's spread over the meshes
        est = "nh_error_estimate" if regime == "at the load" else "p2_error_estimate"
        by_mesh = {r["mesh"]: r for r in runs}
        u_nums = {regime: u_num(max((r.get(est) or 0.0) for r in by_mesh.values()),
                                [_largest(r.get(q.continuum)) for r in by_mesh.values()])[0]}
        parts = decomposed(runs, q)
        p1 = {r["mesh"]: parts[(r["mesh"], r["bc"], r["model"])] for r in runs
              if r["model"] == q.p1}
        for r in runs:
            p = parts[(r["mesh"], r["bc"], r["model"])]
            failed = (r.get("finite_failed") if regime == "at the load" else
                      r.get("static_failed")) or r.get("failed")
            solver, n = solver_of(r["model"])
            info = r.get("model_info") or {}
            rows.append({
                "case": case.name, "regime": regime, "quantity": q.label, "mesh": r["mesh"],
                "bc": r["bc"], "model": r["model"], "solver": solver, "iterations": n,
                "substeps": info.get("substeps"), "dt_s": info.get("dt"),
                "value_rel": _over(r.get(q.key), r.get(q.continuum)),
                "u_num": u_nums.get(regime),
                "estimate": r.get("nh_error_estimate" if regime == "at the load"
                                  else "p2_error_estimate"),
                # the largest free-node force of the engine's own law where it came to rest
                # (the linear regime's, scaled to the case's load): how far from balanced
                "static_residual_n": r.get("static_residual_n") if regime == "linear regime"
                else None,
                "model_form": None if failed or p is None else p.model_form,
                "discretisation": None if p1.get(r["mesh"]) is None
                else p1[r["mesh"]].discretisation,
                "total": None if failed or p is None else p.total,
                "failed": failed or (None if p is not None else f"no {q.label}")})
    return rows


def _largest(q):
    """A quantity's largest-magnitude component (a sequence over load steps), or None."""
    if q is None:
        return None
    q = np.atleast_1d(np.asarray(q, float))
    return float(q[np.argmax(np.abs(q))])


def _over(q, q_c):
    """Q / |Q_c| (the largest-magnitude component of a sequence over load steps), or None."""
    if q is None or q_c is None:
        return None
    q, q_c = np.atleast_1d(np.asarray(q, float)), np.atleast_1d(np.asarray(q_c, float))
    r = q / np.abs(q_c)
    return float(r[np.argmax(np.abs(r - np.sign(r)))]) if r.size > 1 else float(r[0])


def run(s, workers=None, log=True, bench=None, store=OFF):
    """Every case with the engines' models and FEM P1 (both laws) on the study's meshes; no
    runs where the engines extra is not installed (the report says so)."""
    from ...registry import CASES
    if not installed():
        return {"installed": False, "engine": None, "runs": [], "dynamic": [], "costs": {},
                "cost_tets": None, "machine": None}
    rows, dynamic = [], []
    for name, cfg in s.case_settings().items():
        runs, _ = run_case(CASES[name], cfg, workers=workers, store=store, reuse_full=True)
        rows += case_rows(CASES[name], runs)
        dynamic += dynamic_rows(name, runs, cfg)
    import newton
    return jsonable({"installed": True, "engine": f"newton {newton.__version__}", "runs": rows,
                     "dynamic": dynamic, **costs(bench, s.models())})


def dynamic_rows(case, runs, cfg):
    """The dynamic push of each run that has one (the paper cube's: its push over 1 s, then
    held to rest): the top reaction over time and the displacement at the push's end against
    linear FEM's exact transient on the mesh (its element P1 in the cases' quick settings:
    the same tetrahedra), whether it came to rest, or why it failed; beside it the speed
    below which the case calls a body at rest and the smallest speed a single-precision
    position resolves over the run's step (the cube's side times float32's epsilon, over dt)."""
    from ...library.common import CUBE_MM, SPEED_MM_S
    from ...framework import MM
    eps = float(np.finfo(np.float32).eps) * CUBE_MM * MM
    return [{"case": case, "mesh": r["mesh"], "model": r["model"],
             "solver": solver_of(r["model"])[0], "element": cfg.transient_element,
             "rest_speed_m_s": cfg.rest_speed * SPEED_MM_S * MM,
             "float32_speed_m_s": eps / r["dyn_dt_s"] if solver_of(r["model"])[0]
             and r.get("dyn_dt_s") else None,
             "reaction_time_rel_l2": r.get("reaction_time_rel_l2"),
             "disp_end_push_rel_l2": r.get("disp_end_push_rel_l2"),
             "at_rest": r.get("dyn_at_rest"), "dt_s": r.get("dyn_dt_s"),
             "failed": r.get("dyn_failed")}
            for r in runs if "reaction_time_rel_l2" in r]


def costs(bench, models):
    """The bench's wall-clock cost of each engine model on the real-time family's smallest
    cube (the paper's 125 nodes, 320 tetrahedra, under its push, at the model's own step):
    {"costs": {model: row or None (not timed)}, "cost_tets", "machine", "baseline_cost":
    linear FEM P1's row there or None}. Nothing is timed
    here, so that the runs stay deterministic."""
    from ...reporting.costs import sizes
    tets = sizes(True)[0]
    got = {r["model"]: r for r in (bench or {}).get("realtime_rows", [])
           if r["tets"] == tets and r.get("timed")}
    return {"costs": {m: got.get(m) for m in models}, "cost_tets": tets,
            "machine": (bench or {}).get("realtime_machine"),
            # FEM P1's own cost there: what a user replacing it by an engine compares with
            "baseline_cost": got.get(P1_LINEAR)}
