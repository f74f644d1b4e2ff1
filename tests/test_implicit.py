"""Backward Euler, the implicit integrator simulators use: checked against the exact solution
of a linear system, for its order, its stability far beyond the explicit step, its static
limit and its refusals."""
import numpy as np
import pytest
from scipy.linalg import expm

from model import Material, ModelError, build
from model.implicit import backward_euler
from model.mesh import cube

MAT = Material(E=10e3, nu=0.45, rho=1000.0)
L = 0.032


def _block(model="fem-linear", n=3):
    mesh = cube(n, L, "six")
    base = mesh.nodes_on_plane("y", 0.0)
    return mesh, build(model, mesh, MAT), {int(i): (0.0, 0.0, 0.0) for i in base}


def _tilt(mesh, amplitude=1e-4):
    x0 = mesh.points.copy()
    x0[:, 0] += amplitude * mesh.points[:, 1] / L
    return x0


def test_backward_euler_converges_at_first_order_to_the_exact_linear_motion():
    """On a linear model (fem-linear, base held, a released shear tilt) the backward-Euler
    state at 0.02 s approaches the exact solution of M x'' = K (x - X) (a matrix exponential)
    at first order: each halving of dt halves the error (ratio 1.8-2.2 at the finest)."""
    mesh, pm, bc = _block()
    x0 = _tilt(mesh)
    free = np.ones(3 * mesh.n_nodes, bool)
    for i in bc:
        free[3 * i:3 * i + 3] = False
    K = pm.jacobian(mesh.points).toarray()[free][:, free]
    m = np.repeat(pm.mass, 3)[free]
    n = K.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [K / m[:, None], np.zeros((n, n))]])
    T = 0.02
    exact = expm(A * T) @ np.r_[(x0 - mesh.points).ravel()[free], np.zeros(n)]
    errs = []
    for dt in (T / 64, T / 128, T / 256, T / 512):
        tr = backward_euler(pm, lambda t: bc, T, dt, x0=x0, frames=2)
        errs.append(np.abs((tr.x[-1] - mesh.points).ravel()[free] - exact[:n]).max())
    ratios = [a / b for a, b in zip(errs, errs[1:])]
    assert 1.8 < ratios[-1] < 2.2, (ratios, errs)
    assert errs[-1] < 0.05 * np.abs(exact[:n]).max()


def test_backward_euler_is_stable_far_beyond_the_explicit_step_and_only_loses_energy():
    """Undamped, at a frame's step (1/60 s, over ten times the explicit stable step), a
    corotated block released from a tilt neither blows up nor gains energy: its energy
    (stored plus kinetic) falls from step to step."""
    mesh, pm, bc = _block("fem-corotated")
    dt = 1.0 / 60.0
    assert dt > 10 * pm.stable_dt()
    tr = backward_euler(pm, lambda t: bc, 20 * dt, dt, x0=_tilt(mesh), frames=21)
    m = pm.mass[:, None]
    energy = []
    for k in range(len(tr.t)):
        v = (tr.x[k] - tr.x[k - 1]) / dt if k else np.zeros_like(mesh.points)
        energy.append(pm.energy(tr.x[k]) + 0.5 * float((m * v * v).sum()))
    assert np.all(np.diff(energy[1:]) <= 1e-12 * energy[0]) and energy[-1] < energy[0]


def test_backward_euler_comes_to_the_static_equilibrium_under_a_held_push():
    """A corotated block whose top is pushed down 5 % and held comes, with mass damping and
    the haptic step (1 ms), to the static equilibrium of the same constraints to 1e-6 of
    the push."""
    mesh, pm, bc = _block("fem-corotated")
    top = mesh.nodes_on_plane("y", L)
    push = {**bc, **{int(i): (0.0, -0.05 * L, 0.0) for i in top}}
    tr = backward_euler(pm, lambda t: push, 0.5, 1e-3, damping=200.0, frames=2)
    static = pm.solve_static(push)
    assert np.abs(tr.x[-1] - (mesh.points + static.u)).max() < 1e-6 * 0.05 * L


def test_backward_euler_refuses_bad_steps_before_computing():
    """A step that is not a positive time, or an end before the start, is a ModelError that
    names it."""
    mesh, pm, bc = _block()
    for dt in (0.0, -1e-3, float("nan"), None):
        with pytest.raises(ModelError, match="dt must be"):
            backward_euler(pm, lambda t: bc, 0.1, dt)
    with pytest.raises(ModelError, match="t_end"):
        backward_euler(pm, lambda t: bc, -0.1, 1e-3)


def test_the_implicit_presets_step_corotated_fem_by_backward_euler_at_their_own_step():
    """fem-corotated-implicit-frame and -haptic are corotated FEM (the same forces) whose
    dynamics is backward Euler at 1/60 s and 1 ms, by name and not among the default presets;
    their simulate is model.implicit's."""
    from model.presets import IMPLICIT_STEP, NAMED, PRESETS
    mesh, rk4, bc = _block("fem-corotated")
    x = _tilt(mesh)
    for name, dt in (("fem-corotated-implicit-frame", 1.0 / 60.0),
                     ("fem-corotated-implicit-haptic", 1e-3)):
        assert IMPLICIT_STEP[name] == dt and name in NAMED and name not in PRESETS
        pm = build(name, mesh, MAT)
        assert np.array_equal(pm.forces(x), rk4.forces(x)) and pm.stable_dt() == dt
        tr = pm.simulate(lambda t: bc, 4 * dt, x0=x, frames=5)
        direct = backward_euler(pm, lambda t: bc, 4 * dt, dt, x0=x, frames=5)
        assert tr.dt == dt and np.array_equal(tr.x, direct.x)


def test_a_case_runs_the_implicit_baseline_against_its_transient_reference(tmp_path):
    """The paper cube (quick, the mirrored five mesh, clamped) runs the frame-step implicit
    baseline like any model: its dynamics at 1/60 s, judged against the FEM transient
    reference, comes to rest with a finite reaction-history error below 5 %."""
    import json
    from cases.cli import main
    out = tmp_path / "pc"
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--bcs", "clamped",
                 "--models", "fem-corotated-implicit-frame", "--out", str(out)]) == 0
    run = json.loads((out / "metrics.json").read_text())["runs"][0]
    assert run["model"] == "fem-corotated-implicit-frame" and not run["dyn_failed"]
    assert run["dyn_dt_s"] == pytest.approx(1.0 / 60.0)
    assert run["dyn_verdict"] == "at rest" and 0 < run["reaction_time_rel_l2"] < 0.05
