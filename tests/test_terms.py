"""Force terms: rest state, invariance, conservation, gradients, kernels, stiffness."""
import numba
import numpy as np
import pytest

from model import Material, PRESETS, build
from model.errors import DegenerateTetError, ModelError
from model.terms import make_term
from model.terms.shear import Shear
from model.mesh import cube

from conftest import perturbed, rotation

# every term with its parameters; ``c`` fixed so the terms stand alone
TERMS = {
    "volume": ("volume", {}),
    "corner": ("shear", {"reading": "corner", "c": 0.4}),
    "balanced": ("shear", {"reading": "balanced", "c": 0.6}),
    "variational": ("shear", {"reading": "variational", "c": 0.3}),
    "normal_edge": ("normal_edge", {"c": 0.7}),
    "normal_tet": ("normal_tet", {"c": 0.7}),
    "normal_sbd": ("normal_sbd", {"c": 0.7}),
    "normal_corotated": ("normal_corotated", {"c": 0.7}),
    "springs": ("springs", {}),
    "fem_linear": ("fem_linear", {}),
    "fem_corotated": ("fem_corotated", {}),
    "fem_neohookean": ("fem_neohookean", {}),
}
CONSERVATIVE = ["volume", "variational", "normal_edge", "normal_tet", "normal_sbd", "normal_corotated",
                "springs", "fem_linear", "fem_corotated", "fem_neohookean"]
# small strain is not invariant under a finite rotation: that is what co-rotation fixes
ROTATION_INVARIANT = [k for k in TERMS if k != "fem_linear"]


def term(key, mesh, mat):
    name, params = TERMS[key]
    return make_term(name, mesh, mat, **params)


@pytest.mark.parametrize("key", TERMS)
def test_zero_force_at_rest(key, small_mesh, mat):
    """Every force term, with its constant fixed, puts zero force (below 1e-12) on every node of
    the undeformed mesh."""
    f = term(key, small_mesh, mat).forces(small_mesh.points)
    assert np.abs(f).max() < 1e-12


@pytest.mark.parametrize("preset", PRESETS)
def test_presets_at_rest(preset, small_mesh, mat):
    """Every preset model, built with its calibration, puts zero force (below 1e-12) on every
    node of the undeformed mesh."""
    pm = build(preset, small_mesh, mat)
    assert np.abs(pm.forces(small_mesh.points)).max() < 1e-12


def test_shear_strains_invariant_to_translation_rotation_and_scale(small_mesh, mat):
    """The corner reading's shear strains of a perturbed mesh, which are not zero, are unchanged
    (to 1e-12) by a translation, a rotation, and a uniform scaling combined with a rotation and a
    shift."""
    sh = Shear(small_mesh, mat, reading="corner")
    x = perturbed(small_mesh, 0.05)
    g = sh.strains(x)
    assert np.abs(g).max() > 1e-3
    R = rotation([1, 2, 3], 0.7)
    for moved in (x + [0.3, -1.0, 2.0], x @ R.T, 1.7 * x @ R.T - 0.2):
        assert np.allclose(sh.strains(moved), g, rtol=0, atol=1e-12)


@pytest.mark.parametrize("key", ROTATION_INVARIANT)
def test_forces_invariant_under_rigid_motion(key, small_mesh, mat):
    """For every term but the small-strain FEM, the forces at a rotated and translated state are
    the unmoved forces rotated, to 1e-12 of the largest force."""
    t = term(key, small_mesh, mat)
    x = perturbed(small_mesh, 0.05, seed=3)
    R = rotation([0.2, -1, 0.5], 1.1)
    f = t.forces(x)
    assert np.allclose(t.forces(x @ R.T + 0.05), f @ R.T, atol=1e-12 * np.abs(f).max())


@pytest.mark.parametrize("key", ["balanced", "variational", "volume", "springs", "normal_edge",
                                 "normal_tet", "normal_sbd", "normal_corotated",
                                 "fem_linear", "fem_corotated", "fem_neohookean"])
def test_zero_net_force(key, small_mesh, mat):
    """Every term that conserves momentum (all but the corner reading) has a net force on a
    perturbed mesh of at most 1e-10 times the sum of the force magnitudes."""
    f = term(key, small_mesh, mat).forces(perturbed(small_mesh, 0.05))
    assert np.linalg.norm(f.sum(axis=0)) <= 1e-10 * np.abs(f).sum()


@pytest.mark.parametrize("key", ["variational", "volume", "springs", "normal_edge", "normal_tet",
                                 "normal_sbd", "normal_corotated", "fem_corotated",
                                 "fem_neohookean"])
def test_zero_net_torque(key, small_mesh, mat):
    """Every term that conserves angular momentum has a net torque about the centroid on a
    perturbed mesh of at most 1e-10 times the sum of |r_i| |f_i|."""
    x = perturbed(small_mesh, 0.05)
    f = term(key, small_mesh, mat).forces(x)
    r = x - x.mean(axis=0)
    torque = np.cross(r, f).sum(axis=0)
    assert np.linalg.norm(torque) <= 1e-10 * (np.linalg.norm(r, axis=1)
                                              * np.linalg.norm(f, axis=1)).sum()


@pytest.mark.parametrize("key", ["corner", "balanced"])
def test_residual_momentum_of_the_calibrated_readings_is_measured(key, small_mesh, mat, capsys):
    """The calibrated corner and balanced readings' net force and net torque, relative to
    sum |f|, are measured: the corner reading conserves neither (both above 1e-3); the balanced
    reading conserves momentum (net force below 1e-12) but not angular momentum (net torque
    above 1e-6)."""
    pm = build([TERMS[key]], small_mesh, mat)
    nt = pm.net_force_torque(perturbed(small_mesh, 0.05))
    with capsys.disabled():
        print(f"\n  {key}: net force {nt['force_rel']:.3e}, net torque {nt['torque_rel']:.3e} "
              "(relative to sum |f|)")
    assert np.isfinite(nt["force_rel"]) and np.isfinite(nt["torque_rel"])
    if key == "corner":    # the corner reading's forces do not sum to zero
        assert nt["force_rel"] > 1e-3 and nt["torque_rel"] > 1e-3
    if key == "balanced":  # momentum is conserved by construction, angular momentum is not
        assert nt["force_rel"] < 1e-12 and nt["torque_rel"] > 1e-6


def fd_gradient(energy, x, h):
    g = np.zeros_like(x)
    for i in range(x.shape[0]):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += h
            xm[i, k] -= h
            g[i, k] = (energy(xp) - energy(xm)) / (2 * h)
    return g


@pytest.mark.parametrize("key", CONSERVATIVE)
def test_forces_are_minus_energy_gradient(key, small_mesh, mat):
    """For every conservative term the forces at a perturbed state equal minus the
    central-difference gradient of its energy, to 1e-6 of the largest force."""
    t = term(key, small_mesh, mat)
    x = perturbed(small_mesh, 0.05, seed=1)
    f = t.forces(x)
    g = fd_gradient(t.energy, x, 1e-7)
    assert np.abs(f + g).max() <= 1e-6 * np.abs(f).max()


def test_volume_energy_closed_form(one_tet, mat):
    """On one tetrahedron stretched to V = 1.1 V0 the volume term's energy is K ((V - V0) - V0
    ln(V / V0)) to 1e-12, and node 0's force is p / 3 times the sum of the outward area vectors
    of its three faces, with p = -K (V - V0) / V."""
    t = make_term("volume", one_tet, mat)
    V0 = one_tet.volumes[0]
    x = one_tet.points.copy()
    x[3] *= 1.1  # stretch the apex: V = 1.1 V0
    V = one_tet.volumes[0] * 1.1
    assert t.energy(x) == pytest.approx(mat.K * ((V - V0) - V0 * np.log(V / V0)), rel=1e-12)
    # f_i = (p / 3) sum of outward S_f n_f over the three faces at i, checked at node 0
    p = -mat.K * (V - V0) / V
    faces = [(0, 1, 2), (0, 1, 3), (0, 2, 3)]
    centroid = x.mean(axis=0)
    s = np.zeros(3)
    for f in faces:
        n = 0.5 * np.cross(x[f[1]] - x[f[0]], x[f[2]] - x[f[0]])
        s += n if np.dot(n, x[f[0]] - centroid) > 0 else -n
    assert np.allclose(t.forces(x)[0], p / 3 * s, rtol=1e-12)


def test_shear_strain_closed_form(mat):
    """Simple shear x += g y of a right-corner tetrahedron: gamma(0, 2, 1) = g exactly."""
    from model.mesh import TetMesh
    from model.terms.shear import COMBOS
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]) * 0.01
    sh = Shear(TetMesh(pts, np.array([[0, 1, 2, 3]])), mat, reading="corner")
    g = 0.03
    x = pts.copy()
    x[:, 0] += g * x[:, 1]
    s = [i for i, c in enumerate(COMBOS) if tuple(c[:3]) == (0, 2, 1)][0]
    assert sh.strains(x)[0, s] == pytest.approx(g, rel=1e-12)


@pytest.mark.parametrize("key", TERMS)
def test_numba_kernel_equals_numpy(key, small_mesh, mat):
    """Every term's compiled kernel gives the same forces as its numpy implementation at a
    perturbed state, to 1e-12 of the largest force."""
    t = term(key, small_mesh, mat)
    x = perturbed(small_mesh, 0.05, seed=2)
    f = t.forces(x)
    assert np.allclose(f, t.forces_numpy(x), rtol=0, atol=1e-12 * np.abs(f).max())


def test_corner_sign_restores(small_mesh, mat):
    """Moving one node alone must meet a force against the motion: the diagonal of
    d f_a / d x_a is negative for every node and direction."""
    pm = build([TERMS["corner"]], small_mesh, mat)
    J = pm.jacobian(small_mesh.points)
    assert J.diagonal().max() < 0


def test_one_tetrahedron_has_six_zero_stiffness_modes(one_tet, mat):
    """The Jacobian of pbcm-variational on one tetrahedron is symmetric, has exactly six zero
    stiffness modes (the rigid motions, below 1e-7 of the largest) and its other six are
    positive, above 1e-3 of the largest."""
    pm = build("pbcm-variational", one_tet, mat)
    J = pm.jacobian(one_tet.points).toarray()
    assert np.allclose(J, J.T, atol=1e-6 * np.abs(J).max())  # an energy's Hessian
    eig = np.sort(np.linalg.eigvalsh(-(J + J.T) / 2))
    scale = eig[-1]
    assert np.all(np.abs(eig[:6]) < 1e-7 * scale)
    assert np.all(eig[6:] > 1e-3 * scale)


def test_variational_calibration(mat):
    """c = auto: the deviatoric energy of a homogeneous strain is G |dev eps|^2 V on average;
    with the normal term the fit is closer still."""
    m = cube(4, 0.032, "five")
    pm = build("pbcm-variational", m, mat)
    assert pm.info["shear_c"] > 0
    assert 0.8 < pm.info["deviatoric_eig_min"] <= 1.0 <= pm.info["deviatoric_eig_max"] < 1.2
    both = build("pbcm-variational+normal", m, mat)
    spread = both.info["deviatoric_eig_max"] - both.info["deviatoric_eig_min"]
    assert spread <= pm.info["deviatoric_eig_max"] - pm.info["deviatoric_eig_min"]
    # the energy of a pure shear eps_xy = e matches 2 G e^2 V to the fitted accuracy
    e = 1e-4
    F = np.eye(3) + e * np.array([[0, 1, 0], [1, 0, 0], [0, 0, 0]])
    x = m.points @ F.T
    W = both.energy(x)
    assert W == pytest.approx(2 * mat.G * e**2 * m.volumes.sum(), rel=0.05)


@pytest.mark.parametrize("name", ["normal_sbd", "normal_corotated"])
def test_axis_normal_forms_see_exactly_the_normal_deviatoric_strains(name, mat):
    """Linearised, both material-axis forms have the energy G V sum_i (dev eps)_ii^2: in the
    deviatoric basis (two diagonal, three shear tensors) their quadratic form is G V
    diag(1, 1, 0, 0, 0), whatever the mesh; a uniform stretch costs nothing."""
    from model.calibrate import deviatoric_basis, strain_quadratic_form
    m = cube(3, 0.02, "unstructured")
    t = make_term(name, m, mat, c=1.0)
    Q = strain_quadratic_form(t, m.points, deviatoric_basis())
    assert np.allclose(Q / (mat.G * m.volumes.sum()), np.diag([1.0, 1, 0, 0, 0]), atol=1e-6)
    assert t.energy(1.01 * m.points) < 1e-20


def test_tet_edge_form_quadratic_form_closed_form(mat):
    """normal_tet linearised: E_e = n_e . eps n_e (n_e the unit rest edge), so
    Q_pq = G sum_T V0 sum_e (n.D_p n - mean)(n.D_q n - mean), worked out here edge by edge."""
    from model.calibrate import deviatoric_basis, strain_quadratic_form
    m = cube(3, 0.02, "six")
    basis = deviatoric_basis()
    t = make_term("normal_tet", m, mat, c=1.0)
    Q = strain_quadratic_form(t, m.points, basis)
    want = np.zeros((5, 5))
    for tet, V0 in zip(m.tets, m.volumes):
        n = np.array([m.points[tet[j]] - m.points[tet[i]]
                      for i in range(4) for j in range(i + 1, 4)])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        e = np.einsum("ei,pij,ej->pe", n, basis, n)
        e -= e.mean(axis=1, keepdims=True)
        want += mat.G * V0 * e @ e.T
    assert np.allclose(Q, want, rtol=1e-6, atol=1e-9 * np.abs(want).max())


def test_flattened_tetrahedron_is_reported(one_tet, mat):
    """Forces of a tetrahedron whose apex lies in its base plane raise DegenerateTetError naming
    tetrahedron 0."""
    pm = build("pbcm-variational", one_tet, mat)
    x = one_tet.points.copy()
    x[3] = x[0] + 0.5 * (x[1] - x[0]) + 0.2 * (x[2] - x[0])  # apex into the base plane
    with pytest.raises(DegenerateTetError, match="tetrahedron 0"):
        pm.forces(x)


def test_bad_model_specifications(small_mesh, mat):
    """Building a model raises ModelError naming the problem for an unknown preset, an
    unregistered term, an unknown shear reading, an unknown parameter, a negative constant c and
    a knob for a term the preset does not have."""
    with pytest.raises(ModelError, match="presets"):
        build("pbcm-nonsense", small_mesh, mat)
    with pytest.raises(ModelError, match="registered"):
        build([("gravity-ish", {})], small_mesh, mat)
    with pytest.raises(ModelError, match="reading"):
        build([("shear", {"reading": "sideways"})], small_mesh, mat)
    with pytest.raises(ModelError, match="no parameter"):
        build([("volume", {"stiff": 2})], small_mesh, mat)
    with pytest.raises(ModelError, match="positive number"):
        build([("shear", {"c": -1.0})], small_mesh, mat)
    with pytest.raises(ModelError, match="does not have"):
        build("msm", small_mesh, mat, shear={"scale": 0.5})


def test_scale_knob_scales_forces(small_mesh, mat):
    """A scale of 0.5 on the shear and volume terms of pbcm-balanced halves its forces at a
    perturbed state."""
    x = perturbed(small_mesh, 0.05)
    full = build("pbcm-balanced", small_mesh, mat)
    half = build("pbcm-balanced", small_mesh, mat, shear={"scale": 0.5}, volume={"scale": 0.5})
    assert np.allclose(half.forces(x), 0.5 * full.forces(x), atol=1e-15)


def test_tet_stress_outputs(small_mesh, mat):
    """Under a uniform compression by 1e-3, tet_stress gives every tetrahedron the pressure -K (V
    - V0) / V of that volume change and a max_tau below 1e-9 G (no shear)."""
    pm = build("msm", small_mesh, mat)
    x = small_mesh.points * (1 - 1e-3)  # uniform compression: no shear, p = -K (V-V0)/V
    s = pm.tet_stress(x)
    V_ratio = (1 - 1e-3) ** 3
    assert np.allclose(s["pressure"], -mat.K * (V_ratio - 1) / V_ratio, rtol=1e-9)
    assert np.abs(s["max_tau"]).max() < 1e-9 * mat.G


def test_scale_survives_calibration(small_mesh, mat):
    """scale multiplies a calibrated term after the fit (else c = auto would undo it)."""
    x = perturbed(small_mesh, 0.05)
    full = build("pbcm-variational+normal", small_mesh, mat)
    half = build("pbcm-variational+normal", small_mesh, mat, shear={"scale": 0.5},
                 normal_edge={"scale": 0.5}, volume={"scale": 0.5})
    assert half.info["shear_c"] == full.info["shear_c"]
    assert np.allclose(half.forces(x), 0.5 * full.forces(x), atol=1e-15)
    assert half.energy(x) == pytest.approx(0.5 * full.energy(x), rel=1e-12)


def quadratic_form(energy, points, basis, delta=1e-4):
    """Q with energy(X + delta eps X) = delta^2 a^T Q a + O(delta^4) (symmetric differences)
    from whole energies: slower than the calibration's strain_quadratic_form, and its check."""
    centred = points - points.mean(axis=0)

    def w(eps):
        return 0.5 * (energy(points + centred @ eps.T) + energy(points - centred @ eps.T))

    nb = len(basis)
    Q = np.empty((nb, nb))
    for k in range(nb):
        Q[k, k] = w(delta * basis[k]) / delta**2
    for k in range(nb):
        for l in range(k + 1, nb):
            Q[k, l] = Q[l, k] = 0.5 * (w(delta * (basis[k] + basis[l])) / delta**2
                                       - Q[k, k] - Q[l, l])
    return Q


@pytest.mark.parametrize("preset", ["pbcm-variational", "pbcm-variational+normal"])
def test_fast_calibration_form_equals_the_energy_form(preset, mat):
    """The quadratic form calibration fits, from the strain measures chunk by chunk, equals
    the one taken from second differences of whole energies (an independent route)."""
    from model.calibrate import deviatoric_basis, strain_quadratic_form
    m = cube(4, 0.032, "bcc")
    pm = build(preset, m, mat)
    for t in pm.terms:
        if getattr(t, "calibrate", False):
            fast = strain_quadratic_form(t, m.points, deviatoric_basis(), chunk=7)
            slow = quadratic_form(t.unit_energy, m.points, deviatoric_basis())
            assert np.allclose(fast, slow, rtol=0, atol=1e-6 * np.abs(slow).max())


def test_generated_shear_kernels_are_current():
    """_shear_kernels.py is what _shear_codegen.py writes from the current helpers: edit the
    generator and forget to rerun it, and this goes red (as it must: the file is what runs)."""
    from model.terms import _shear_codegen
    assert _shear_codegen.TARGET.read_text() == _shear_codegen.source(), (
        "run: python model/terms/_shear_codegen.py")


# the terms with a two-thread kernel (which the next test finds by making every term: not at
# collection, where it would compile every kernel in each xdist worker before any test runs)
THREADED = ["volume", "corner", "balanced", "variational", "normal_edge", "fem_linear",
            "fem_corotated", "fem_neohookean"]
EDGE_THREADED = ["springs"]     # its elements are edges: a flattened tetrahedron is no fault


def test_every_presets_terms_have_a_threaded_kernel():
    """Exactly the volume term, the three shear readings (corner, balanced, variational), the
    edge normal term (the +normal preset's), the springs and the three FEM baselines have a
    threaded kernel, so every preset runs wholly on two threads; every other term has none."""
    mesh, material = cube(2, 0.01, "five"), Material(E=1e4, nu=0.3)
    assert sorted(k for k in TERMS if make_term(*TERMS[k][:1], mesh, material, **TERMS[k][1])
                  .threaded_kernel() is not None) == sorted(THREADED + EDGE_THREADED)


def test_the_springs_threaded_kernel_reports_the_first_collapsed_edge(mat):
    """With edges 30 and 5 collapsed to a point, the springs' threaded kernel returns the
    first one (5), as the serial kernel does."""
    mesh = cube(4, 0.02, "five")
    t = term("springs", mesh, mat)
    x = mesh.points.copy()
    for e in (30, 5):
        i, j = t.edge[e]
        x[j] = x[i]
    fn, args = t.threaded_kernel()
    assert fn(x, *args, np.zeros_like(x)) == 5
    assert t.kernel()[0](x, *t.kernel()[1], np.zeros_like(x)) == 5


def test_the_edge_normal_terms_threaded_kernel_reports_the_first_tetrahedron_with_a_collapsed_edge(mat):
    """With an edge of tetrahedra 40 and 7 collapsed to a point, the edge normal term's
    threaded kernel returns the first tetrahedron holding a collapsed edge, as the serial
    kernel does."""
    mesh = cube(4, 0.02, "five")
    t = term("normal_edge", mesh, mat)
    x = mesh.points.copy()
    for k in (40, 7):
        x[mesh.tets[k, 1]] = x[mesh.tets[k, 0]]
    serial = t.kernel()[0](x, *t.kernel()[1], np.zeros_like(x))
    fn, args = t.threaded_kernel()
    assert serial >= 0 and fn(x, *args, np.zeros_like(x)) == serial


@pytest.mark.parametrize("key", THREADED + EDGE_THREADED)
@pytest.mark.parametrize("family", ["five", "six"])
def test_threaded_kernel_equals_serial_bit_for_bit(key, family, mat):
    """The two-thread mode sums each node's contributions in the serial kernel's order, so
    the forces are the same bits (not merely close)."""
    mesh = cube(7, 0.02, family)
    t = term(key, mesh, mat)
    x = perturbed(mesh, 0.05, seed=5)
    fn, args = t.threaded_kernel()
    out = np.full_like(x, 0.25)             # adds into out, as the serial kernel does
    assert fn(x, *args, out) == -1
    assert np.array_equal(out, t.forces(x, np.full_like(x, 0.25)))


@pytest.mark.parametrize("key", [k for k in THREADED if k != "normal_edge"])
def test_threaded_kernel_reports_the_first_flattened_tetrahedron(key, mat):
    """With tetrahedra 40 and 7 flattened, the threaded kernel returns the same degenerate
    tetrahedron as the serial kernel, the first one, which is the one the serial
    DegenerateTetError names."""
    mesh = cube(4, 0.02, "five")
    t = term(key, mesh, mat)
    x = mesh.points.copy()
    for k in (40, 7):                       # flatten two; the first (7) is reported
        x[mesh.tets[k, 3]] = x[mesh.tets[k, :3]].mean(axis=0)
    fn, args = t.threaded_kernel()
    assert fn(x, *args, np.zeros_like(x)) == t.kernel()[0](x, *t.kernel()[1], np.zeros_like(x))
    with pytest.raises(DegenerateTetError) as serial:
        t.forces(x)
    assert fn(x, *args, np.zeros_like(x)) == serial.value.tets[0]


def test_threads_of_a_model(small_mesh, mat):
    """A model built with threads=2 (where numba has two threads) gives forces bit for bit equal
    to the serial model's, and threads=0 raises ModelError."""
    serial = build("pbcm-balanced", small_mesh, mat)
    x = perturbed(small_mesh, 0.05, seed=1)
    if numba.config.NUMBA_NUM_THREADS >= 2:
        two = build("pbcm-balanced", small_mesh, mat, threads=2)
        assert np.array_equal(two.forces(x), serial.forces(x))
    with pytest.raises(ModelError, match="threads must be an integer from 1"):
        build("pbcm-balanced", small_mesh, mat, threads=0)


def test_calibration_may_drop_a_term_and_says_so(mat):
    """On bcc the co-rotated normal term only moves the deviatoric moduli away from 2G, so the
    joint fit sets its c to 0: the model is the paper's, and info names it."""
    m = cube(4, 0.032, "bcc")
    pm = build("pbcm-variational + normal_corotated(c=auto)", m, mat)
    assert pm.info["normal_corotated_c"] == 0.0
    assert pm.info["calibration_dropped"] == ["normal_corotated"]
    base = build("pbcm-variational", m, mat)
    x = perturbed(m, 0.05, seed=5)
    # the same least-squares problem from another start: the same c to the fit's tolerance
    assert pm.info["shear_c"] == pytest.approx(base.info["shear_c"], rel=1e-8)
    # the fits agree to 1e-8, so do the forces, relative to their scale (a component that
    # cancels to near zero keeps only the absolute agreement)
    f = base.forces(x)
    assert np.allclose(pm.forces(x), f, rtol=1e-8, atol=1e-8 * np.abs(f).max())
    assert "calibration_dropped" not in base.info


def test_every_term_with_a_fitted_constant_is_a_calibrated_term():
    """Every term whose constant c the calibration can fit (c = "auto": the shear readings
    among them) is a CalibratedTerm: its c is checked and fitted one way, and a shear reading whose forces are
    not an energy's gradient refuses an energy while its calibrated one is defined."""
    from model.terms import TERMS, CalibratedTerm
    mesh = cube(3, 0.01, "five")
    mat = Material(E=3000.0, nu=0.45, rho=1000.0)
    fitted = [name for name, cls in TERMS.items() if cls.params.get("c") == "auto"]
    assert "shear" in fitted
    assert [n for n in fitted if not issubclass(TERMS[n], CalibratedTerm)] == []
    sheared = mesh.points + 0.01 * mesh.points[:, [1]] * np.array([1.0, 0.0, 0.0])
    for reading in ("corner", "balanced", "variational"):
        t = Shear(mesh, mat, reading=reading, c=1.0)
        assert t.unit_energy(mesh.points) < 1e-30 < t.unit_energy(sheared)
        if reading == "variational":
            assert t.energy(sheared) == pytest.approx(t.unit_energy(sheared), rel=1e-12)
        else:
            with pytest.raises(ModelError, match="not conservative"):
                t.energy(mesh.points)
    with pytest.raises(ModelError, match="shear c must be"):
        Shear(mesh, mat, reading="corner", c=-1.0)


def test_the_neohookean_law_is_one_and_its_stress_is_its_energy_gradient():
    """The compressible neo-Hookean law is written once (model.material): its first Piola
    stress a F + b F^-T matches central differences of its energy, and the FEM term's numpy
    twin and the reference's element kernel take both from it (the same numbers)."""
    from model.material import neohookean_energy, neohookean_stress
    from model.terms.fem import FemNeoHookean
    lam, mu = 2.3e4, 1.1e3
    F = np.array([[1.05, 0.02, -0.01], [0.03, 0.97, 0.04], [-0.02, 0.01, 1.02]])

    def W(G):
        return neohookean_energy(np.sum(G * G), np.log(np.linalg.det(G)), lam, mu)
    a, b = neohookean_stress(np.log(np.linalg.det(F)), lam, mu)
    P = a * F + b * np.linalg.inv(F).T
    h = 1e-6
    fd = np.array([[(W(F + h * E) - W(F - h * E)) / (2 * h)
                    for E in np.eye(9).reshape(9, 3, 3)[3 * i:3 * i + 3]] for i in range(3)])
    assert np.allclose(P, fd, rtol=1e-7, atol=1e-6 * np.abs(P).max())
    import reference._neohookean as element
    import model.terms.fem as fem
    assert element.neohookean_energy is fem.neohookean_energy is neohookean_energy
    assert element.neohookean_stress is fem.neohookean_stress is neohookean_stress
    mesh = cube(2, 0.01, "six")
    term = FemNeoHookean(mesh, Material(E=3000.0, nu=0.45, rho=1000.0))
    Fs = np.stack([F, F @ F])
    assert np.allclose(term.energy_density(Fs), [neohookean_energy(np.sum(G * G),
                       np.log(np.linalg.det(G)), term.lam, term.mu) for G in Fs], rtol=1e-14)


@pytest.mark.parametrize("preset", ["fem-linear", "fem-corotated", "fem-neohookean"])
def test_a_closed_form_tangent_is_the_finite_difference_jacobian(preset):
    """Each FEM baseline's closed-form d f / d x equals the coloured central difference of
    its forces (to the difference's own error) at a stretched, rotated and jiggled state, and
    the model's jacobian is that closed form."""
    from model import Material, build
    from model.mesh import cube
    from model.static import jacobian
    mesh = cube(4, 0.032, "six")
    th = 0.4
    R = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
    x = mesh.points @ R.T * 1.02 + 3e-4 * np.random.default_rng(1).standard_normal(
        mesh.points.shape)
    pm = build(preset, mesh, Material(E=10e3, nu=0.45))
    closed = pm.terms[0].tangent(x).toarray()
    fd = jacobian(pm.forces, mesh, x).toarray()
    assert np.abs(closed - fd).max() < 1e-8 * np.abs(fd).max()
    assert np.array_equal(pm.jacobian(x).toarray(), closed)
