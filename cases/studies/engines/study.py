"""The engines study's runs: the Newton engine's solvers (model.simulators.newton) on the bar,
the cube and the cantilever of the case library, each at its default settings and, for the
iterative solvers, up a ladder of iteration counts, beside FEM P1 on the same tetrahedra, through
the cases' own runner (the same references, the same error model as every model).

The bar is the library's block settling under its own weight (``self-weight``, sliding base: a
prismatic bar whose closed form is exact), the cube the paper's (``paper-cube``, clamped base),
the cantilever ``cantilever`` (clamped). Each runs on its quick-mode meshes and references (the
engines' single precision and run-to-rest tolerance, 1e-3, are coarser than those references'
estimates), on the 'five' split in the quick run and on 'five' and 'six' in the full run."""
import importlib.util
from dataclasses import dataclass

import numpy as np

from ...framework import MaterialSettings
from ...measuring.error_model import P1_FINITE, P1_LINEAR, at_load, decomposed
from ...running.runner import jsonable, run as run_case
from ...running.store import OFF

CASE_NAMES = {"self-weight": "the bar", "paper-cube": "the cube", "cantilever": "the cantilever"}
BCS = {"self-weight": "sliding", "paper-cube": "clamped", "cantilever": "clamped"}
SOLVERS = ("newton-semi-implicit", "newton-xpbd", "newton-vbd")
# the iteration counts each iterative solver runs at: its default first, then up by 4x each
LADDER = {"newton-xpbd": (2, 8, 32), "newton-vbd": (10, 40, 160)}
QUICK_LADDER = {"newton-xpbd": (2, 8), "newton-vbd": (10, 40)}
MESHES, QUICK_MESHES = ("five", "six"), ("five",)
CONVERGED = 0.01      # within this of its own answer at the ladder's top (relative to |Q_c|)
MATCH = 0.05          # "matches FEM P1": a model-form error at most this


def spec(solver, iterations):
    """The model name of ``solver`` at ``iterations`` (its default: the plain name)."""
    ladder = LADDER.get(solver)
    if ladder is None or iterations == ladder[0]:
        return solver
    return f"{solver}(iterations={iterations})"


def installed():
    """Whether the engines extra (newton, on warp) is installed."""
    return importlib.util.find_spec("newton") is not None


@dataclass
class EngineSettings(MaterialSettings):
    """The material (every case's, as the extensions study gives it) and the mode."""

    quick: bool = False

    @property
    def ladder(self):
        return QUICK_LADDER if self.quick else LADDER

    @property
    def meshes(self):
        return QUICK_MESHES if self.quick else MESHES

    def models(self):
        """Every engine model run: the semi-implicit solver, each iterative one up its ladder."""
        out = ["newton-semi-implicit"]
        for solver, counts in self.ladder.items():
            out += [spec(solver, n) for n in counts]
        return tuple(out)

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
        return {"installed": False, "engine": None, "runs": []}
    rows = []
    for name, cfg in s.case_settings().items():
        runs, _ = run_case(CASES[name], cfg, workers=workers, store=store, reuse_full=True)
        rows += case_rows(CASES[name], runs)
    import newton
    return jsonable({"installed": True, "engine": f"newton {newton.__version__}", "runs": rows})
