"""The large-compression case: bonded plates make a barrel judged against the
converged mixed neo-Hookean reference with its estimate; the homogeneous (sliding) compression
is a constitutive check whose law is the closed form and whose energy curve is dW/d(push)."""
import numpy as np
import pytest

from cases.library import large_compression as lc
from cases.registry import CASES
from model.material import Material
from model import build
from model.terms.shear import Shear
from reference.hyperelastic import uniaxial

CASE = CASES["large-compression"]


def test_the_law_in_closed_form_is_the_hand_formula():
    """At stretch 0.7 with E = 10 kPa and nu = 0.45 the closed-form uniaxial law gives a lateral
    stretch of 1.17085 and a force of 4.4435 N on the 32 mm cube, the case's last law force; at
    stretch 1 it gives (1, 0), and a negative stretch is refused."""
    # lateral stretch and nominal stress at stretch 0.7, E = 10 kPa, nu = 0.45, worked by hand
    # in tests/test_hyperelastic.py: 1.17085 and 4.4435 N on the 32 mm cube
    lt, P = uniaxial(0.7, Material(10e3, 0.45))
    assert lt == pytest.approx(1.17085, abs=1e-5)
    assert -P * 0.032 ** 2 == pytest.approx(4.4435, abs=1e-4)
    s = CASE.settings()
    assert lc.law_force(s)[-1] == pytest.approx(4.4435, abs=1e-4)
    assert uniaxial(1.0, Material(10e3, 0.45)) == (1.0, 0.0)
    with pytest.raises(Exception, match="stretch"):
        uniaxial(-0.5, Material(10e3, 0.45))


@pytest.fixture(scope="module")
def bonded():
    s = CASE.settings(quick=True, steps=3)
    mesh = CASE.mesh("five", s)
    probe = Shear(mesh, s.material, reading="corner")
    return s, mesh, CASE.solve_reference(mesh, "clamped", s, probe)


def test_bonded_reference_is_a_barrel_with_an_estimate(bonded):
    """The bonded reference is the refined mixed neo-Hookean solution: its force rises at every step
    and exceeds the homogeneous law by over 5 %, the mid layer bulges out the most while the
    bonded layers do not move sideways, and its error estimate lies in (0, 0.1) and bounds the
    last refinement's change. Its reaction is the last step's force, and its linear-regime scale
    brings the nominal strain to between 3e-5 and 1e-4."""
    s, mesh, ref = bonded
    nh = ref.nonlinear
    assert nh.result.info["mixed"] and nh.result.info["refine"] == s.nh_levels >= 1
    force, law = np.array(ref.extra["force"]), np.array(lc.law_force(s))
    assert len(force) == s.steps and np.all(np.diff(force) > 0)
    # bonded plates restrain the lateral expansion: stiffer than the homogeneous law
    assert np.all(force > 1.05 * law)
    # a barrel: the mid layer bulges out, the bonded layers do not move sideways
    profile = lc.M.layer_profile(mesh.points, nh.result.u, [y * lc.MM for y in lc.LAYERS_MM],
                                 lc.SIZE_MM * lc.MM)
    assert profile[0] == pytest.approx(0, abs=1e-12) and profile[-1] == pytest.approx(0, abs=1e-12)
    assert profile[2] > profile[1] > 0 and profile[2] > profile[3] > 0
    assert 0 < nh.error_estimate < 0.1
    # the estimate brackets the change between the two refinements it came from
    assert nh.error_estimate >= nh.increments[-1] * (1 - 1e-12)
    assert ref.nonlinear_reaction == force[-1]
    # the linear regime: the largest strain of the linear reference scaled to 1e-4
    eps = 9.6 / 32 * ref.scale      # about the nominal strain, scaled
    assert 0.3 * 1e-4 < eps < 1e-4


def test_homogeneous_check_of_fem_neohookean_is_the_law():
    """P1 neo-Hookean represents the homogeneous field exactly: its sliding curve is the law
    to the Newton tolerance, and the force its energy implies equals it to the central
    difference's error (ENERGY_STEP^2 of the curvature)."""
    s = CASE.settings(steps=3)
    mesh = CASE.mesh("six", s)
    pm = build("fem-neohookean", mesh, s.material)
    force, from_energy = lc.homogeneous_curve(pm, mesh, s)
    assert np.allclose(force, lc.law_force(s), rtol=1e-8)
    assert np.allclose(from_energy, force, rtol=1e-5)


def test_a_non_conservative_reading_has_no_energy_curve():
    """For a non-conservative model (pbcm-corner) the homogeneous compression gives a positive force
    at each step and no force curve derived from an energy."""
    s = CASE.settings(steps=2)
    mesh = CASE.mesh("five", s)
    force, from_energy = lc.homogeneous_curve(build("pbcm-corner", mesh, s.material), mesh, s)
    assert from_energy is None and len(force) == 2 and all(f > 0 for f in force)
