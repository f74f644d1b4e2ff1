"""How far is each model from a measured body? The Truth Cube (an 80 mm silicone cube with 343
beads, CT-scanned at rest and at 5, 12.5 and 18.25 % compression between two plates): every
model on the cube at 10 and 5 mm spacing, the plates bonded (and frictionless), the travel
nominal (and fitted), nu 0.499 (and the silicone's range), compared bead by bead with the
measurement beside the neo-Hookean continuum and linear P2, against the measurement's own
floor.
"""
from ...framework import Study
from ...running.store import OFF
from . import report
from .study import TruthCubeSettings, run


class TruthCube(Study):
    name = "truth-cube"
    runs_recorded = ("rows",)
    selections = ("models",)  # its meshes are the cube's spacings
    title = ("the Truth Cube: every model against 343 measured beads of a silicone cube "
             "compressed 5, 12.5 and 18.25 %")

    settings_class = TruthCubeSettings
    takes = ("models",)       # the material (no rho: a static study) and the models
    recorded_keys = ("rows", "references", "travels_mm", "nominal_travels_mm", "data")

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, log=log, store=store or OFF, workers=workers)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def scorecard(self, metrics):
        return report.scorecard(metrics)

    def definitions(self):
        return report.definitions()


STUDY = TruthCube()
