"""The artefact study's runs: every (mesh, model, base, load) cell of the paper's cube, its layer
profile and alternation against the continuum's, and per (mesh, model) the linearised growth
rate of the paper's clamped RK4 run."""
import functools
from dataclasses import dataclass

import numpy as np

from model import CalibrationDroppedError, build
from model.candidates import NORMAL_FORMS
from model.compose import label
from model.mesh import cube
from model.paper_mesh import unmatched_faces
from reference import hyperelastic, linear
from ...measuring import metrics as M
from ...framework import (MaterialSettings, FINDINGS, LOAD_SPLITS, STALL,
                          solve_split)
from ...library import paper_cube as P
from ...library.common import layers_mm
from ...running.progress import Progress
from ...reporting.costs import sim_ratio
from ...running.runner import free_components, jsonable
from ...running.store import OFF, key
from ...running.workers import dearest_first

READINGS = ("corner", "balanced", "variational")
# constant-strain FEM with the continuum's own law (neo-Hookean) on the same tetrahedra: the
# control, so that a model's part (model - control) holds no linearisation error
YARDSTICK = "fem-neohookean"
LINEAR_SCALE = 1e-3           # the linear regime: the paper's push times this
STATIC_RTOL = 1e-10
# the push split into up to 32 equal steps before a cell is called failed: the finest meshes'
# first failures (an inverted tetrahedron at 8 steps) are told from a load-path problem
SPLITS_TRIED = LOAD_SPLITS + (16, 32)
REF_MESH = ("six", 5)         # the reference's own mesh (refined REF_LEVELS times, P2)
REF_LEVELS = 2               # two refinements: its own period-2 error 1.4e-5 on 17 clamped layers
QUICK_REF_LEVELS = 1         # a preview's reference (its 9-node meshes decide nothing)
# msm with the paper's shear force at the paper's constant: with c = auto the fit sets c = 0
# on every mesh (the springs alone are stiffer than 2G in the modes the shear adds to)
FIXED_NORMAL_C = 1.0          # the normal terms' constant where it is held, not fitted
LITERAL_NORMAL = "normal_edge"    # the normal term run beside the literal readings
MSM_SHEAR = label("msm + shear(reading=variational, c=1)")


def model_specs(quick=False):
    """{model: its factors}: each reading calibrated and literal, each reading calibrated with
    each normal-stress term, msm, msm with a shear term, and the FEM control."""
    out = {}
    for r in READINGS:
        out[f"pbcm-{r}"] = {"family": "particle", "reading": r, "constant": "calibrated",
                            "normal": "none"}
        out[f"pbcm-{r}-literal"] = {"family": "particle", "reading": r, "constant": "literal",
                                    "normal": "none"}
        # each normal term fitted beside the reading's shear c held at its own fit on the
        # same mesh: the pair with and without it then differs in the normal stress alone
        for form in NORMAL_FORMS:
            out[label(f"pbcm-{r} + {form}(c=auto)")] = {
                "family": "particle", "reading": r, "constant": "calibrated", "normal": form,
                "shear_c_of": SAME_MESH}
        # beside a literal shear (c = 1, stiffer than 2G in every deviatoric mode) a fit sets
        # c_n to 0, so the literal reading takes the preset's normal term at c_n = 1
        out[label(f"pbcm-{r}-literal + {LITERAL_NORMAL}(c={FIXED_NORMAL_C:g})")] = {
            "family": "particle", "reading": r, "constant": "literal",
            "normal": fixed_normal(LITERAL_NORMAL)}
    # beside pbcm-balanced (the paper's sign) the fit sets every c_n to 0 on the mirrored five
    # split, so the terms are also run at a fixed c_n = 1 (the shear's own scale, G) with the
    # shear's c held at pbcm-balanced's fit on the same mesh: whether a normal stress changes
    # the paper's sign of the pattern is then tested with nothing else changed
    for form in NORMAL_FORMS:
        out[label(f"pbcm-balanced + {form}(c={FIXED_NORMAL_C:g})")] = {
            "family": "particle", "reading": "balanced", "constant": "calibrated",
            "normal": fixed_normal(form), "shear_c_of": SAME_MESH}
    # each model whose constants are fitted per mesh, run on the other splits with the
    # constants fitted on the mirrored five split of the same size (the shear's c, and a fitted
    # normal term's c_n): the mirror's controls then differ from it in the split alone
    for m, f in list(out.items()):
        if f["constant"] == "calibrated":
            out[held(m)] = {**f, "constant": HELD, "shear_c_of": MIRRORED_FIVE}
    out["msm"] = {"family": "msm", "reading": "none", "constant": "springs", "normal": "edges"}
    out[MSM_SHEAR] = {"family": "msm", "reading": "variational", "constant": "literal",
                      "normal": "edges"}
    out[YARDSTICK] = {"family": "fem", "reading": "none", "constant": "none", "normal": "fem"}
    if quick:
        keep = ("pbcm-balanced", "pbcm-variational", "pbcm-balanced-literal",
                label("pbcm-balanced + normal_edge(c=auto)"), held("pbcm-balanced"),
                held(label("pbcm-balanced + normal_edge(c=auto)")), "msm", YARDSTICK)
        out = {m: out[m] for m in keep}
    return out


SAME_MESH, MIRRORED_FIVE = "this mesh", "five"   # where a held shear c was fitted
HELD = "held (the mirrored five's fit)"
HELD_SUFFIX = " (c of mirrored five)"      # a held model's name: its calibrated reading's + this


def held(model):
    """The name of a calibrated reading run with the shear's c of the mirrored five split."""
    return model + HELD_SUFFIX


def builds(model):
    """The spec ``model`` is built from (a held model: its calibrated reading's)."""
    return model.removesuffix(HELD_SUFFIX)


def fixed_normal(form):
    """The ``normal`` factor of a term at the fixed constant FIXED_NORMAL_C."""
    return f"{form} (c_n = {FIXED_NORMAL_C:g})"


def short(model):
    """The name tables and figures use: 'pbcm-balanced +normal_edge' for a reading with a
    fitted normal term, 'pbcm-balanced +normal_edge (c_n = 1)' with a fixed one, 'msm +shear
    (c = 1)' for msm with the shear term, else the model; a held twin's is its model's with
    HELD_SUFFIX."""
    if model.endswith(HELD_SUFFIX):
        return short(model[:-len(HELD_SUFFIX)]) + HELD_SUFFIX
    for r in READINGS:
        for form in NORMAL_FORMS:
            if model == label(f"pbcm-{r} + {form}(c=auto)"):
                return f"pbcm-{r} +{form}"
            for reading in (f"pbcm-{r}", f"pbcm-{r}-literal"):
                if model == label(f"{reading} + {form}(c={FIXED_NORMAL_C:g})"):
                    return f"{reading} +{fixed_normal(form)}"
    return "msm +shear (c = 1)" if model == MSM_SHEAR else model


# the splits of the paper's lattice: the mirrored five (the paper's), the same five split in
# every cell (not conforming: its faces' diagonals cross), and two conforming splits without
# the mirror
SPLITS = {"five": "mirrored five", "five-unmirrored": "unmirrored five (non-conforming)",
          "six": "six (Kuhn)", "bcc": "bcc"}
SIZES = (5, 9, 17)            # nodes per side: the paper's 5 layers, then h halved twice
DECISIVE = 9                  # from this many layers the signature decides; 5 is the paper's view


def mesh_name(kind, n):
    return kind if n == P.NODES_PER_SIDE else f"{kind}-{n}"


def mesh_specs(quick=False):
    """{mesh name: (split, nodes per side, seed)}: each split at each size."""
    if quick:
        return {mesh_name(k, n): (k, n, 0) for k, n in (("five", 5), ("six", 5),
                                                       ("five-unmirrored", 5), ("five", 9),
                                                       ("six", 9))}
    return {mesh_name(k, n): (k, n, 0) for n in SIZES for k in SPLITS}


def models_on(spec, models):
    """The models run on a mesh of ``spec``: every one; a held model is not run on the
    mirrored five split, where it is the model it holds the constants of."""
    kind, n, _ = spec
    return [m for m, f in models.items() if not (kind == "five" and f["constant"] == HELD)]


def loads_on(spec, loads):
    """The paper's push on every mesh; the linear regime (a check, and the patch test the
    consistency hypothesis reads) up to once refined."""
    return [x for x in loads if x == "paper" or spec[1] < max(SIZES)]


@functools.lru_cache(maxsize=16)
def make_mesh(name, spec):
    """The mesh ``name`` of ``spec`` (built once per process: a worker runs its models one by
    one; callers do not modify it)."""
    kind, n, _ = spec
    return cube(n, P.SIZE_MM * P.MM, kind)


def mesh_factors(name, spec, mesh):
    kind, n, _ = spec
    return {"split": SPLITS[kind], "nodes_per_side": n, "tets": mesh.n_tets,
            "unmatched_faces": unmatched_faces(mesh, P.SIZE_MM * P.MM)}


@dataclass
class ArtefactSettings(MaterialSettings):
    """Material (the paper cube's), the factors and the mode."""

    quick: bool = False
    bcs: tuple = P.BCS
    loads: tuple = ("paper", "linear")
    damping: float = 50.0     # the paper cube's mass damping [1/s]: what flutter must beat

    def __post_init__(self):
        super().__post_init__()

    @property
    def ref_levels(self):
        return QUICK_REF_LEVELS if self.quick else REF_LEVELS

    @property
    def models(self):
        return model_specs(self.quick)

    @property
    def meshes(self):
        return mesh_specs(self.quick)

    def problem(self):
        return {**self.material_record(), "size_mm": P.SIZE_MM,
                "push_mm": P.PUSH_MM, "linear_scale": LINEAR_SCALE, "damping_1_s": self.damping,
                "reference": {"element": "P2", "mesh": f"{REF_MESH[0]} {REF_MESH[1]}^3",
                              "refinements": self.ref_levels}}

    def cells(self):
        """[(mesh, model)]: every unit of work, in the order the cells are reported."""
        return [(name, m) for name, spec in self.meshes.items()
                for m in models_on(spec, self.models)]

    @property
    def units(self):
        """Work units a pool could share: each model on each mesh (and before them each
        reference)."""
        return len(self.cells())

    def describe(self):
        return {**self.problem(), "quick": self.quick, "bcs": list(self.bcs),
                "loads": list(self.loads), "meshes": list(self.meshes),
                "models": list(self.models)}


def push_mm(load):
    return P.PUSH_MM * (LINEAR_SCALE if load == "linear" else 1.0)


def reference(bc, load, s):
    """The continuum on the reference mesh: linear P2 in the linear regime, neo-Hookean P2
    at the paper's push (each refined ``s.ref_levels`` times, with its error estimate)."""
    mesh = cube(REF_MESH[1], P.SIZE_MM * P.MM, REF_MESH[0])
    dirichlet = P.static_bc(mesh, bc, push_mm(load))
    if load == "linear":
        return linear.converged(mesh, s.material, dirichlet, levels=s.ref_levels)
    return hyperelastic.converged(mesh, s.material, dirichlet, levels=s.ref_levels,
                                  mixed="auto")


def _free_layers(bc, n_layers):
    free = np.ones(n_layers, bool)
    if bc == "clamped":           # base and top held laterally
        free[[0, -1]] = False
    return free


def cell(pm, mesh, n, bc, load, u_ref):
    """One cell: the model's static layer profile (``n`` node planes), the reference's
    (``u_ref`` (n_nodes, 3) [m], the continuum at the mesh's nodes) on the same nodes, the
    alternation and the displacement error over the free components."""
    layers = [y * P.MM for y in layers_mm(n)]
    dirichlet = P.static_bc(mesh, bc, push_mm(load))
    size = P.SIZE_MM * P.MM
    ref_profile = M.layer_profile(mesh.points, u_ref, layers, size) / P.MM
    free_layers = _free_layers(bc, len(layers))

    def lines(u):
        """Each side-face line's signature [mm]: the node-level pattern the layer mean averages."""
        got = M.line_alternations(M.side_line_profiles(mesh.points, u, layers, size) / P.MM,
                                  ref_profile, free_layers)
        return None if got is None else got.tolist()
    out = {"bulge_profile_fem_mm": ref_profile.tolist(), "failed": None,
           "line_alternation_fem_mm": lines(u_ref)}
    try:
        st, steps = solve_split(pm, dirichlet, splits=SPLITS_TRIED, rtol=STATIC_RTOL,
                                stall=STALL)
    except FINDINGS as exc:
        return {**out, "failed": str(exc), "bulge_profile_mm": None, "alternation_mm": None,
                "alternation_rel": None, "disp_rel_l2": None, "load_steps": None,
                "line_alternation_mm": None}
    profile = M.layer_profile(mesh.points, st.u, layers, size) / P.MM
    amplitude, relative = M.alternation(profile, ref_profile, free_layers)
    free = free_components(dirichlet, mesh.n_nodes)
    return {**out, "bulge_profile_mm": profile.tolist(), "alternation_mm": amplitude,
            "alternation_rel": relative, "disp_rel_l2": M.rel_l2(st.u, u_ref, free),
            "load_steps": steps, "line_alternation_mm": lines(st.u)}


def _cells_key(s, name, model):
    return key(kind="artefact-cells", **s.problem(), mesh=name, spec=list(s.meshes[name]),
               bcs=list(s.bcs), loads=loads_on(s.meshes[name], s.loads), model=model)


def _model_rows(model, factors, name, spec, mesh, s, u_refs):
    base = {"mesh": name, **mesh_factors(name, spec, mesh), "model": model,
            **{k: v for k, v in factors.items() if k != "shear_c_of"}}
    loads = loads_on(spec, s.loads)
    try:
        pm, dropped = _built(model, factors, spec, mesh, s)
    except FINDINGS as exc:
        return [{**base, "constants": None, "bc": bc, "load": load, "failed": f"build: {exc}",
                 "bulge_profile_mm": None, "alternation_mm": None, "alternation_rel": None,
                 "disp_rel_l2": None, "load_steps": None, "growth_rate_1_s": None,
                 "flutter": None, "line_alternation_mm": None,
                 "line_alternation_fem_mm": None}
                for bc in s.bcs for load in loads]
    # the model linearised at rest with each base's constraints (a dense eigenproblem: the
    # paper's 5 nodes per side only)
    rates = {bc: P.growth_rate(pm, mesh, bc) if spec[1] == P.NODES_PER_SIDE else None
             for bc in s.bcs}
    # each term's constant as built (fitted or given): {term_c: value}
    constants = {**{k: v for k, v in pm.info.items() if k.endswith("_c")}, **dropped}
    return [{**base, "constants": constants, "bc": bc, "load": load,
             "growth_rate_1_s": rates[bc],
             "flutter": None if rates[bc] is None else rates[bc] > 0.0,
             **cell(pm, mesh, spec[1], bc, load, u_refs[(bc, load)])}
            for bc in s.bcs for load in loads]


def _built(model, factors, spec, mesh, s):
    """``model`` built on ``mesh`` and the constants its fit dropped ({term_c: 0.0}): a normal
    term beside a held shear whose fit comes out c_n = 0 adds nothing on this mesh, so the
    model is its reading with that shear (a finding: the pair is one observation)."""
    params, dropped = held_constants(model, factors, spec, mesh, s)
    if dropped:
        return build(f"pbcm-{factors['reading']}", mesh, s.material, **params), dropped
    try:
        return build(builds(model), mesh, s.material, **params), {}
    except CalibrationDroppedError:
        if factors["normal"] not in NORMAL_FORMS or not params:
            raise
    return (build(f"pbcm-{factors['reading']}", mesh, s.material, **params),
            {f"{factors['normal']}_c": 0.0})


def held_constants(model, factors, spec, mesh, s):
    """``(build's term parameters, the constants dropped)`` for a model whose constants are
    held (``shear_c_of``): the calibrated reading's shear c fitted on this mesh ('this mesh');
    or, held from the mirrored five split of the same size ('five'), every constant ``model``'s
    calibrated twin fits there (the shear's c, and a fitted normal term's c_n, dropped where
    that fit gives 0); ``({}, {})`` for the others."""
    where = factors.get("shear_c_of")
    if where is None:
        return {}, {}
    if where == SAME_MESH:
        fitted = build(f"pbcm-{factors['reading']}", mesh, s.material).info["shear_c"]
        return {"shear": {"c": float(fitted)}}, {}
    five_spec = ("five", spec[1], spec[2])
    five = make_mesh(mesh_name(*five_spec[:2]), five_spec)
    if factors["normal"] not in NORMAL_FORMS:
        return held_constants(model, {**factors, "shear_c_of": SAME_MESH}, five_spec, five, s)
    twin, dropped = _built(builds(model), {**factors, "constant": "calibrated",
                                           "shear_c_of": SAME_MESH}, five_spec, five, s)
    params = {"shear": {"c": float(twin.info["shear_c"])}}
    if dropped:
        return params, dropped
    form = factors["normal"]
    return {**params, form: {"c": float(twin.info[f"{form}_c"])}}, {}


def _reference_unit(job):
    """The continuum of one (bc, load) at the nodes of each mesh that ``names`` lists, and
    its error estimate."""
    bc, load, names, s = job
    ref = reference(bc, load, s)
    return {"at": {name: ref.result.at(make_mesh(name, s.meshes[name]).points)
                   for name in names}, "error_estimate": ref.error_estimate}


def _cell_unit(job):
    """One model's rows on one mesh (the model built, and calibrated, once), kept in the
    store."""
    name, model, s, u_refs, store = job
    spec = s.meshes[name]
    return store.put(_cells_key(s, name, model), _model_rows(
        model, s.models[model], name, spec, make_mesh(name, spec), s, u_refs))


def run(s, workers=None, log=True, bench=None, store=OFF):
    """Every mesh's cells, and the references' error estimates (stored apart): first the
    references a missing cell or estimate needs (a unit each, on ``workers`` where given),
    then each (mesh, model) not stored (a unit each)."""
    pairs = [(bc, load) for bc in s.bcs for load in s.loads]
    cells = s.cells()
    found = {c: store.get(_cells_key(s, *c)) for c in cells}
    todo = [c for c in cells if found[c] is None]
    info_keys = {p: key(kind="artefact-reference", **s.problem(), bc=p[0], load=p[1])
                 for p in pairs}
    infos = {p: store.get(k) for p, k in info_keys.items()}
    with Progress("artefact", len(pairs) + len(cells), log=log) as progress:
        progress.advance(len(cells) - len(todo))
        need = [p for p in pairs if todo or infos[p] is None]
        names = list(dict.fromkeys(name for name, _ in todo))
        refs = dict(zip(need, dearest_first(
            _reference_unit, [(bc, load, names, s) for bc, load in need], workers,
            lambda i: progress.advance(1, f"{need[i][0]} {need[i][1]}: reference"))))
        progress.advance(len(pairs) - len(need))
        for p in need:
            infos[p] = infos[p] or store.put(info_keys[p], {
                "bc": p[0], "load": p[1], "error_estimate": refs[p]["error_estimate"]})
        made = dearest_first(
            _cell_unit, [(name, model, s, {p: refs[p]["at"][name] for p in pairs}, store)
                         for name, model in todo], workers,
            lambda i: progress.advance(1, " ".join(todo[i])),
            [s.meshes[name][1] ** 3 for name, _ in todo])
    found.update(zip(todo, made))
    return jsonable({"cells": recorded_lines([r for c in cells for r in found[c]]),
                     "references": [infos[p] for p in pairs],
                     **bench_costs(bench, list(s.models))})


LINES = ("line_alternation_mm", "line_alternation_fem_mm")
LINE_DIGITS = 9      # significant digits: far below the static solve's tolerance
CELL_KEY = ("mesh", "model", "bc", "load")


def recorded_lines(cells):
    """``cells`` with their line signatures as recorded: to LINE_DIGITS significant digits,
    and the continuum's on FEM P1's cells alone (it is the same on every model's cell of a
    mesh, base and load, and the analysis reads it there)."""
    def rounded(v):
        return None if v is None else [float(f"{x:.{LINE_DIGITS}g}") for x in v]
    out = []
    for c in cells:
        c = {**c, **{k: rounded(c.get(k)) for k in LINES}}
        if c["model"] != YARDSTICK:
            c["line_alternation_fem_mm"] = None
        out.append(c)
    return out


def lines_apart(cells):
    """(the cells without their line signatures, one row per cell with them): the signatures
    are most of a record's size, so they are kept in a file of their own."""
    return ([{k: v for k, v in c.items() if k not in LINES} for c in cells],
            [{k: c.get(k) for k in CELL_KEY + LINES} for c in cells])


def lines_joined(cells, rows):
    """The cells with the line signatures ``lines_apart`` took from them put back."""
    if len(rows) != len(cells) or any(tuple(r[k] for k in CELL_KEY)
                                      != tuple(c[k] for k in CELL_KEY)
                                      for c, r in zip(cells, rows)):
        raise KeyError("line signatures row for row with the cells")
    return [{**c, **{k: r[k] for k in LINES}} for c, r in zip(cells, rows)]


FIVE_TETS = 5 * (P.NODES_PER_SIDE - 1) ** 3     # the mirrored five cube: 320 tetrahedra


def bench_costs(bench, models):
    """What the study takes from the bench document ``bench``: each model's step over msm's
    on the paper's cube (``step_costs``) and its spread over the bench's rounds at that size
    (``step_ranges``), with the size and rounds that spread covers."""
    rows = [r for r in (bench or {}).get("rows", []) if r["tets"] == FIVE_TETS]
    return {"step_vs_msm": step_costs(bench, models),
            "step_vs_msm_range": step_ranges(bench, models),
            "step_vs_msm_sizes": size_ranges(bench, models),
            "sim_vs_msm_sizes": per_simulated_second(bench, models),
            "bench_spread": None if not rows else {
                "tets": [FIVE_TETS],
                "rounds": max([r.get("rounds") or 0 for r in rows], default=0)}}


def _paper_row(bench, model):
    """The bench's row of ``model`` at the paper's size (FIVE_TETS), or None."""
    return next((r for r in (bench or {}).get("rows", []) if r["model"] == model
                 and r["tets"] == FIVE_TETS and r.get("step_vs_msm") is not None), None)


def step_ranges(bench, models):
    """{model: [smallest, largest]} of its RK4 step over msm's over the bench's rounds at the
    paper's size (FIVE_TETS: one population, never pooled with other sizes); a literal
    reading's is its calibrated reading's (the same kernel); None where the bench lacks the
    model at that size or its range."""
    out = {}
    for m in models:
        r = _paper_row(bench, m.replace("-literal", ""))
        span = None if r is None else r.get("step_vs_msm_range")
        out[m] = [float(span[0]), float(span[1])] if span else None
    return out


def size_ranges(bench, models):
    """{model: {tetrahedra: [smallest, largest]}}: its RK4 step over msm's over the bench's
    rounds at each size the bench ran, each size its own population (the paper's Figure 2
    reads the cost's growth with mesh size); a literal reading's is its calibrated reading's."""
    out = {}
    for m in models:
        got = {int(r["tets"]): [float(v) for v in r["step_vs_msm_range"]]
               for r in (bench or {}).get("rows", [])
               if r["model"] == m.replace("-literal", "") and r.get("step_vs_msm_range")}
        out[m] = dict(sorted(got.items())) or None
    return out


def per_simulated_second(bench, models):
    """{model: {tetrahedra: [ratio, smallest, largest]}}: the cost of one simulated second over
    msm's, each at its own largest stable RK4 step (the in-round step ratio times msm's stable
    step over the model's, what a user of either pays), at every size the bench measured the
    stable steps; a literal reading's is its calibrated reading's. Not the paper's measure
    (Figure 2 compares the time of one step)."""
    rows = (bench or {}).get("rows", [])
    msm = {int(r["tets"]): r for r in rows if r["model"] == "msm" and r.get("stable_dt_us")}
    out = {}
    for m in models:
        got = {}
        for r in rows:
            t = int(r["tets"])
            if r["model"] != m.replace("-literal", "") or r.get("step_vs_msm") is None \
                    or not r.get("stable_dt_us") or t not in msm:
                continue
            ratio, span = sim_ratio(r, msm[t])
            got[t] = [float(ratio), *map(float, span or [ratio, ratio])]
        out[m] = dict(sorted(got.items())) or None
    return out


def step_costs(bench, models):
    """Each model's RK4 step over msm's on the paper's 125-node five cube (320 tetrahedra):
    the bench's in-round ratio at that size, the number every report prints for it; a literal
    reading costs what its calibrated one does (the constant only scales the same kernel)."""
    out = {}
    for m in models:
        r = _paper_row(bench, m.replace("-literal", ""))
        out[m] = None if r is None else float(r["step_vs_msm"])
    return out
