"""The measurement side of the Truth Cube comparison: the measured bead displacements in the
model's frame with each state's rigid in-plane motion removed (and raw), the measurement
floor, the bead errors of a modelled field and the layer profiles the figures draw."""
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from model.errors import ModelError
from reference import truthcube as T
from model.units import MM

# a model reproduces the measurement when its error beyond the noise,
# sqrt(max(rms^2 - floor^2, 0)), is at most this many floors (its misfit no larger than the
# scatter of the beads themselves)
WITHIN = 1.0


@dataclass
class Measured:
    """The data set as the comparison reads it: ``beads`` (343, 3) rest positions in the
    model's frame [m]; per state (1..3) the measured displacement with the rigid in-plane
    motion removed (``u``) and raw (``u_raw``), in the model's frame [m]."""

    data: T.TruthCube

    @cached_property
    def beads(self):
        return self.data.in_model_frame(self.data.rest)

    def u(self, state):
        rest, deformed = self.data.rest, self.data.positions[state]
        return self.data.displacement_in_model_frame(
            T.remove_rigid_inplane(rest, deformed) - rest)

    def u_raw(self, state):
        return self.data.displacement_in_model_frame(self.data.displacement(state))

    def rigid(self, state):
        """The removed motion: (translation x, y [mm], rotation about z [deg])."""
        t, theta, _ = T.rigid_inplane(self.data.rest, self.data.positions[state])
        return [float(t[0] / MM), float(t[1] / MM), float(np.degrees(theta))]

    def floor(self, state):
        """The measurement floor [mm] of the RMS errors: the noise of each displacement
        component (``reference.truthcube.noise``), combined as the errors are (axial: z;
        lateral: |(x, y)|; total: |(x, y, z)|)."""
        n = T.noise(self.data.rest, self.u(state)) / MM
        return {"axial": float(n[2]), "lateral": float(np.hypot(n[0], n[1])),
                "total": float(np.linalg.norm(n)), "noise_xyz": n.tolist()}

    def layer_noise(self, state):
        """The noise [mm] of a layer mean: (axial: the z noise over sqrt(49 beads), lateral:
        one in-plane component's over sqrt(24 outer beads)), the error bars of the layer
        profiles."""
        n = T.noise(self.data.rest, self.u(state)) / MM
        per_layer = T.BEADS_PER_SIDE ** 2
        ring = 4 * (T.BEADS_PER_SIDE - 1)
        return {"axial": float(n[2] / np.sqrt(per_layer)),
                "lateral": float(np.hypot(n[0], n[1]) / np.sqrt(2 * ring))}

    def scale(self, state):
        """The RMS measured displacement [mm], total, axial and lateral (what the relative
        errors divide by)."""
        u = self.u(state) / MM
        return {"total": _rms(u), "axial": _rms(u[:, 2:]), "lateral": _rms(u[:, :2])}

    def summary(self):
        """The data's own numbers for the report: per state its quantisation steps, noise,
        floor, scale and removed rigid motion, and the rest positions' scatter about the
        best regular grid."""
        idx = np.c_[np.ones(len(self.beads)), self.data.index]
        coef, *_ = np.linalg.lstsq(idx, self.data.rest, rcond=None)
        scatter = (self.data.rest - idx @ coef).std(axis=0) / MM
        states = []
        for s in range(1, len(T.STRAINS)):
            q = [T.quantisation_step(self.data.positions[s][:, c]) for c in range(3)]
            states.append({"state": s, "strain": T.STRAINS[s],
                           "quantisation_mm": [None if v is None else v / MM for v, _ in q],
                           "quantisation_coherence": [c for _, c in q],
                           "floor_mm": self.floor(s), "scale_mm": self.scale(s),
                           "layer_noise_mm": self.layer_noise(s),
                           "rigid_removed": self.rigid(s),
                           "layer_axial_mm": layer_axial(self.data, self.u(s)),
                           "layer_lateral_mm": layer_lateral(self.data, self.u(s))})
        rest_q = [T.quantisation_step(self.data.rest[:, c]) for c in range(3)]
        return {"beads": len(self.beads), "states": states,
                "rest_quantisation_mm": [None if v is None else v / MM for v, _ in rest_q],
                "rest_scatter_mm": scatter.tolist(), "grid_spacing_mm": (
                    np.linalg.norm(coef[1:], axis=1) / MM).tolist()}


def _rms(a):
    return float(np.sqrt((np.asarray(a) ** 2).sum(axis=-1).mean()))


def errors(u_model, u_measured, u_raw, scale):
    """The bead errors of a modelled displacement (343, 3) [m] against the corrected
    measurement: RMS (of the error vector's length), largest, axial (z) and lateral ((x, y))
    RMS in mm, each RMS also over the measured RMS of the same components, and the RMS
    against the raw measurement."""
    if not np.all(np.isfinite(u_model)):
        raise ModelError("the modelled bead displacement is not finite")
    e = (u_model - u_measured) / MM
    rms, axial, lateral = _rms(e), _rms(e[:, 2:]), _rms(e[:, :2])
    return {"bead_rms_mm": rms, "bead_max_mm": float(np.linalg.norm(e, axis=1).max()),
            "bead_axial_rms_mm": axial, "bead_lateral_rms_mm": lateral,
            "bead_rms_rel": rms / scale["total"], "bead_axial_rel": axial / scale["axial"],
            "bead_lateral_rel": lateral / scale["lateral"],
            "bead_raw_rms_mm": _rms((u_model - u_raw) / MM)}


def excess(rms, floor):
    """A model's error beyond the measurement's noise: sqrt(max(rms^2 - floor^2, 0))."""
    return float(np.sqrt(max(rms * rms - floor * floor, 0.0)))


def within(rms, floor):
    """True when the error beyond the noise is at most WITHIN floors."""
    return excess(rms, floor) <= WITHIN * floor


def layer_axial(data, u):
    """Mean axial displacement [mm] of each bead layer k = 1..7 (k = 1 at the fixed plate)."""
    return [float(u[data.layer(k), 2].mean() / MM) for k in range(1, T.BEADS_PER_SIDE + 1)]


def layer_lateral(data, u):
    """Mean outward lateral displacement [mm] of each layer's outer ring of beads (the 24
    beads with i or j at 1 or 7), along the outward normal of its face: the barrel."""
    n = T.BEADS_PER_SIDE
    i, j = data.index[:, 0], data.index[:, 1]
    out = []
    for k in range(1, n + 1):
        total, count = 0.0, 0
        for axis, idx in ((0, i), (1, j)):
            for side, sign in ((1, -1.0), (n, 1.0)):
                sel = data.layer(k) & (idx == side)
                total += sign * u[sel, axis].sum()
                count += int(sel.sum())
        out.append(float(total / count / MM))
    return out
