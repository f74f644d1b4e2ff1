"""The Truth Cube study's files: metrics.json (every row, the references, the data's numbers, the
rows the gate reads), report.md/.html (the answer, the data and its noise, the errors per
strain and model, the sensitivity to the plates, the travel and nu, figures by layer). Every
sentence is computed from the rows it is written with."""
from pathlib import Path

import numpy as np

from ...measuring import catalogue
from ...reporting import figures
from ...reporting.document import Document, fmt, rel
from ...measuring.error_model import input_spread, u_val
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from .beads import WITHIN, excess, within
from .study import LINEAR, NH, REF_MESH

GATED = catalogue.gated("bead_axial_rms_mm", "bead_lateral_rms_mm", "bead_vs_continuum_mm")
DEFAULT = "bonded"
COMPONENTS = (("total", "bead_rms_mm"), ("axial", "bead_axial_rms_mm"),
              ("lateral", "bead_lateral_rms_mm"))


def percent(strain):
    return f"{100 * strain:g} %"


def gate_rows(rows):
    return [{"mesh": r["mesh"], "bc": f"{r['variant']}/{percent(r['strain'])}",
             "model": r["model"], **{k: r.get(k) for k in GATED}} for r in rows]


def floors(data):
    """{state: {"total"|"axial"|"lateral": floor [mm]}}."""
    return {s["state"]: s["floor_mm"] for s in data["states"]}


def verdicts(rows, data, u=None):
    """{(mesh, variant, model): [(state, within?) ...]}: a run reproduces a state when its
    total RMS error lies within its u_val at that state (``u`` {state: {model: u_val}},
    ``cases.reporting.answers.u_vals``); where ``u`` does not name the model, when its total, axial and
    lateral RMS errors each lie within the floor (``beads.within``)."""
    fl = floors(data)
    out = {}
    for r in rows:
        mine = (u or {}).get(r["state"], {}).get(r["model"])
        if r.get("failed"):
            ok = None
        elif mine is not None:
            ok = r["bead_rms_mm"] <= mine
        else:
            ok = all(within(r[k], fl[r["state"]][c]) for c, k in COMPONENTS)
        out.setdefault((r["mesh"], r["variant"], r["model"]), []).append((r["state"], ok))
    return out


WITHIN_ALL = "within u_val at every state"


def departure(states, strains):
    """A run's answer in words: within u_val at every state, beyond it from the first, or up
    to the strain at which it departs."""
    oks = [ok for _, ok in states]
    if any(ok is None for ok in oks):
        return "failed"
    if all(oks):
        return WITHIN_ALL
    first = next(i for i, ok in enumerate(oks) if not ok)
    if first == 0:
        return f"beyond u_val from {percent(strains[0])}"
    return f"within up to {percent(strains[first - 1])}, departs at {percent(strains[first])}"


def finest(rows):
    """The finest mesh of the default variant (the most nodes)."""
    meshes = {r["mesh"]: r["nodes"] for r in rows if r["variant"] == DEFAULT}
    return max(meshes, key=meshes.get)


def against_continuum(rows, data, mesh, u):
    """{model: its answer against the continuum on ``mesh`` (default assumptions)}: the RMS
    distance of its bead displacements from the neo-Hookean continuum's within the model's
    uncertainty at every state (``u`` {state: {model: u}}, the beads' noise left out: no
    measurement enters), or the strain from which it is farther."""
    out = {}
    for r in sorted(rows, key=lambda r: r["state"]):
        if r["mesh"] not in (mesh, "reference") or r["variant"] != DEFAULT \
                or r["model"] == NH:
            continue
        d = r.get("bead_vs_continuum_mm")
        mine = u.get(r["state"], {}).get(r["model"])
        ok = None if d is None or mine is None else d <= mine
        out.setdefault(r["model"], []).append((r["state"], ok))
    strains = [st["strain"] for st in data["states"]]
    return {m: departure(v, strains) for m, v in out.items()}


def state_u_vals(data, parameters):
    """{state: {model: u_val}} of every state (``cases.reporting.answers.u_vals``), the continuum's
    included."""
    from ...reporting.answers import u_vals
    truth = {**data, "parameters": parameters, "headline": {"continuum": NH}}
    out = {}
    for st in data["data"]["states"]:
        u, u_num, _, _ = u_vals(truth, st["strain"], st["floor_mm"]["total"])
        # the linear reference ran under the default assumptions only: no u_input
        out[st["state"]] = {LINEAR: float(np.hypot(u_num, st["floor_mm"]["total"])), **u}
    return out


def without_noise(u, data):
    """{state: {model: sqrt(u_val^2 - u_D^2)}}: the uncertainty of a model read against the
    continuum at the beads, where no measurement enters (u_num and u_input only)."""
    noise = {st["state"]: st["floor_mm"]["total"] for st in data["states"]}
    return {state: {m: float(np.sqrt(max(v ** 2 - noise.get(state, 0.0) ** 2, 0.0)))
                    for m, v in us.items()} for state, us in u.items()}


def analyse(data, parameters):
    rows, refs = data["rows"], data["references"]
    strains = sorted({r["strain"] for r in rows + refs})
    u = state_u_vals(data, parameters)
    v = verdicts(rows + refs, data["data"], u)
    mesh = finest(rows)
    said = {m: departure(v[(mesh, DEFAULT, m)], strains)
            for (x, var, m) in v if x == mesh and var == DEFAULT}
    said.update({m: departure(v[("reference", DEFAULT, m)], strains)
                 for (x, var, m) in v if x == "reference" and var == DEFAULT})
    last = strains[-1]
    at_last = {r["model"]: r for r in _rows({"rows": rows, "references": refs}, mesh, DEFAULT)
               if r["strain"] == last and not r.get("failed")}
    state = next(st for st in data["data"]["states"] if st["strain"] == last)
    assumptions = {r["variant"]: r["bead_rms_mm"] for r in refs
                   if r["model"] == NH and r["strain"] == last and not r.get("failed")}
    return {"finest_mesh": mesh, "departure": said,
            "within_at_every_state": [m for m, t in said.items() if t == WITHIN_ALL],
            "against_continuum": against_continuum(rows + refs, data["data"], mesh,
                                                   without_noise(u, data["data"])),
            "continuum_by_assumption_mm": assumptions,
            "u_val_by_state": u,
            "headline": {"strain": last, "floor_mm": state["floor_mm"]["total"],
                         "continuum": NH, "states": len(data["data"]["states"]),
                         "mesh": mesh, "models": {
                             m: {"bead_rms_mm": r["bead_rms_mm"],
                                 "bead_rms_rel": r["bead_rms_rel"], "departure": said.get(m),
                                 "states_within": sum(bool(ok) for _, ok in v[(
                                     r["mesh"], DEFAULT, m)])}
                             for m, r in at_last.items()}}}


def scorecard(doc):
    """The index's row measured against reality: per model its bead RMS error over the RMS
    measured displacement at the largest strain, and whether its RMS in mm lies within its
    validation uncertainty u_val (``cases.reporting.answers.validation``); band 0 within, 2 beyond."""
    from ...reporting.answers import validation
    h = doc["headline"]
    val = validation(doc)
    cells = {}
    for m, v in h["models"].items():
        if m not in val["u_val"]:
            continue
        u = val["u_val"][m]
        within = v["bead_rms_mm"] <= u
        cells[m] = (f"{fmt(v['bead_rms_rel'])} at {percent(h['strain'])}, "
                    f"{fmt(v['bead_rms_mm'])} mm RMS, {'within' if within else 'above'} its "
                    f"u_val {fmt(u, 2)} mm", 0 if within else 2)
    return [(f"truth-cube/bonded, {h['mesh']} (measured beads)", "bead_rms_rel", cells)]


def write(out, study, s, data):
    found = analyse(data, s.describe())
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, **found, "gate_runs": gate_rows(data["rows"])})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def _rows(doc, mesh, variant):
    return [r for r in doc["rows"] + doc["references"]
            if r["variant"] == variant and r["mesh"] in (mesh, "reference")]


def conclusion(doc):
    """The report's three lines: who agrees with the measurement within its u_val (and the
    continuum's own distance, with what the assumptions do to it), which models the
    measurement cannot tell from the continuum, and the spread of the errors with the ties."""
    said, mesh = doc["departure"], doc["finest_mesh"]
    models = [m for m in said if m not in (NH, LINEAR)]
    last = max(s["strain"] for s in doc["data"]["states"])
    at_last = {r["model"]: r for r in _rows(doc, mesh, DEFAULT) if r["strain"] == last}
    nh = at_last.get(NH, {}).get("bead_rms_mm")
    from ...reporting.answers import validation
    val = validation(doc)
    within = val["within"]
    line = (f"**Against the measured beads** (bonded plates, nominal travel, {mesh} mesh; the "
            "plates prescribe displacement, so the beads test the deformed shape, not the "
            f"stiffness): at {percent(last)}, read against each model's u_val "
            f"(sqrt(u_num^2 + u_input^2 + u_D^2): the beads' noise {fmt(val['u_d'], 2)} mm, the "
            f"neo-Hookean continuum's spread over the unmeasured friction, travel and nu (the "
            "inputs' own effect; a model's response beyond it, a P1 mesh locking near "
            "incompressibility, is its error, not uncertainty), the neo-Hookean reference's change over its last refinement "
            f"{fmt(val['u_num'], 2)} mm), "
            + (f"{', '.join(within)} agree with the measurement" if within else
               "no model agrees with the measurement")
            )
    by = doc["continuum_by_assumption_mm"]
    if nh:
        # the continuum read as the models are (error_model.input_spread)
        u_in = input_spread(by, doc["parameters"].get("variants", {}))
        u_nh = u_val(val["u_num"], u_in, val["u_d"])
        line += (f"; the neo-Hookean continuum is {fmt(nh)} mm RMS off at {percent(last)}, "
                 f"{'within' if nh <= u_nh else 'beyond'} its u_val {fmt(u_nh, 2)} mm")
        others = {k: v for k, v in by.items() if k != DEFAULT}
        if others:
            lo, hi = min(others, key=others.get), max(others, key=others.get)
            line += (f" (the assumptions weigh most: {lo} {fmt(others[lo])} mm, {hi} "
                     f"{fmt(others[hi])} mm)")
    lines = [line + "."]
    vs = doc["against_continuum"]
    close = [m for m, t in vs.items() if t == WITHIN_ALL]
    far = {m: t for m, t in vs.items() if t != WITHIN_ALL}
    lines.append("**Against the continuum at the beads** (the RMS distance of a model's bead "
                 "displacements from the continuum's, read against sqrt(u_num^2 + u_input^2), "
                 "the beads' noise left out since no measurement enters): "
                 + (f"{', '.join(close)} stay within it at every state (the unmeasured inputs "
                    "cannot tell them from it)" if close else
                    "no model stays within it at every state")
                 + ("; " + "; ".join(f"{m} {t.replace('within', 'within it')}"
                                     for m, t in far.items()) if far else "") + ".")
    best = sorted((m for m in models if at_last.get(m, {}).get("bead_rms_mm") is not None),
                  key=lambda m: at_last[m]["bead_rms_mm"])
    if best:
        lines.append(f"At {percent(last)}: bead RMS error from "
                     f"{fmt(at_last[best[0]]['bead_rms_mm'])} mm ({best[0]}) to "
                     f"{fmt(at_last[best[-1]]['bead_rms_mm'])} mm ({best[-1]}); tied (a "
                     "difference below the larger u_val, not ranked among themselves): "
                     f"{', '.join(val['tied'])}.")
    return lines


def opening(doc):
    """The conclusion, or for a quick run the line that says it decides nothing: a quick run
    has no variants of the inputs nobody measured, so no u_input to read the beads against."""
    if doc["parameters"].get("quick"):
        return ["**Quick: not decided** (`pbcm run truth-cube` decides: a quick run has no "
                "variants of the inputs nobody measured, so no u_input to read the beads "
                "against); the tables below are a preview of its one mesh and decide nothing."]
    return conclusion(doc)


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    d.opening(opening(doc))
    d.h(2, "What was run")
    ref = [r for r in doc["references"] if r["model"] == NH and r["variant"] == DEFAULT
           and r.get("error_estimate") is not None]
    d.ul([study.title + ". Data: Kerdok et al., Medical Image Analysis 7(3) 283-291, 2003 "
          "(in `reference/data/truthcube/` with its attribution).",
          "The 80 mm cube on the mirrored five split at "
          + ", ".join(f"{h:g} mm" for h in s.spacings_mm) + " spacing; the moving plate at "
          "z = 0 pushed to +z, the fixed one at z = 80 mm, "
          f"placed on the bead lattice's centre; one static solve through the three states "
          f"in steps of at most {doc['problem']['step_of_spacing']:g} of the mesh spacing.",
          f"nu = {s.nu:g} (the silicone's range is 0.49 to 0.4999: both ends shown below); "
          f"E = {s.E:g} Pa (the plates prescribe displacement and every force scales with E, "
          "so E sets only the force scale).",
          f"Models: {', '.join(s.models)} (the readings calibrated, c = auto). References: "
          f"{NH} on the {REF_MESH[0]} split of {REF_MESH[1]} nodes per side refined "
          f"{s.ref_levels} time(s) (its bead displacement changed by "
          + (", ".join(f"{fmt(r['bead_change_mm'])} mm at {percent(r['strain'])}" for r in ref)
             or "n/a") + " RMS over the last refinement; the global estimate "
          + (rel(ref[-1]["error_estimate"]) if ref else "n/a") + ") and linear P2 on the same "
          "mesh, both at the beads by their own basis; the models by P1 interpolation on "
          "their own mesh at the measured rest bead positions.",
          "Each measured state's best rigid in-plane motion (translation in x, y and rotation "
          "about z; the whole cube moves between scans) is removed before comparing; the raw "
          "error is in the tables beside it."])
    _data(d, doc)
    _errors(d, doc)
    _sensitivity(d, doc, s)
    _figures(d, out, doc)
    d.p(f"Environment: {doc['environment']}.")
    return d


def _data(d, doc):
    data = doc["data"]
    d.h(2, "The measurement and its noise")
    d.p("The noise of a measured displacement component is: the RMS residual of a "
        "degree-4 polynomial of the rest positions fitted to each state's displacement (the "
        "compressed cube's field is smooth; the beads' scatter about it is not), combined as "
        "each error is. A model's error beyond the noise is sqrt(rms^2 - noise^2) (the '*' "
        "of the tables: beyond the noise in total, axially or laterally). A model reproduces "
        "a state when its total RMS error is within its u_val there: the noise, the "
        "neo-Hookean continuum's spread over the inputs nobody measured and the neo-Hookean reference's change over "
        "its last refinement combined (sqrt(u_num^2 + u_input^2 + u_D^2)).")
    d.table(["strain", "nominal travel [mm]", "RMS displacement [mm]", "axial", "lateral",
             "noise total [mm]", "axial", "lateral", "quantisation x, y, z [mm]",
             "rigid motion removed x, y [mm], z-rotation [deg]"],
            [[percent(st["strain"]), fmt(t), fmt(st["scale_mm"]["total"]),
              fmt(st["scale_mm"]["axial"]), fmt(st["scale_mm"]["lateral"]),
              fmt(st["floor_mm"]["total"]), fmt(st["floor_mm"]["axial"]),
              fmt(st["floor_mm"]["lateral"]),
              ", ".join("-" if q is None else fmt(q) for q in st["quantisation_mm"]),
              ", ".join(fmt(x) for x in st["rigid_removed"])]
             for st, t in zip(data["states"], doc["nominal_travels_mm"])])
    q = [v for st in data["states"] for v in st["quantisation_mm"] if v is not None]
    found = (f"the step found is {fmt(max(q))} mm, whose own RMS error in a displacement is "
             f"step / sqrt(6) = {fmt(max(q) / np.sqrt(6))} mm" if q else "no coordinate is")
    d.p("Quantisation: a coordinate is on a grid of steps when most of its values are "
        f"(coherence at least 0.5); {found}. The rest positions scatter "
        + ", ".join(f"{fmt(v)} mm" for v in data["rest_scatter_mm"])
        + " (x, y, z) about the best regular grid (spacing "
        + ", ".join(f"{fmt(v)}" for v in data["grid_spacing_mm"])
        + " mm): bead placement, not noise, which is why the measured rest positions are "
        "used.")


def _state_table(d, rows, data, title):
    fl = floors(data)
    d.h(3, title)
    models = list(dict.fromkeys(r["model"] for r in rows))
    by = {(r["model"], r["state"]): r for r in rows}
    header = ["model"]
    for st in data["states"]:
        p = percent(st["strain"])
        header += [f"{p} RMS [mm]", f"{p} axial", f"{p} lateral", f"{p} max", f"{p} raw"]
    body = [["noise"] + [x for st in data["states"] for x in (
        fmt(fl[st["state"]]["total"]), fmt(fl[st["state"]]["axial"]),
        fmt(fl[st["state"]]["lateral"]), "", "")]]
    for m in models:
        line = [m]
        for st in data["states"]:
            r = by.get((m, st["state"]))
            if r is None or r.get("failed"):
                line += ["failed" if r else "n/a"] + [""] * 4
                continue
            f = fl[st["state"]]
            mark = "" if all(within(r[k], f[c]) for c, k in COMPONENTS) else " *"
            line += [fmt(r["bead_rms_mm"]) + mark, fmt(r["bead_axial_rms_mm"]),
                     fmt(r["bead_lateral_rms_mm"]), fmt(r["bead_max_mm"]),
                     fmt(r["bead_raw_rms_mm"])]
        body.append(line)
    d.table(header, body)


def _errors(d, doc):
    d.h(2, "Bead errors per strain and model")
    d.p("RMS over the 343 beads of the error vector's length, its axial (z) and lateral (x, y) "
        "parts and the largest, in mm, against the measurement with its rigid in-plane motion "
        "removed; raw: the RMS against the measurement as scanned. '*': beyond the noise (the "
        "error beyond the noise exceeds it in total, axially or laterally). Relative errors "
        "(over the RMS measured displacement) are in metrics.json.")
    meshes = sorted({r["mesh"] for r in doc["rows"] if r["variant"] == DEFAULT},
                    key=lambda m: -float(m.rstrip("m")))
    for mesh in meshes:
        _state_table(d, _rows(doc, mesh, DEFAULT), doc["data"],
                     f"Bonded plates, nominal travel, {mesh} mesh")
    d.h(3, "Where each departs")
    d.p(f"On the {doc['finest_mesh']} mesh: from the measurement (its error beyond the noise "
        "above the noise) and from the neo-Hookean continuum under the same assumptions (the "
        "RMS distance of their bead displacements beyond the model's u_val there, the beads' "
        "noise left out of it: no measurement enters that comparison).")
    vs = doc["against_continuum"]
    d.table(["model", "against the measurement", "against the continuum"],
            [[m, t, vs.get(m, "(the continuum)" if m == NH else "n/a")]
             for m, t in doc["departure"].items()])


def _sensitivity(d, doc, s):
    variants = list(dict.fromkeys(r["variant"] for r in doc["rows"]))
    if len(variants) < 2:
        return
    mesh = next(r["mesh"] for r in doc["rows"] if r["variant"] != DEFAULT)
    last = max(st["strain"] for st in doc["data"]["states"])
    floor = floors(doc["data"])[len(doc["data"]["states"])]["total"]
    d.h(2, "How the answer moves with the plates, the travel and nu")
    d.p(f"Bead RMS error [mm] at {percent(last)} on the {mesh} mesh, each assumption changed "
        f"alone (noise {fmt(floor)} mm; '*': beyond it). The continuum's row says how far the "
        "assumption itself moves the answer.")
    by = {(r["model"], r["variant"]): r for r in doc["rows"] + doc["references"]
          if r["strain"] == last and r["mesh"] in (mesh, "reference")}
    models = list(dict.fromkeys(m for m, _ in by))

    def cell(r):
        if r is None or r.get("failed"):
            return "failed" if r else "n/a"
        return fmt(r["bead_rms_mm"]) + ("" if within(r["bead_rms_mm"], floor) else " *")
    d.table(["model"] + variants, [[m] + [cell(by.get((m, v))) for v in variants]
                                   for m in models])
    fitted = doc["travels_mm"].get("fitted-travel")
    if fitted:
        d.p("The fitted travel (the continuum's axial bead displacements closest to the "
            "measured ones, per state) against the nominal: " + "; ".join(
                f"{percent(st['strain'])}: {fmt(f)} mm against {fmt(n)} mm"
                for st, f, n in zip(doc["data"]["states"], fitted,
                                    doc["nominal_travels_mm"])) + ".")
    ex = {v: by.get((NH, v)) for v in variants}
    ok = {v: r for v, r in ex.items() if r and not r.get("failed")}
    if ok:
        lo, hi = min(ok, key=lambda v: ok[v]["bead_rms_mm"]), max(
            ok, key=lambda v: ok[v]["bead_rms_mm"])
        d.p(f"The continuum's bead RMS error at {percent(last)} ranges from "
            f"{fmt(ok[lo]['bead_rms_mm'])} mm ({lo}) to {fmt(ok[hi]['bead_rms_mm'])} mm "
            f"({hi}); its error beyond the noise, {fmt(excess(ok[lo]['bead_rms_mm'], floor))} "
            f"to {fmt(excess(ok[hi]['bead_rms_mm'], floor))} mm.")


def _figures(d, out, doc):
    mesh = doc["finest_mesh"]
    data = doc["data"]
    rows = _rows(doc, mesh, DEFAULT)
    refs = [m for m in (NH, LINEAR) if any(r["model"] == m for r in rows)]
    models = [m for m in dict.fromkeys(r["model"] for r in rows) if m not in refs]
    beyond = {m for m, t in doc["against_continuum"].items() if t != WITHIN_ALL}
    columns = []
    for st in data["states"]:
        here = {r["model"]: r for r in rows if r["state"] == st["state"]
                and not r.get("failed")}
        f = st["layer_noise_mm"]
        columns.append((f"{percent(st['strain'])} compression", [
            (f"{what} [mm]", st[key], f[comp], [(m, here[m][key]) for m in refs if m in here],
             [(m, here[m][key]) for m in models if m in here])
            for what, key, comp in (("mean axial displacement", "layer_axial_mm", "axial"),
                                    ("outward lateral, outer beads", "layer_lateral_mm",
                                     "lateral"))]))
    name = "beads_by_layer.png"
    figures.measured_layers(out / name, list(range(1, len(data["states"][0]["layer_axial_mm"])
                                                   + 1)), columns,
                            f"Measured against modelled, by bead layer (bonded, {mesh} mesh; "
                            "colour: farther than its u_val from the continuum)",
                            highlight=beyond)
    d.img(name, "Measured against modelled bead displacements by layer")
    variants = list(dict.fromkeys(r["variant"] for r in doc["references"]))
    if len(variants) > 1:
        columns = []
        for st in data["states"]:
            here = {r["variant"]: r for r in doc["references"] if r["model"] == NH
                    and r["state"] == st["state"] and not r.get("failed")}
            f = st["layer_noise_mm"]
            columns.append((f"{percent(st['strain'])} compression", [
                (f"{what} [mm]", st[key], f[comp], [],
                 [(v, here[v][key]) for v in variants if v in here])
                for what, key, comp in (("mean axial displacement", "layer_axial_mm", "axial"),
                                        ("outward lateral, outer beads", "layer_lateral_mm",
                                         "lateral"))]))
        name = "continuum_assumptions.png"
        figures.measured_layers(out / name, list(range(1, 8)), columns,
                                f"The continuum ({NH}) under each assumption")
        d.img(name, "The continuum under each plate, travel and nu assumption")


def definitions():
    return [
        "measurement noise: the scatter of a measured bead displacement component, the RMS "
        "residual of a degree-4 polynomial of the rest positions fitted to the measured "
        "displacement of each state; combined over components as each error is.",
        "within measurement: a run whose total RMS error is at most its u_val at that state "
        "(the noise, the neo-Hookean continuum's spread over the unmeasured plate friction, "
        "travel and nu, "
        "and the neo-Hookean reference's change over its last refinement, combined in "
        "quadrature); two runs whose RMS errors differ by less than the larger u_val are not "
        "ranked. '*' in the tables: the error beyond the noise, sqrt(rms^2 - noise^2), "
        f"exceeds {WITHIN:g} times the noise in total, axially or laterally.",
        "rigid in-plane motion: the translation in x, y and rotation about z best carrying "
        "the rest beads to a measured state (2-D Procrustes); removed from each state before "
        "comparing.",
        "fitted travel: the moving plate's travel per state whose neo-Hookean continuum "
        "(bonded) fits the measured axial bead displacements best in least squares."]
