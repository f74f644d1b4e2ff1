"""Two regimes kept apart: every case with a load is answered in the linear regime
(loads scaled to strains of 1e-4, against linear FEM) and at its own load (against the
converged neo-Hookean reference). The sliding paper cube is homogeneous, so both references
are closed forms there: the tests work them out by hand."""
from types import SimpleNamespace

import numpy as np
import pytest

from cases.framework import LINEAR_STRAIN, linear_scale
from cases.library.paper_cube import CASE, PUSH_MM, SIZE_MM
from cases.running.runner import finite_metrics, linear_regime, reference, static_metrics
from model import Material
from model.bc import bc_arrays
from model.errors import ModelError
from model.terms.shear import Shear
from reference.hyperelastic import uniaxial

E, NU = 10e3, 0.45


def test_the_scale_brings_the_largest_principal_strain_to_the_regime():
    """The linear-regime scale brings the largest principal strain of a stress field to
    LINEAR_STRAIN, leaves a field already below it unscaled (scale 1.0), and refuses a field with
    no strain with a ModelError."""
    # a uniaxial stress sigma: strains sigma / E axially and -nu sigma / E laterally
    sigma = np.zeros((2, 3, 3))
    sigma[0, 1, 1] = 1e-3 * E           # strain 1e-3: the largest
    sigma[1, 0, 0] = -5e-4 * E
    k = linear_scale(SimpleNamespace(stress=sigma), Material(E=E, nu=NU))
    assert k == pytest.approx(LINEAR_STRAIN / 1e-3, rel=1e-12)
    # already small: left alone
    assert linear_scale(SimpleNamespace(stress=sigma * 1e-3), Material(E=E, nu=NU)) == 1.0
    with pytest.raises(ModelError, match="no strain"):
        linear_scale(SimpleNamespace(stress=0 * sigma), Material(E=E, nu=NU))


@pytest.fixture(scope="module")
def sliding():
    s = CASE.settings(quick=True, meshes=("five",), bcs=("sliding",), static_only=True)
    mesh = CASE.mesh("five", s)
    ref = reference(CASE, mesh, "sliding", s, Shear(mesh, s.material, reading="corner"),
                    extra=False, nonlinear=True)
    return s, mesh, ref


def test_the_sliding_cube_references_are_the_closed_forms(sliding):
    """For the sliding paper cube the linear-regime scale is LINEAR_STRAIN over the axial push
    strain, and the neo-Hookean reference displacement is the homogeneous uniaxial closed form to
    1e-9 of the push."""
    s, mesh, ref = sliding
    strain = PUSH_MM / SIZE_MM
    # homogeneous: the largest strain is the axial one
    assert ref.scale == pytest.approx(LINEAR_STRAIN / strain, rel=1e-9)
    lt, _ = uniaxial(1 - strain, Material(E, NU))
    x = mesh.points
    expect = np.column_stack([(lt - 1) * x[:, 0], -strain * x[:, 1], (lt - 1) * x[:, 2]])
    assert np.abs(ref.nonlinear.result.u - expect).max() < 1e-9 * PUSH_MM * 1e-3


def runs(sliding, model):
    """The runner's metrics of ``model`` in both regimes (its phases called one by one: the
    fixture's settings are static-only, which skips the case's load in a whole run)."""
    s, mesh, ref = sliding
    pm = CASE.build_model(model, mesh, s)
    lr = linear_regime(CASE, pm, mesh, "sliding", s, ref)
    st = CASE.solve_static(pm, mesh, "sliding", s, ref)
    return {**static_metrics(CASE, lr, mesh, "sliding", s, ref),
            **finite_metrics(CASE, st, mesh, "sliding", s, ref)}


def test_fem_neohookean_is_exact_at_the_load_and_linear_in_the_regime(sliding):
    """On the sliding cube fem-neohookean matches the neo-Hookean reference at the case's load to a
    relative L2 error below 1e-7, and linear P2 in the linear regime to within three times the
    regime's strain."""
    r = runs(sliding, "fem-neohookean")
    # the same law on a field P1 represents exactly
    assert r["disp_rel_l2_nh"] < 1e-7
    # its linearisation is linear elasticity: the patch test passes to the strain left
    # (1e-4), where at the case's load (5.3 %) it was 0.0202 off linear P2
    assert r["disp_rel_l2_p2"] < 3 * LINEAR_STRAIN


def test_fem_linear_at_the_load_is_off_by_its_linearisation_error(sliding):
    """On the sliding cube fem-linear matches linear P2 in the linear regime to 1e-8, and at the
    case's load its relative L2 error against the neo-Hookean field equals the hand-worked
    distance of the linear from the neo-Hookean homogeneous field over the free components (above
    0.005)."""
    s, mesh, _ = sliding
    r = runs(sliding, "fem-linear")
    assert r["disp_rel_l2_p2"] < 1e-8              # the patch test, exact
    # by hand: u_lin = (nu e x, -e y, nu e z) against the neo-Hookean field
    e = PUSH_MM / SIZE_MM
    lt, _ = uniaxial(1 - e, Material(E, NU))
    x = mesh.points
    lin = np.column_stack([NU * e * x[:, 0], -e * x[:, 1], NU * e * x[:, 2]])
    nh = np.column_stack([(lt - 1) * x[:, 0], -e * x[:, 1], (lt - 1) * x[:, 2]])
    # over the free components: the prescribed ones (y on top and base, the pins) are equal
    free = ~bc_arrays(CASE.dirichlet(mesh, "sliding", s), mesh.n_nodes)[0]
    expect = np.linalg.norm(np.where(free, lin - nh, 0)) / np.linalg.norm(np.where(free, nh, 0))
    assert 0.005 < expect
    assert r["disp_rel_l2_nh"] == pytest.approx(expect, rel=1e-6)
