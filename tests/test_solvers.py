"""Static equilibrium, RK4 dynamics, materials and their errors."""
import math

import numpy as np
import scipy.sparse as sp
import pytest

from model import Material, build
from model.bc import ramp
from model.errors import BlowUpError, ConvergenceError, MaterialError, ModelError
from model.mesh import TetMesh, box, cube

L = 0.032


def cube_bc(mesh, dy):
    bot, top = mesh.nodes_on_plane("y", 0.0), mesh.nodes_on_plane("y", L)
    return bot, top, {**{i: (0.0, 0.0, 0.0) for i in bot}, **{i: (0.0, dy, 0.0) for i in top}}


@pytest.mark.parametrize("preset", ["pbcm-corner", "pbcm-balanced", "pbcm-variational", "msm"])
def test_static_equilibrium_and_reactions(preset, mat):
    """For each preset, the static solve of a compressed cube converges with the free nodes'
    forces within tolerance and the prescribed displacements held; the reactions are the
    negated internal forces on the prescribed nodes, zero elsewhere, and push the top down.
    For the momentum-conserving presets (all but pbcm-corner) the reactions balance to 1e-12
    of the top load."""
    mesh = cube(3, L, "five")
    bot, top, bc = cube_bc(mesh, -1.7e-3)
    res = build(preset, mesh, mat).solve_static(bc)
    f = build(preset, mesh, mat).forces(res.x)
    free = np.setdiff1d(np.arange(mesh.n_nodes), np.r_[bot, top])
    assert res.residual <= res.tol and np.abs(f[free]).max() <= res.tol
    assert np.allclose(res.u[top], [0, -1.7e-3, 0]) and np.allclose(res.u[bot], 0)
    assert np.allclose(res.reaction[np.r_[bot, top]], -f[np.r_[bot, top]])
    assert np.all(res.reaction[free] == 0)
    assert res.reaction[top, 1].sum() < 0  # the support pushes the top down to compress it
    if preset != "pbcm-corner":
        # momentum-conserving: the forces sum to zero, so the supports balance up to what the
        # free nodes' residual (below the solver's tolerance) leaves
        assert abs(res.reaction[:, 1].sum() - f[free, 1].sum()) \
            < 1e-12 * -res.reaction[top, 1].sum()


def test_a_free_interior_node_stays_affine_under_uniform_compression(mat):
    """Under a uniform 1 % compression of msm+volume prescribed at every node but the centre,
    the static solve puts the free centre node at its affine position (to 1e-12 m)."""
    mesh = cube(3, L, "six")
    s = 0.99
    centre = mesh.nodes_where(lambda p: np.all(np.isclose(p, L / 2), axis=1))
    bc = {i: tuple((s - 1) * mesh.points[i]) for i in range(mesh.n_nodes) if i not in centre}
    res = build("msm+volume", mesh, mat).solve_static(bc)
    assert np.allclose(res.x[centre], s * mesh.points[centre], atol=1e-12)


def test_a_load_step_starts_from_the_last_two_equilibria_extrapolated(mat, monkeypatch):
    """A linear model's equilibria extrapolate exactly: four load steps take the Newton
    iterations of one (each later step starts converged) and land where one step does. A
    nonlinear one (pbcm-variational at 20 % compression) forms fewer Jacobians than when each
    step starts from the last state with the boundary moved, to the same equilibrium."""
    import model.static as static
    mesh = cube(3, L, "five")
    _, _, bc = cube_bc(mesh, -1.7e-3)
    pm = build("fem-linear", mesh, mat)
    one, four = pm.solve_static(bc), pm.solve_static(bc, load_steps=4)
    assert four.iterations == one.iterations >= 1 and four.jacobians == one.jacobians
    assert np.abs(four.u - one.u).max() < 1e-9 * np.abs(one.u).max()
    _, _, bc = cube_bc(mesh, -0.2 * L)
    pm = build("pbcm-variational", mesh, mat)
    predicted = pm.solve_static(bc, load_steps=4)
    monkeypatch.setattr(static, "_predicted", lambda x, r, *rest: (x, r))
    plain = pm.solve_static(bc, load_steps=4)
    assert predicted.jacobians < plain.jacobians
    assert np.abs(predicted.u - plain.u).max() < 1e-7 * np.abs(plain.u).max()


def test_a_full_newton_step_that_raises_the_residual_is_watched_not_cut(mat, monkeypatch):
    """pbcm-corner on a cantilever (64 x 16 x 16 mm, nodes every 4 mm, 1 uN at the tip): the
    first full Newton step raises the largest residual, the next one converges. Backtracking
    on every step creeps (10 Jacobians here, 47 on the 2 mm mesh); the watched full step takes
    2, to the same equilibrium."""
    import model.static as static
    mesh = box(17, 5, 5, 0.064, 0.016, 0.016, scheme="six")
    root, tip = mesh.nodes_on_plane("x", 0.0), mesh.nodes_on_plane("x", 0.064)
    f_ext = np.zeros_like(mesh.points)
    f_ext[tip, 1] = -1e-6 / len(tip)
    bc = {int(i): (0.0, 0.0, 0.0) for i in root}
    pm = build("pbcm-corner", mesh, mat)
    watched = pm.solve_static(bc, f_ext=f_ext, rtol=1e-12)
    monkeypatch.setattr(static, "_full_step", lambda *a: None)
    cut = pm.solve_static(bc, f_ext=f_ext, rtol=1e-12)
    assert watched.jacobians <= 3 < cut.jacobians
    assert np.abs(watched.u - cut.u).max() < 1e-6 * np.abs(cut.u).max()


def test_static_errors(mat):
    """solve_static raises ModelError for an unsupported (singular) problem, a non-finite
    value, a node outside the mesh and a value that is not (ux, uy, uz), and ConvergenceError
    when Newton exceeds max_iter or when a 60 % compression in one step needs more load
    steps."""
    mesh = cube(3, L, "five")
    pm = build("pbcm-variational", mesh, mat)
    with pytest.raises(ModelError, match="singular"):
        pm.solve_static({})
    with pytest.raises(ModelError, match="not finite"):
        pm.solve_static({0: (0.0, np.nan, 0.0)})
    with pytest.raises(ModelError, match="nodes are"):
        pm.solve_static({999: (0.0, 0.0, 0.0)})
    with pytest.raises(ModelError, match=r"\(ux, uy, uz\)"):
        pm.solve_static({0: (0.0, 0.0)})
    _, _, bc = cube_bc(mesh, -0.2 * L)
    with pytest.raises(ConvergenceError, match="did not converge"):
        pm.solve_static(bc, max_iter=2)
    _, _, bc = cube_bc(mesh, -0.6 * L)
    with pytest.raises(ConvergenceError, match="increase load_steps"):
        pm.solve_static(bc)


def test_a_load_step_whose_residual_does_not_halve_is_called_stalled_only_when_asked(mat):
    """With ``stall`` given, a load step whose Newton iterations have not halved its residual
    that many times in a row raises a ConvergenceError naming the stall (here a Jacobian
    1000 times too stiff makes every step a thousandth of Newton's); without it the same
    solve runs to max_iter; a solve that converges is the same with and without it."""
    mesh = cube(3, L, "five")
    pm = build("pbcm-variational", mesh, mat)
    _, _, bc = cube_bc(mesh, -0.05 * L)
    plain = pm.solve_static(bc)
    guarded = pm.solve_static(bc, stall=3)
    assert np.array_equal(plain.u, guarded.u) and plain.iterations == guarded.iterations
    exact = pm.jacobian
    pm.jacobian = lambda x: 1e3 * exact(x)
    with pytest.raises(ConvergenceError, match="stalled at load step 1/1: 3 Newton iterations"):
        pm.solve_static(bc, stall=3)
    with pytest.raises(ConvergenceError, match="did not converge in 8 Newton iterations"):
        pm.solve_static(bc, max_iter=8)


def test_a_newton_direction_that_inverts_a_tetrahedron_at_every_length_is_a_convergence_error():
    """Where every backtracked Newton step inverts a tetrahedron, the solve raises a
    ConvergenceError (naming the tetrahedron and asking for more load steps), the error a
    caller answers by splitting the load, never a bare inversion that skips the split."""
    import model.static as static
    from model.errors import DegenerateTetError

    def inverts(x, s):
        raise DegenerateTetError("tetrahedron 7 (nodes [0, 1, 2, 3]) is inverted", [7])
    x = np.zeros((2, 3))
    with pytest.raises(ConvergenceError, match="tetrahedron 7.*increase load_steps"):
        static._backtracked(x, np.ones(6), 1.0, 1.0, np.ones(6, bool), inverts)


def test_damped_dynamics_settles_on_the_static_solution(mat):
    """A damped pbcm-balanced simulation of a ramped compression ends at 2 s with the
    prescribed nodes exactly at their static positions, every node within 1e-6 of the push of
    the static solution, and reactions equal to the static ones."""
    mesh = cube(3, L, "five")
    bot, top, bc = cube_bc(mesh, -1.7e-3)
    pm = build("pbcm-balanced", mesh, mat)
    traj = pm.simulate(ramp(top, (0.0, -1.7e-3, 0.0), 0.2, fixed=bot), 2.0, damping=40.0)
    static = pm.solve_static(bc)
    assert np.allclose(traj.x[-1][top], static.x[top], atol=1e-15)  # followed exactly
    assert np.abs(traj.x[-1] - static.x).max() < 1e-6 * 1.7e-3
    assert np.allclose(traj.reaction[-1], static.reaction, atol=1e-6 * np.abs(
        static.reaction).max())
    assert traj.t[0] == 0 and traj.t[-1] == pytest.approx(2.0)


def test_rk4_converges_at_fourth_order(mat):
    """One free node on three springs (the other nodes fixed), pulled by a constant force: the
    largest position error over the trajectory, against a fine-step solution, drops 16-fold
    when dt halves."""
    pts = np.array([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0.002, 0.003, 0.01]])
    mesh = TetMesh(pts, np.array([[0, 1, 2, 3]]))
    pm = build("msm", mesh, mat)
    f_ext = np.zeros((4, 3))
    f_ext[3] = [0.02, -0.01, 0.03]
    fixed = {i: (0.0, 0.0, 0.0) for i in range(3)}
    t_end = 0.02
    n = 10 * math.ceil(t_end / 10 / pm.stable_dt())  # steps divide t_end and the 11 frames

    def path(steps):
        return pm.simulate(lambda t: fixed, t_end, dt=t_end / steps, f_ext=f_ext,
                           frames=11).x[:, 3]

    ref = path(64 * n)
    e1, e2 = (np.abs(path(k) - ref).max() for k in (n, 2 * n))
    assert 14 < e1 / e2 < 18


def test_prescribed_velocity_follows_the_path(mat):
    """Halfway through a linear ramp of -1 mm, the simulated top nodes have moved exactly
    -0.5 mm in y."""
    mesh = cube(3, L, "five")
    bot, top, _ = cube_bc(mesh, 0)
    pm = build("msm", mesh, mat)
    traj = pm.simulate(ramp(top, (0.0, -1e-3, None), 0.5, fixed=bot), 0.25, frames=3)
    assert np.allclose(traj.x[-1][top, 1] - mesh.points[top, 1], -0.5e-3, rtol=1e-12)


def test_blow_up_names_step_time_and_smaller_dt(mat):
    """A simulation at 20 times the stable step raises BlowUpError naming the step, its time
    and a suggested dt, which is smaller than the step used."""
    mesh = cube(3, L, "five")
    bot, top, _ = cube_bc(mesh, 0)
    pm = build("pbcm-variational", mesh, mat)
    with pytest.raises(BlowUpError, match=r"step \d+ \(t = .* s.*try dt = ") as err:
        pm.simulate(ramp(top, (0.0, -1.7e-3, 0.0), 0.2, fixed=bot), 0.5,
                    dt=20 * pm.stable_dt())
    assert err.value.dt_suggested < 20 * pm.stable_dt()


def test_simulate_argument_errors(mat):
    """simulate raises ModelError for a negative t_end, a zero dt, and a boundary condition
    whose prescribed components change during the run."""
    mesh = cube(3, L, "five")
    pm = build("msm", mesh, mat)
    with pytest.raises(ModelError, match="t_end"):
        pm.simulate(lambda t: {0: (0, 0, 0)}, -1.0)
    with pytest.raises(ModelError, match="dt"):
        pm.simulate(lambda t: {0: (0, 0, 0)}, 1.0, dt=0.0)
    with pytest.raises(ModelError, match="prescribes other components"):
        pm.simulate(lambda t: {0: (0, 0, 0)} if t < 0.01 else {1: (0, 0, 0)}, 0.05)


@pytest.mark.parametrize("kw,match", [
    (dict(E=0.0, nu=0.3), "E must be > 0"), (dict(E=-5.0, nu=0.3), "E must be > 0"),
    (dict(E=1e3, nu=0.5), "nu must satisfy"), (dict(E=1e3, nu=-1.0), "nu must satisfy"),
    (dict(E=float("nan"), nu=0.3), "finite"), (dict(E=1e3, nu=0.3, rho=0.0), "rho"),
])
def test_material_errors(kw, match):
    """Material refuses E <= 0, nu of 0.5 or -1, a non-finite E and rho = 0 with a
    MaterialError naming the bad constant."""
    with pytest.raises(MaterialError, match=match):
        Material(**kw)


def test_material_moduli():
    """Material(E=10 kPa, nu=0.45) gives G = E / 2.9 and K = E / 0.3, and lam + 2 G / 3
    equals K."""
    m = Material(E=10e3, nu=0.45)
    assert m.G == pytest.approx(10e3 / 2.9) and m.K == pytest.approx(10e3 / 0.3)
    assert m.lam + 2 * m.G / 3 == pytest.approx(m.K)


def _rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


@pytest.mark.parametrize("scheme", ["five", "six"])
def test_fem_linear_statics_are_linear_fem_p1(scheme, mat):
    """The explicit small-strain baseline is P1 on the same mesh: its static equilibrium is
    the scikit-fem P1 solution (a different code: assembly by quadrature, sparse solve)."""
    from reference import linear
    mesh = cube(4, L, scheme)
    bot, top, _ = cube_bc(mesh, 0.0)
    bc = {**{i: (0.0, 0.0, 0.0) for i in bot}, **{i: (0.3e-3, -1.0e-3, None) for i in top}}
    res = build("fem-linear", mesh, mat).solve_static(bc)
    ref = linear.solve(mesh, mat, bc, element="P1")
    assert _rel(res.u, ref.u) < 1e-8
    assert _rel(res.reaction[top], ref.reaction[top]) < 1e-8


def test_fem_neohookean_statics_are_the_hyperelastic_reference(mat):
    """At 20 % compression with shear, the neo-Hookean baseline's equilibrium is the
    scikit-fem neo-Hookean P1 solution on the same mesh, and the co-rotated one differs from
    both by a visible amount (another law), as does small strain."""
    from reference import hyperelastic
    mesh = cube(4, L, "five")
    bot, top, _ = cube_bc(mesh, 0.0)
    bc = {**{i: (0.0, 0.0, 0.0) for i in bot}, **{i: (1.6e-3, -6.4e-3, 0.0) for i in top}}
    nh = build("fem-neohookean", mesh, mat).solve_static(bc, load_steps=4)
    ref = hyperelastic.solve(mesh, mat, bc, element="P1", load_steps=4)
    assert _rel(nh.u, ref.u) < 1e-8
    for other in ("fem-corotated", "fem-linear"):
        u = build(other, mesh, mat).solve_static(bc, load_steps=4).u
        assert _rel(u, ref.u) > 1e-3, other


@pytest.mark.parametrize("preset", ["msm", "pbcm-variational"])
def test_compiled_ramp_step_is_the_plain_rk4_step(preset, mat):
    """The compiled step (low-storage node passes, sparse prescribed components) does the
    arithmetic of model.integrate.rk4_step: both paths agree to rounding, damping, external
    force and a half-prescribed node included. The compiled step sums the stages as they come,
    in another order, and the stiff stages' large h a terms cancel: rounding reaches about
    1e-12 of the state, where a wrong RK4 weight would give 1e-3."""
    mesh = cube(3, L, "five")
    bot, top, _ = cube_bc(mesh, 0)
    pm = build(preset, mesh, mat)
    r = ramp(top, (0.0, -1e-3, None), 0.01, fixed=bot)

    class Plain:   # the same ramp, not a Ramp: simulate takes the Python path
        def __call__(self, t):
            return r(t)

        def velocity(self, t, n):
            return r.velocity(t, n)

    f_ext = np.zeros_like(mesh.points)
    f_ext[-1] = (1e-3, 2e-3, -1e-3)
    a = pm.simulate(r, 0.02, damping=30.0, f_ext=f_ext, frames=5)
    b = pm.simulate(Plain(), 0.02, damping=30.0, f_ext=f_ext, frames=5)
    assert a.steps == b.steps > 20
    assert np.abs(a.x - b.x).max() < 1e-10 * np.abs(a.x - mesh.points).max()
    assert np.abs(a.v - b.v).max() < 1e-10 * np.abs(a.v).max()


@pytest.mark.parametrize("scheme", ["five", "six", "bcc", "unstructured"])
def test_node_colours_share_no_neighbour_and_are_the_smallest_free(scheme):
    """The finite-difference Jacobian's colouring: no two nodes of one colour are within two
    edges, and each node took the smallest colour its earlier neighbours left (greedy, so
    a colour c > 0 is taken near the node for every smaller one)."""
    from model.static import colour_nodes, node_adjacency
    mesh = cube(5, L, scheme)
    adj = node_adjacency(mesh)
    near = (adj.astype(int) @ adj.astype(int)).tocsr()
    colour = colour_nodes(adj)
    for i in range(mesh.n_nodes):
        others = np.setdiff1d(near.indices[near.indptr[i]:near.indptr[i + 1]], [i])
        assert colour[i] not in colour[others]
        earlier = colour[others[others < i]]
        assert set(range(colour[i])) <= set(earlier)


def _grid_laplacian(m):
    """The 7-point Laplacian on an m^3 grid and its unknowns' positions."""
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m))
    eye = sp.identity(m)
    A = (sp.kron(sp.kron(T, eye), eye) + sp.kron(sp.kron(eye, T), eye)
         + sp.kron(sp.kron(eye, eye), T)).tocsc()
    g = np.arange(m, dtype=float)
    return A, np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)


def test_a_nested_dissection_ordering_solves_the_same_system_and_is_kept_only_where_sparser(
        mat, monkeypatch):
    """The nested dissection is a permutation of the unknowns; factors in its order solve the
    Newton system as minimum degree's do (to round-off); a solve keeps it only where its
    factors hold fewer entries (the 3D Jacobian of msm on the 9-node bcc cube: yes; the
    7-point grid Laplacian, where minimum degree fills less: no) and never tries it below
    DISSECT_FROM unknowns; positions that do not match the unknowns are refused."""
    import model.static as static
    from model.ordering import nested_dissection
    mesh = cube(9, L, "bcc")
    pm = build("msm", mesh, mat)
    J = pm.jacobian(mesh.points).tocsc()
    free = np.ones(J.shape[0], bool)
    free[:3 * 81] = False                  # some fixed nodes: a non-singular matrix
    A = J[free][:, free].tocsc()
    xyz = np.repeat(mesh.points, 3, axis=0)[free]
    order = nested_dissection(A, xyz)
    assert np.array_equal(np.sort(order), np.arange(A.shape[0]))
    b = np.sin(np.arange(A.shape[0], dtype=float))
    plain, dissected = static.factorise(A), static.factorise(A, order)
    x = plain.solve(b)
    assert np.abs(dissected.solve(b) - x).max() < 1e-10 * np.abs(x).max()
    assert A.shape[0] >= static.DISSECT_FROM
    chooser = static.Factoriser(xyz)
    kept = chooser(A)
    assert chooser.order is not None and np.array_equal(chooser.order, order)
    assert kept.L.nnz + kept.U.nnz < plain.L.nnz + plain.U.nnz
    assert np.abs(chooser(A).solve(b) - x).max() < 1e-10 * np.abs(x).max()
    lap, where = _grid_laplacian(16)
    by_degree = static.Factoriser(where)
    by_degree(lap)
    assert by_degree.order is None
    def never(*a):
        raise AssertionError("dissected below DISSECT_FROM")
    monkeypatch.setattr(static, "nested_dissection", never)
    small = static.Factoriser(xyz[:300])
    small(A[:300][:, :300])
    assert small.order is None
    with pytest.raises(ValueError, match="one per row"):
        nested_dissection(A, xyz[:10])
