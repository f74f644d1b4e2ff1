"""Manufactured solutions (reference.manufactured): the loads against finite differences and
closed forms, the L2 error against a closed form, and every ladder of the verification spec
(cases/studies/convergence/verification.toml) on every family: the observed L2 order of the
finest pair within the tolerance of the element's formal order (P1 2, P2 3), the finest error
under its bound."""
import numpy as np
import pytest

from model.material import Material
from model.errors import ModelError
from model.mesh import cube
from reference import linear
from reference.manufactured import l2_error, manufactured, prescribed_faces, solve, waves
from cases.studies.convergence.manufactured import orders, run_entry
from cases.studies.convergence.verification import spec

L, E, NU = 0.02, 10e3, 0.3


def _fd_divergence(stress, x, h):
    div = np.zeros(x.shape)
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        div += (stress(x + e)[:, :, k] - stress(x - e)[:, :, k]) / (2 * h)
    return div


@pytest.mark.parametrize("material,amplitude", [("linear", 1e-3), ("neo-Hookean", 0.05)])
def test_body_force_is_minus_the_divergence_of_the_stress(material, amplitude):
    """For the linear and the neo-Hookean law the manufactured body force equals minus the finite-
    difference divergence of the stress to within 1e-7 of its largest value, and the traction on
    a face is the stress applied to the face's normal."""
    p = manufactured(waves(L, amplitude), material, Material(E, NU))
    x = np.random.default_rng(0).uniform(0, L, (20, 3))
    b = p.body_force(x)
    assert np.abs(b + _fd_divergence(p.stress, x, 1e-5 * L)).max() <= 1e-7 * np.abs(b).max()
    n = np.array([0.0, 0.6, 0.8])
    assert np.allclose(p.traction(x, np.tile(n, (20, 1))), p.stress(x) @ n, rtol=1e-14)


def test_hessian_is_the_gradient_of_the_gradient():
    """The manufactured wave field's Hessian matches the central finite difference of its gradient
    to within 1e-8 of the largest entry."""
    f = waves(L)
    x = np.random.default_rng(1).uniform(0, L, (10, 3))
    h = 1e-5 * L
    fd = np.stack([(f.grad(x + h * e) - f.grad(x - h * e)) / (2 * h) for e in np.eye(3)], -1)
    assert np.abs(f.hessian(x) - fd).max() <= 1e-8 * np.abs(fd).max()


def test_the_two_stresses_in_closed_form():
    """Linear: lam tr(eps) I + 2 mu eps of a worked strain; neo-Hookean: zero at rest, and the
    uniaxial stretch's P_11 = mu (s - 1/s) + lam ln(s) / s."""
    lam, mu = Material(E, NU).lame
    g = np.array([[1e-3, 2e-3, 0.0], [0.0, -1e-3, 0.0], [0.0, 0.0, 0.0]])
    sig = manufactured(waves(L), "linear", Material(E, NU)).law.stress(g)
    assert sig[0, 1] == pytest.approx(mu * 2e-3) and sig[2, 2] == pytest.approx(0.0, abs=1e-12)
    assert sig[0, 0] == pytest.approx(2 * mu * 1e-3)      # tr eps = 0
    nh = manufactured(waves(L), "neo-Hookean", Material(E, NU)).law
    assert np.abs(nh.stress(np.zeros((3, 3)))).max() < 1e-12 * E
    s = 1.2
    P = nh.stress(np.diag([s - 1, 0.0, 0.0]))
    assert P[0, 0] == pytest.approx(mu * (s - 1 / s) + lam * np.log(s) / s, rel=1e-12)
    with pytest.raises(ModelError, match="inverts"):
        nh.stress(np.diag([-1.5, 0.0, 0.0]))


def test_l2_error_of_a_constant_offset_is_its_norm_times_root_volume():
    """The L2 error of a zero P2 solution against a constant field c on a cube of side L is |c|
    times L^1.5 (the root of the volume), and the returned norm of the exact field equals it."""
    m = cube(3, L, "five")
    bc = {i: (0.0, 0.0, 0.0) for i in range(m.n_nodes)}
    r = linear.solve(m, Material(E, NU), bc, element="P2")
    c = np.array([1e-4, -2e-4, 2e-4])
    err, norm = l2_error(r.basis, r.dofs, lambda x: np.broadcast_to(c, x.shape))
    assert err == pytest.approx(np.linalg.norm(c) * L ** 1.5, rel=1e-12)
    assert norm == pytest.approx(err, rel=1e-12)


def test_orders_of_a_power_law_are_its_exponent():
    """Errors that fall as the square of the cell size over the ladder 4, 8, 16 give an observed
    order of 2 for each consecutive pair."""
    assert orders([4, 8, 16], [1.0, 0.25, 0.0625]) == pytest.approx([2.0, 2.0])


def test_bad_problems_are_refused():
    """An unknown material law, prescribed faces on which no mesh node lies, and a mixed form asked
    of the linear reference are each refused with a ModelError naming the cause."""
    with pytest.raises(ModelError, match="unknown law"):
        manufactured(waves(L), "rubber", Material(E, NU))
    p = manufactured(waves(L), "linear", Material(E, NU))
    with pytest.raises(ModelError, match="no node of the mesh lies on the faces"):
        solve(cube(3, L, "five"), p, 2 * L, faces="X")
    with pytest.raises(ModelError, match="no mixed form"):
        solve(cube(3, L, "five"), p, L, mixed=True)


SPEC = spec()
LADDERS = [(e, fam) for e in SPEC["manufactured"] for fam in e.cells]


@pytest.mark.parametrize("entry,family", LADDERS,
                         ids=[f"{e.name}-{f}" for e, f in LADDERS])
def test_observed_order_is_the_formal_order(entry, family):
    """On every ladder and mesh family of the verification spec the observed L2 order of the finest
    pair is at least the formal order minus the tolerance and, unless the spec declares the
    family faster, at most the formal order plus it. The finest relative error is under the
    ladder's bound, the row is marked passed, and the errors fall strictly from level to level."""
    row = run_entry(entry, family, SPEC["size"], SPEC["E"], SPEC["tolerance"])
    order, formal, tol = row["mms_order"], entry.formal_order, SPEC["tolerance"]
    assert order >= formal - tol, row
    if family not in entry.faster:
        assert order <= formal + tol, row
    assert row["mms_rel_l2"] <= entry.finest_bound, row
    assert row["passed"]
    # the errors fall monotonically: no level is lucky
    assert all(a > b for a, b in zip(row["mms_errors"], row["mms_errors"][1:]))


def test_the_neo_hookean_field_is_at_finite_strain():
    """The neo-Hookean ladders' field strains the cube by more than 10 %: linear P2 under the
    same loads misses it by over 10x the neo-Hookean ladder's finest bound."""
    entry = next(e for e in SPEC["manufactured"] if e.material == "neo-Hookean")
    size = SPEC["size"]
    p = entry.problem(size, SPEC["E"])
    x = np.random.default_rng(0).uniform(0, size, (4000, 3))
    assert np.abs(p.field.grad(x)).max() > 0.1
    mesh = cube(entry.cells["five"][1] + 1, size, "five")
    on = prescribed_faces(mesh.points, size, entry.faces)
    bc = {int(i): tuple(p.field.u(mesh.points[i])) for i in np.flatnonzero(on)}
    r = linear.solve(mesh, Material(SPEC["E"], entry.nu), bc, body_force=p.body_force,
                     traction=p.traction, element="P2",
                     dirichlet_fn=lambda q: np.where(
                         prescribed_faces(q, size, entry.faces)[:, None], p.field.u(q), np.nan))
    e, n = l2_error(r.basis, r.dofs, p.field.u)
    assert e / n > 10 * entry.finest_bound


def test_a_neo_hookean_level_started_from_the_one_below_is_the_same_solution():
    """The ladders' nested iteration across lattices that do not nest (2 then 4 cells of
    five: the coarse field probed at the fine dofs): the solution of Newton from rest to the
    tolerance, in fewer iterations."""
    entry = next(e for e in SPEC["manufactured"] if e.material == "neo-Hookean"
                 and not e.mixed)
    size = SPEC["size"]
    p = entry.problem(size, SPEC["E"])
    args = (p, size, entry.element, entry.mixed, entry.faces, entry.load_steps)
    _, coarse = solve(cube(3, size, "five"), *args)
    e_rest, rest = solve(cube(5, size, "five"), *args)
    e_nested, nested = solve(cube(5, size, "five"), *args, start=coarse)
    assert np.abs(nested.dofs - rest.dofs).max() < 1e-9 * np.abs(rest.dofs).max()
    assert e_nested == pytest.approx(e_rest, rel=1e-6)
    assert nested.iterations < rest.iterations
