"""Does each model converge to the continuum? The paper cube (clamped and sliding), the
cantilever and the torsion bar at falling mesh sizes h on every mesh family, every model
against one converged FEM reference per problem: observed order, extrapolated limit e_inf with
its uncertainty and a verdict (converges, floor, diverges); the effective elasticity tensor of
every model on every lattice, which explains the floors; and the error against the cost of one
RK4 step, with the models on the Pareto front.
"""
from ...framework import Study
from ...running.store import OFF
from . import report
from .problems import PROBLEMS
from .cost import judge
from .extrapolation import EXACT
from .study import ConvergenceSettings, cancelling, fits, run

# what metrics.json records of a run, all the report is drawn from
RECORDED = ("runs", "fits", "references", "elasticity", "cost", "manufactured", "patch",
            "steps")


class Convergence(Study):
    name = "convergence"
    runs_recorded = ("runs", "steps", "patch", "elasticity")
    title = ("h-convergence of every model on the paper cube, cantilever and torsion bar; "
             "effective elasticity of every lattice; accuracy per cost")
    # --quick: two levels on the two mesh families the paper cube's quick mode keeps, against
    # references down to 2 mm
    quick = {"h_mm": (8.0, 4.0), "meshes": ("five", "six"), "ref_finest_mm": 2.0}

    settings_class = ConvergenceSettings
    recorded_keys = RECORDED

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def definitions(self):
        return report.definitions()

    def fits(self, runs, references=()):
        """The fits of recorded runs by this study's rule (another study's runs included), so
        that one rule gives one verdict wherever the same runs are read."""
        return fits(runs, references)

    def recorded_settings(self, parameters):
        return {**super().recorded_settings(parameters),
                "ref_finest_mm": _finest(parameters["ref_ladders_mm"])}

    def redrawn(self, s, data, metrics):
        # the fits are derived from the recorded runs and references: drawn again by the
        # current rule, never recomputing a run
        data["fits"] = fits(data["runs"], data["references"])
        if data.get("cost"):
            data["cost"] = judge(data["cost"], data["runs"], EXACT, cancelling(data["fits"]),
                                 {(r["case"], r["bc"]): r.get("error_estimate") or 0.0
                                  for r in data["references"]})
        return data


def _finest(ladders):
    """The ``ref_finest_mm`` of the recorded reference ladders {problem: spacings}: None
    where each is its problem's own ladder, else the finest spacing kept."""
    if all(tuple(hs) == tuple(PROBLEMS[p].ref_ladder_mm) for p, hs in ladders.items()):
        return None
    return min(min(hs) for hs in ladders.values())


STUDY = Convergence()
