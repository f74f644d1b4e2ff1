"""A cantilever: a 64 x 16 x 16 mm beam along x, the x = 0 face clamped, a total end load of
1 mN in -y as a uniform traction on the x = L face. Closed form: Euler-Bernoulli bending plus
Timoshenko shear deflection."""
from dataclasses import dataclass


from reference import analytic
from ..measuring.error_model import Scalar
from ..framework import Case, Knob, Loads, MM, Settings, Traction
from . import common

LENGTH_MM, HEIGHT_MM, WIDTH_MM = common.BAR_MM
LOAD_N = 1e-3


@dataclass
class CantileverSettings(Settings):
    spacing_mm: float = 4.0
    load_N: float = LOAD_N

    def problem(self):
        return {**super().problem(), "length_mm": LENGTH_MM, "height_mm": HEIGHT_MM,
                "width_mm": WIDTH_MM, "spacing_mm": self.spacing_mm, "load_N": self.load_N}


class Cantilever(Case):
    narrative = "cases.library.narratives.cantilever:CantileverNarrative"
    name = "cantilever"
    resolution = Knob("spacing_mm", "lattice spacing [mm]")
    load = Knob("load_N", "end load [N]")
    title = (f"Cantilever {LENGTH_MM:g} x {HEIGHT_MM:g} x {WIDTH_MM:g} mm, clamped at x = 0, "
             f"{LOAD_N * 1e3:g} mN end load in -y (bending; closed form Euler-Bernoulli + "
             "Timoshenko)")
    settings_class = CantileverSettings
    bcs = ("clamped",)
    fem_solver = "direct"   # AMG-CG stagnates on this slender beam
    headline = "tip_deflection_rel_err"
    headline_pair = "disp_rel_l2_p2"
    decomposed = Scalar("tip_deflection_mm", "tip_deflection_fem_mm", "tip deflection")
    qoi_errors = ("tip_deflection_mm",)
    gated = ("tip_deflection_rel_err",)
    columns = ("tip_deflection_mm", "tip_deflection_fem_mm", "tip_deflection_rel_err")

    def mesh(self, family, s):
        return common.bar(family, LENGTH_MM, HEIGHT_MM, WIDTH_MM, s.spacing_mm)

    def dirichlet(self, mesh, bc, s):
        return {int(i): (0.0, 0.0, 0.0) for i in common.face(mesh, 0.0)}

    def loads(self, mesh, bc, s):
        area = HEIGHT_MM * WIDTH_MM * MM**2
        return Loads(tractions=(Traction(0, LENGTH_MM * MM, (0.0, -s.load_N / area, 0.0)),))

    def quantities(self, mesh, u, reaction, s, bc):
        tip = common.face(mesh, LENGTH_MM * MM)
        return {"tip_deflection_mm": float(-u[tip, 1].mean() / MM)}

    def closed_form(self, s, bc):
        d = analytic.cantilever_tip_deflection(s.load_N, LENGTH_MM * MM, WIDTH_MM * MM,
                                               HEIGHT_MM * MM, s.material)
        return {"tip_deflection_mm": d / MM}

    def params(self, s):
        return {"length_mm": LENGTH_MM, "height_mm": HEIGHT_MM, "width_mm": WIDTH_MM,
                "load_N": s.load_N, **s.material_record(static=True),
                "spacing_mm": s.spacing_mm}

CASE = Cantilever()
