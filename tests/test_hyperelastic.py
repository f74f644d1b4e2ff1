"""The converged neo-Hookean reference: the homogeneous closed form, the small-load
limit equal to linear P2, a tangent and a residual consistent with finite differences of the
energy, convergence under refinement with an estimate, the mixed form up to nu = 0.499, and an
independent code (FElupe) on a bonded block compressed 20 %."""
import numpy as np
import pytest
from scipy.optimize import brentq

from model.material import Material
from model.errors import ConvergenceError, ModelError
from model.mesh import box, cube
from reference import hyperelastic, linear
from reference.discretisation import skfem_mesh
from reference.solvers import DIRECT_MAX_DOFS
from reference.hyperelastic import Discretisation

E, L = 10e3, 0.01


def sliding_cube(mesh, stretch):
    """Symmetry planes x = 0, y = 0, z = 0 and the top face moved to ``stretch``: the
    homogeneous uniaxial field, which P1 and P2 represent exactly."""
    bc = {}

    def put(nodes, k, value):
        for i in nodes:
            u = list(bc.get(int(i), (None, None, None)))
            u[k] = value
            bc[int(i)] = tuple(u)
    put(mesh.nodes_on_plane("x", 0.0), 0, 0.0)
    put(mesh.nodes_on_plane("y", 0.0), 1, 0.0)
    put(mesh.nodes_on_plane("z", 0.0), 2, 0.0)
    put(mesh.nodes_on_plane("z", L), 2, (stretch - 1) * L)
    return bc


def uniaxial(stretch, nu):
    """The compressible neo-Hookean law by hand: the lateral stretch that frees the lateral
    faces, mu (l - 1/l) + lam ln(J) / l = 0 with J = stretch l^2, and the axial nominal
    stress mu (s - 1/s) + lam ln(J) / s."""
    lam, mu = Material(E, nu).lame
    lt = brentq(lambda l: mu * (l - 1 / l) + lam * np.log(stretch * l * l) / l, 0.5, 2.0)
    J = stretch * lt * lt
    return lt, mu * (stretch - 1 / stretch) + lam * np.log(J) / stretch


@pytest.mark.parametrize("element, mixed, nu", [("P1", False, 0.45), ("P2", False, 0.45),
                                                ("P2", True, 0.45), ("P2", True, 0.499)])
def test_homogeneous_compression_is_the_law_worked_by_hand(element, mixed, nu):
    """A sliding cube compressed to stretch 0.7 takes the homogeneous neo-Hookean field
    worked by hand to 1e-9 L, a top reaction of nominal stress times area to 1e-8 and a
    uniaxial Cauchy stress (lateral components zero), for P1, P2 and mixed P2/P1 (nu up to
    0.499)."""
    mesh = cube(3, L, "six")
    r = hyperelastic.solve(mesh, Material(E, nu), sliding_cube(mesh, 0.7), element=element,
                           mixed=mixed, load_steps=3)
    lt, P = uniaxial(0.7, nu)
    expect = np.column_stack([(lt - 1) * mesh.points[:, 0], (lt - 1) * mesh.points[:, 1],
                              -0.3 * mesh.points[:, 2]])
    assert np.abs(r.u - expect).max() < 1e-9 * L
    top = mesh.nodes_on_plane("z", L)
    assert r.reaction[top, 2].sum() == pytest.approx(P * L * L, rel=1e-8)
    # the Cauchy stress is uniaxial: sigma_zz = P stretch / J, the lateral ones zero
    assert np.allclose(r.stress[:, 2, 2], P * 0.7 / (0.7 * lt * lt), rtol=1e-7)
    assert np.abs(r.stress[:, 0, 0]).max() < 1e-7 * abs(P)


def test_the_worked_numbers_of_the_sliding_compression():
    """The reference's uniaxial closed form equals the law worked by hand and, at stretch 0.7
    and nu = 0.45, gives a lateral stretch of 1.17085 and a top force of 4.4435 N on the
    32 mm cube."""
    lt, P = uniaxial(0.7, 0.45)
    got = hyperelastic.uniaxial(0.7, Material(E, 0.45))
    assert got == pytest.approx((lt, P), rel=1e-10)
    assert got[0] == pytest.approx(1.17085, abs=1e-5)
    assert abs(got[1]) * 0.032 ** 2 == pytest.approx(4.4435, abs=1e-4)


def bonded_block(mesh, strain, height):
    """Base clamped, top bonded and moved down by ``strain`` of the height."""
    bc = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("z", 0.0)}
    bc.update({int(i): (0.0, 0.0, -strain * height) for i in mesh.nodes_on_plane("z", height)})
    return bc


def test_the_small_load_limit_is_linear_p2():
    """Under a compression of 1e-7 of its height, the neo-Hookean P2 displacement and top
    reaction of a bonded block equal the linear P2 ones to 1e-6 relative."""
    mesh = box(4, 3, 4, 0.012, 0.008, 0.012, "five")
    bc = bonded_block(mesh, 1e-7, 0.012)
    nh = hyperelastic.solve(mesh, Material(E, 0.45), bc, element="P2")
    lin = linear.solve(mesh, Material(E, 0.45), bc, element="P2", solver="direct")
    assert np.linalg.norm(nh.u - lin.u) < 1e-6 * np.linalg.norm(lin.u)
    top = mesh.nodes_on_plane("z", 0.012)
    assert nh.reaction[top, 2].sum() == pytest.approx(lin.reaction[top, 2].sum(), rel=1e-6)


@pytest.mark.parametrize("mixed", [False, True])
def test_residual_and_tangent_are_the_derivatives_of_the_energy(mixed):
    """At a random strained state, in displacement and in mixed form, the residual equals the
    central difference of the energy and the tangent times a direction equals the central
    difference of the residual, both to 1e-7; the tangent is symmetric."""
    m = skfem_mesh(box(3, 3, 3, 0.01, 0.01, 0.01, "six"))
    lam, mu = Material(E, 0.45).lame
    d = Discretisation(m, "P2", mixed, lam, mu)
    rng = np.random.default_rng(1)
    x = np.zeros(d.N)
    x[:d.ub.N] = 1e-4 * rng.standard_normal(d.ub.N)      # strains of several per cent
    if mixed:
        x[d.ub.N:] = 0.1 * E * rng.standard_normal(d.N - d.ub.N)
    res, K, energy = d.evaluate(x)
    v = rng.standard_normal(d.N)
    v[:d.ub.N] *= 1e-3
    if mixed:
        v[d.ub.N:] *= 0.1 * E
    h = 1e-5
    e_plus, e_minus = (d.evaluate(x + s * h * v, tangent=False)[2] for s in (1, -1))
    assert (e_plus - e_minus) / (2 * h) == pytest.approx(res @ v, rel=1e-7)
    r_plus, r_minus = (d.evaluate(x + s * h * v, tangent=False)[0] for s in (1, -1))
    fd = (r_plus - r_minus) / (2 * h)
    assert np.linalg.norm(K @ v - fd) < 1e-7 * np.linalg.norm(fd)
    assert abs(K - K.T).max() < 1e-12 * abs(K).max()


def test_the_mixed_form_solves_the_same_law_and_converges_with_an_estimate():
    """On a bonded block compressed 10 %, the mixed-form reference converges over two
    refinements (increments at least halving, displacement order above 1, energy order above
    0.5) with an error estimate below 5 % that bounds the last increment. The displacement
    form on the finest mesh agrees with it within that estimate."""
    mesh = box(3, 3, 4, 0.01, 0.01, 0.012, "five")
    bc = bonded_block(mesh, 0.1, 0.012)
    conv = hyperelastic.converged(mesh, Material(E, 0.45), bc, levels=2, mixed=True, load_steps=2)
    assert conv.increments[1] < 0.5 * conv.increments[0]        # converging
    assert conv.rate > 1 and conv.energy_rate > 0.5
    assert conv.increments[-1] <= conv.error_estimate < 0.05
    disp = hyperelastic.solve(mesh, Material(E, 0.45), bc, element="P2", refine=2, load_steps=2)
    # the displacement form on the same mesh agrees within the mixed form's estimate
    diff = np.linalg.norm(disp.u - conv.result.u) / np.linalg.norm(conv.result.u)
    assert diff < conv.error_estimate


def test_bad_input_is_refused_before_solving():
    """hyperelastic.solve raises ModelError for the mixed form with P1 and for load_steps=0,
    and converged for levels=0, each naming the argument; a stretch of -0.5 raises
    ConvergenceError saying an element is inverted."""
    mesh = cube(2, L, "six")
    with pytest.raises(ModelError, match="Taylor-Hood"):
        hyperelastic.solve(mesh, Material(E, 0.45), sliding_cube(mesh, 0.9), element="P1",
                           mixed=True)
    with pytest.raises(ModelError, match="load_steps"):
        hyperelastic.solve(mesh, Material(E, 0.45), sliding_cube(mesh, 0.9), load_steps=0)
    with pytest.raises(ModelError, match="levels"):
        hyperelastic.converged(mesh, Material(E, 0.45), sliding_cube(mesh, 0.9), levels=0)
    with pytest.raises(ConvergenceError, match="inverted"):
        hyperelastic.solve(mesh, Material(E, 0.45), sliding_cube(mesh, -0.5), element="P1")


def test_against_felupe_on_a_bonded_block_compressed_20_percent():
    """FElupe (an independent code) solves the same law on the same quadratic tetrahedra."""
    fem = pytest.importorskip("felupe")
    H = 0.01
    mesh = box(3, 3, 3, 0.01, 0.01, H, "five")
    nu = 0.45
    lam, mu = Material(E, nu).lame
    ours = hyperelastic.solve(mesh, Material(E, nu), bonded_block(mesh, 0.2, H), element="P2",
                              load_steps=4)

    m1 = fem.Mesh(np.array(mesh.points), np.array(mesh.tets), "tetra")
    m2 = fem.mesh.add_midpoints_edges(m1.points, m1.cells, m1.cell_type)
    m2 = fem.Mesh(*m2)
    region = fem.RegionQuadraticTetra(m2)
    field = fem.FieldContainer([fem.Field(region, dim=3)])
    base = fem.Boundary(field[0], fz=lambda z: np.isclose(z, 0.0))
    top_fixed = fem.Boundary(field[0], fz=lambda z: np.isclose(z, H), skip=(0, 0, 1))
    top_move = fem.Boundary(field[0], fz=lambda z: np.isclose(z, H), skip=(1, 1, 0))
    boundaries = {"base": base, "top": top_fixed, "move": top_move}
    solid = fem.SolidBody(fem.NeoHookeCompressible(mu=mu, lmbda=lam), field)
    step = fem.Step(items=[solid], ramp={top_move: fem.math.linsteps([0, -0.2 * H], num=4)},
                    boundaries=boundaries)
    fem.Job(steps=[step]).evaluate(tol=1e-12, verbose=0)
    theirs = field[0].values[:mesh.n_nodes]
    # the same law, element and quadrature: agreement to the Newton tolerance
    assert np.linalg.norm(ours.u - theirs) < 1e-7 * np.linalg.norm(theirs)
    # the total force on the top face: FElupe's on every node of the face (vertices and
    # midpoints), ours carried to the vertices by the P1 hats (which keeps the sum)
    force = solid.results.force.toarray().reshape(-1, 3)
    top = mesh.nodes_on_plane("z", H)
    assert ours.reaction[top, 2].sum() == pytest.approx(
        force[np.isclose(m2.points[:, 2], H), 2].sum(), rel=1e-7)


def top_traction(value):
    """A dead load ``value`` [Pa] along z on the face z = L (per reference area)."""
    def traction(points, normals):
        t = np.zeros_like(points)
        t[..., 2] = np.where(np.abs(points[..., 2] - L) < 1e-9, value, 0.0)
        return t
    return traction


def test_a_dead_traction_gives_the_law_worked_by_hand():
    """Under a dead nominal traction of -0.2 E on its top, the sliding cube's top moves by
    (stretch - 1) L to 1e-8, with the stretch at which the hand formula's nominal stress
    equals that traction."""
    # the sliding cube under a nominal stress P on its top: the stretch where the law's
    # nominal stress is P (the inverse of the hand formula)
    mesh = cube(3, L, "six")
    bc = sliding_cube(mesh, 1.0)
    for i in mesh.nodes_on_plane("z", L):       # the top is loaded, not moved
        bc[int(i)] = bc[int(i)][:2] + (None,)
    bc = {i: u for i, u in bc.items() if u != (None, None, None)}
    P = -0.2 * E
    stretch = brentq(lambda s: uniaxial(s, 0.45)[1] - P, 0.3, 1.0)
    r = hyperelastic.solve(mesh, Material(E, 0.45), bc, element="P2", traction=top_traction(P),
                           load_steps=2)
    top = mesh.nodes_on_plane("z", L)
    assert r.u[top, 2] == pytest.approx((stretch - 1) * L, rel=1e-8)


def test_the_small_load_limit_with_a_traction_is_linear_p2():
    """Under a top traction of 1e-7 E, the neo-Hookean P2 displacement of a block clamped at
    its base equals the linear P2 one to 1e-6 relative."""
    mesh = box(3, 3, 3, 0.01, 0.01, L, "five")
    bc = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("z", 0.0)}
    t = top_traction(1e-7 * E)
    nh = hyperelastic.solve(mesh, Material(E, 0.45), bc, element="P2", traction=t)
    lin = linear.solve(mesh, Material(E, 0.45), bc, element="P2", traction=t, solver="direct")
    assert np.linalg.norm(nh.u - lin.u) < 1e-6 * np.linalg.norm(lin.u)


@pytest.mark.parametrize("nu, mixed", [(0.45, False), (0.49, True)])
def test_auto_takes_the_mixed_form_above_the_locking_threshold(nu, mixed):
    """converged with mixed="auto" solves the displacement form at nu = 0.45 and the mixed
    form at nu = 0.49, above the locking threshold MIXED_ABOVE_NU."""
    mesh = cube(2, L, "six")
    conv = hyperelastic.converged(mesh, Material(E, nu), sliding_cube(mesh, 0.99), mixed="auto")
    assert conv.result.info["mixed"] is mixed


@pytest.mark.parametrize("element", ["P1", "P2"])
@pytest.mark.parametrize("family", ["six", "unstructured"])
def test_prolongation_to_the_refined_mesh_is_exact_for_the_coarse_space(element, family):
    """A linear (P1) or quadratic (P2) vector field given on the coarse mesh is reproduced at
    every dof of the mesh refined once, to round-off; the P1 pressure by the hats too."""
    from reference.discretisation import element_basis
    from reference.hyperelastic import _hats, prolong
    from reference.linear import dof_component
    m = skfem_mesh(cube(3, L, family))
    mf = m.refined()

    def field(b):
        x, y, z = b.doflocs / L
        v = np.array([1 + 2 * x - y, 3 * z + x, y - z])
        if element == "P2":
            v = v + np.array([x * x + 2 * y * z, y * y - 3 * x * z, z * x + y * y])
        return v[dof_component(b), np.arange(b.N)]

    coarse, fine = element_basis(m, element), element_basis(mf, element)
    assert np.abs(prolong(coarse, field(coarse), fine) - field(fine)).max() < 1e-13
    x, y, z = m.p / L
    assert np.allclose(_hats(m) @ (x - 2 * y + z), (mf.p[0] - 2 * mf.p[1] + mf.p[2]) / L,
                       atol=1e-13)
    assert prolong(coarse, field(coarse), element_basis(mf.refined(), element)) is None


@pytest.mark.parametrize("mixed", [False, True])
def test_a_level_started_from_the_coarser_one_reaches_the_same_solution(mixed, monkeypatch):
    """Nested iteration: the refined level started from the coarse solution takes the load
    at once and converges in fewer iterations to the solution of the load steps from rest
    (the same to the Newton tolerance); where the start fails, the load steps run."""
    mesh = cube(3, L, "five")
    bc = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("z", 0.0)}   # a barrel
    bc.update({int(i): (0.0, 0.0, -0.15 * L) for i in mesh.nodes_on_plane("z", L)})
    kw = dict(element="P2", mixed=mixed, load_steps=3)
    coarse = hyperelastic.solve(mesh, Material(E, 0.45), bc, **kw)
    plain = hyperelastic.solve(mesh, Material(E, 0.45), bc, refine=1, **kw)
    nested = hyperelastic.solve(mesh, Material(E, 0.45), bc, refine=1, start=coarse, **kw)
    assert np.abs(nested.dofs - plain.dofs).max() < 1e-9 * np.abs(plain.dofs).max()
    assert nested.iterations < plain.iterations
    monkeypatch.setattr(hyperelastic, "NESTED_MAX_ITER", 0)     # the start gives up at once
    fallen = hyperelastic.solve(mesh, Material(E, 0.45), bc, refine=1, start=coarse, **kw)
    assert np.array_equal(fallen.dofs, plain.dofs) and fallen.iterations == plain.iterations


def test_the_forcing_term_follows_the_residual_between_its_bounds():
    """Eisenstat-Walker's choice 2 (gamma 0.9, alpha 2), worked by hand."""
    from reference.hyperelastic import ETA_MAX, forcing
    assert forcing(1e-3, 1e-1, 1e-12) == pytest.approx(0.9 * 1e-4)     # 0.9 (1e-2)^2
    assert forcing(0.5, 1.0, 1e-12) == ETA_MAX                       # 0.225: capped
    assert forcing(1e-9, 1e-5, 1e-10) == pytest.approx(0.1 * 1e-10 / 1e-9)   # near the end
    assert forcing(1e-20, 1.0, 1e-30) == 1e-10                       # linear_solve's own
    assert forcing(1e-3, 0.0, 1e-12) == forcing(0.0, 1e-3, 1e-12) == ETA_MAX


def test_inexact_newton_reaches_the_solution_of_exact_tangent_solves(monkeypatch):
    """A barrel on 5 943 unknowns (AMG-CG): with the forcing term, the same solution to the
    Newton tolerance for fewer CG iterations than with every tangent solved to 1e-10."""
    mesh = cube(7, L, "five")
    bc = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("z", 0.0)}
    bc.update({int(i): (0.0, 0.0, -0.15 * L) for i in mesh.nodes_on_plane("z", L)})
    inexact = hyperelastic.solve(mesh, Material(E, 0.4), bc, element="P2", load_steps=2)
    monkeypatch.setattr(hyperelastic, "ETA_MAX", 1e-10)
    monkeypatch.setattr(hyperelastic, "forcing", lambda *a: 1e-10)
    exact = hyperelastic.solve(mesh, Material(E, 0.4), bc, element="P2", load_steps=2)
    assert inexact.info["dofs"] == exact.info["dofs"] > DIRECT_MAX_DOFS     # AMG-CG
    assert np.abs(inexact.dofs - exact.dofs).max() < 1e-8 * np.abs(exact.dofs).max()
    assert inexact.info["cg_iterations"] < 0.6 * exact.info["cg_iterations"]


def test_a_finer_lattice_is_not_taken_for_a_refinement():
    """The six (Kuhn) lattice of 2 cells and of 4 have the counts of one refinement (125 =
    27 + 98 vertices, 384 = 8 x 48 tetrahedra) but not its vertices: only the refined mesh
    is one."""
    from reference.hyperelastic import _one_refinement
    coarse, finer = skfem_mesh(cube(3, L, "six")), skfem_mesh(cube(5, L, "six"))
    assert finer.nvertices == coarse.nvertices + coarse.edges.shape[1]
    assert finer.nelements == 8 * coarse.nelements
    assert not _one_refinement(coarse, finer)
    assert _one_refinement(coarse, coarse.refined())


def test_the_mixed_form_reuses_a_factorisation_and_reaches_the_same_solution(monkeypatch):
    """A barrel at nu = 0.499 (mixed P2/P1, 30 % compression in 3 steps): GMRES on the last
    factorisation solves most tangents, to the solution (and the Newton iterations) of a
    factorisation at every iteration."""
    from reference import solvers
    mesh = cube(4, L, "six")
    bc = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("z", 0.0)}
    bc.update({int(i): (0.0, 0.0, -0.3 * L) for i in mesh.nodes_on_plane("z", L)})
    reused = hyperelastic.solve(mesh, Material(E, 0.499), bc, element="P2", mixed=True,
                                load_steps=3)

    class EveryTime(solvers.SaddleSolver):
        def __call__(self, A, b, doflocs=None, comp=None, rtol=1e-10):
            self.lu = None
            return super().__call__(A, b, rtol=rtol)
    monkeypatch.setattr(hyperelastic, "SaddleSolver", EveryTime)
    every = hyperelastic.solve(mesh, Material(E, 0.499), bc, element="P2", mixed=True,
                               load_steps=3)
    assert every.info["factorisations"] == every.iterations
    assert reused.info["factorisations"] < 0.5 * reused.iterations
    assert reused.info["gmres_iterations"] > 0
    assert reused.iterations <= every.iterations + 1
    assert np.abs(reused.dofs - every.dofs).max() < 1e-8 * np.abs(every.dofs).max()
