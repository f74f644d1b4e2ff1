"""Models pbcm does not integrate itself (model.simulators): the Simulator contract, a user's
simulator file, and the Newton engine's solvers on Warp's CPU backend."""
import os
from pathlib import Path

import numpy as np
import pytest

import model.simulators
from model import Material, build
from model.compose import label
from model.errors import ModelError
from model.mesh import cube
from model.simulators import Simulator, run_to_rest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "docs" / "example_simulator.py"
MAT = Material(E=3e3, nu=0.45, rho=1000.0)
SIZE = 0.01


def compression(mesh, strain):
    """A sliding base (z held, one corner pinned, one more held in y and z) and the top pushed
    down by ``strain`` of the height: homogeneous uniaxial stress, the closed form
    reaction E A strain on the top."""
    p = mesh.points
    base = np.flatnonzero(p[:, 2] < 1e-12)
    top = np.flatnonzero(p[:, 2] > SIZE - 1e-12)
    bc = {int(n): (None, None, 0.0) for n in base}
    corner = base[np.argmin(np.abs(p[base]).sum(axis=1))]
    bc[int(corner)] = (0.0, 0.0, 0.0)
    other = base[np.argmin(np.abs(p[base, 0] - SIZE) + np.abs(p[base, 1]))]
    bc[int(other)] = (None, 0.0, 0.0)
    bc.update({int(n): (None, None, -strain * SIZE) for n in top})
    return bc, top


@pytest.fixture(scope="module")
def example():
    saved = os.environ.get("PBCM_MODELS")
    model.simulators.add_user_file(EXAMPLE)
    yield model.simulators.SIMULATORS["symplectic-p1"]
    if saved is None:
        os.environ.pop("PBCM_MODELS", None)
    else:
        os.environ["PBCM_MODELS"] = saved


def test_pbcms_models_are_simulators():
    """Every pbcm model satisfies the Simulator contract through its own code."""
    pm = build("fem-linear", cube(2, SIZE, "five"), MAT)
    assert isinstance(pm, Simulator) and pm.gives_forces
    x = pm.mesh.points + 1e-4 * pm.mesh.points ** 2 / SIZE
    f = np.zeros_like(x)
    np.add.at(f, pm.mesh.tets, pm.tet_forces(x))
    assert np.abs(f - pm.forces(x)).max() < 1e-10 * np.abs(f).max()     # round-off


def test_running_to_rest_reaches_the_static_equilibrium():
    """Run to rest, pbcm's explicit FEM P1 comes to its Newton equilibrium: displacements
    within a thousandth of the largest, the reaction within a hundredth."""
    mesh = cube(3, SIZE, "five")
    pm = build("fem-linear", mesh, MAT)
    bc, top = compression(mesh, 0.01)
    newton = pm.solve_static(bc)
    rest = run_to_rest(pm, bc)
    scale = np.abs(newton.u).max()
    assert np.abs(rest.u - newton.u).max() < 2e-3 * scale
    assert rest.reaction[top, 2].sum() == pytest.approx(newton.reaction[top, 2].sum(), rel=1e-2)


def test_a_user_simulator_file_is_a_model(example):
    """A simulator file registers a model by name: built with its settings, run to rest it
    reproduces the closed-form reaction of uniaxial stress, and a bad setting is refused."""
    mesh = cube(3, SIZE, "five")
    sim = build("symplectic-p1(safety=0.4)", mesh, MAT)
    assert sim.name == label("symplectic-p1(safety=0.4)") == "symplectic-p1(safety=0.4)"
    bc, top = compression(mesh, 0.001)
    st = sim.solve_static(bc)
    assert st.reaction[top, 2].sum() == pytest.approx(-MAT.E * SIZE ** 2 * 0.001, rel=2e-3)
    with pytest.raises(ModelError, match="no parameter 'steps'"):
        build("symplectic-p1(steps=3)", mesh, MAT)


def test_a_simulator_file_that_registers_nothing_is_refused(tmp_path):
    """Loading a model file that registers no simulator names the file and what to do."""
    f = tmp_path / "empty.py"
    f.write_text("x = 1\n")
    with pytest.raises(ModelError, match="registers no model"):
        model.simulators.load_file(f)


def test_the_command_line_runs_a_user_simulator(example, tmp_path):
    """`pbcm run --model-file FILE --models NAME` runs the case with that model beside FEM P1
    and reports its model-form error."""
    import json
    from cases.cli import main
    out = tmp_path / "pc"
    assert main(["run", "paper-cube", "--quick", "--model-file", str(EXAMPLE), "--models",
                 "symplectic-p1", "fem-linear", "--meshes", "five", "--bcs", "sliding",
                 "--out", str(out), "--no-cache"]) == 0
    runs = json.loads((out / "metrics.json").read_text())["runs"]
    ours = [r for r in runs if r["model"] == "symplectic-p1"]
    assert ours and all(r["static_failed"] is None for r in ours)
    assert all(r["reaction_rel_err"] < 1e-2 for r in ours)


# --------------------------------------------------------------------- Newton (on Warp's CPU)
newton = pytest.importorskip("newton")
from model.simulators.newton import small_strain_moduli as moduli  # noqa: E402

SOLVERS = ("newton-semi-implicit", "newton-xpbd", "newton-vbd")


@pytest.mark.parametrize("name", SOLVERS)
def test_a_newton_model_at_rest_stays_at_rest(name):
    """Each Newton solver left alone at rest, base clamped, stays there to its single
    precision."""
    mesh = cube(3, SIZE, "five")
    sim = build(name, mesh, MAT)
    base = np.flatnonzero(mesh.points[:, 2] < 1e-12)
    tr = sim.simulate(lambda t: {int(n): (0.0, 0.0, 0.0) for n in base}, 0.05, frames=3)
    assert np.abs(tr.x[-1] - mesh.points).max() < 1e-7 * SIZE * 100


def small_strain_moduli(solver):
    return moduli(solver, MAT)


def test_newtons_laws_at_small_strain_with_the_documented_lame_parameters():
    """With k_mu = G and k_lambda = lam (Newton's documentation: the Lame parameters), VBD's
    law is linear elasticity at small strain; the semi-implicit kernel's shear modulus is 3/4 G
    and its lambda lam - 5/8 G (Smith et al.'s law needs their rescaled parameters); XPBD's
    constraints have no shear stiffness at first order and a bulk term of lam + 4 G."""
    G, lam = MAT.G, MAT.lam
    assert small_strain_moduli("vbd") == pytest.approx((G, lam), rel=1e-4)
    assert small_strain_moduli("semi-implicit") == pytest.approx((0.75 * G, lam - 0.625 * G),
                                                                 rel=1e-4)
    g_x, lam_x = small_strain_moduli("xpbd")
    assert abs(g_x) < 1e-4 * G and lam_x == pytest.approx(lam + 4.0 * G, rel=1e-4)


def test_the_semi_implicit_law_is_the_engines_kernel():
    """The semi-implicit law as transcribed gives the forces of Newton's own eval_tetrahedra
    kernel at a finite deformation (to its single precision)."""
    import warp as wp
    from newton._src.solvers.semi_implicit.kernels_particle import eval_tetrahedra_forces
    mesh = cube(2, SIZE, "five")
    sim = build("newton-semi-implicit", mesh, MAT)
    rng = np.random.default_rng(1)
    x = mesh.points @ (np.eye(3) + 0.05 * rng.standard_normal((3, 3))).T
    state, control = sim._model.state(), sim._model.control()
    state.particle_q.assign(x.astype(np.float32))
    f = wp.zeros(sim._model.particle_count, dtype=wp.vec3, device="cpu")
    eval_tetrahedra_forces(sim._model, state, control, f)
    ours = sim.forces(x)
    assert np.abs(f.numpy() - ours).max() < 1e-4 * np.abs(ours).max()


@pytest.mark.parametrize("name, relaxation", [("newton-semi-implicit", 1.0),
                                              ("newton-vbd(iterations=1)", 1.0),
                                              ("newton-xpbd(iterations=1)", 0.9)])
def test_the_engines_first_step_moves_a_corner_by_the_transcribed_force(name, relaxation):
    """One free corner of a deformed tetrahedron, the others held: the engine's own step from
    rest, at a step short against the tetrahedron's period, moves the corner by dt^2 / m
    times the force of the law as transcribed (XPBD's by its relaxation, 0.9, as well), within
    2 %: the law each solver integrates is the one its forces, reactions and stresses here
    come from."""
    from model.mesh import TetMesh
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float) * SIZE
    sim = build(name, TetMesh(pts, np.array([[0, 1, 2, 3]])), MAT)
    rng = np.random.default_rng(3)
    x = pts + 0.03 * SIZE * rng.standard_normal(pts.shape)
    x[3] = pts[3] + 0.05 * SIZE * rng.standard_normal(3)
    held = {n: tuple(x[n] - pts[n]) for n in range(3)}
    f = sim.forces(x)[3]
    dt = 3e-5
    tr = sim.simulate(lambda t: held, dt, dt=dt, frames=2, x0=x)
    moved = sim.mass[3] * (tr.x[-1][3] - x[3]) / dt ** 2
    assert np.abs(moved - relaxation * f).max() < 0.02 * np.abs(f).max()


def test_the_semi_implicit_model_reproduces_its_closed_form_under_compression():
    """Newton's semi-implicit model run to rest under 0.1 % uniaxial compression: the reaction
    its own law's small-strain Young's modulus gives, within 1 % (its single precision and the
    rest tolerance)."""
    mesh = cube(3, SIZE, "five")
    sim = build("newton-semi-implicit", mesh, MAT)
    bc, top = compression(mesh, 0.001)
    st = sim.solve_static(bc)
    G, lam = small_strain_moduli("semi-implicit")
    E = G * (3 * lam + 2 * G) / (lam + G)
    assert st.reaction[top, 2].sum() == pytest.approx(-E * SIZE ** 2 * 0.001, rel=1e-2)


def test_a_prescribed_path_is_the_mapping_it_comes_from_and_refuses_changing_components():
    """``path`` gives at every t the displacements ``bc_arrays(bc_of_t(t))`` gives, through a
    ramp's own arrays where it has them (the run to rest's ramp included), and refuses a
    ``bc_of_t`` whose prescribed components change with time."""
    from model.bc import Ramp, bc_arrays, path
    from model.simulators.base import _RampedHeld
    held = {0: (0.0, 0.0, 0.0), 3: (None, -1e-3, None), 5: (2e-4, None, 1e-4)}
    for bc_of_t in (_RampedHeld(held, 0.5), Ramp([3, 4], (None, -1e-3, 0.0), 0.5, fixed=[0]),
                    lambda t: {n: tuple(None if u is None else min(t / 0.5, 1) * u for u in c)
                               for n, c in held.items()}):
        mask, u_of_t = path(bc_of_t, 6)
        for t in (0.0, 0.2, 0.5, 0.9):
            m, u = bc_arrays(bc_of_t(t), 6)
            assert np.array_equal(m, mask) and np.allclose(u_of_t(t), u, rtol=0, atol=1e-18)
    _, u_of_t = path(lambda t: {0: (0.0, 0.0, 0.0)} if t < 1 else {1: (0.0, 0.0, 0.0)}, 6)
    with pytest.raises(ModelError, match="other components"):
        u_of_t(2.0)


def test_a_users_problem_file_runs_a_newton_model_beside_fem_p1(tmp_path):
    """`pbcm run --problem FILE --models newton-semi-implicit fem-linear` runs the user's
    problem with the engine through the cases' runner: the engine's run comes to rest and its
    model-form error against FEM P1 on the user's mesh is a number in the metrics."""
    import json
    from cases.cli import main
    toml = tmp_path / "demo.toml"
    assert main(["problem", "new", "demo", "--out", str(toml)]) == 0
    out = tmp_path / "demo"
    assert main(["run", "--problem", str(toml), "--quick", "--models", "newton-semi-implicit",
                 "fem-linear", "--out", str(out), "--no-cache"]) == 0
    doc = json.loads((out / "metrics.json").read_text())
    ours = [r for r in doc["runs"] if r["model"] == "newton-semi-implicit"]
    assert ours and all(r["static_failed"] is None for r in ours)
    # its law's shear modulus is 3/4 G under the documented mapping: the end force is off
    assert all(0.05 < r["end_force_rel_err"] < 1 for r in ours)
    assert "newton-semi-implicit" in (out / "report.md").read_text()
