"""The time integrators' observed orders: RK4 (the particle models') is of order 4 and Newmark's
average acceleration (the FEM transient's) of order 2, each asserted within 0.15 by halving the
step, on a linear oscillator with its closed form and on a small mesh."""
import numpy as np
import pytest

from model import Material, build
from model.bc import Ramp
from model.integrate import rk4_step
from model.mesh import TetMesh, cube
from reference import dynamic

TOL = 0.15


def orders(errors):
    """log2 of the ratio of successive errors (the step halved each time)."""
    e = np.asarray(errors, float)
    return np.log2(e[:-1] / e[1:])


def test_rk4_is_of_order_four_on_a_damped_oscillator():
    """x'' = -w^2 x - 2 z w x', x(0) = 1, x'(0) = 0, against its closed form."""
    w, z, T = 2 * np.pi, 0.05, 1.3
    wd = w * np.sqrt(1 - z * z)

    def exact(t):
        return np.exp(-z * w * t) * (np.cos(wd * t) + z * w / wd * np.sin(wd * t))

    errors = []
    for n in (20, 40, 80, 160):
        dt = T / n
        x, v = np.array([1.0]), np.array([0.0])
        for k in range(n):
            x, v = rk4_step(lambda x, v, t: -w * w * x - 2 * z * w * v, x, v, k * dt, dt,
                            lambda x, v, t: None)
        errors.append(abs(x[0] - exact(T)))
    assert np.all(np.abs(orders(errors) - 4) < TOL), orders(errors)


def _vibrating(model_name, steps):
    """The small clamped cube released from a smooth deformation: positions at the end after
    ``steps`` RK4 steps (the compiled integrator, a Ramp that holds the base)."""
    mesh = cube(3, 0.02, "six")
    pm = build(model_name, mesh, Material(E=10e3, nu=0.3, rho=1000.0))
    base = mesh.nodes_on_plane("y", 0.0)
    X = mesh.points
    x0 = X + 1e-3 * np.c_[np.sin(np.pi * X[:, 1] / 0.04), 0 * X[:, 0],
                          0.5 * np.sin(np.pi * X[:, 1] / 0.04)]
    x0[base] = X[base]
    T = 40 * pm.stable_dt(0.5)
    traj = pm.simulate(Ramp(base, (0.0, 0.0, 0.0), T), T, dt=T / steps, x0=x0, frames=2)
    return traj.x[-1]


@pytest.mark.parametrize("model_name", ["fem-linear", "pbcm-variational"])
def test_rk4_is_of_order_four_on_a_small_mesh(model_name):
    """Against the same run at 1/32 of the coarsest step: linear (fem-linear) and
    nonlinear (a particle reading) forces alike."""
    # from half the stable step down: the stiffest modes then resolved, the error asymptotic
    runs = [_vibrating(model_name, n) for n in (80, 160, 320)]
    fine = _vibrating(model_name, 80 * 32)
    errors = [np.linalg.norm(x - fine) for x in runs]
    assert np.all(np.abs(orders(errors) - 4) < TOL), orders(errors)


def _one_tet():
    pts = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.003, 0.002, 0.01]])
    return TetMesh(pts, np.array([[0, 1, 2, 3]]))


def test_newmark_is_of_order_two_on_a_one_node_oscillator():
    """A tetrahedron with three nodes held: its fourth node is a three-degree-of-freedom
    linear oscillator, released with a velocity; Newmark against the modal solution (exact in
    time)."""
    mesh = _one_tet()
    E, nu, rho, T = 10e3, 0.3, 1000.0, 0.02
    held = Ramp([], (0.0, 0.0, 0.0), T, fixed=[0, 1, 2])
    v0 = np.zeros((4, 3))
    v0[3] = (0.05, -0.02, 0.1)
    exact = dynamic.solve(mesh, Material(E, nu, rho), held, T, v0=v0, method="modal", frames=2)
    errors = []
    for n in (100, 200, 400, 800):
        r = dynamic.solve(mesh, Material(E, nu, rho), held, T, dt=T / n, v0=v0, frames=2)
        errors.append(np.linalg.norm(r.u[-1] - exact.u[-1]))
    assert np.all(np.abs(orders(errors) - 2) < TOL), orders(errors)


def test_newmark_is_of_order_two_on_a_small_mesh():
    """The small cube, its base held, released with a smooth velocity field: Newmark against
    the modal superposition, exact in time."""
    mesh = cube(3, 0.02, "five")
    E, nu, rho, T = 10e3, 0.3, 1000.0, 0.02
    base = mesh.nodes_on_plane("y", 0.0)
    held = Ramp([], (0.0, 0.0, 0.0), T, fixed=base)
    X = mesh.points
    v0 = 0.05 * np.c_[np.sin(np.pi * X[:, 1] / 0.04), 0 * X[:, 0], np.sin(np.pi * X[:, 1] / 0.04)]
    exact = dynamic.solve(mesh, Material(E, nu, rho), held, T, v0=v0, method="modal", frames=2)
    errors = []
    for n in (100, 200, 400, 800):
        r = dynamic.solve(mesh, Material(E, nu, rho), held, T, dt=T / n, v0=v0, frames=2)
        errors.append(np.linalg.norm(r.u[-1] - exact.u[-1]))
    assert np.all(np.abs(orders(errors) - 2) < TOL), orders(errors)


def test_paper_cube_push_converges_at_rk4_order_in_the_step():
    """The convergence report's step ladder (cases.studies.convergence.steps) on the paper
    cube: the end-of-push error falls as dt^4 when the case's step is halved, and is far below
    any mesh error at the case's step; fem-linear's is at round-off at every step."""
    from cases.library.paper_cube import Config
    from cases.studies.convergence import steps
    cfg = Config()
    row = steps.run_model("pbcm-variational", "five", cfg)
    assert row["failed"] is None and abs(row["dt_order"] - 4) < 0.15, row
    assert row["dt_error"] < 1e-9
    lin = steps.run_model("fem-linear", "five", cfg)
    assert lin["dt_order"] is None and max(lin["dt_errors"]) < steps.ROUNDOFF
