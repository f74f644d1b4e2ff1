"""Today's fast models as baselines: the Newton engine's XPBD, VBD and semi-implicit solvers
(model.simulators.newton) on the bar, the cube and the cantilever, against FEM P1 on the same
tetrahedra and the converged continuum, at their default settings and up a ladder of iteration
counts. Needs the engines extra; without it the report says so and runs nothing."""
from ...framework import Study
from ...running.store import OFF
from . import report
from .study import MESHES, EngineSettings, costs, run


class Engines(Study):
    name = "engines"
    selections = ()            # its models and meshes are its own
    takes = ()
    runs_recorded = ("runs",)
    recorded_keys = ("installed", "engine", "runs", "dynamic", "costs", "cost_tets", "machine")
    title = ("today's fast models: Newton's XPBD, VBD and semi-implicit FEM against the "
             "continuum, on the cases' quick meshes and references")
    settings_class = EngineSettings
    full_mode = f"full, on the cases' quick meshes ({', '.join(MESHES)})"

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def redrawn(self, s, data, metrics):
        # the costs are the checkout's bench, the numbers every other report prints; the
        # recorded ones only where the checkout has no bench
        from ...reporting.costs import load
        bench = load()
        if bench:
            data.update(costs(bench, s.models()))
        else:
            data["baseline_cost"] = metrics.get("baseline_cost")
        return data

    def scorecard(self, metrics):
        return report.scorecard(metrics)


STUDY = Engines()
