"""Torsion: a 16 x 16 mm square bar, 64 mm along x, x = 0 clamped, the x = L face rotated
rigidly by 10 degrees in its plane about the bar's axis (axial motion free). Torque against
FEM and against Saint-Venant (beta = 0.1406 for a square); the warping of the end face."""
from dataclasses import dataclass

import numpy as np

from ..measuring.error_model import Scalar
from ..framework import Case, Knob, MM, Settings
from . import common

LENGTH_MM, SIDE_MM, _ = common.BAR_MM
ANGLE_DEG = 10.0
BETA_SQUARE = 0.1406   # Saint-Venant torsion constant of a square, J = beta a^4


@dataclass
class TorsionSettings(Settings):
    spacing_mm: float = 4.0
    angle_deg: float = ANGLE_DEG

    def problem(self):
        return {**super().problem(), "length_mm": LENGTH_MM, "side_mm": SIDE_MM,
                "spacing_mm": self.spacing_mm, "angle_deg": self.angle_deg}


def end_rotation(points, angle, centre):
    """In-plane displacement (k, 2) of points (k, 3) under the rigid rotation by ``angle``
    about the x axis through ``centre`` (y, z): exact, not linearised."""
    c, s = np.cos(angle), np.sin(angle)
    y, z = points[:, 1] - centre[0], points[:, 2] - centre[1]
    return np.column_stack([c * y - s * z - y, s * y + c * z - z])


def end_rotation_linearised(points, angle, centre):
    """The same rotation linearised, u = angle e_x x r: the small rotation of linear
    elasticity, whose torque Saint-Venant's beta G a^4 angle / L bounds from below."""
    y, z = points[:, 1] - centre[0], points[:, 2] - centre[1]
    return angle * np.column_stack([-z, y])


class Torsion(Case):
    narrative = "cases.library.narratives.torsion:TorsionNarrative"
    name = "torsion"
    resolution = Knob("spacing_mm", "lattice spacing [mm]")
    load = Knob("angle_deg", "end rotation [deg]")
    title = (f"Torsion of a {SIDE_MM:g} x {SIDE_MM:g} x {LENGTH_MM:g} mm bar, x = 0 clamped, "
             f"the end face turned {ANGLE_DEG:g} degrees (torque against FEM and Saint-Venant; "
             "end-face warping)")
    settings_class = TorsionSettings
    bcs = ("clamped",)
    fem_solver = "direct"   # a slender bar, as the cantilever: AMG-CG stagnates
    headline = "torque_rel_err"
    headline_pair = "disp_rel_l2_p2"
    decomposed = Scalar("torque_nm", "torque_fem_nm", "torque")
    qoi_errors = ("torque_nm", "warping_mm")
    gated = ("torque_rel_err", "warping_rel_err")
    columns = ("torque_nm", "torque_fem_nm", "torque_rel_err", "warping_mm", "warping_fem_mm",
               "warping_rel_err")

    def mesh(self, family, s):
        return common.bar(family, LENGTH_MM, SIDE_MM, SIDE_MM, s.spacing_mm)

    def dirichlet(self, mesh, bc, s):
        return self._turned(mesh, s, end_rotation)

    def dirichlet_linear(self, mesh, bc, s):
        return self._turned(mesh, s, end_rotation_linearised)

    def _turned(self, mesh, s, rotation):
        """x = 0 clamped, the end face moved in its plane by ``rotation``, x free."""
        end = common.face(mesh, LENGTH_MM * MM)
        uv = rotation(mesh.points[end], np.radians(s.angle_deg), (SIDE_MM * MM / 2,) * 2)
        out = {int(i): (0.0, 0.0, 0.0) for i in common.face(mesh, 0.0)}
        out.update({int(i): (None, float(a), float(b)) for i, (a, b) in zip(end, uv)})
        return out

    def quantities(self, mesh, u, reaction, s, bc):
        end = common.face(mesh, LENGTH_MM * MM)
        x = mesh.points[end]    # arms at rest, as linear FEM's equilibrium is written
        c = SIDE_MM * MM / 2
        torque = ((x[:, 1] - c) * reaction[end, 2] - (x[:, 2] - c) * reaction[end, 1]).sum()
        ux = u[end, 0]
        return {"torque_nm": float(torque),
                "warping_mm": float(np.sqrt(((ux - ux.mean()) ** 2).mean()) / MM)}

    def closed_form(self, s, bc):
        G = s.material.G
        a = SIDE_MM * MM
        return {"torque_nm": BETA_SQUARE * G * a**4 * np.radians(s.angle_deg)
                / (LENGTH_MM * MM)}

CASE = Torsion()
