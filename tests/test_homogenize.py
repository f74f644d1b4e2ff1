"""Effective elasticity (model.homogenize) against closed forms: the isotropic tensor, a cubic
crystal's Voigt and Reuss moduli and its anisotropy index, Young's modulus along [100], [110]
and [111], and the constant-strain FEM whose patch must answer with exactly the target C."""
import numpy as np
import pytest

from model import Material, ModelError, build
from model.homogenize import (anisotropy_index, asymmetry, directional_young, moduli_errors,
                              effective_stiffness, engineering_constants, isotropic_stiffness,
                              voigt_reuss)
from model.mesh import cube
from model.terms._kernels import volume_gradient_numpy


def cubic(c11, c12, c44):
    C = np.zeros((6, 6))
    C[:3, :3] = c12
    C[range(3), range(3)] = c11
    C[range(3, 6), range(3, 6)] = c44
    return C


def test_isotropic_tensor_gives_back_its_constants():
    """The isotropic stiffness for E and nu has C11 = lambda + 2 mu, C12 = lambda and C44 = mu,
    gives back E, nu and G as its engineering constants, and has anisotropy index zero and
    Young's modulus E in every direction."""
    E, nu = 7.0e3, 0.3
    C = isotropic_stiffness(E, nu)
    # sigma_xx under a unit uniaxial strain is lambda + 2 mu
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    assert C[0, 0] == pytest.approx(lam + 2 * mu) and C[0, 1] == pytest.approx(lam)
    assert C[3, 3] == pytest.approx(mu)
    c = engineering_constants(C)
    for k in ("E_x", "E_y", "E_z"):
        assert c[k] == pytest.approx(E, rel=1e-12)
    for k in ("nu_xy", "nu_yx", "nu_zx"):
        assert c[k] == pytest.approx(nu, rel=1e-12)
    assert c["G_xy"] == pytest.approx(mu, rel=1e-12)
    assert anisotropy_index(C) == pytest.approx(0.0, abs=1e-12)
    d = np.random.default_rng(1).standard_normal((20, 3))
    assert np.allclose(directional_young(C, d), E, rtol=1e-12)


def test_cubic_crystal_against_the_closed_forms():
    """For a cubic crystal (copper's constants) the Voigt and Reuss bulk and shear moduli, the
    anisotropy index 5 G_V / G_R - 5, Young's modulus along [100], [110] and [111] and the
    Poisson ratio nu_xy equal their closed forms."""
    c11, c12, c44 = 168.4, 121.4, 75.4           # copper, GPa (Hill's classic example)
    C = cubic(c11, c12, c44)
    K_V, G_V, K_R, G_R = voigt_reuss(C)
    assert K_V == pytest.approx((c11 + 2 * c12) / 3) and K_R == pytest.approx(K_V)
    assert G_V == pytest.approx((c11 - c12 + 3 * c44) / 5)
    assert G_R == pytest.approx(5 * (c11 - c12) * c44 / (4 * c44 + 3 * (c11 - c12)))
    assert anisotropy_index(C) == pytest.approx(5 * G_V / G_R - 5)
    # compliances of a cubic crystal in closed form
    s11 = (c11 + c12) / ((c11 - c12) * (c11 + 2 * c12))
    s12 = -c12 / ((c11 - c12) * (c11 + 2 * c12))
    s44 = 1 / c44
    E = directional_young(C, [[1, 0, 0], [1, 1, 0], [1, 1, 1]])
    assert E[0] == pytest.approx(1 / s11)
    assert E[1] == pytest.approx(1 / (s11 - 0.5 * (s11 - s12 - s44 / 2)))
    assert E[2] == pytest.approx(1 / (s11 - 2 / 3 * (s11 - s12 - s44 / 2)))
    assert engineering_constants(C)["nu_xy"] == pytest.approx(-s12 / s11)


@pytest.mark.parametrize("family", ["five", "six", "bcc", "unstructured"])
def test_constant_strain_fem_patch_answers_with_the_target(family):
    """On every mesh family the effective stiffness of linear FEM equals its material's isotropic
    tensor to a largest relative modulus error below 1e-8, and is symmetric to 1e-8."""
    mat = Material(E=10e3, nu=0.45)
    C = effective_stiffness(build("fem-linear", cube(4, 0.032, family), mat))
    assert moduli_errors(C, mat.E, mat.nu)["largest"] < 1e-8
    assert asymmetry(C) < 1e-8


def test_springs_on_the_five_lattice_have_the_cauchy_poisson_ratio():
    """Central springs on a lattice whose affine motion is in equilibrium obey Cauchy's
    relation C12 = C44: with cubic symmetry nu = C12 / (C11 + C12), and van Gelder's
    stiffness on 'five' gives nu = 0.2 whatever nu the material asks for."""
    for nu in (0.3, 0.45):
        C = effective_stiffness(build("msm", cube(5, 0.032, "five"), Material(E=10e3, nu=nu)))
        assert C[0, 1] == pytest.approx(C[3, 3], rel=1e-6)
        assert engineering_constants(C)["nu_xy"] == pytest.approx(
            C[0, 1] / (C[0, 0] + C[0, 1]), rel=1e-9)
        assert engineering_constants(C)["nu_xy"] == pytest.approx(0.2, abs=1e-6)


def test_a_patch_is_refused_when_its_interior_is_not_held():
    """A model that does not hold the interior nodes (no force on them) is singular: an
    error naming the model, not a NaN tensor."""
    class Free:
        name = "nothing"
        mesh = cube(4, 0.032, "five")

        def jacobian(self, x):
            import scipy.sparse as sp
            return sp.csr_matrix((3 * len(x), 3 * len(x)))
    with pytest.raises(ModelError, match="effective stiffness of nothing is undefined"):
        effective_stiffness(Free())


def test_isotropy_judged_by_moduli_sees_a_soft_shear_modulus_the_frobenius_norm_hides():
    """Isotropy is judged by the largest relative modulus error, which sees one shear modulus
    12 % low (the deviatoric modulus 2 C44 over 2G) where the Frobenius distance of C moves
    by under 1 % (at nu = 0.45 the bulk block dominates ||C||)."""
    E, nu = 10e3, 0.45
    C = isotropic_stiffness(E, nu)
    soft = C.copy()
    soft[5, 5] *= 0.878
    frobenius = np.linalg.norm(soft - C) / np.linalg.norm(C)
    assert frobenius < 0.01
    err = moduli_errors(soft, E, nu)
    assert err["largest"] == pytest.approx(0.122, rel=1e-12)
    assert err["bulk"] == pytest.approx(0.0, abs=1e-14)
    assert sorted(err["deviatoric"])[0] == pytest.approx(-0.122, rel=1e-12)


def test_the_virial_stress_of_a_homogeneous_strain_and_its_split_over_tetrahedra():
    """Linear FEM's per-tetrahedron virial is Hooke's stress of the strain (closed form); for
    every momentum-conserving model the tetrahedra's virials add up to the virial of the
    total nodal forces, -sym sum_i x_i (x) f_i: the split over tetrahedra loses nothing."""
    mat = Material(E=10e3, nu=0.3)
    mesh = cube(3, 0.02, "five")
    eps = np.array([[1.0, 0.3, 0.0], [0.3, -0.5, 0.2], [0.0, 0.2, 0.4]]) * 1e-6
    lam, mu = mat.E * mat.nu / ((1 + mat.nu) * (1 - 2 * mat.nu)), mat.G
    sigma = lam * np.trace(eps) * np.eye(3) + 2 * mu * eps
    x = mesh.points + mesh.points @ eps.T
    s = build("fem-linear", mesh, mat).tet_virial(x)
    assert np.allclose(s, sigma, rtol=0, atol=1e-5 * np.abs(sigma).max())
    rng = np.random.default_rng(1)
    y = mesh.points + 1e-4 * rng.standard_normal(mesh.points.shape)
    for name in ("fem-linear", "pbcm-balanced", "pbcm-variational", "msm"):
        pm = build(name, mesh, mat)
        V, _ = volume_gradient_numpy(y, mesh.tets)
        total = np.einsum("t,tij->ij", V, pm.tet_virial(y))
        f = pm.forces(y)
        whole = -np.einsum("ai,aj->ij", y - y.mean(axis=0), f)
        whole = 0.5 * (whole + whole.T)
        assert np.allclose(total, whole, rtol=1e-9, atol=1e-12 * np.abs(whole).max()), name
