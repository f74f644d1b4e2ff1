"""Which normal-stress extension, if any, fixes which failure of the paper's model? Every
candidate (the paper's variational reading plus one deviatoric normal term each) on every case
of the library and in the convergence study, ranked by error per case and overall, by cost
(from `pbcm bench`), by the bulge/neck artefact, by convergence floor and by how far the moduli
of its effective elasticity are from the isotropic target's.
"""
from dataclasses import fields

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

    def settings(self, quick=False, **kw):
        kw = {k: v for k, v in kw.items() if v is not None}
        names = {f.name for f in fields(ExtensionSettings) if f.init}
        return ExtensionSettings(**{k: v for k, v in {**kw, "quick": quick}.items()
                                    if k in names})

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def recorded(self, metrics):
        p = metrics["parameters"]
        s = self.settings(quick=p["quick"], models=tuple(p["models"]), E=p["E_Pa"], nu=p["nu"],
                          rho=p["rho_kg_m3"], cases=tuple(p["cases"]),
                          problems=tuple(p["convergence"]["ref_ladders_mm"]))
        return s, {k: metrics[k] for k in RUN_KEYS}


STUDY = Extensions()
