"""The extensions study's runs: the library's cases and the convergence study with the
candidate models, reduced to what the rankings read."""
from dataclasses import dataclass, replace

from model.candidates import BASE, CANDIDATES, NORMAL_FORMS, short  # noqa: F401 (the study's names)
from ...framework import MaterialSettings
from ...measuring.catalogue import STATIC, err_name
from ...reporting.costs import near
from ...measuring.error_model import decomposed
from ...running.store import OFF
from ...registry import studies
from ...running.runner import jsonable, run as run_case

YARDSTICK = "fem-linear"     # what the same tetrahedra give as constant-strain FEM
TWIN = "pbcm-variational+normal"   # the preset whose terms are +normal_edge's


@dataclass
class ExtensionSettings(MaterialSettings):
    """Material, the models (the paper's model, the candidates and the FEM yardstick) and the
    mode; each case and the convergence study run with their own quick or full settings."""

    models: tuple = (BASE, *CANDIDATES, YARDSTICK)
    quick: bool = False
    cases: tuple = None        # library cases (None: every one)
    problems: tuple = None     # convergence problems (None: the study's own)

    def __post_init__(self):
        super().__post_init__()
        if BASE not in self.models:
            from model.errors import ModelError
            raise ModelError(f"the extensions study ranks models against the paper's model: "
                             f"keep {BASE} among --models")

    def case_settings(self):
        from ...registry import CASES
        return {name: case.settings(quick=self.quick, models=self.models, E=self.E, nu=self.nu,
                                    rho=self.rho) for name, case in CASES.items()
                if (self.cases is None or name in self.cases) and case.decomposed is not None}

    def convergence_settings(self):
        return studies()["convergence"].settings(
            quick=self.quick, models=self.models, E=self.E, nu=self.nu, rho=self.rho,
            problems=self.problems, verification=False)    # its fits and elasticity alone

    def problem(self):
        """What the gate compares: each case's problem and the convergence study's."""
        return {**self.material_record(),
                "cases": {n: c.problem() for n, c in self.case_settings().items()},
                "convergence": self.convergence_settings().problem()}

    @property
    def units(self):
        return max([c.units for c in self.case_settings().values()]
                   + [self.convergence_settings().units])

    def describe(self):
        return {**self.problem(), "models": list(self.models), "quick": self.quick,
                "cases": list(self.case_settings())}


def static_headline(case):
    """True when the case's headline comes from its static problem (a standard metric or the
    error of a quantity of interest), so that the dynamics and modes can be skipped."""
    return case.headline in STATIC or case.headline in {err_name(q) for q in case.qoi_errors}


def with_p1(case, cfg):
    """The case's settings with the FEM P1 its model-form error is taken against (the same
    law on the same tetrahedra: neo-Hookean P1 at finite load) among the models."""
    return replace(cfg, models=tuple(dict.fromkeys((*cfg.models, case.decomposed.p1))))


def case_rows(case, runs):
    """What the rankings read of a case's runs: each run's model-form error on the case's
    decomposed quantity (the error model's, magnitude), with the discretisation error of FEM
    P1 on that mesh beside it."""
    parts = decomposed(runs, case.decomposed)
    rows = []
    for r in runs:
        failed = r.get("failed") or r.get("static_failed")
        p = parts[(r["mesh"], r["bc"], r["model"])]
        info = r.get("model_info") or {}
        rows.append({"case": case.name, "mesh": r["mesh"], "bc": r["bc"], "model": r["model"],
                     "metric": f"{case.decomposed.label}: model-form",
                     "error": None if failed or p is None else abs(p.model_form),
                     "discretisation": None if p is None else abs(p.discretisation),
                     "failed": failed or (None if p is not None else
                                          f"no {case.decomposed.label} or no FEM P1 twin"),
                     "alternation_rel": r.get("alternation_rel"),
                     "dropped": info.get("calibration_dropped", [])})
    return rows


STEP_RATIO = f"step_vs_{YARDSTICK}"


def costs(bench, models):
    """Each model's RK4 step time over fem-linear's: the bench's in-round ratio (its median over
    the rounds, the number the bench prints) at the size it ran closest to COST_TETS; None
    where the bench lacks the model."""
    rows = {m: near(bench, m, STEP_RATIO) for m in models}
    return {m: None if r is None else float(r[STEP_RATIO]) for m, r in rows.items()}


def cost_ranges(bench, models):
    """Each model's [smallest, largest] over the bench's rounds of the ratio ``costs`` reads,
    or None where the bench lacks it."""
    rows = {m: near(bench, m, STEP_RATIO) for m in models}
    return {m: None if r is None or not r.get(f"{STEP_RATIO}_range") else
            [float(x) for x in r[f"{STEP_RATIO}_range"]] for m, r in rows.items()}


def bench_costs(bench, models):
    """What the study takes from the bench document: each model's cost, the size it is read
    at and its range, and the preset with +normal_edge's terms (timed by another bench run)."""
    return {"cost_vs_fem_linear": costs(bench, models),
            "cost_same_terms": {TWIN: costs(bench, [TWIN])[TWIN]},
            "cost_tets": cost_size(bench), "cost_range": cost_ranges(bench, models)}


def cost_size(bench):
    """The size ``costs`` reads: the bench's size closest to COST_TETS, or None."""
    r = near(bench, YARDSTICK, STEP_RATIO)
    return None if r is None else int(r["tets"])


# what a run computes (the rest of metrics.json is derived from it by the report); the fits
# are derived from the convergence runs and references by the convergence study's own rule
RUN_KEYS = ("case_runs", "conv_runs", "conv_references", "elasticity", "cost_vs_fem_linear",
            "cost_same_terms")
# what the convergence fits read of a run and of a reference
CONV_RUN_KEYS = ("case", "mesh", "bc", "h_mm", "model", "disp_rel_l2", "reaction_ratio")
CONV_REFERENCE_KEYS = ("case", "bc", "error_estimate")


def conv_fits(data):
    """The convergence fits of the recorded runs, by the convergence study's rule (the same
    runs give the same verdicts in both reports)."""
    return studies()["convergence"].fits(data["conv_runs"], data["conv_references"])


def run(s, workers=None, log=True, bench=None, store=OFF):
    """Every case with the study's models and its FEM P1 twin, then the convergence study
    with the models. The models the cases ran already (the paper's model, fem-linear) come
    from ``store``; a case whose headline is a static metric runs its static problem only (no
    dynamics, no modes: no ranking reads them)."""
    from ...registry import CASES
    rows = []
    for name, cfg in s.case_settings().items():
        case = CASES[name]
        cfg = replace(with_p1(case, cfg), static_only=static_headline(case))
        runs, _ = run_case(case, cfg, workers=workers, store=store, reuse_full=True)
        rows += case_rows(case, runs)
    conv = studies()["convergence"].run(s.convergence_settings(), workers=workers, log=log,
                                        bench=None, store=store)
    return jsonable({"case_runs": rows,
                     "conv_runs": [{k: r.get(k) for k in CONV_RUN_KEYS} for r in conv["runs"]],
                     "conv_references": [{k: r.get(k) for k in CONV_REFERENCE_KEYS}
                                         for r in conv["references"]],
                     "elasticity": [
        {k: e.get(k) for k in ("model", "mesh", "moduli_rel_err", "anisotropy_AU", "E_x_pa",
                               "nu_xy", "G_xy_pa", "failed")} for e in conv["elasticity"]],
        **bench_costs(bench, s.models)})
