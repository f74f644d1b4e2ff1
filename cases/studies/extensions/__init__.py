"""Which normal-stress extension, if any, fixes which failure of the paper's model? Every
candidate (the paper's variational reading plus one deviatoric normal term each) on every case
of the library and in the convergence study, ranked by error per case and overall, by cost
(from `pbcm bench`), by the bulge/neck artefact, by convergence floor and by how far the moduli
of its effective elasticity are from the isotropic target's.
"""
from ...framework import Study
from ...running.store import OFF
from . import report
from .study import RUN_KEYS, ExtensionSettings, run


class Extensions(Study):
    name = "extensions"
    runs_recorded = ("case_runs",)
    selections = ("models",)  # it runs every case on its own meshes
    title = ("normal-stress extensions of the paper's model ranked over the case library and "
             "the convergence study")

    settings_class = ExtensionSettings
    recorded_keys = RUN_KEYS

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def redrawn(self, s, data, metrics):
        # the costs are the checkout's bench, the numbers the bench report prints; the
        # recorded ones only where the checkout has no bench
        from ...reporting.costs import load
        from .study import bench_costs
        bench = load()
        if bench:
            data.update(bench_costs(bench, s.models))
        else:
            data.update({k: metrics.get(k) for k in ("cost_tets", "cost_range")})
        return data

    def recorded_settings(self, parameters):
        return {**super().recorded_settings(parameters),
                "problems": tuple(parameters["convergence"]["ref_ladders_mm"])}


STUDY = Extensions()
