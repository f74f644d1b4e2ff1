"""What causes the bulge/neck artefact of the paper (section 5), and which reading of its
equations did it use? A controlled study on the paper's cube: the mesh (the mirrored five
split, six, bcc, reconstructions of the paper's 374-tetrahedron mesh, the five split refined),
the shear reading (calibrated and literal), normal stress, msm with and without a shear term,
the base and the load, each cell's alternation against the continuum's; the factors that
switch the pattern on and off, and the answers computed from them.
"""
from ...framework import Study
from ...store import OFF
from . import report
from .study import ArtefactSettings, bench_costs, run


class Artefact(Study):
    name = "artefact"
    selections = ()           # its meshes and models are the controlled factors
    title = ("the bulge/neck pattern of the paper's cube over mesh, reading, normal stress, "
             "base and load")

    def settings(self, quick=False, **kw):
        keep = {"E", "nu", "rho"}
        return ArtefactSettings(quick=quick, **{k: v for k, v in kw.items()
                                                if k in keep and v is not None})

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def recorded(self, metrics):
        p = metrics["parameters"]
        s = self.settings(quick=p["quick"], E=p["E_Pa"], nu=p["nu"], rho=p["rho_kg_m3"])
        data = {k: metrics[k] for k in ("cells", "references", "step_vs_msm")}
        if "step_vs_msm_range" in metrics:
            data.update({k: metrics.get(k) for k in ("step_vs_msm_range", "bench_spread")})
        else:   # recorded before the spread was: every cost from the checkout's bench
            from ...costs import load
            bench = load()
            data.update(bench_costs(bench, list(s.models)) if bench else
                        {"step_vs_msm_range": None, "bench_spread": None})
        return s, data


STUDY = Artefact()
