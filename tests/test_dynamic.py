"""The dynamic FEM reference (reference/dynamic.py) against closed forms."""
import numpy as np
import pytest

from model.material import Material
from model.bc import Ramp
from model.errors import MaterialError, ModelError
from model.mesh import box, cube
from reference import dynamic, linear

E, RHO, L, H = 10e3, 1000.0, 0.064, 0.008
C = np.sqrt(E / RHO)          # bar wave speed at nu = 0
T = 4 * L / C                 # fixed-free bar: the released end-loaded bar is periodic in 4 L / c


@pytest.fixture(scope="module")
def bar():
    mesh = box(17, 3, 3, L, H, H, "six")
    fixed = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("x", 0.0)}

    def pull(x, n):
        t = np.zeros_like(x)
        t[..., 0] = np.where(np.isclose(x[..., 0], L), 50.0, 0.0)
        return t

    return mesh, fixed, pull


def released(bar, element, damping=0.0, periods=2.2, method="newmark"):
    mesh, fixed, pull = bar
    u0 = linear.solve(mesh, Material(E, 0.0), fixed, traction=pull, element=element).u
    if method == "modal":   # the same frames as the Newmark steps; a Ramp that stays put
        r = dynamic.solve(mesh, Material(E, 0.0, RHO), Ramp([], (0.0, 0.0, 0.0), 1.0, held=fixed),
                          periods * T, element=element, u0=u0, damping=damping,
                          frames=int(round(periods * 400)) + 1, method="modal")
    else:
        r = dynamic.solve(mesh, Material(E, 0.0, RHO), lambda t: fixed, periods * T, dt=T / 400,
                          element=element, u0=u0, damping=damping)
    tip = r.u[:, np.isclose(mesh.points[:, 0], L), 0].mean(axis=1)
    return r, tip


@pytest.mark.parametrize("method", ["newmark", "modal"])
@pytest.mark.parametrize("element", ["P1", "P2"])
def test_fixed_free_bar_period_is_4L_over_c(bar, element, method):
    """Released from its static deflection under an end load, the tip moves as a triangle
    wave of period 4 L / c: its zero crossings are T / 2 apart."""
    r, tip = released(bar, element, method=method)
    z = np.flatnonzero(np.diff(np.sign(tip)) != 0)
    crossing = r.t[z] - tip[z] * (r.t[z + 1] - r.t[z]) / (tip[z + 1] - tip[z])
    assert len(crossing) >= 4
    assert abs(2 * np.mean(np.diff(crossing)) / T - 1) < 0.01
    assert tip[0] > 0 and abs(tip.min() / tip[0] + 1) < 0.05      # swings to -u0


@pytest.mark.parametrize("method,tol", [("newmark", 1e-6), ("modal", 1e-11)])
def test_undamped_energy_is_constant(bar, method, tol):
    """Without damping, the released bar exchanges kinetic and strain energy (kinetic zero at
    release, later above half the total) while the total stays constant to 1e-6 with Newmark
    and to 1e-11 with the modal method."""
    r, _ = released(bar, "P1", method=method)
    e = r.kinetic + r.strain
    assert r.kinetic[0] == 0 and r.kinetic.max() > 0.5 * e[0]    # energy is exchanged
    assert np.ptp(e) / e[0] < tol


@pytest.mark.parametrize("method", ["newmark", "modal"])
def test_mass_proportional_damping_decays_energy_at_its_rate(bar, method):
    """Every mode decays as exp(-zeta t / 2): the energy as exp(-zeta t), checked at whole
    periods where the oscillating part vanishes."""
    zeta = 0.2 * 2 * np.pi / T
    r, _ = released(bar, "P1", damping=zeta, periods=2.0, method=method)
    e = r.kinetic + r.strain
    for k in (1, 2):
        i = np.argmin(abs(r.t - k * T))
        assert abs(e[i] / e[0] / np.exp(-zeta * r.t[i]) - 1) < 0.01


@pytest.mark.parametrize("method", ["newmark", "modal"])
@pytest.mark.parametrize("element,mass", [("P1", "lumped"), ("P1", "consistent"),
                                          ("P2", "consistent")])
def test_slow_push_then_rest_gives_the_static_reaction(element, mass, method):
    """A cube pushed 1 % over many periods and held with damping comes to the static FEM
    state: displacement and reaction (sign and size) equal to linear.solve. (The default step
    resolves the mesh's modes: at a step 2.5 times longer, the modes the kinks of the path
    excite through a consistent mass ring on at 1e-6 to 1e-5 of the push: the trapezoidal
    rule hardly damps modes it does not resolve.)"""
    mesh = cube(4, 0.032, "six")
    top, bottom = mesh.nodes_on_plane("y", 0.032), mesh.nodes_on_plane("y", 0.0)
    held = {int(i): (0.0, 0.0, 0.0) for i in bottom}
    ramp = Ramp(top, (0.0, -0.32e-3, 0.0), 0.2, held=held)
    r = dynamic.solve(mesh, Material(E, 0.3, RHO), ramp, 1.0, damping=60.0, element=element,
                      mass=mass, frames=11, method=method)
    static = linear.solve(mesh, Material(E, 0.3), ramp(1.0), element=element)
    assert np.abs(r.u[-1] - static.u).max() < 1e-6 * np.abs(static.u).max()
    assert np.allclose(r.reaction[-1], static.reaction, atol=1e-4 * np.abs(static.reaction).max())
    assert r.reaction[-1][top, 1].sum() < 0          # the supports push the top down
    assert len(r.t) == 11 and r.t[-1] == pytest.approx(1.0)


def test_bad_input():
    """dynamic.solve refuses a negative rho, t_end = 0, a negative dt, negative damping, an
    unknown mass and a u0 of the wrong shape, each error naming the argument, and a boundary
    condition whose prescribed components change during the run."""
    mesh = cube(3, 0.032, "six")
    held = {0: (0.0, 0.0, 0.0)}
    for kw, word in [(dict(rho=-1.0), "rho"), (dict(t_end=0.0), "t_end"),
                     (dict(dt=-1.0), "dt"), (dict(damping=-1.0), "damping"),
                     (dict(mass="diagonal"), "mass"), (dict(u0=np.zeros((2, 3))), "u0")]:
        args = dict(rho=RHO, t_end=0.01)
        args.update(kw)
        with pytest.raises((ModelError, MaterialError), match=word):
            dynamic.solve(mesh, Material(E, 0.3, args.pop("rho")), lambda t: held,
                          args.pop("t_end"), **args)
    moving = Ramp([1], (0.0, 1e-4, None), 0.01, held=held)
    changing = (lambda t: held if t < 0.005 else moving(t))
    with pytest.raises(ModelError, match="prescribed components"):
        dynamic.solve(mesh, Material(E, 0.3, RHO), changing, 0.01, dt=1e-3)


def test_model_frequencies_of_one_spring_node_by_hand():
    """One tetrahedron of springs (van Gelder: k = E V / L^2), three nodes held: the free node
    vibrates at sqrt(eig(sum k e e^T) / m) / 2 pi, m = rho V / 4; free-free, six springs on
    four nodes leave exactly the six rigid modes."""
    from model import build
    from model.mesh import TetMesh
    from cases.library.transient import model_frequencies
    X = 0.01 * np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.3, 1]])
    mesh = TetMesh(X, np.array([[0, 1, 2, 3]]))
    mat = Material(E=E, nu=0.25, rho=RHO)
    pm = build("msm", mesh, mat)
    V = abs(np.linalg.det(X[1:] - X[0])) / 6
    Kn = np.zeros((3, 3))
    for i in range(3):
        d = X[3] - X[i]
        Kn += E * V / (d @ d) * np.outer(d, d) / (d @ d)
    expected = np.sort(np.sqrt(np.linalg.eigvalsh(Kn) / (RHO * V / 4))) / (2 * np.pi)
    free = np.zeros(12, dtype=bool)
    free[9:] = True
    freq, rigid = model_frequencies(pm, free)
    assert rigid == 0 and np.allclose(freq, expected, rtol=1e-5)
    _, rigid = model_frequencies(pm, np.ones(12, dtype=bool))
    assert rigid == 6


@pytest.mark.parametrize("zeta", [20.0, 2000.0])   # every mode underdamped; the lowest over
def test_modal_ramp_equals_the_matrix_exponential(zeta):
    """The exact-in-time transient of a push with a kink (ramp, then hold) against the
    matrix exponential of the first-order system, written here from scikit-fem's own forms:
    z = (u_I, v_I, 1, t), z' = A z on each piece, the kink's impulse
    M_II dv_I = M_ID x_moving / T between."""
    from scipy.linalg import expm, solve
    from skfem import BilinearForm, Basis, ElementTetP1, ElementVector, asm
    from skfem.helpers import dot
    from skfem.models.elasticity import lame_parameters, linear_elasticity
    from reference.discretisation import skfem_mesh
    mesh = cube(3, 0.032, "six")
    top, bottom = mesh.nodes_on_plane("y", 0.032), mesh.nodes_on_plane("y", 0.0)
    held = {int(i): (0.0, 0.0, 0.0) for i in bottom}
    push = np.array([1e-4, -0.32e-3])
    T_push, t_end, nu = 0.03, 0.06, 0.3
    ramp = Ramp(top, (push[0], push[1], None), T_push, held=held)
    r = dynamic.solve(mesh, Material(E, nu, RHO), ramp, t_end, damping=zeta, frames=13,
                      method="modal")

    basis = Basis(skfem_mesh(mesh), ElementVector(ElementTetP1()))
    K = asm(linear_elasticity(*lame_parameters(E, nu)), basis).toarray()
    M = RHO * asm(BilinearForm(lambda u, v, w: dot(u, v)), basis).toarray()
    dof = basis.nodal_dofs            # dof[k, i]: component k of node i
    D = np.concatenate([dof[:, bottom].ravel(), dof[:2, top].ravel()])
    x_mov = np.concatenate([np.zeros(3 * len(bottom)), np.repeat(push, len(top))])
    Ifree = np.setdiff1d(np.arange(basis.N), D)
    nI = len(Ifree)
    K_II, K_ID, M_II, M_ID = (K[np.ix_(Ifree, Ifree)], K[np.ix_(Ifree, D)],
                              M[np.ix_(Ifree, Ifree)], M[np.ix_(Ifree, D)])

    def generator(a, b):              # z' = A z for M u'' + zeta M u' + K u = a + b t
        A = np.zeros((2 * nI + 2, 2 * nI + 2))
        A[:nI, nI:2 * nI] = np.eye(nI)
        A[nI:2 * nI, :nI] = -solve(M_II, K_II)
        A[nI:2 * nI, nI:2 * nI] = -zeta * np.eye(nI)
        A[nI:2 * nI, 2 * nI] = solve(M_II, a)
        A[nI:2 * nI, 2 * nI + 1] = solve(M_II, b)
        A[2 * nI + 1, 2 * nI] = 1.0
        return A

    pushing = generator(-zeta * M_ID @ x_mov / T_push, -K_ID @ x_mov / T_push)
    holding = generator(-K_ID @ x_mov, np.zeros(nI))
    z0 = np.zeros(2 * nI + 2)
    z0[2 * nI] = 1.0
    zT = expm(pushing * T_push) @ z0
    zT[nI:2 * nI] += solve(M_II, M_ID @ x_mov) / T_push
    for k, t in enumerate(r.t):
        z = expm(pushing * t) @ z0 if t < T_push else expm(holding * (t - T_push)) @ zT
        u = np.zeros(basis.N)
        u[Ifree], u[D] = z[:nI], min(t / T_push, 1.0) * x_mov
        assert np.abs(r.u[k] - u[dof].T).max() <= 1e-9 * np.abs(push).max(), t
        v = z[nI:2 * nI]
        assert np.abs(r.v[k].ravel()[Ifree] - v).max() <= 1e-9 * np.abs(push).max() / T_push


@pytest.mark.parametrize("w2", [1.0e4, 2.5e5 * (1 - 1e-13), 2.5e5, 2.5e5 * (1 + 1e-13),
                                1.0e7])
def test_free_response_is_the_damped_oscillator(w2):
    """C and S of the free response against the textbook forms: over-, critically and
    underdamped (zeta = 1000 1/s, so critical at omega^2 = 2.5e5), continuous across
    critical."""
    zeta, tau = 1000.0, np.linspace(0.0, 0.02, 9)
    C, S = dynamic._free_response(np.array([w2]), zeta, tau)
    decay = np.exp(-zeta * tau / 2)
    d = zeta**2 / 4 - w2
    if abs(d) < 1e-6 * w2:
        C_ok, S_ok = decay, tau * decay
    elif d > 0:
        lam = np.sqrt(d)
        C_ok, S_ok = decay * np.cosh(lam * tau), decay * np.sinh(lam * tau) / lam
    else:
        wd = np.sqrt(-d)
        C_ok, S_ok = decay * np.cos(wd * tau), decay * np.sin(wd * tau) / wd
    assert np.allclose(C[0], C_ok, rtol=1e-9, atol=1e-14)
    assert np.allclose(S[0], S_ok, rtol=1e-9, atol=1e-14 * tau[-1])


def test_modal_method_names_what_it_needs():
    """dynamic.solve with method="modal" raises ModelError naming what is wrong: a boundary
    condition that is not a Ramp, a dt given, or supports that leave rigid motions; an
    unknown method name is refused too."""
    mesh = cube(3, 0.032, "six")
    held = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("y", 0.0)}
    ramp = Ramp(mesh.nodes_on_plane("y", 0.032), (0.0, -1e-4, 0.0), 0.01, held=held)
    free = Ramp([0], (0.0, 0.0, None), 0.01)      # one component held: rigid motions left
    for args, kw, word in [((lambda t: held,), {}, "Ramp"), ((ramp,), {"dt": 1e-3}, "dt"),
                           ((free,), {}, "rigid"), ((ramp,), {"method": "euler"}, "method")]:
        kw = {"method": "modal", **kw}
        with pytest.raises(ModelError, match=word):
            dynamic.solve(mesh, Material(E, 0.3, RHO), *args, 0.02, **kw)


def test_mac_of_shapes_and_spaces_worked_by_hand():
    """mac is 1 for a shape against itself, 0 against an orthogonal one, 0.5 for a shape at
    45 degrees to a single vector and 1 for a shape in the span of two vectors; a complex
    shape is compared by its modulus."""
    from cases.measuring.metrics import mac
    e = np.eye(5)
    assert mac(e[0], e[:1].T) == pytest.approx(1.0)
    assert mac(e[0], e[1:2].T) == pytest.approx(0.0)
    a = np.array([1.0, 1.0, 0, 0, 0])
    assert mac(a, e[:1].T) == pytest.approx(0.5)          # |a.b|^2 / (|a|^2 |b|^2)
    assert mac(a, e[:2].T) == pytest.approx(1.0)          # in the span of the pair
    assert mac(1j * a, e[:2].T) == pytest.approx(1.0)     # a complex shape by its modulus


def test_pairing_by_shape_skips_a_spurious_mode_and_spans_degenerate_pairs():
    """pair_modes pairs by shape: a rotated degenerate pair matches the reference pair and a
    spurious model mode is skipped, so the worst frequency error is 0.1 rather than the 0.25
    of pairing by rank; reference modes no model mode spans stay unpaired."""
    from cases.measuring.metrics import pair_modes
    e = np.eye(6)
    f_ref, v_ref = [1.0, 1.0, 2.0, 3.0], e[[0, 1, 2, 3]]
    rot = np.array([e[0] + e[1], e[0] - e[1]]) / np.sqrt(2)   # the pair's space, rotated
    f_model = [1.05, 1.06, 1.5, 2.2, 3.3]
    v_model = np.vstack([rot, e[4], e[2], e[3]])              # 1.5 Hz: a spurious shape
    pairs, unpaired = pair_modes(f_model, v_model, f_ref, v_ref)
    assert pairs == [(0, 0), (1, 1), (2, 3), (3, 4)] and unpaired == []
    errors = [abs(f_model[j] / f_ref[i] - 1) for i, j in pairs]
    assert max(errors) == pytest.approx(0.1)   # by rank it would be |1.5 / 2 - 1| = 0.25
    # a reference shape no model mode has stays unpaired
    pairs, unpaired = pair_modes(f_model[:3], v_model[:3], f_ref, v_ref)
    assert pairs == [(0, 0), (1, 1)] and unpaired == [2, 3]


def _orthonormal(n, k, seed=0):
    return np.linalg.qr(np.random.default_rng(seed).standard_normal((n, k)))[0].T


def test_a_model_equal_to_the_reference_pairs_every_mode_with_itself():
    """A model equal to the reference (its frequencies and shapes, with a nodal mass) pairs
    every mode with itself, and so does the same model with a degenerate pair given in a
    non-orthogonal basis."""
    from cases.measuring.metrics import pair_modes
    f, v = [1.0, 1.0, 1.3, 2.0, 2.0, 2.0, 2.5], _orthonormal(30, 7)
    mass = np.random.default_rng(1).uniform(0.5, 2.0, 10)
    pairs, unpaired = pair_modes(f, v, f, v, mass=mass)
    assert pairs == [(i, i) for i in range(7)] and unpaired == []
    # the same model, its degenerate pair in a non-orthogonal basis (np.linalg.eig's of a
    # non-symmetric M^-1 K): both shapes lie 0.81 along the first reference one
    skew = v.copy()
    skew[1] = 0.9 * v[0] + np.sqrt(0.19) * v[1]
    pairs, unpaired = pair_modes(f, skew, f, v)
    assert pairs == [(i, i) for i in range(7)] and unpaired == []


def test_a_spurious_mode_stays_unpaired_and_does_not_shift_the_later_pairs():
    """A model mode whose shape no reference mode has stays unpaired, and the model modes
    after it still pair with their own reference modes."""
    from cases.measuring.metrics import pair_modes
    e = _orthonormal(30, 7)
    f_ref, v_ref = [1.0, 1.2, 1.5, 2.0, 2.4, 3.0], e[:6]
    f_model = [1.0, 1.2, 1.3, 1.5, 2.0, 2.4, 3.0]           # 1.3: a shape no reference has
    v_model = np.vstack([e[:2], e[6], e[2:6]])
    pairs, unpaired = pair_modes(f_model, v_model, f_ref, v_ref, count=5)
    assert pairs == [(0, 0), (1, 1), (2, 3), (3, 4), (4, 5)] and unpaired == []


def test_two_mixed_modes_pair_as_one_space_though_their_frequencies_differ():
    """A model's error mixes reference modes a few % apart (FEM P1 those 15 % apart): each
    model mode then matches neither alone (MAC 0.5) but the two together."""
    from cases.measuring.metrics import pair_modes
    e = _orthonormal(30, 4)
    f_ref, v_ref = [1.0, 1.05, 1.5, 2.0], e
    mixed = np.array([e[0] + e[1], e[0] - e[1]]) / np.sqrt(2)
    f_model = [1.1, 1.2, 1.55, 2.1]
    pairs, unpaired = pair_modes(f_model, np.vstack([mixed, e[2:]]), f_ref, v_ref)
    assert pairs == [(0, 0), (1, 1), (2, 2), (3, 3)] and unpaired == []
    # one of the two alone pairs the lower reference mode of the space; the other is lost
    pairs, unpaired = pair_modes(f_model[1:], np.vstack([mixed[1:], e[2:]]), f_ref, v_ref)
    assert pairs == [(0, 0), (2, 1), (3, 2)] and unpaired == [1]


@pytest.mark.parametrize("bc", ["free", "clamped"])
@pytest.mark.parametrize("family", ["five", "six", "bcc", "unstructured"])
def test_fem_p1_pairs_all_its_modes_with_fem_p2_and_with_itself(family, bc):
    """The modes case's cube: FEM P1 (lumped mass) differs from FEM P2 only by
    discretisation, so every one of its first 10 modes pairs with a mode of FEM P2 on the
    mesh, on every family and both supports."""
    from cases.measuring.error_model import P1_LINEAR
    from cases.library import transient
    from cases.library.modes import CASE, ModesSettings
    from cases.measuring.metrics import pair_modes
    s = ModesSettings(fem_refine=0)
    mesh = CASE.mesh(family, s)
    ref = CASE.solve_reference(mesh, bc, s, None)
    mass = CASE.build_model(P1_LINEAR, mesh, s).mass
    f2, v2 = ref.extra["frequencies_hz"], ref.extra["shapes"]
    f1, v1 = ref.extra["p1_frequencies_hz"], ref.extra["p1_shapes"]
    pairs, unpaired = pair_modes(f1, v1, f2, v2, count=transient.N_MODES, mass=mass)
    assert unpaired == [] and len(pairs) == transient.N_MODES
    err = max(abs(f1[j] / f2[i] - 1) for i, j in pairs)
    assert err < 0.5        # P1 on the 5-node cube: up to 42 % (unstructured, clamped)
    pairs, unpaired = pair_modes(f1, v1, f1, v1, count=transient.N_MODES, mass=mass)
    assert pairs == [(i, i) for i in range(transient.N_MODES)] and unpaired == []


def test_fem_frequency_estimates_fall_under_refinement_as_rayleigh_ritz_bounds_do():
    """Nested conforming P2 spaces with consistent mass bound each frequency from above, so
    the refined frequencies lie below the coarse ones and each estimate, relative to the refined reference, is f_0 / f_1 - 1 >= 0
    (an estimate of the wrong sign, or taken against the wrong level, goes red)."""
    from cases.library.transient import CLUSTER_EXTRA, N_MODES, fem_frequencies
    from model.mesh import cube
    mesh = cube(3, 0.032, "five")
    mat = Material(E=1e4, nu=0.3, rho=1e3)
    held = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("y", 0.0)}
    (f0, _), none = fem_frequencies(mesh, mat, held, refine=0)
    (f1, shapes), each = fem_frequencies(mesh, mat, held, refine=1)
    # the modes past N_MODES complete a cluster the tenth cuts; estimates are of the first ten
    assert none is None and shapes.shape == (N_MODES + CLUSTER_EXTRA, 3 * mesh.n_nodes)
    assert np.all(f1 <= f0 * (1 + 1e-10))
    assert np.allclose(each, f0[:N_MODES] / f1[:N_MODES] - 1, rtol=1e-12, atol=0)
    assert 0 < each.max() < 0.2
