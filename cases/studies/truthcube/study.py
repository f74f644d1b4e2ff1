"""The Truth Cube study's runs: every model on the cube at each spacing and plate variant,
compressed through the three measured states in one static solve, its displacement at the
measured rest bead positions (P1 on its mesh) against the measured one; the references (the
neo-Hookean mixed P2/P1 continuum with its estimate, linear P2) at the beads by their own
basis; the travel that best fits the measured axial displacements."""
from dataclasses import dataclass, replace

import numpy as np

from model import build
from model.errors import ModelError
from model.mesh import cube
from model.presets import PRESETS
from reference import hyperelastic, linear
from reference.linear import converged_from
from reference import truthcube as T
from ...running import stop
from ...framework import MaterialSettings, FINDINGS
from ...running.progress import Progress
from ...running.runner import jsonable
from ...running.store import OFF, key
from ...running.workers import dearest_first
from .specimen import (FAMILY, STEP_OF_SPACING, dirichlet as plate_dirichlet,
                      mesh as spacing_mesh, nominal_travels, schedule, step_strain)
from .beads import Measured, errors, layer_axial, layer_lateral
from model.units import MM

NU = 0.499                       # RTV 6166: nearly incompressible; the range's middle
NU_RANGE = (0.49, 0.4999)        # the silicone's range, shown as a sensitivity
E = 15e3                         # under displacement control the bead field does not depend
#                                  on E (tested); this only sets the force scale
SPACINGS_MM = (10.0, 5.0)
STATIC_RTOL = 1e-10
# the continuum on the six split of 20 mm refined REF_LEVELS times, P2/P1, the estimate from
# the change between the levels: its beads move 0.025-0.12 mm RMS over the refinement, under
# the measurement's floor (0.30-0.35 mm); one more refinement multiplies the unknowns by 8
REF_MESH, REF_LEVELS = ("six", 5), 1
NH = "neo-Hookean P2/P1"         # the references' names in the tables
LINEAR = "linear P2"
# the continuum's load steps: Newton on the neo-Hookean form with its tangent predictor
# converges from one measured state to the next (3 steps, 11 iterations on the reference
# mesh), the particle models' do not (problem.STEP_OF_SPACING)
REF_STEP_STRAIN = 0.1
FIT_STEP = 0.1                   # the secant of the travel fit: the travel times 1 + this


def variants(nu=NU):
    """{variant: (plates, travel, nu)}: the default (bonded, nominal travel, ``nu``), each
    assumption changed alone: frictionless plates, the travel fitted to the measured axial
    displacements, and nu at the ends of the silicone's range."""
    out = {"bonded": ("bonded", "nominal", nu), "frictionless": ("frictionless", "nominal", nu),
           "fitted-travel": ("bonded", "fitted", nu)}
    out.update({f"nu={v:g}": ("bonded", "nominal", v) for v in NU_RANGE if v != nu})
    return out


@dataclass
class TruthCubeSettings(MaterialSettings):
    """The material, the meshes, the variants and the models."""

    E: float = E
    nu: float = NU
    quick: bool = False
    models: tuple = tuple(PRESETS)
    spacings_mm: tuple = SPACINGS_MM
    ref_levels: int = REF_LEVELS

    def __post_init__(self):
        if not 0.45 <= self.nu < 0.5:
            raise ModelError(f"the truth-cube study: nu = {self.nu} is not a nearly "
                             "incompressible silicone's; give 0.45 <= nu < 0.5 (the Truth "
                             "Cube's silicone: 0.49 to 0.4999)")
        if self.quick:
            self.spacings_mm = self.spacings_mm[:1]
        super().__post_init__()

    @property
    def units(self):
        """Work units a pool could share: each model on each cell (and before them each
        variant's references)."""
        return len(self.cells()) * len(self.models)

    @property
    def variants(self):
        """{variant: (plates, travel, nu)}; quick: the default only."""
        v = variants(self.nu)
        return {"bonded": v["bonded"]} if self.quick else v

    def cells(self):
        """[(spacing, variant)]: every variant on the coarsest mesh, the default on the
        finer ones."""
        first = self.spacings_mm[0]
        return [(first, v) for v in self.variants] + [(h, "bonded")
                                                      for h in self.spacings_mm[1:]]

    def problem(self):
        return {**self.material_record(static=True), "side_mm": T.SIDE / MM,
                "strains": list(T.STRAINS[1:]), "family": FAMILY,
                "step_of_spacing": STEP_OF_SPACING, "static_rtol": STATIC_RTOL,
                "reference": {"element": "P2/P1 mixed", "mesh": f"{REF_MESH[0]} "
                              f"{REF_MESH[1]}^3", "refinements": self.ref_levels}}

    def describe(self):
        return {**self.problem(), "quick": self.quick, "spacings_mm": list(self.spacings_mm),
                "variants": {k: list(v) for k, v in self.variants.items()},
                "models": list(self.models)}


def mesh_name(spacing_mm):
    return f"{spacing_mm:g}mm"


def reference_mesh():
    return cube(REF_MESH[1], T.SIDE, REF_MESH[0])


def _nh_solves(plates, travels, nu, s, levels):
    m = reference_mesh()
    fractions, at = schedule(travels, REF_STEP_STRAIN)
    material = replace(s.material, nu=nu)        # the study's, at the spec's nu
    return [hyperelastic.solve(m, material, plate_dirichlet(m, plates, travels[-1]),
                               element="P2",
                               mixed=True, refine=k, load_steps=fractions, keep_steps=at)
            for k in levels], at


def continuum(plates, travels, nu, s, beads):
    """The neo-Hookean mixed P2/P1 solution through ``travels`` on the reference mesh refined
    0..``s.ref_levels`` times: (the bead displacements (3, 343, 3) [m] of the finest at the
    three states, its error estimate (``reference.linear.estimate``), and per state the RMS
    change of the bead displacement over the last refinement [m], the estimate where it is
    compared)."""
    sols, at = _nh_solves(plates, travels, nu, s, range(s.ref_levels + 1))
    conv = converged_from(sols)
    fine, coarse = ([np.array([x.at(beads, step) for step in at]) for x in sols[-2:]][::-1])
    change = np.sqrt(((fine - coarse) ** 2).sum(axis=-1).mean(axis=-1))
    return fine, conv.error_estimate, change


def continuum_finest(plates, travels, nu, s, beads):
    """The finest level alone: the bead displacements (3, 343, 3) [m]."""
    (sol,), at = _nh_solves(plates, travels, nu, s, [s.ref_levels])
    return np.array([sol.at(beads, step) for step in at])


def linear_reference(plates, travels, nu, s, beads):
    """Linear P2 through the same travels (it scales with the travel), as
    :func:`continuum` gives the neo-Hookean one."""
    m = reference_mesh()
    bc = plate_dirichlet(m, plates, travels[-1])
    sols = [linear.solve(m, replace(s.material, nu=nu), bc, element="P2", refine=k)
            for k in range(s.ref_levels + 1)]
    conv = converged_from(sols)
    u = sols[-1].at(beads)
    change = np.sqrt(((u - sols[-2].at(beads)) ** 2).sum(axis=-1).mean())
    return (np.array([u * t / travels[-1] for t in travels]), conv.error_estimate,
            [change * t / travels[-1] for t in travels])


def fit_travels(measured, s, nu):
    """The travel [m] per state whose continuum (bonded, the finest reference level alone)
    fits the measured axial bead displacements best in least squares: one secant step from
    the nominal travel (the response is nearly linear in it), with the nominal and fitted
    axial RMS error [mm]."""
    nominal = nominal_travels()
    beads = measured.beads
    u0 = continuum_finest("bonded", nominal, nu, s, beads)
    u1 = continuum_finest("bonded", [t * (1 + FIT_STEP) for t in nominal], nu, s, beads)
    fitted = []
    for k, t in enumerate(nominal):
        g = (u1[k][:, 2] - u0[k][:, 2]) / (FIT_STEP * t)          # d u_z / d travel
        r = measured.u(k + 1)[:, 2] - u0[k][:, 2]
        fitted.append(float(t + (g @ r) / (g @ g)))
    return fitted


def bead_displacements(model, mesh, spec, travels, beads, s):
    """``model`` on ``mesh`` under ``spec`` = (plates, travel, nu) through ``travels``: its
    displacement (343, 3) [m] at the rest positions ``beads`` (P1 on its mesh) per measured
    state, in a list (shorter when the solve failed on the way), and the failure or None."""
    plates, _, nu = spec
    fractions, at = schedule(travels, step_strain(mesh))
    located = mesh.locate(beads)
    kept = {}
    try:
        pm = build(model, mesh, replace(s.material, nu=nu))
        pm.solve_static(plate_dirichlet(mesh, plates, travels[-1]), load_steps=fractions,
                        rtol=STATIC_RTOL,
                        on_step=lambda step, x: kept.__setitem__(step, x - mesh.points))
    except FINDINGS as exc:
        failed = f"{type(exc).__name__}: {exc}"
    else:
        failed = None
    out = [mesh.interpolate(kept[step], located) for step in at if step in kept]
    return out, failed


def model_rows(model, mesh, name, variant, spec, travels, measured, s, continuum=None):
    """The rows (one per measured state) of ``model`` on ``mesh`` under ``variant``, with its
    distance to the ``continuum``'s bead displacements (3, 343, 3) [m] under the same
    assumptions where given."""
    plates, travel, nu = spec
    base = {"mesh": name, "variant": variant, "plates": plates, "travel": travel, "nu": nu,
            "model": model, "nodes": mesh.n_nodes, "tets": mesh.n_tets}
    fields, failed = bead_displacements(model, mesh, spec, travels, measured.beads, s)
    rows = []
    for state in range(1, len(T.STRAINS)):
        row = {**base, "state": state, "strain": T.STRAINS[state],
               "travel_mm": travels[state - 1] / MM, "failed": None}
        if state > len(fields):
            rows.append({**row, "failed": failed or "not reached"})
            continue
        u = fields[state - 1]
        rows.append({**row, **bead_row(u, state, measured), "bead_vs_continuum_mm": None
                     if continuum is None else rms_mm(u - continuum[state - 1])})
    return rows


def rms_mm(e):
    """RMS over the beads of the length of ``e`` (343, 3) [m], in mm."""
    return float(np.sqrt((np.asarray(e) ** 2).sum(axis=-1).mean()) / MM)


def bead_row(u, state, measured):
    """The errors and layer profiles of a modelled bead displacement at ``state``."""
    return {**errors(u, measured.u(state), measured.u_raw(state), measured.scale(state)),
            "layer_axial_mm": layer_axial(measured.data, u),
            "layer_lateral_mm": layer_lateral(measured.data, u)}


def reference_rows(variant, spec, travels, measured, s, store):
    """The continuum's rows (neo-Hookean, and linear P2 under the default assumptions), and
    the neo-Hookean bead displacements (3, 343, 3) [m] (None where it failed):
    ``{"rows": [...], "continuum": ...}``."""
    plates, travel, nu = spec
    what = {"kind": "truthcube-reference", **s.problem(), "variant": variant,
            "spec": list(spec), "travels": list(travels)}
    found = store.get(key(**what))
    if found is not None:
        return found
    out, field = [], None
    todo = [(NH, continuum)] + ([(LINEAR, linear_reference)] if variant == "bonded" else [])
    for name, solve in todo:
        stop.checkpoint()
        base = {"mesh": "reference", "variant": variant, "plates": plates, "travel": travel,
                "nu": nu, "model": name}
        try:
            u, estimate, change = solve(plates, travels, nu, s, measured.beads)
        except FINDINGS as exc:
            out += [{**base, "state": k, "strain": T.STRAINS[k], "failed": str(exc)}
                    for k in range(1, len(T.STRAINS))]
            continue
        if name == NH:
            field = u
        # linear P2 against the continuum: where linear elasticity stops holding at the beads
        out += [{**base, "state": k, "strain": T.STRAINS[k], "travel_mm": travels[k - 1] / MM,
                 "failed": None, "error_estimate": estimate,
                 "bead_change_mm": change[k - 1] / MM, **bead_row(u[k - 1], k, measured),
                 "bead_vs_continuum_mm": None if name == NH or field is None
                 else rms_mm(u[k - 1] - field[k - 1])} for k in range(1, len(T.STRAINS))]
    return store.put(key(**what), {"rows": out, "continuum": None if field is None
                                    else field.tolist()})


def _reference_unit(job):
    """The references of one variant (after fitting its travels where it asks for them):
    (travels [m], {"rows", "continuum"})."""
    variant, s, store = job
    measured = Measured(T.load())
    plates, travel, nu = spec = s.variants[variant]
    if travel == "fitted":
        k = key(kind="truthcube-fit", **s.problem(), nu_fit=nu)
        travels = store.get(k) or store.put(k, fit_travels(measured, s, nu))
    else:
        travels = nominal_travels()
    return travels, reference_rows(variant, spec, travels, measured, s, store)


def _cell_unit(job):
    """One model's rows on one (spacing, variant) cell."""
    spacing, variant, travels, model, continuum, s, store = job
    spec = s.variants[variant]
    name = mesh_name(spacing)
    what = {"kind": "truthcube-cells", **s.problem(), "mesh": name, "variant": variant,
            "spec": list(spec), "travels": list(travels), "model": model}
    found = store.get(key(**what))
    if found is not None:
        return found
    return store.put(key(**what), model_rows(model, spacing_mesh(spacing), name, variant, spec,
                                             travels, Measured(T.load()), s, continuum))


def run(s, log=True, store=OFF, workers=None):
    """Every (spacing, variant) cell's model rows, the references' rows, the fitted travels
    and the data's own numbers: first each variant's references (a unit each, on
    ``workers`` where given), then each (cell, model) (a unit each)."""
    measured = Measured(T.load())
    cells = s.cells()
    variants = list(dict.fromkeys(v for _, v in cells))
    with Progress("truth-cube", len(variants) + len(cells) * len(s.models),
                  log=log) as progress:
        found = dearest_first(_reference_unit, [(v, s, store) for v in variants], workers,
                              lambda i: progress.advance(1, f"{variants[i]}: references"),
                              [2 if s.variants[v][1] == "fitted" else 1 for v in variants])
        travels_used = {v: [t / MM for t in tr] for v, (tr, _) in zip(variants, found)}
        refs = [row for _, ref in found for row in ref["rows"]]
        fields = {v: None if ref["continuum"] is None else np.array(ref["continuum"])
                  for v, (_, ref) in zip(variants, found)}
        travels = {v: tr for v, (tr, _) in zip(variants, found)}
        jobs = [(spacing, variant, travels[variant], model, fields[variant], s, store)
                for spacing, variant in cells for model in s.models]
        rows = dearest_first(_cell_unit, jobs, workers,
                             lambda i: progress.advance(1, " ".join(map(str, jobs[i][:2]))),
                             [1.0 / job[0] ** 3 for job in jobs])
    return jsonable({"rows": [r for rs in rows for r in rs], "references": refs,
                     "travels_mm": travels_used,
                     "nominal_travels_mm": [t / MM for t in nominal_travels()],
                     "data": measured.summary()})
