"""Every shear reading calibrated alike (model.calibrate): a given c acts on every reading, the
fit is the least-squares optimum of the deviatoric Kelvin moduli of the relaxed patch, and the
moduli themselves are checked against closed forms."""
import numpy as np
import pytest

from model import Material, build
from model.calibrate import calibration_patch
from model.homogenize import effective_stiffness, isotropic_stiffness, kelvin_moduli, \
    moduli_errors
from model.mesh import TetMesh, cube
from model.terms import make_term

from conftest import perturbed

MAT = Material(E=10e3, nu=0.45)
READINGS = ("corner", "balanced", "variational")


def test_kelvin_moduli_of_isotropic_and_cubic_tensors_worked_by_hand():
    """The Kelvin moduli of an isotropic tensor are K and 2G five times, and of a cubic tensor K =
    (C11 + 2 C12) / 3 with C11 - C12 twice and 2 C44 three times; against the isotropic target K
    = 3, G = 0.7 that cubic tensor has zero bulk error and a largest error of 3 / 1.4 - 1."""
    E, nu = 10e3, 0.45
    K, mu = kelvin_moduli(isotropic_stiffness(E, nu))
    assert K == pytest.approx(E / (3 * (1 - 2 * nu)), rel=1e-14)
    assert np.allclose(mu, 2 * E / (2 * (1 + nu)), rtol=1e-14)
    # cubic symmetry: 3K = C11 + 2 C12, C11 - C12 twice, 2 C44 three times (Mandel)
    C11, C12, C44 = 5.0, 2.0, 0.7
    C = np.zeros((6, 6))
    C[:3, :3] = C12
    C[np.arange(3), np.arange(3)] = C11
    C[np.arange(3, 6), np.arange(3, 6)] = C44
    K, mu = kelvin_moduli(C)
    assert K == pytest.approx((C11 + 2 * C12) / 3, rel=1e-14)
    assert np.allclose(mu, sorted([C11 - C12] * 2 + [2 * C44] * 3), rtol=1e-14)
    # the target K = 3, G = 0.7: bulk exact, C11 - C12 = 3 the worst against 2G = 1.4
    K_t, G_t = 3.0, 0.7
    err = moduli_errors(C, E=9 * K_t * G_t / (3 * K_t + G_t),
                        nu=(3 * K_t - 2 * G_t) / (2 * (3 * K_t + G_t)))
    assert err["bulk"] == pytest.approx(0.0, abs=1e-12)
    assert err["largest"] == pytest.approx(3.0 / 1.4 - 1, rel=1e-12)


@pytest.mark.parametrize("reading", READINGS)
def test_a_given_c_acts_on_every_reading(reading):
    """A given c scales every reading's forces: c = 0.5 halves them."""
    mesh = cube(3, 0.032, "five")
    x = perturbed(mesh, 0.05, seed=3)
    one = make_term("shear", mesh, MAT, reading=reading, c=1.0).forces(x)
    half = make_term("shear", mesh, MAT, reading=reading, c=0.5).forces(x)
    assert np.abs(one).max() > 0
    assert np.allclose(half, 0.5 * one, rtol=1e-13, atol=1e-16 * np.abs(one).max())
    literal = build(f"pbcm-{reading}-literal", mesh, MAT)
    assert literal.info["shear_c"] == 1.0


def test_balanced_on_five_is_isotropic_at_an_eighth():
    """By hand (docs/model.md): the balanced reading on the mirrored five split is exactly
    isotropic with an effective shear modulus of 8 G at c = 1, so its calibrated c is 1/8 and
    its calibrated C_eff the isotropic one; literal, E' = 6.49 E and nu' = 0.176 follow from
    K exact and G' = 8 G."""
    pm = build("pbcm-balanced", cube(5, 0.032, "five"), MAT)
    assert pm.info["shear_c"] == pytest.approx(1 / 8, rel=1e-8)
    assert pm.info["bulk_ratio"] == pytest.approx(1.0, rel=1e-10)
    patch = cube(9, 0.032, "five")
    C = effective_stiffness(build("pbcm-balanced", patch, MAT))
    assert moduli_errors(C, MAT.E, MAT.nu)["largest"] < 1e-7
    C1 = effective_stiffness(build("pbcm-balanced-literal", patch, MAT))
    K, G = MAT.K, 8 * MAT.G
    E_lit, nu_lit = 9 * K * G / (3 * K + G), (3 * K - 2 * G) / (2 * (3 * K + G))
    assert E_lit / MAT.E == pytest.approx(6.49, abs=0.005) and nu_lit == pytest.approx(0.176,
                                                                                     abs=5e-4)
    assert moduli_errors(C1, E_lit, nu_lit)["largest"] < 1e-7


@pytest.mark.parametrize("family", ["six", "unstructured"])
@pytest.mark.parametrize("reading", READINGS)
def test_calibrated_c_is_the_least_squares_optimum_of_the_deviatoric_moduli(family, reading):
    """Around the fitted c, on the relaxed patch the fit uses, the sum of squared deviatoric
    moduli errors rises both ways (1 % each side): the criterion, for conservative and
    non-conservative readings alike."""
    mesh = cube(5, 0.032, family)
    c = build(f"pbcm-{reading}", mesh, MAT).info["shear_c"]
    patch = calibration_patch(mesh)

    def cost(k):
        C = effective_stiffness(build(f"shear(reading={reading}, c={k!r}) + volume", patch,
                                      MAT))
        return float(np.sum(np.array(moduli_errors(C, MAT.E, MAT.nu)["deviatoric"]) ** 2))
    assert cost(c) < cost(0.99 * c) and cost(c) < cost(1.01 * c)


def test_the_patch_is_the_lattice_not_the_body():
    """c is dimensionless: a body of the same lattice at twice the spacing gets the same c
    (to rounding); a mesh without a lattice is its own patch."""
    a = build("pbcm-corner", cube(5, 0.032, "six"), MAT).info
    coarse = build("pbcm-corner", cube(4, 0.048, "six"), MAT).info
    assert coarse["shear_c"] == pytest.approx(a["shear_c"], rel=1e-7)
    assert a["calibration_patch"].startswith("8^3 cells")
    m = cube(5, 0.032, "six")
    bare = TetMesh(m.points, m.tets)
    assert calibration_patch(bare) is bare
    assert build("pbcm-corner", bare, MAT).info["calibration_patch"] == "the mesh itself"
