"""Torsion's linear regime: the end face gets the linearised rotation u = theta x r,
and then the converged linear torque is at or above Saint-Venant's beta G a^4 theta / L: the
clamped root restrains the warping Saint-Venant leaves free, and P2's energy (twice the work of
the prescribed rotation) bounds the exact one from above."""
import numpy as np
import pytest

from cases.library import torsion as T
from cases.registry import CASES
from reference import linear

CASE = CASES["torsion"]


def test_the_linearised_rotation_is_the_small_angle_limit_of_the_exact_one():
    """At a tiny angle the exact end-face rotation equals its linearisation to 1e-5 relative; at 10
    degrees the exact rotation moves each point radially by cos(theta) - 1 of its radius, and the
    linearised one has no radial part."""
    p = np.array([[0.0, 0.003, 0.011], [0.0, 0.016, 0.0]])
    c = (0.008, 0.008)
    small = 1e-6
    assert np.allclose(T.end_rotation(p, small, c), T.end_rotation_linearised(p, small, c),
                       rtol=1e-5, atol=0)
    # at 10 degrees the exact rotation pulls the face in radially by 1 - cos 10 deg
    ang = np.radians(10.0)
    r = p[:, 1:] - c
    radial = (T.end_rotation(p, ang, c) * r).sum(axis=1) / (r ** 2).sum(axis=1)
    assert np.allclose(radial, np.cos(ang) - 1)
    assert np.allclose((T.end_rotation_linearised(p, ang, c) * r).sum(axis=1), 0)


def test_converged_linear_torque_is_at_or_above_saint_venant():
    """The converged linear torque of the clamped bar under the linearised end rotation lies between
    Saint-Venant's beta G a^4 theta / L and 2 % above it, and the torque of the exact rotation
    read as a small strain is lower by the factor sin(theta) / theta to 1e-3."""
    s = CASE.settings(spacing_mm=8.0)
    mesh = CASE.mesh("five", s)
    bc = CASE.dirichlet_linear(mesh, "clamped", s)
    conv = linear.converged(mesh, s.material, bc, levels=2, solver="direct")
    sv = CASE.closed_form(s, "clamped")["torque_nm"]
    torque = CASE.quantities(mesh, conv.result.u, conv.result.reaction, s,
                             "clamped")["torque_nm"]
    assert sv == pytest.approx(0.1406 * s.material.G * 0.016 ** 4 * np.radians(10) / 0.064)
    # above Saint-Venant, by the restraint of a clamped root on a bar 4 sides long (< 2 %)
    assert sv <= torque <= 1.02 * sv
    # the exact rotation, read as a small strain, loses the factor sin(theta) / theta
    exact = linear.solve(mesh, s.material, CASE.dirichlet(mesh, "clamped", s), element="P2",
                         refine=2, solver="direct")
    t_exact = CASE.quantities(mesh, exact.u, exact.reaction, s, "clamped")["torque_nm"]
    assert t_exact / torque == pytest.approx(np.sin(np.radians(10)) / np.radians(10),
                                                  rel=1e-3)
