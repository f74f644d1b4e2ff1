"""The engines study's files: metrics.json (each run's errors, the per-solver findings and the
rows the gate reads) and report.md/.html. Every sentence is computed from the runs it is
written with."""
import numpy as np

from model.simulators.newton import LADDER, spec

from ...measuring import catalogue
from ...measuring.error_model import P1_LINEAR
from ...reporting.document import Document, fmt
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from .study import BCS, CASE_NAMES, CONVERGED, MATCH, MESHES, SOLVERS, mesh_sizes

GATED = catalogue.gated("engine_error")
REGIMES = ("linear regime", "at the load")


def _spread(values):
    """'median [min-max], n of N' of the values (None: a failed run, counted in N)."""
    got = [v for v in values if v is not None]
    if not got:
        return f"failed, 0 of {len(values)}"
    med, lo, hi = np.median(got), min(got), max(got)
    return f"{fmt(med, 3)} [{fmt(lo, 3)} to {fmt(hi, 3)}], {len(got)} of {len(values)}"


def _runs(data, case, regime, model):
    return [r for r in data["runs"] if r["case"] == case and r["regime"] == regime
            and r["model"] == model]


def convergence(data, case, regime, solver, ladder):
    """The smallest iteration count from which the quantity stays within CONVERGED of its own
    value at the ladder's top (relative to it) on every mesh; None where no count does or a
    run failed; the reason beside."""
    top = ladder[-1]
    meshes = sorted({r["mesh"] for r in _runs(data, case, regime, spec(solver, top))})
    if not meshes:
        return None, "not run"
    for n in ladder:
        ok = True
        for mesh in meshes:
            for m in [k for k in ladder if k >= n]:
                a = [r for r in _runs(data, case, regime, spec(solver, m)) if r["mesh"] == mesh]
                b = [r for r in _runs(data, case, regime, spec(solver, top)) if r["mesh"] == mesh]
                if not a or not b or a[0]["failed"] or b[0]["failed"]:
                    return None, f"a run failed (at {m} iterations on {mesh})"
                if abs(a[0]["value_rel"] - b[0]["value_rel"]) > CONVERGED * abs(
                        b[0]["value_rel"]):
                    ok = False
        if ok:
            return n, ("only at the ladder's top: not shown converged" if n == top else None)
    return None, "no count"


def findings(data, ladder):
    """Per solver: its default settings' model-form and total errors per case and regime, the
    iteration count at which its own answer converges, the settings at which it matches FEM P1
    (|model-form error| <= MATCH on every mesh)."""
    out, costs = {}, data.get("costs") or {}
    for solver in SOLVERS:
        counts = ladder.get(solver, (None,))
        f = {"cases": {}}
        for case in CASE_NAMES:
            for regime in REGIMES:
                default = _runs(data, case, regime, spec(solver, counts[0]))
                if not default:
                    continue
                key = f"{case}/{regime}"
                match = [n for n in counts
                         if (rs := _runs(data, case, regime, spec(solver, n)))
                         and all(r["model_form"] is not None and abs(r["model_form"]) <= MATCH
                                 for r in rs)]
                conv = convergence(data, case, regime, solver, counts) \
                    if solver in ladder else (None, "not iterative")
                top = _runs(data, case, regime, spec(solver, counts[-1]))
                n_runs = sum(len(_runs(data, case, regime, spec(solver, n))) for n in counts)
                n_failed = sum(1 for n in counts for r in _runs(data, case, regime, spec(solver, n))
                               if r["failed"])
                # what one simulated second costs at the count it converges from (the bench's)
                at = solver if solver not in ladder else (
                    None if conv[0] is None else spec(solver, conv[0]))
                f["cases"][key] = {
                    "cost_model": at, "cost": cost_of(costs, at),
                    "top_iterations": counts[-1],
                    "top_model_form": [r["model_form"] for r in top],
                    "runs_failed": [n_failed, n_runs],
                    "dt_s": sorted({r["dt_s"] for r in default if r.get("dt_s")}),
                    "residual_n": [r.get("static_residual_n") for r in default],
                    "model_form": [r["model_form"] for r in default],
                    "total": [r["total"] for r in default],
                    "discretisation": [r["discretisation"] for r in default],
                    "estimate": [r["estimate"] for r in default],
                    "u_num": max((r.get("u_num") or 0.0) for r in default),
                    "failed": [r["failed"] for r in default if r["failed"]],
                    "matches_p1_at": match, "converged_at": conv[0], "converged_why": conv[1]}
        out[solver] = f
    return out


def cost_of(costs, model):
    """[median, smallest, largest] wall-clock seconds per simulated second of ``model`` on the
    bench's machine, or None where the bench did not time it."""
    row = costs.get(model) if model else None
    return None if row is None else [row["wall_s_per_simulated_s"], *row["wall_range"]]


def gate_rows(data):
    return [{"mesh": r["mesh"], "bc": f"{r['case']}/{r['bc']}/{r['regime']}", "model": r["model"],
             "engine_error": None if r["model_form"] is None else abs(r["model_form"])}
            for r in data["runs"] if r["solver"]]


def matches(f, ladder):
    """{case: [(solver, least count or None)]}: the solvers within MATCH of FEM P1 in every
    regime of the case on every mesh, each from the least iteration count from which it stays
    so (None: a solver without iterations)."""
    out = {}
    for case in CASE_NAMES:
        got = []
        for solver in SOLVERS:
            cs = [c for k, c in f[solver]["cases"].items() if k.startswith(case + "/")]
            if not cs:
                continue
            counts = ladder.get(solver, (None,))
            common = [n for n in counts if all(n in c["matches_p1_at"] for c in cs)]
            # from a count on: every larger count matches too
            start = next((n for i, n in enumerate(counts) if all(m in common for m in counts[i:])),
                         "none")
            if start != "none":
                got.append((solver, start))
        out[case] = got
    return out


def pick(f, ladder, costs):
    """(model, [cases]) of the setting that matches FEM P1 on the most cases (``matches``),
    the cheapest of those per simulated second (the bench's; one not timed last), the fewest
    iterations among equals; None where none matches on any case."""
    got = matches(f, ladder)
    best = None
    for solver in SOLVERS:
        for n in ladder.get(solver, (None,)):
            where = [c for c, ms in got.items() for sv, start in ms
                     if sv == solver and (start is None or n >= start)]
            model = spec(solver, n) if n else solver
            cost = cost_of(costs, model)
            key = (-len(where), cost[0] if cost else float("inf"), n or 0)
            if where and (best is None or key < best[0]):
                best = (key, model, where)
    return None if best is None else best[1:]


def answer(f, ladder, quick, installed, shear=None, costs=None, where="", baseline=None,
           tets=None):
    """The index's line: per case, which engine replaces FEM P1 there (within MATCH on both
    regimes and every mesh) and from which setting; the pick with its cost on the bench's
    machine (``where``) beside linear FEM P1's there (``baseline``, its bench row), the sizes
    of the quick meshes it was judged on (``tets``, ``mesh_sizes``), said provisional in the
    pick itself: judged on the quick meshes alone, and, where its count is below the one its
    answer converges from, not converged in iterations."""
    if not installed:
        return "not measured: the engines extra is not installed"
    if quick:
        return "quick: not decided (`pbcm run engines` decides)"
    parts = []
    for case, got in matches(f, ladder).items():
        name = CASE_NAMES[case]
        who = ", ".join(f"{sv}" + (f" from {n} iterations" if n else "") for sv, n in got)
        # a base that holds one component of a node, which Newton's particles hold only by
        # being set back between steps: a miss there is the solver's or the support's
        partial = (f" (its {BCS[case]} base held only between steps: the support's share "
                   "not measured, so not decided for the iterative solvers)"
                   if BCS[case] == "sliding" and not got else "")
        parts.append(f"{name} ({case}): {who or 'none'}{partial}"
                     + ("" if got else _closest(f, case)))
    laws = ", ".join(f"{sv} " + (f"{fmt(g, 3)} G" if g > 1e-6 else "0 (to first order)")
                     for sv, g in (shear or {}).items())
    same = [sv for sv, g in (shear or {}).items() if abs(g - 1.0) < 1e-6]
    chosen = pick(f, ladder, costs or {})
    if chosen:
        model, cases = chosen
        cost = cost_of(costs or {}, model)
        solver, n = next((sv, k) for sv in SOLVERS for k in ladder.get(sv, (None,))
                         if (spec(sv, k) if k else sv) == model)
        # where the pick's count is below the one its answer converges from (within 1 %)
        early = [_where(k) for k, c in f[solver]["cases"].items() if n is not None
                 and k.split("/")[0] in cases
                 and (c["converged_at"] is None or c["converged_at"] > n)]
        # FEM P1's distance as the scorecard reads it (unsigned), with the u_val it is
        # read against: the quick reference's estimate (a computed comparison)
        p1 = [(CASE_NAMES[c], _median(_unsigned(got["discretisation"]))
               + f" (u_val {fmt(got['u_num'], 2)})")
              for c in cases if (got := f[solver]["cases"].get(f"{c}/{REGIMES[0]}"))]
        sizes = sizes_text(tets or {}, [c for c in cases if c in CASE_NAMES])
        # a pick judged on the cases' quick meshes alone, or whose answer still moves with
        # the count, is provisional: said in the pick
        said = (f"pick {model}, provisional (judged on the cases' quick meshes and quick "
                "references only: no run on their full meshes decides it"
                + (f"; not converged in iterations at {n}: not within "
                   f"{CONVERGED:.0%} of its answer at the ladder's top on " + "; ".join(early)
                   if early else "") + ")"
                + f" (the setting within {MATCH:g} of FEM P1 on the most cases, then "
                "the cheapest per simulated second): within it on "
                + ", ".join(CASE_NAMES[c] for c in cases)
                + (", every case" if len(cases) == len(CASE_NAMES) else
                   ", not on " + ", ".join(
                       CASE_NAMES[c] + (" (not decided there: its sliding support)"
                                        if BCS[c] == "sliding" else "")
                       for c in CASE_NAMES if c not in cases))
                + f", so within {MATCH:g} of FEM P1's own distance from the continuum on "
                f"those {len(MESHES)} quick meshes (" + (f"{sizes}; " if sizes else "")
                + "|Q_P1 - Q_c| / |Q_c|, the median over the meshes: "
                + ", ".join(f"{name} {v}" for name, v in p1) + ", linear regime)"
                + (f"; {fmt(cost[0], 3)} [{fmt(cost[1], 3)}-{fmt(cost[2], 3)}] wall s per "
                   f"simulated s on the paper's cube ({where}, single precision on Warp's "
                   "CPU backend through pbcm's adapter): "
                   + ("real time there" if cost[0] <= 1.0 else "not real time there")
                   + (f", against {P1_LINEAR}'s {fmt(base[0], 3)} [{fmt(base[1], 3)}-"
                      f"{fmt(base[2], 3)}] (double precision, pbcm's compiled kernels, serial: "
                      "unlike treatment, the engine's step through an adapter, so a cost a "
                      "user of each would pay, not a comparison of kernels)"
                      if (base := cost_of({P1_LINEAR: baseline}, P1_LINEAR)) else "")
                   if cost else "; its cost not timed (`pbcm bench --family`)"))
    else:
        said = f"no setting comes within {MATCH:g} of FEM P1 on any case: none to pick"
    failed = failed_counts(f)
    if failed:      # a failure is a result: counted in the line that picks
        said += ("; failed runs (not at rest), every setting: "
                 + ", ".join(f"{sv} {n} of {t}" for sv, (n, t) in failed.items()))
    return (said + f". Within {MATCH:g} of FEM P1 (the difference a fraction of the continuum's "
            "value, both regimes, every mesh), with the material mapped as Newton documents "
            "it: " + "; ".join(parts)
            + (f" ({', '.join(same)}: its law is the material's at small strain, so a match is "
               "its solver reaching FEM P1's answer, FEM P1's own distance from the continuum "
               "included, not an accuracy beyond it)" if same else "")
            + (f"; under that mapping the laws' small-strain shear moduli are {laws}" if laws
               else ""))


def sizes_text(tets, cases):
    """"the cube's 320 and 384 tetrahedra, the cantilever's 1280 and 1536": the sizes of each
    of ``cases``' meshes in ``tets`` ({case: {mesh: tetrahedra}}, ``mesh_sizes``), in the
    study's mesh order; '' where none is known."""
    got = [(CASE_NAMES[c], " and ".join(str(n) for n in tets[c].values()))
           for c in cases if tets.get(c)]
    return ", ".join(f"{name}'s {n}" + (" tetrahedra" if k == 0 else "")
                     for k, (name, n) in enumerate(got))


def scorecard(doc):
    """The index's scorecard rows: per case and regime, each solver at its default settings,
    its model-form error against FEM P1 (median over the study's meshes [range], n of N, a
    failed run counted), banded 0 within MATCH, 1 within 0.20, 2 beyond or failed."""
    if not doc.get("installed") or doc["parameters"]["quick"]:
        return []
    f, meshes = doc["findings"], "/".join(doc["parameters"]["meshes"])
    n_meshes, tets = len(doc["parameters"]["meshes"]), doc.get("mesh_tets") or {}
    # the study's own meshes and signs, said in its shared cells: not the cases' quantities
    marked = f" (engines study, {n_meshes} quick mesh{'es' if n_meshes != 1 else ''}"
    out = []
    for case, name in CASE_NAMES.items():
        for regime in REGIMES:
            key, cells, p1, u = f"{case}/{regime}", {}, None, None
            for solver in SOLVERS:
                c = f[solver]["cases"].get(key)
                if c is None:
                    continue
                vals = c["model_form"]
                got = [abs(v) for v in vals if v is not None]
                worst = max(got) if len(got) == len(vals) and got else float("inf")
                # an iterative solver on a base holding one component of a node (set back only
                # between steps): its constraints are not FEM's, so not decided
                partial = BCS[case] == "sliding" and solver in LADDER and got  # a failure stays one
                cells[solver] = (("not decided (its support held between steps only): "
                                  if partial else "") + _spread(vals),
                                 0 if worst <= MATCH else 1 if worst <= 0.2 else 2)
                p1 = p1 or _spread(c["discretisation"])
                u = u if u is not None else c.get("u_num")
            if cells:
                size = "/".join(str(n) for n in tets.get(case, {}).values())
                out.append((f"{case}/{BCS[case]}{'' if regime == 'linear regime' else ' at the load'}"
                            f" (engines study, the case's quick meshes {meshes}"
                            + (f", {size} tetrahedra," if size else "") + " and references)",
                            "model-form vs FEM P1 at the engine's defaults, signed", cells,
                            (p1 + marked + ", signed)",
                             "n/a" if u is None else fmt(u, 2) + " (of FEM P1's distance; "
                             + marked.removeprefix(" (") + ")")))
    return out


def cost_where(data):
    """Where the costs were measured: the cube's size and the bench's machine."""
    m = data.get("machine") or {}
    return (f"{data.get('cost_tets')} tetrahedra, "
            + (f"{m.get('cpu')}, serial: one of its {m.get('cores')} cores" if m
               else "the bench's machine"))


def shear_moduli(material):
    """{solver: its law's small-strain shear modulus over G} under the documented mapping."""
    from model.simulators.newton import small_strain_moduli
    return {sv: small_strain_moduli(sv.removeprefix("newton-"), material)[0] / material.G
            for sv in SOLVERS}


def write(out, study, s, data):
    found = findings(data, s.ladder) if data["installed"] else {}
    # the meshes' sizes from the cases' builders under the recorded problem (nothing is run)
    tets = mesh_sizes(s) if data["installed"] else {}
    doc = jsonable({"case": study.name, "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, "findings": found, "mesh_tets": tets,
                    "answer": answer(found, s.ladder, s.quick, data["installed"],
                                     shear_moduli(s.material) if data["installed"] else None,
                                     data.get("costs"), cost_where(data),
                                     data.get("baseline_cost"), tets),
                    "gate_runs": gate_rows(data)})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def _signed(values):
    """'median [min to max], n of N' of signed values (None: a failed run, counted in N)."""
    return _spread(values)


def _where(key):
    case, regime = key.split("/")
    return f"{CASE_NAMES[case]}, {regime}"


def _closest(f, case):
    """' (at their defaults, linear regime: newton-vbd 0.439, ...)': each solver's median
    model-form error on a case none matches, so that a miss is a number, not a word."""
    said = [f"{sv} {_median(_unsigned(c['model_form']))}" for sv in SOLVERS
            if (c := f.get(sv, {}).get("cases", {}).get(f"{case}/{REGIMES[0]}"))]
    return f" (at their defaults, linear regime: {', '.join(said)})" if said else ""


def _unsigned(values):
    """``values`` as magnitudes, a failed run (None) kept as one."""
    return [None if v is None else abs(v) for v in values]


def _median(values):
    """The median of a run's values over the meshes, signed; 'failed' where a run failed."""
    if not values or any(v is None for v in values):
        return "failed"
    return fmt(float(np.median(values)), 3)


def _per_case(cases, key):
    """'the bar a / b, the cube ...': each case's median over the meshes of ``key``, linear
    regime / at the load."""
    out = []
    for case, name in CASE_NAMES.items():
        got = [_median(cases[k][key]) for k in (f"{case}/{r}" for r in REGIMES) if k in cases]
        if got:
            out.append(f"{name} {' / '.join(got)}")
    return ", ".join(out)


def solver_line(solver, f, ladder, moduli, material):
    """One solver's finding: its law at small strain under the documented mapping, its
    model-form error per case at its defaults and at the ladder's top, its failures."""
    cases = f["cases"]
    G, lam = moduli
    g = (f"{fmt(G / material.G, 3)} G" if G > 1e-6 * material.G else "0 (to first order)")
    text = (f"**{solver}** ({_setting(solver, ladder, cases)}; its law at small strain: shear "
            f"modulus {g}, lambda {fmt(lam / material.lam, 3)} of the material's): model-form "
            "error at its defaults (signed, median over the meshes, linear regime / at the "
            f"load): {_per_case(cases, 'model_form')}")
    if solver in ladder:
        text += f"; at {ladder[solver][-1]} iterations: {_per_case(cases, 'top_model_form')}"
    return text + "."


def dynamic_summary(dynamic):
    """{model: {"reaction": [...], "end": [...], "at_rest": n, "failed": [...]}} over the meshes
    of the dynamic push (None: a failed run)."""
    out = {}
    for r in dynamic:
        m = out.setdefault(r["model"], {"reaction": [], "end": [], "at_rest": 0,
                                        "unresolved": 0, "failed": []})
        m["reaction"].append(None if r["failed"] else r["reaction_time_rel_l2"])
        m["end"].append(None if r["failed"] else r["disp_end_push_rel_l2"])
        m["at_rest"] += bool(r["at_rest"]) and not r["failed"]
        # still moving, where a float32 position cannot resolve the rest speed: not decided
        m["unresolved"] += (not r["at_rest"] and not r["failed"]
                            and (r.get("float32_speed_m_s") or 0) > r["rest_speed_m_s"])
        if r["failed"]:
            m["failed"].append(r["failed"])
    return out


def _float32_speeds(dynamic):
    """'a to b m/s': the smallest speeds the engines' float32 positions resolve per step."""
    v = sorted({r["float32_speed_m_s"] for r in dynamic if r.get("float32_speed_m_s")})
    return (f"{fmt(v[0], 2)}" + (f" to {fmt(v[-1], 2)}" if len(v) > 1 else "") + " m/s"
            if v else "n/a")


def ladder_spread(dynamic, ladder):
    """{solver: the largest change of the dynamic reaction error between its ladder's counts
    on one mesh}, for the iterative solvers with every run of the ladder there."""
    out = {}
    for solver, counts in ladder.items():
        by_mesh = {}
        for r in dynamic:
            if r["solver"] == solver:
                by_mesh.setdefault(r["mesh"], []).append(r["reaction_time_rel_l2"])
        spans = [max(v) - min(v) for v in by_mesh.values()
                 if len(v) == len(counts) and None not in v]
        if spans:
            out[solver] = max(spans)
    return out


def dynamic_line(dynamic):
    """The dynamic push in one line: each solver at its defaults and FEM P1 (RK4, lumped
    mass) against linear FEM's exact transient on the same tetrahedra; None without runs."""
    got = dynamic_summary(dynamic)
    if not got:
        return None
    element = dynamic[0]["element"]
    shown = [m for m in (*SOLVERS, "fem-linear", "fem-neohookean") if m in got]
    nh = got.get("fem-neohookean")
    share = None if nh is None or None in nh["reaction"] else float(np.median(nh["reaction"]))

    def within(m):      # at most the finite-strain share (and a tenth of it): not resolved
        v = got[m]["reaction"]
        return (m in SOLVERS and share is not None and None not in v
                and float(np.median(v)) <= 1.1 * share)
    return ("**The paper's dynamic push** (the cube pushed 1.7 mm over 1 s, then held: the "
            "top reaction over time against linear FEM's exact transient, consistent mass, "
            f"{element} on the same tetrahedra, relative L2, median over the meshes; at its "
            "defaults): " + ", ".join(
                f"{m} {_median(got[m]['reaction'])}"
                + (" (not resolved from the finite-strain share)" if within(m) else "")
                for m in shown)
            + " (fem-linear: FEM P1 itself stepped by RK4 with lumped masses, the integrator's "
            "own share; fem-neohookean: the continuum's law on the same tetrahedra, what the "
            "push's finite strain adds against a linear transient, which a solver with a "
            "nonlinear law shares).")


def failed_counts(f):
    """{solver: (runs failed, runs)} of the solvers with a failed run."""
    out = {}
    for solver in SOLVERS:
        cases = f[solver]["cases"]
        failed, total = (sum(c["runs_failed"][i] for c in cases.values()) for i in (0, 1))
        if failed:
            out[solver] = (failed, total)
    return out


def failures_line(f):
    """The failed runs first: per solver, how many of its runs did not come to rest, where
    every setting failed, and what it settled at elsewhere; None without failures."""
    said = []
    for solver, (failed, total) in failed_counts(f).items():
        cases = f[solver]["cases"]
        every = [_where(k) for k, c in cases.items() if c["runs_failed"][0] == c["runs_failed"][1]]
        rest = {k: c for k, c in cases.items() if c["runs_failed"][0] < c["runs_failed"][1]}
        said.append(f"{solver} {failed} of {total}"
                    + (f", at every setting in {'; '.join(every)}" if every else "")
                    + ("; where it came to rest, its model-form error at its defaults is "
                       + "; ".join(f"{_where(k)} {_median(c['model_form'])}"
                                   for k, c in rest.items()) if rest else ""))
    if not said:
        return None
    return ("**Failed runs** (not at rest: each counts against its solver, none is left out): "
            + ". ".join(said) + ".")


def findings_rows(doc, ladder, quick):
    rows = []
    for solver in SOLVERS:
        for key, c in doc["findings"][solver]["cases"].items():
            if solver not in ladder:
                conv = "not iterative"
            elif quick:
                conv = "quick: not decided"
            elif c["converged_at"] is not None:
                conv = f"{c['converged_at']}" + (f" ({c['converged_why']})"
                                                 if c["converged_why"] else "")
            else:
                conv = f"not within the ladder ({c['converged_why']})"
            match = ("quick: not decided" if quick else
                     ", ".join(str(n) if n else "its setting" for n in c["matches_p1_at"])
                     or "none")
            top = "-" if solver not in ladder else _signed(c["top_model_form"])
            res = [v for v in c["residual_n"] if v is not None]
            cost = c.get("cost")
            rows.append([solver, _where(key), _signed(c["model_form"]), top,
                         _signed(c["total"]) + _cancellation(c), _signed(c["discretisation"]),
                         fmt(c["u_num"], 2) if c.get("u_num") is not None else "n/a",
                         fmt(max(res), 2) if res else "n/a", conv,
                         "-" if c.get("cost_model") is None else
                         "not timed" if cost is None else
                         f"{fmt(cost[0], 3)} [{fmt(cost[1], 3)}-{fmt(cost[2], 3)}]", match,
                         f"{c['runs_failed'][0]} of {c['runs_failed'][1]}"])
    return rows


def _cancellation(c):
    """Beside a solver's distance from the continuum: '; cancellation on k of n meshes' where,
    on a mesh, it is smaller than FEM P1's own and of the other sign (its error and the
    mesh's cancel: not accuracy). Two distances on one mesh share the continuum's value, so
    they differ by the model-form error alone, which the table gives."""
    pairs = [(t, d) for t, d in zip(c["total"], c["discretisation"])
             if t is not None and d is not None]
    k = sum(1 for t, d in pairs if abs(t) < abs(d) and t * d < 0)
    return f"; cancellation on {k} of {len(pairs)} meshes" if k else ""


def _setting(solver, ladder, cases=None):
    counts = ladder.get(solver)
    dts = sorted({d for c in (cases or {}).values() for d in c["dt_s"]})
    dt = (f", dt {fmt(dts[0], 3)}" + (f" to {fmt(dts[-1], 3)}" if len(dts) > 1 else "") + " s"
          if dts else "")
    return (f"explicit, at its own stable step{dt}" if counts is None else
            f"{counts[0]} iterations a step by default{dt}; ladder {', '.join(map(str, counts))}")


def build(out, study, s, doc):
    from model.simulators.newton import small_strain_moduli
    d = Document(f"pbcm report: {study.name}")
    if not doc["installed"]:
        d.opening(["**Not measured here**: the engines extra is not installed (`pip install -e "
                   "\".[engines]\"`), so no Newton model ran; every row below reads 'not "
                   "installed'."])
        d.table(["solver", "status"], [[sv, "not installed"] for sv in SOLVERS])
        return d
    ladder, material = s.ladder, s.material
    f = doc["findings"]
    moduli = {sv: small_strain_moduli(sv.removeprefix("newton-"), material) for sv in SOLVERS}
    lines = [solver_line(sv, f[sv], ladder, moduli[sv], material)
             for sv in sorted(SOLVERS, key=lambda sv: -sum(bool(c["matches_p1_at"])
                                                         for c in f[sv]["cases"].values()))]
    head = (["**Quick: not decided** (`pbcm run engines` decides: two meshes, the full "
             "iteration ladders): the lines below are a preview."] if s.quick
            else [f"**In one line:** {doc['answer']}."])
    failures, dyn = failures_line(f), dynamic_line(doc.get("dynamic") or [])
    d.opening(head + ([failures] if failures else []) + lines + ([dyn] if dyn else []))
    d.p(f"The Newton engine ({doc['engine']}, single precision on Warp's CPU backend) runs each "
        "case's problem through the cases' own runner, beside FEM P1 on the same tetrahedra: "
        "linear FEM in the linear regime, neo-Hookean FEM at the load (the continuum's law; "
        "not the engine's own, so the model-form error (Q - Q_P1) / |Q_c| holds both what the "
        "engine's law differs from the material's by and what its solver and supports add). "
        "The distance from the continuum (Q - Q_c) / |Q_c| adds FEM P1's own discretisation "
        "error on the mesh, shown beside it: a distance below FEM P1's own is a cancellation "
        "of the two, not accuracy. The material is mapped as Newton's documentation defines its "
        "parameters (k_mu = G, k_lambda = lambda); the small-strain moduli each law then has "
        "are computed from the law as transcribed from the engine's kernels "
        "(docs/simulators.md). Each equilibrium is run to rest: a solver whose motion stops "
        "shrinking, or that is still moving after 200 of the body's slowest periods, is a "
        "failed run; the rest test bounds the motion still to come (1e-3 of the largest "
        "displacement), not how far the engine's law is from balanced, which the residual "
        "column gives (the largest free-node force of that law at rest, linear regime). A "
        f"quantity converges in iterations where it stays within {CONVERGED:.0%} of its own "
        "value at the ladder's top from that count on, on every mesh; a solver matches FEM P1 "
        f"where |Q - Q_P1| / |Q_c| is at most {MATCH:g} on every mesh. The meshes are the "
        "cases' quick meshes, split 'five' and 'six' (two splits of one lattice size, the "
        "quick run 'five' only" + (f"; here {sizes}" if (sizes := sizes_text(
            doc.get("mesh_tets") or {}, CASE_NAMES)) else "")
        + "), and their references the cases' quick references (each "
        "reference's own estimate in the table of every run). The bar is the block settling "
        "under its own weight on a sliding base (self-weight), the cube the paper's on a "
        "clamped base, the cantilever clamped. Only the iteration count was varied; the "
        "substeps and the step were not. Newton's particles cannot hold one component "
        "of a node: the bar's sliding base is set back after every step, which the explicit "
        "solver then satisfies exactly and the iterative ones (VBD, XPBD) only between steps; "
        "how much of their error on the bar that support makes is not measured here.")
    d.h(2, "Each solver on each case")
    d.p("Per case and regime (signed errors, median [range], n of N meshes): the model-form "
        "error at the solver's defaults and at the top of its iteration ladder, the distance "
        "from the continuum at its defaults and FEM P1's own on the same meshes, the largest "
        "residual force of its law at rest, the iteration count from which its answer stays "
        f"within {CONVERGED:.0%} of its own answer at the ladder's top and what a simulated "
        "second costs at that count (wall clock, the bench's real-time family: the paper's "
        "push on its 125-node cube at the solver's own step, through pbcm's adapter, median "
        "[range over the bench's rounds]; '-' where no count converged), the counts at which "
        f"it is within {MATCH:g} of FEM P1 on every mesh, and its failed runs over every "
        "setting. A distance from the continuum is read against u_val (the reference's "
        "estimate and the continuum's spread over the meshes, in quadrature); on one mesh a "
        "solver's and FEM P1's distances share the continuum's value, so they differ by the "
        "model-form error alone; a distance below FEM P1's own and of the other sign is "
        "cancellation. An iterative solver with few iterations a step can stop moving before "
        "its law balances (its updates below single precision's resolution): its answer "
        "then moves with the count although each run came to rest, and the residual column "
        "says how far from balanced its law is (in the linear regime single precision's "
        "resolution of the forces dominates it).")
    d.table(["solver", "case", "model-form error, defaults", "model-form error, ladder's top",
             "from the continuum, defaults", "FEM P1 from the continuum",
             "u_val of a distance", "residual [N]",
             "converged from (iterations)",
             f"wall s per simulated s there ({cost_where(doc)})",
             f"within {MATCH:g} of FEM P1 at (iterations)", "failed runs"],
            findings_rows(doc, ladder, s.quick), keys=2)
    rows = []
    for r in doc["runs"]:
        rows.append([r["case"], r["regime"], r["model"], r["mesh"],
                     "n/a" if r["value_rel"] is None else fmt(r["value_rel"], 4),
                     "n/a" if r["model_form"] is None else fmt(r["model_form"], 3),
                     "n/a" if r["total"] is None else fmt(r["total"], 3),
                     "n/a" if r["discretisation"] is None else fmt(r["discretisation"], 3),
                     "n/a" if r["estimate"] is None else fmt(r["estimate"], 2),
                     r["failed"] or ""])
    got = dynamic_summary(doc.get("dynamic") or [])
    if got:
        d.h(2, "The paper's dynamic push")
        d.p("The paper cube's push (1.7 mm over 1 s, then held until at rest or 1 s), run by "
            "each model at its own step, against linear FEM's exact transient (modal, "
            f"consistent mass, {doc['dynamic'][0]['element']} on the same tetrahedra): the "
            "top reaction over time and the displacement at the push's end, relative L2, "
            "median [range] over the meshes, n of N (a failed run counted); fem-linear is FEM "
            "P1 stepped by RK4 with lumped masses (the integrator's own share), fem-neohookean "
            "the continuum's law on P1 (what the push's finite strain adds against the linear "
            "transient, which every nonlinear law shares). 'At rest' is "
            f"every node slower than {fmt(doc['dynamic'][0]['rest_speed_m_s'], 2)} m/s; a "
            "single-precision position resolves over the engines' steps no speed below "
            + _float32_speeds(doc["dynamic"]) + ", so an engine's 'still moving' may be its "
            "arithmetic's, not its motion.")
        d.table(["model", "reaction over time", "displacement at the push's end",
                 "at rest after the hold", "failed"],
                [[m, _spread(g["reaction"]), _spread(g["end"]),
                  f"{g['at_rest']} of {len(g['reaction'])}"
                  + (f" ({g['unresolved']} not decided: below float32's resolution)"
                     if g["unresolved"] else ""), "; ".join(g["failed"]) or "-"]
                 for m, g in got.items()])
        moved = ladder_spread(doc["dynamic"], ladder)
        if moved:
            d.p("Up each iterative solver's ladder the reaction's error moves by at most "
                + ", ".join(f"{fmt(v, 2)} ({sv})" for sv, v in moved.items())
                + ": the push is slow against the body's periods, and each step starts "
                "from the last one's state, so a few iterations already reach it.")
    d.h(2, "Every run")
    d.table(["case", "regime", "model", "mesh", "Q / abs(Q_c)", "model-form error (signed)",
             "from the continuum (signed)", "FEM P1 from the continuum", "reference's estimate",
             "failed"], rows, keys=4)
    return d
