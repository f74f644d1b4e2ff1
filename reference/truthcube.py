"""The Truth Cube: measured bead positions of a silicone cube in uniaxial compression, the one
reference in pbcm that is a physical measurement, not a computation.

Data: ``reference/data/truthcube/uniaxial_positions.csv`` (Kerdok et al., "Truth cube:
establishing physical standards for soft tissue simulation", Medical Image Analysis 7(3),
283-291, 2003; copied unchanged from the OpenSurgSim repository, Apache License 2.0; the
attribution travels with it in ``reference/data/truthcube/README.md``). 343 Teflon beads on a
10 mm grid inside an 80 mm cube, CT positions at rest and at 5, 12.5 and 18.25 % nominal
compression along z. Millimetres in the file, metres here.

What a comparison needs besides the positions, worked from the data alone: the best rigid
in-plane motion of each state (:func:`rigid_inplane`; the whole cube moves between scans),
the quantisation step of a coordinate (:func:`quantisation_step`) and the measurement noise of
a displacement component (:func:`noise`), the floor under any model-data comparison.
"""
import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from model.errors import ModelError
from model.units import MM

DATA = Path(__file__).parent / "data" / "truthcube" / "uniaxial_positions.csv"
HEADER_LINES = 7
SIDE = 80 * MM                                 # the specimen's edge [m]
STRAINS = (0.0, 0.05, 0.125, 0.1825)           # the four states' nominal compression
BEADS_PER_SIDE = 7
AXIS = 2                                       # compression along z
# a coordinate counts as quantised when at least this fraction of its values lies on one
# grid of steps (the coherence of exp(2 pi i x / q), 1 for every value on the grid)
QUANTISED_COHERENCE = 0.5
# the smooth field the noise is measured against: a polynomial of this degree in the rest
# positions, per state and component (35 terms for 343 beads)
NOISE_DEGREE = 4


@dataclass(frozen=True)
class TruthCube:
    """``index`` (343, 3) bead indices i, j, k (1..7); ``positions`` (4, 343, 3) bead centres
    [m] at the four states (rest first); ``strains`` the states' nominal compression."""

    index: np.ndarray
    positions: np.ndarray
    strains: tuple = STRAINS

    @property
    def rest(self):
        return self.positions[0]

    def displacement(self, state):
        """(343, 3) measured displacement [m] from rest to ``state`` (1, 2 or 3)."""
        if state not in range(1, len(self.strains)):
            raise ModelError(f"state must be 1..{len(self.strains) - 1} (the compressed "
                             f"scans), got {state!r}")
        return self.positions[state] - self.positions[0]

    def layer(self, k):
        """Boolean mask of the beads of layer ``k`` (1 next to the fixed plate, 7 next to the
        moving one)."""
        return self.index[:, 2] == k

    def frame(self):
        """(origin, moving side) of the model's cube [0, SIDE]^3 in the data's coordinates:
        the data point at the model's origin, centred on the bead lattice (the mean of its two
        outer layers per axis: the beads sit 10 mm in from every face), and the sign of z in
        the data toward the moving plate (-1: it is below, at low z)."""
        lo = np.array([self.rest[self.index[:, a] == 1, a].mean() for a in range(3)])
        hi = np.array([self.rest[self.index[:, a] == BEADS_PER_SIDE, a].mean()
                       for a in range(3)])
        return (lo + hi) / 2 - SIDE / 2, np.sign(hi[AXIS] - lo[AXIS])

    def in_model_frame(self, points):
        """Data points [m] in the model's cube [0, SIDE]^3 (moving plate at z = 0 moving to
        +z, fixed plate at z = SIDE): a translation, and z mirrored when the data's fixed
        plate is at low z."""
        origin, toward = self.frame()
        out = np.asarray(points, float) - origin
        if toward > 0:                 # k grows toward +z: the fixed plate (k = 1) is below
            out[..., AXIS] = SIDE - out[..., AXIS]
        return out

    def displacement_in_model_frame(self, u):
        """A displacement [m] of the data turned into the model's frame (z mirrored alike)."""
        _, toward = self.frame()
        out = np.array(u, float)
        if toward > 0:
            out[..., AXIS] *= -1
        return out


def load(path=DATA):
    """The data set (a :class:`TruthCube`), millimetres converted to metres."""
    path = Path(path)
    if not path.is_file():
        raise ModelError(f"Truth Cube data not found at {path}: the package ships it in "
                         "reference/data/truthcube/; reinstall pbcm or pass its path")
    try:
        table = np.loadtxt(path, delimiter=",", skiprows=HEADER_LINES)
    except ValueError as exc:
        raise ModelError(f"{path}: not the Truth Cube table ({exc}); expected {HEADER_LINES} "
                         "header lines, then i, j, k and x, y, z at four states per row") from None
    n = BEADS_PER_SIDE ** 3
    if table.shape != (n, 3 + 3 * len(STRAINS)):
        raise ModelError(f"{path}: expected {n} rows of {3 + 3 * len(STRAINS)} columns, got "
                         f"{table.shape}")
    index = table[:, :3].astype(int)
    if not np.all(np.sort(index[:, 0] * 100 + index[:, 1] * 10 + index[:, 2]) == np.sort(
            [i * 100 + j * 10 + k for i, j, k in itertools.product(range(1, 8), repeat=3)])):
        raise ModelError(f"{path}: the bead indices are not the 7 x 7 x 7 lattice")
    positions = table[:, 3:].reshape(n, len(STRAINS), 3).transpose(1, 0, 2) * MM
    return TruthCube(index=index, positions=np.ascontiguousarray(positions))


def rigid_inplane(rest, deformed):
    """The best rigid in-plane motion (translation in x, y and rotation about z) carrying
    ``rest`` to ``deformed`` (both (n, 3) [m]) in least squares: ``(t, theta, centre)`` with
    deformed_xy ~ R(theta) (rest_xy - centre) + centre + t. A 2-D Procrustes fit, exact for
    any rotation."""
    a = rest[:, :2] - rest[:, :2].mean(axis=0)
    b = deformed[:, :2] - deformed[:, :2].mean(axis=0)
    theta = np.arctan2((a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum(), (a * b).sum())
    return deformed[:, :2].mean(axis=0) - rest[:, :2].mean(axis=0), float(theta), \
        rest[:, :2].mean(axis=0)


def remove_rigid_inplane(rest, deformed):
    """``deformed`` with its best rigid in-plane motion relative to ``rest`` undone."""
    t, theta, c = rigid_inplane(rest, deformed)
    rot = np.array([[np.cos(theta), np.sin(theta)], [-np.sin(theta), np.cos(theta)]])
    out = np.array(deformed, float)
    out[:, :2] = (deformed[:, :2] - c - t) @ rot.T + c
    return out


def quantisation_step(values, steps=np.linspace(0.2e-3, 1.5e-3, 2601)):
    """``(q, coherence)``: the grid step [m] on which most of ``values`` lie, and the fraction
    that does (|mean exp(2 pi i x / q)|, 1 when every value is on the grid). The step is
    returned only when the coherence reaches QUANTISED_COHERENCE, else ``(None, coherence)``.
    """
    v = np.asarray(values, float)
    coherence = np.abs(np.exp(2j * np.pi * v[:, None] / steps[None, :]).mean(axis=0))
    best = int(coherence.argmax())
    c = float(coherence[best])
    return (float(steps[best]) if c >= QUANTISED_COHERENCE else None), c


def _polynomial(points, degree):
    x = (points - points.mean(axis=0)) / (SIDE / 2)
    cols = [np.ones(len(x))]
    for d in range(1, degree + 1):
        for c in itertools.combinations_with_replacement(range(3), d):
            cols.append(np.prod(x[:, list(c)], axis=1))
    return np.array(cols).T


def noise(rest, u, degree=NOISE_DEGREE):
    """(3,) the measurement noise [m] of each displacement component: the RMS residual of a
    least-squares polynomial of ``degree`` in the rest positions fitted to the measured
    displacement ``u`` (n, 3), over n - terms degrees of freedom. The field of a compressed
    cube is smooth; what a smooth field cannot follow bead by bead is the scatter of the
    positions (quantisation, localisation in the images), rest and deformed alike."""
    basis = _polynomial(np.asarray(rest, float), degree)
    coef, *_ = np.linalg.lstsq(basis, u, rcond=None)
    r = u - basis @ coef
    return np.sqrt((r * r).sum(axis=0) / (len(u) - basis.shape[1]))


__all__ = ["TruthCube", "load", "rigid_inplane", "remove_rigid_inplane", "quantisation_step",
           "noise", "STRAINS", "SIDE", "DATA"]
