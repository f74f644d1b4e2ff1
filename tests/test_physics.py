"""Physics pinned by values worked out here, sharing no code with the implementation
a wrong factor, sign or weight in the model must turn one of these red."""
import itertools

import numpy as np
import pytest

from model import Material, build
from model.integrate import rk4_step
from model.mesh import TetMesh, cube

MAT = Material(E=10e3, nu=0.3, rho=1000.0)
X = 0.01 * np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
S = 0.02  # simple shear x += S y


def sheared():
    x = X.copy()
    x[:, 0] += S * X[:, 1]
    return x


def hand_strains(x, X):
    """Every (corner a, tip j, in-plane edge m, other base vertex l): gamma, S_F, e, written
    out from docs/model.md with loops and an explicit orientation test."""
    out = []
    for a, j in itertools.permutations(range(4), 2):
        base = [i for i in range(4) if i not in (a, j)]
        for m, l in (base, base[::-1]):
            def tilt(p):
                d, u, w = p[j] - p[a], p[m] - p[a], p[l] - p[a]
                e = u / np.linalg.norm(u)
                n = np.cross(u, w) / np.linalg.norm(np.cross(u, w))
                n = n if n @ d > 0 else -n          # the base normal towards the tip
                return (d @ e) / (d @ n), 0.5 * np.linalg.norm(np.cross(u, w)), e
            g, area, e = tilt(x)
            out.append((a, j, m, l, g - tilt(X)[0], area, e))
    return out


def test_a_strain_of_the_simple_shear_by_hand():
    """Corner 0, tip 2 = (0, 1, 0), base (0, 1, 3) in the xz-plane, edge along x: the tip
    tilts by S over a height of 1, so gamma = S exactly; along z it does not tilt."""
    strains = {(a, j, m): g for a, j, m, _, g, _, _ in hand_strains(sheared(), X)}
    assert strains[(0, 2, 1)] == pytest.approx(S, rel=1e-12)
    assert strains[(0, 2, 3)] == pytest.approx(0.0, abs=1e-15)
    G = MAT.G
    pm = build([("shear", {"reading": "corner", "c": 1.0})], TetMesh(X, np.array([[0, 1, 2, 3]])),
               MAT)
    worst = max(abs(g) for *_, g, _, _ in hand_strains(sheared(), X))
    assert pm.tet_stress(sheared())["max_tau"][0] == pytest.approx(G * worst, rel=1e-12)


@pytest.mark.parametrize("reading", ["corner", "balanced"])
def test_corner_and_balanced_forces_on_one_tetrahedron_by_hand(reading):
    """corner: f_a = (1/4) sum tau S_F e over a's six strains (the restoring sign);
    balanced: f_j = -tau S_F e on the tip and +tau S_F e / 3 on each base vertex."""
    G = MAT.G
    f = np.zeros((4, 3))
    for a, j, m, l, g, area, e in hand_strains(sheared(), X):
        push = G * g * area * e
        if reading == "corner":
            f[a] += 0.25 * push
        else:
            f[j] -= push
            for i in (a, m, l):
                f[i] += push / 3
    pm = build([("shear", {"reading": reading, "c": 1.0})], TetMesh(X, np.array([[0, 1, 2, 3]])),
               MAT)
    assert np.abs(f).max() > 0
    assert np.allclose(pm.forces(sheared()), f, rtol=1e-12, atol=1e-12 * np.abs(f).max())


def test_lumped_mass_is_a_quarter_of_each_tetrahedron():
    """The lumped mass gives each node of a single tetrahedron a quarter of its mass rho V, and the
    nodal masses of a meshed cube sum to the cube's mass rho L^3."""
    one = build("msm", TetMesh(X, np.array([[0, 1, 2, 3]])), MAT)
    volume = 0.01**3 / 6
    assert np.allclose(one.mass, MAT.rho * volume / 4, rtol=1e-12)
    pm = build("msm", cube(3, 0.032, "five"), MAT)
    assert pm.mass.sum() == pytest.approx(MAT.rho * 0.032**3, rel=1e-12)


def test_one_rk4_step_by_hand():
    """x'' = -w^2 x from (x0, v0): classical RK4 advances by the 4th-order Taylor polynomials
    x1 = x0 (1 - z/2 + z^2/24) + v0 h (1 - z/6),
    v1 = v0 (1 - z/2 + z^2/24) - x0 w^2 h (1 - z/6), z = (w h)^2."""
    w, h, x0, v0 = 3.0, 0.1, np.array([[0.7, 0, 0]]), np.array([[-0.2, 0, 0]])
    z = (w * h) ** 2
    x1, v1 = rk4_step(lambda x, v, t: -w**2 * x, x0, v0, 0.0, h, lambda x, v, t: None)
    assert x1[0, 0] == pytest.approx(x0[0, 0] * (1 - z / 2 + z**2 / 24)
                                     + v0[0, 0] * h * (1 - z / 6), rel=1e-14)
    assert v1[0, 0] == pytest.approx(v0[0, 0] * (1 - z / 2 + z**2 / 24)
                                     - x0[0, 0] * w**2 * h * (1 - z / 6), rel=1e-14)
    # a velocity-dependent acceleration checks the v stages too: v' = -c v
    c = 2.0
    _, v1 = rk4_step(lambda x, v, t: -c * v, x0, v0, 0.0, h, lambda x, v, t: None)
    y = c * h
    assert v1[0, 0] == pytest.approx(v0[0, 0] * (1 - y + y**2 / 2 - y**3 / 6 + y**4 / 24),
                                     rel=1e-14)


def test_paper_cube_dynamic_reaction_is_the_force_that_moves_the_top():
    """At the end of the damped hold the case's dynamic reaction on the driven nodes equals
    the static reaction: positive (the body pushes back up, the supports push down) and of
    the same size."""
    from cases.library import paper_cube as P
    cfg = P.CASE.settings(quick=True, models=("msm",), meshes=("five",), bcs=("clamped",))
    mesh = P.make_mesh("five")
    pm = build("msm", mesh, cfg.material)
    dyn = P.dynamic_run(pm, mesh, "clamped", cfg)
    top = P.boundary_sets(mesh, "clamped")[0]
    static = -pm.solve_static(P.static_bc(mesh, "clamped")).reaction[top, 1].sum()
    assert dyn["at_rest"] and static > 0
    assert dyn["reaction_y"][-1] == pytest.approx(static, rel=1e-3)
