"""The Truth Cube as a boundary-value problem: the 80 mm cube between two plates, the moving
plate at z = 0 pushed to +z, the fixed one at z = 80 mm; the load schedule that stops at the
three measured states; the plates bonded or frictionless."""
import numpy as np

from model.errors import ModelError
from model.mesh import cube
from reference.truthcube import SIDE, STRAINS

PLATES = ("bonded", "frictionless")
# the largest plate travel of one load step, over the mesh spacing: at nu = 0.499 Newton
# stalls on the particle readings with 0.2 h per step on the 5 mm mesh (pbcm-variational, 6.8
# N left at step 2) and converges with 0.1 h (1.25 % strain per step on the 10 mm mesh,
# 0.625 % on the 5 mm one)
STEP_OF_SPACING = 0.1
FAMILY = "five"                  # the paper's mirrored five split


def mesh(spacing_mm):
    """The cube with nodes every ``spacing_mm`` (80 mm / spacing cells per side)."""
    cells = 80.0 / spacing_mm
    if abs(cells - round(cells)) > 1e-9 or round(cells) < 2:
        raise ModelError(f"spacing {spacing_mm} mm does not divide the 80 mm cube into "
                         "at least 2 cells; choose e.g. 10, 5 or 2.5")
    return cube(int(round(cells)) + 1, SIDE, FAMILY)


def step_strain(m):
    """The largest nominal strain of one load step on lattice mesh ``m``: STEP_OF_SPACING of
    its spacing over the side."""
    return STEP_OF_SPACING * max(m.lattice[2]) / SIDE


def schedule(travels, step_strain):
    """``(fractions, at)``: the load fractions of the last travel (increasing, ending at 1)
    that reach every travel in ``travels`` [m] (increasing) in steps of at most
    ``step_strain`` x 80 mm, and the step number (1-based) at which each travel is reached."""
    travels = np.asarray(travels, float)
    if travels.ndim != 1 or travels.size == 0 or travels[0] <= 0 \
            or np.any(np.diff(travels) <= 0):
        raise ModelError(f"travels must increase from above 0, got {travels.tolist()}")
    fractions, at, last = [], [], 0.0
    for t in travels:
        n = max(1, int(np.ceil((t - last) / (step_strain * SIDE) - 1e-9)))
        fractions += [(last + (t - last) * k / n) / travels[-1] for k in range(1, n + 1)]
        at.append(len(fractions))
        last = t
    fractions[-1] = 1.0
    return fractions, at


def nominal_travels():
    """The moving plate's travel [m] at the three measured states: nominal strain x 80 mm."""
    return [e * SIDE for e in STRAINS[1:]]


def dirichlet(m, plates, travel):
    """{node: (ux, uy, uz)}: the moving plate's nodes (z = 0) pushed ``travel`` [m] along +z,
    the fixed plate's (z = SIDE) held. ``bonded``: the plates hold the faces laterally too.
    ``frictionless``: only u_z is prescribed on the plates; the fixed plate's centre node is
    held in x and y and its node at (SIDE, SIDE/2) in y, which removes the rigid in-plane
    motion and nothing else (those nodes lie on the symmetry planes)."""
    moving, fixed = m.nodes_on_plane("z", 0.0), m.nodes_on_plane("z", SIDE)
    if plates == "bonded":
        out = {int(i): (0.0, 0.0, 0.0) for i in fixed}
        out.update({int(i): (0.0, 0.0, travel) for i in moving})
        return out
    if plates != "frictionless":
        raise ModelError(f"unknown plate condition {plates!r}; choose from {', '.join(PLATES)}")
    out = {int(i): (None, None, 0.0) for i in fixed}
    out.update({int(i): (None, None, travel) for i in moving})
    centre = _node_at(m, (SIDE / 2, SIDE / 2, SIDE))
    side = _node_at(m, (SIDE, SIDE / 2, SIDE))
    out[centre] = (0.0, 0.0, 0.0)
    out[side] = (None, 0.0, 0.0)
    return out


def _node_at(m, point):
    d = np.linalg.norm(m.points - np.asarray(point), axis=1)
    i = int(d.argmin())
    if d[i] > 1e-9 * SIDE:
        raise ModelError(f"no node at {point} m: the frictionless plates need an odd number of "
                         "nodes per side (the centre lines)")
    return i
