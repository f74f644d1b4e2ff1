"""The real-time study's files: metrics.json (each run's errors and the bench's cost beside
them, the verdict and the rows the gate reads), report.md/.html and the figure. Every sentence
is computed from the data it is written with."""
import math
from pathlib import Path

from model.compose import simulator
from ...measuring import catalogue
from ...measuring.error_model import JUDGES, ROUND_OFF, u_val
from ...reporting import figures
from ...reporting.costs import REAL_TIME
from ...reporting.document import Document, fmt
from ...reporting.report import environment, write_study
from ...running.runner import jsonable
from ...reporting import costs as bench_costs
from .study import P1, CubePush

GATED = catalogue.gated("disp_rel_l2", "disp_form_rel_l2")


def laws(runs):
    """The laws of the runs, in their order (an implicit preset's is fem-corotated's)."""
    return tuple(dict.fromkeys(r["law"] for r in runs))


def models(runs):
    """The models of the runs, in their order."""
    return tuple(dict.fromkeys(r["model"] for r in runs))


def ranked_laws(runs):
    """The laws ranked: every one but the engines' solvers (timed on one core, the others on
    two: their costs not compared); FEM P1 with the continuum's law, the yardstick of the
    model-form error (0 by definition), is ranked too: a user can run it."""
    return tuple(m for m in laws(runs) if not engine(m))


def engine(model):
    """Whether ``model`` is an engine's solver run through pbcm's adapter (Newton's)."""
    return simulator(model) is not None


def err(v):
    """An error for a sentence: four decimals (the same for every model), 'n/a' for None."""
    return "n/a" if v is None else (f"{v:.4f}" if abs(v) >= 1e-4 else fmt(v, 2))


def _cost(run):
    """(wall s per simulated s, mode, [lo, hi] over the rounds) of a run's faster mode, or
    (None, None, None) where the bench did not time it."""
    cost, mode = bench_costs.best(run["cost"])
    if cost is None:
        return None, None, None
    key = "two_thread_range" if mode == "two threads" else "wall_range"
    return cost, mode, run["cost"][key]


MARGIN = 0.9       # the step a cautious user takes: 90 % of the own stable step
STIFF = 0.05       # a top force within this of FEM P1's (relative to the continuum's): stiff right


def reach(runs, margin=1.0):
    """{law: its reach, or None}: the largest size at which any model with that law's statics
    (an implicit preset's is fem-corotated's) runs in real time in its faster mode (median wall
    time per simulated second at most REAL_TIME), the cheapest such model there, and the reach
    over the rounds' range: ``sure`` the largest size real time in every round (in one of its
    modes: a user picks the mode), ``maybe`` the largest real time in some round. With
    ``margin`` < 1 every cost is divided by it (a step that much below the own stable
    step)."""
    out = {}
    for law in laws(runs):
        own = [(r, c / margin, mode, [x / margin for x in _either(r, rng)]) for r in runs
               if r["law"] == law for c, mode, rng in [_cost(r)] if c is not None]
        timed = own
        fit = [x for x in timed if x[1] <= REAL_TIME]
        if not fit:
            out[law] = None
            continue
        top = max(x[0]["tets"] for x in fit)
        r, cost, mode, rng = min((x for x in fit if x[0]["tets"] == top), key=lambda x: x[1])
        out[law] = {"tets": top, "model": r["model"], "mode": mode, "cost": cost,
                    "range": [x / margin for x in _cost(r)[2]], "run": r,
                    "sure": max((x[0]["tets"] for x in timed if x[3][1] <= REAL_TIME),
                                default=None),
                    "maybe": max(x[0]["tets"] for x in timed if x[3][0] <= REAL_TIME)}
    return out


def _either(run, faster):
    """[smallest, largest] over the rounds in the mode real time in more of them: the faster
    mode's range ``faster``, widened to the other mode's smallest and narrowed to its largest
    where that is lower (the rounds a user of either mode would see)."""
    c = run["cost"]
    ranges = [x for x in (c.get("wall_range"), c.get("two_thread_range")) if x]
    return [min(x[0] for x in ranges + [faster]), min(x[1] for x in ranges + [faster])]


def bound(runs, run):
    """A run's error bound: its model-form error plus FEM P1's distance from the continuum on
    the same mesh (the discretisation error every model there shares), the triangle
    inequality's bound of its distance from the continuum; a model whose own distance is
    smaller has an error that cancels part of FEM P1's, luck of that mesh that the bound does
    not reward. None where either part is missing."""
    p1 = next((r for r in runs if r["model"] == P1 and r["tets"] == run["tets"]), None)
    if run["disp_form_rel_l2"] is None or p1 is None or p1["disp_rel_l2"] is None:
        return None
    return run["disp_form_rel_l2"] + p1["disp_rel_l2"]


def pair_u(a, b, u_two):
    """The uncertainty of the difference of two error bounds: on one mesh they differ only in
    their model-form errors, which the reference does not enter (round-off); on two meshes
    ``u_two``, what the reference's estimate carries through each FEM P1 distance."""
    return ROUND_OFF if a["tets"] == b["tets"] else u_two


def u_two_meshes(estimate):
    """u_val of two bounds on two meshes: u_num the reference's estimate on each mesh's FEM
    P1 distance, added (the two meshes' errors come from one reference, so they are not
    independent: the triangle inequality's bound, whatever their correlation); u_input and
    u_D as the report states them (not estimated; round-off)."""
    return u_val(2.0 * estimate, 0.0, ROUND_OFF)


def rank(scores, at, estimate, points=None, u_two=None):
    """[(rank, law, [laws tied with it], [laws resolved ahead of it])], in rank order:
    ``scores`` {law: error bound at its reach, or None (counts as failed, behind every
    bound)}; ``points`` {law: [(tets, bound)]} the bounds over its reach's range in the
    bench's rounds (a round's reach is one of those sizes; default the reach alone). Two laws
    are tied where some pair of their points differ within ``pair_u`` (of those two meshes),
    where the pairs do not agree on which is ahead (that depends on the timing round), or
    where both bounds are below JUDGES times the reference's estimate (it cannot order them).
    A tie is not transitive (two laws on one mesh are ordered within round-off, each tied with
    a third on another mesh), so a law's rank is one more than the number of laws resolved
    ahead of it (a smaller bound, not tied): the first are those no law is resolved ahead of,
    every two of them tied."""
    order = sorted(scores, key=lambda m: (scores[m] is None, scores[m] or 0.0, m))
    points = points or {}
    u_two = u_two_meshes(estimate) if u_two is None else u_two

    def tied(a, b):
        sa, sb = scores[a], scores[b]
        if sa is None or sb is None:
            return sa is None and sb is None
        small = judged_floor(estimate)
        if sa < small and sb < small:
            return True
        pa = points.get(a) or [(at[a]["tets"], sa)]
        pb = points.get(b) or [(at[b]["tets"], sb)]
        ahead = set()
        for ta, ba in pa:
            for tb, bb in pb:
                if abs(ba - bb) <= pair_u({"tets": ta}, {"tets": tb}, u_two):
                    return True
                ahead.add(ba < bb)
        return len(ahead) > 1

    def resolved_ahead(o, m):
        if tied(o, m) or scores[o] is None:
            return False
        return scores[m] is None or scores[o] < scores[m]
    out = [(1 + sum(resolved_ahead(o, m) for o in order), m,
            [o for o in order if o != m and tied(m, o)],
            [o for o in order if resolved_ahead(o, m)]) for m in order]
    return sorted(out, key=lambda x: x[0])          # stable: by bound within a rank


def reach_points(runs, law, reach_):
    """[(tets, bound)] of a law over its reach's range in the bench's rounds, smallest size
    first: each size of the family from the largest real time in every round to the largest
    real time in some round at which it was timed (a round's reach is one of them), led by
    (None, inf) where no size is real time in every round (a round without a reach); a size
    without a bound counts as failed there (inf)."""
    lo, hi = reach_["sure"], reach_["maybe"]
    sizes = sorted({r["tets"] for r in runs if r["law"] == law and _cost(r)[0] is not None
                    and lo is not None and lo <= r["tets"] <= hi} | {hi})
    out = [(t, next((b for r in runs if r["model"] == law and r["tets"] == t
                     for b in [bound(runs, r)] if b is not None), math.inf)) for t in sizes]
    return ([(None, math.inf)] if lo is None else []) + out


def verdict(data, family="the bench's real-time family (run `pbcm bench` on this machine)"):
    """The most accurate model at real time: the laws other than the yardstick ranked by their
    error bound at their own reach (``bound``; a failed run or an error not computed counts as
    failed), ties by ``rank``; the yardstick's reach and distance beside; the laws whose
    distance from the continuum is below their model-form error by more than the reference's
    estimate (their error cancels FEM P1's)."""
    runs = data["runs"]
    at = reach(runs)
    e = data["error_estimate"] or 0.0
    exact = p1_exact(runs, e)
    # where FEM P1 reproduces the continuum its distance is an identity check: not ranked
    measured = {m: r for m, r in at.items() if r is not None and m in ranked_laws(runs)
                and not (exact is not None and m == P1)}
    if not measured:
        return {"decided": False, "why": f"no model was measured at real time on {family}",
                "reach": {m: None for m in laws(runs)}, "ranks": []}
    bounds = {m: bound(runs, r["run"]) for m, r in measured.items()}
    points = {m: reach_points(runs, m, r) for m, r in measured.items()
              if bounds[m] is not None}
    spans = {m: (bounds[m], p[0][1]) for m, p in points.items()}
    # every size the reach takes over the rounds, the largest real time in some round too
    over_range = {m: (min(b for _, b in p), max(b for _, b in p)) for m, p in points.items()}
    ranked = rank(bounds, measured, e, points)
    first = [m for k, m, _, _ in ranked if k == 1 and bounds[m] is not None]
    yard = at.get(P1)
    cautious = reach(runs, MARGIN)
    # the top force at each reach against FEM P1's: the stiffness the displacement bound
    # hardly sees; the pick is among the tied first whose force is within STIFF of FEM P1's
    force = {m: r["run"].get("force_form_rel") for m, r in at.items() if r is not None}
    stiff = [m for m in first if force[m] is not None and abs(force[m]) <= STIFF]
    # then real time in every round at its reach; then not costlier on every mesh both
    # were timed on than another such (like with like: reaches on different meshes are not
    # costs of one problem); then the most headroom (the smallest cost there in its
    # slowest round), so that the machine's jitter does not break it
    if not first:
        return {"decided": False, "why": "no model measured at real time has an error bound "
                "at its reach (FEM P1's run or its own failed there)",
                "reach": {m: None if r is None else {k: v for k, v in r.items() if k != "run"}
                          for m, r in at.items()}, "ranks": []}
    pool = stiff or first
    sure = [m for m in pool if measured[m]["sure"] == measured[m]["tets"]] or pool
    cheaper = [m for m in sure if not any(dearer(runs, m, o) for o in sure if o != m)]
    pick = min(cheaper or sure, key=lambda m: measured[m]["range"][1])
    modes = {m: max((r["tets"] for r in runs if r["model"] == m and _cost(r)[0] is not None
                     and _cost(r)[0] <= REAL_TIME), default=None)
             for m in models(runs) if m not in laws(runs)}
    return {"decided": bool(first), "best": first, "estimate": e, "pick": pick,
            "pick_sure": measured[pick]["sure"] == measured[pick]["tets"],
            "pick_by_headroom": len(cheaper or sure) > 1,
            "pick_cheaper": [o for o in sure if o != pick and dearer(runs, o, pick)],
            "modes": modes, "force": force, "pick_stiff": bool(stiff),
            "engines": {m: None if r is None else r["tets"] for m, r in at.items()
                        if engine(m)},
            "engine_bounds": {m: bound(runs, r["run"]) for m, r in at.items()
                              if engine(m) and r is not None},
            "cautious": {m: None if r is None else r["tets"] for m, r in cautious.items()},
            "u_two_meshes": u_two_meshes(e), "bounds": bounds, "spans": spans,
            "over_range": over_range,
            "reach": {m: None if r is None else {k: v for k, v in r.items() if k != "run"}
                      for m, r in at.items()},
            "ranks": [{"rank": k, "model": m, "tied": tied, "behind": behind,
                       "score": bounds[m]} for k, m, tied, behind in ranked],
            "yardstick": None if yard is None else {
                "model": P1, "tets": yard["tets"], "distance": yard["run"]["disp_rel_l2"]},
            "p1_exact": exact, "smaller": smaller_better(runs, measured, e, bounds),
            "cancels": [] if exact is not None else [m for m, r in measured.items()
                        if r["run"]["disp_form_rel_l2"] is not None
                        and r["run"]["disp_rel_l2"] is not None
                        and r["run"]["disp_rel_l2"] + u_val(e, 0.0, ROUND_OFF)
                        < r["run"]["disp_form_rel_l2"]]}


def smaller_better(runs, measured, estimate, bounds):
    """{law: [tets, bound]}: the laws more accurate on a smaller mesh they run in real time
    (median) than at their reach, beyond the uncertainty of those two meshes (their error
    grows with refinement there): the smallest bound below the reach."""
    out = {}
    for m, r in measured.items():
        if bounds.get(m) is None:
            continue
        here = [(q["tets"], b) for q in runs if q["model"] == m and q["tets"] < r["tets"]
                for b in [bound(runs, q)] if b is not None
                and any(c is not None and c <= REAL_TIME for x in runs
                        if x["law"] == m and x["tets"] == q["tets"] for c in [_cost(x)[0]])]
        if here:
            t, b = min(here, key=lambda x: x[1])
            if b + pair_u({"tets": t}, r["run"], u_two_meshes(estimate)) < bounds[m]:
                out[m] = [t, b]
    return out


def p1_exact(runs, estimate):
    """FEM P1's largest distance from the continuum over the family where it is below the
    judged floor (``judged_floor``) on every mesh it was solved on and that floor is the
    solves' round-off (the problem's field is one every P1 element reproduces: its distance
    is an identity check, and every bound a model-form error alone), else None."""
    got = [r["disp_rel_l2"] for r in runs if r["model"] == P1 and r["accuracy"]]
    # only a reference that resolves far below the solves (its estimate under round-off)
    # can say P1 is exact; a coarser one leaves P1's small distances merely not resolved
    if got and estimate < ROUND_OFF and all(d is not None and d < judged_floor(estimate)
                                            for d in got):
        return max(got)
    return None


def _failed_sizes(runs, model):
    """The sizes where ``model``'s static run failed, smallest first."""
    return sorted(r["tets"] for r in runs if r["model"] == model and r.get("failed"))


def _failed_at(runs, model):
    """' (its static run failed at 1715, 2560 tetrahedra: no error there)' for a model whose
    static runs failed, '' where none did."""
    failed = _failed_sizes(runs, model)
    return (f" (its static run failed at {', '.join(map(str, failed))} tetrahedra: no error "
            "there)") if failed else ""


def _engine_words(runs, model, tets, force, w):
    """'newton-xpbd up to 1080 tetrahedra (top force 2.5 from FEM P1's there)', or where its
    static run fails on a larger mesh '... (top force 2.5 from FEM P1's there, not decided:
    its static run failed at 1715, 2560 tetrahedra, larger meshes)'."""
    if _fails_above(runs, model, tets):
        failed = _failed_sizes(runs, model)
        return (f"{model} up to {tets} tetrahedra ("
                + (f"{w['force']} {fmt(force, 2)} from FEM P1's there, " if force is not None
                   else "")
                + f"not decided: its static run failed at {', '.join(map(str, failed))} "
                "tetrahedra, larger meshes)")
    return (f"{model} up to {tets} tetrahedra"
            + (f" ({w['force']} {fmt(force, 2)} from FEM P1's there)" if force is not None
               else "") + _failed_at(runs, model))


def _fails_above(runs, model, tets):
    """Whether ``model``'s static run failed on a mesh larger than ``tets``: its equilibrium
    there is that of a solver the next refinements break, so no error of it is decided."""
    return any(t > tets for t in _failed_sizes(runs, model))


def dearer(runs, a, b):
    """Whether law ``a`` costs more than law ``b`` (median wall time per simulated second in
    its faster mode) on every mesh both were timed on, there being one."""
    def costs(law):
        return {r["tets"]: c for r in runs if r["model"] == law
                for c in [_cost(r)[0]] if c is not None}
    ca, cb = costs(a), costs(b)
    shared = set(ca) & set(cb)
    return bool(shared) and all(ca[t] > cb[t] for t in shared)


def machine(data):
    m = data.get("machine") or {}
    return f"{m.get('cpu', 'an unnamed processor')}, {m.get('cores', '?')} cores"


def _law_run(runs, law, tets):
    return next(r for r in runs if r["model"] == law and r["tets"] == tets)


def _parts(data, v, m):
    """(model-form error, FEM P1's distance) that model m's bound at its reach adds, or None
    where either was not computed."""
    bound = v["bounds"][m]
    form = _law_run(data["runs"], m, v["reach"][m]["tets"]).get("disp_form_rel_l2")
    return None if bound is None or form is None else (form, bound - form)


def _p1_larger(data, v):
    """Whether FEM P1's distance is the larger part of every tied first's bound."""
    parts = [_parts(data, v, m) for m in v["best"]]
    return bool(parts) and all(q is not None and q[0] < q[1] for q in parts)


def _split_words(data, v, m):
    """The bound of model m split into its two parts (rule 9): ' = model-form a + FEM P1's
    b', or nothing where either was not computed."""
    q = _parts(data, v, m)
    return "" if q is None else f" = model-form {err(q[0])} + FEM P1's {err(q[1])}"


def answer_line(data, v, quick, words=None):
    """The index's one line: the most accurate model at real time on the bench's machine
    (``words``: how the loading is named, ``study.CubePush.words`` by default)."""
    w = words or CubePush.words
    if quick:
        return f"Quick: not decided (two mesh sizes; {w['quick']})."
    if not v["decided"]:
        return f"Not decided: {v.get('why', 'no model has an error at its real-time reach')}."
    said = []
    for m in v["best"]:
        reach_ = v["reach"][m]
        mode = _mode(m, reach_)
        said.append(f"{m} ({mode}, {_reach_words(reach_, v['spans'].get(m))}, "
                    f"{_judged(v['bounds'][m], v)}{_split_words(data, v, m)})")
    y, p = v.get("yardstick"), v["pick"]
    if len(said) > 1:
        reaches = [v["reach"][m] for m in v["best"]]
        one_mesh = len({r["tets"] for r in reaches}) == 1 and all(
            r["sure"] == r["maybe"] == r["tets"] for r in reaches)
        within = ("within round-off on one mesh" if one_mesh else
                  f"within {err(v['u_two_meshes'])} or what their reach spans over the timing "
                  "rounds")
        own = [_law_run(data["runs"], m, r["tets"])["disp_rel_l2"]
               for m, r in zip(v["best"], reaches)]
        apart = (None in own or max(own) - min(own) > (
            ROUND_OFF if one_mesh else v["u_two_meshes"]))
        head = ("the smallest error bound (model-form error plus FEM P1's discretisation "
                "error at the model's reach; "
                + ("the tied models' own distances from the continuum differ by more (the "
                   "second table)" if apart else "the tied models' own distances from the "
                   "continuum lie within the same uncertainty of each other")
                + f") is tied between {len(said)} models, {within}: " + "; ".join(said))
    else:
        head = ("the smallest error bound (model-form error plus FEM P1's discretisation "
                f"error at the model's reach) is {said[0]}")
    if _p1_larger(data, v):
        head += (" (in each, FEM P1's share is the larger: the mesh the budget allows "
                 "weighs more than the law)")
    # the runners-up: tied with some of the first, resolved behind first ones only
    nearly = [k for k in v["ranks"] if k["rank"] > 1 and set(k["tied"]) & set(v["best"])
              and set(k["behind"]) <= set(v["best"])]
    if nearly:
        head += ("; tied with some of them but resolved behind another: "
                 + "; ".join(_behind_words(k, v) for k in nearly))
    why = _why_pick(v)
    force = v.get("force") or {}
    stiff = (f"The bound reads {w['field']}; {w['force_detail']} against FEM P1's at the "
             "reach: "
             + ", ".join(
                 f"{m} {'n/a' if force.get(m) is None else fmt(force[m], 2)}"
                 for m in v["best"])
             + (f"; the pick is among those within {STIFF:g} there" if v.get("pick_stiff")
                else f"; none within {STIFF:g}, so the pick is among all the tied") + ". "
             if any(f is not None for f in force.values()) else "")
    beside = (f". FEM P1 with the continuum's law ({P1}), the yardstick "
              f"({'an identity check here, not ranked' if v.get('p1_exact') is not None else 'ranked'}), runs "
              f"{y['tets']} tetrahedra at distance {_judged(y['distance'], v)}" if y else "")
    engines = v.get("engines") or {}
    newton = ("; Newton's solvers (single precision on one core of Warp's CPU backend, "
              "through pbcm's adapter; their cost is one core's, the ranked models' that of "
              "their faster mode, two threads where they have one, so their reaches are not "
              "compared with those) in real time: "
              + ", ".join(_engine_words(data["runs"], m, t, force.get(m), w)
                          for m, t in engines.items() if t)
              + ("; at none of the sizes timed: " + ", ".join(
                  m + _failed_at(data["runs"], m) for m, t in engines.items() if not t)
                 if not all(engines.values())
                 else "") if engines else "")
    return (f"At real time on this machine ({machine(data)}, wall clock, {w['loading']}; "
            f"the errors are each model's static equilibrium under {w['load']}, how "
            f"far a timed run lags it not measured), {head}. {stiff}Pick {p}: {why} "
            f"({fmt(v['reach'][p]['range'][1])} wall s per simulated s in its slowest round)"
            f"{beside}{newton}.{_smaller_words(v)}{_exact_words(v)}")


def _mode(law, reach_):
    """How a law runs at its reach: its mode ('two threads'), or the implicit preset that
    reaches it for the law."""
    return reach_["model"] if reach_["model"] != law else reach_["mode"]


def _why_pick(v):
    """Why the pick among the tied first: 'real time in every timing round at its reach,
    cheaper than ... on every mesh both were timed on'."""
    why = ("real time in every timing round at its reach" if v["pick_sure"] else
           "no tied model is real time in every round at its reach")
    beaten = v.get("pick_cheaper") or []
    return why + ((", cheaper than " + ", ".join(beaten) + " on every mesh both were timed on")
                  if beaten else "") + (", with the most headroom of those left"
                                        if v.get("pick_by_headroom") else "")


def index_line(data, v, quick, words=None):
    """The index's line: at real time on the bench's machine, the most accurate model, its mesh
    and error, those tied with it and the pick among them; the report's opening gives the
    evidence (the runners-up, the forces, the engines)."""
    if quick or not v["decided"]:
        return answer_line(data, v, quick, words)
    w = words or CubePush.words
    p = v["pick"]

    def at(m):
        r = v["reach"][m]
        return (f"{_mode(m, r)}, {r['tets']} tetrahedra, "
                f"error bound {_judged(v['bounds'][m], v)}{_split_words(data, v, m)}")
    what = (f"({machine(data)}, wall clock, {w['loading']}; the error bound is the model-form "
            "error plus FEM P1's distance from the continuum at the model's reach"
            + (", which is round-off here: FEM P1 is exact for this problem's field"
               if v.get("p1_exact") is not None else "") + ")")
    if len(v["best"]) == 1:
        return (f"At real time on this machine {what}, the most accurate model is {p} "
                f"({at(p)}): {_why_pick(v)}.")
    force = v.get("force") or {}
    passed = [m for m in v["best"] if force.get(m) is not None and abs(force[m]) <= STIFF]
    # the force test decides only where some of the tied fail it; P1's own law passes it by
    # construction
    test = (f"the top force within {STIFF:g} of FEM P1's ("
            + ", ".join(f"{m} {fmt(force[m], 2)}" for m in passed)
            + (f"; {P1} by construction" if P1 in passed else "") + ") "
            + ("decides nothing here, all passing it" if len(passed) == len(v["best"]) else
               "leaves " + ", ".join(passed) + (" alone" if len(passed) == 1 else ""))
            ) if v.get("pick_stiff") else ""
    decides = "" if len(passed) == 1 and v.get("pick_stiff") else "; the cost does"
    r = v["reach"][p]
    return (f"At real time on this machine {what}, the most accurate models are tied "
            f"({len(v['best'])}, within u_val {err(v['u_two_meshes'])} of two bounds on two "
            "meshes: the reference's estimate on each; u_input 0, a stated problem; static "
            "equilibria, a timed run's lag not measured): "
            + "; ".join(f"{m} ({at(m)})" for m in v["best"])
            + (" (FEM P1's share the larger in each: the mesh the budget allows decides more "
               "than the law)" if _p1_larger(data, v) else "")
            + ". Accuracy does not decide among them"
            + (f"; {test}" if test else "")
            + f"{decides}: pick {p}, {_wall(r['cost'])} [{_wall(r['range'][0])}-"
            f"{_wall(r['range'][1])}] wall s per simulated s at its reach: {_why_pick(v)}.")


def _smaller_words(v):
    """' More accurate on a smaller mesh ...' naming the laws whose error grows with
    refinement below their reach, '' where none."""
    got = v.get("smaller") or {}
    if not got:
        return ""
    return (" Laws more accurate on a smaller mesh they also run in real time than at their "
            "reach (their error grows with refinement there): " + ", ".join(
                f"{m} {t} tetrahedra, {err(b)} (at its reach {err(v['bounds'][m])})"
                for m, (t, b) in got.items()) + ".")


def _exact_words(v):
    """' FEM P1 reproduces the continuum ...' where it does on every mesh, else ''."""
    if v.get("p1_exact") is None:
        return ""
    return (f" FEM P1 reproduces the continuum on every mesh (its largest distance "
            f"{fmt(v['p1_exact'])}, not resolved from zero): a field every P1 element is exact "
            "for, so its distance is an identity check, each bound is the model's model-form "
            "error alone, and this problem does not test what a coarse mesh costs.")


def _behind_words(k, v):
    """'pbcm-variational (0.0275, behind pbcm-balanced on the same mesh, 0.0269)'."""
    tets = v["reach"][k["model"]]["tets"]
    return f"{k['model']} ({err(k['score'])}, behind " + ", ".join(
        f"{b}{' on the same mesh' if v['reach'][b]['tets'] == tets else ''}, "
        f"{err(v['bounds'][b])}" for b in k["behind"]) + ")"


def _reach_words(reach_, span_=None):
    """'10985 tetrahedra (8640 in every timing round, bound 0.0345 there)', or '6655
    tetrahedra' where every round is real time there."""
    if reach_["sure"] == reach_["tets"]:
        return f"{reach_['tets']} tetrahedra"
    if reach_["sure"] is None:
        return f"{reach_['tets']} tetrahedra (none in every timing round)"
    there = "" if span_ is None else f", bound {err(span_[1])} there"
    return f"{reach_['tets']} tetrahedra ({reach_['sure']} in every timing round{there})"


def write(out, study, s, data):
    w = s.loading.words
    v = verdict(data, w["family"])
    doc = jsonable({"case": getattr(s, "case_name", study.name), "study": True, "parameters": s.describe(),
                    "problem": s.problem(), "gated": GATED, "environment": environment(),
                    **data, "verdict": v, "answer": answer_line(data, v, s.quick, w),
                    "index_answer": index_line(data, v, s.quick, w),
                    "gate_runs": [{"mesh": r["mesh"], "bc": r["bc"], "model": r["model"],
                                   "disp_rel_l2": r["disp_rel_l2"],
                                   "disp_form_rel_l2": r["disp_form_rel_l2"]}
                                  for r in data["runs"]
                                  if r["accuracy"] and r["model"] == r["law"]]})
    return write_study(out, doc, lambda folder: build(folder, study, s, doc))


def judged_floor(estimate):
    """The error below which the comparison cannot judge: JUDGES times the reference's
    estimate, or times the static solve's round-off where that is larger (an exact
    reference's estimate is its own round-off, far below the models' solves')."""
    return JUDGES * max(estimate, ROUND_OFF)


def _floor_words(estimate, what):
    """'5 times WHAT', or where the solve's round-off sets the floor, say so."""
    if estimate >= ROUND_OFF:
        return f"{JUDGES} times {what}"
    return (f"{JUDGES} times the static solve's round-off {fmt(ROUND_OFF)}, above the "
            f"reference's estimate {fmt(estimate, 2)}")


def _judged(value, v):
    """An error against the continuum, 'not resolved' beside it where the reference's
    estimate is more than a fifth of it, 'round-off' where it is within the static solve's
    round-off (an identity: the reference reproduced)."""
    e = v.get("estimate")
    if value is None or e is None:
        return err(value)
    if value < judged_floor(e):
        return f"{err(value)} (not resolved)"
    return f"{err(value)} (round-off)" if value <= ROUND_OFF else err(value)


def _span_cell(span_):
    if span_ is None:
        return "n/a"
    lo, hi = span_
    return f"{err(lo)}-{'none real time in every round' if math.isinf(hi) else err(hi)}"


def _cost_cell(run, key):
    c = run["cost"]
    if not c.get("timed"):
        return "not timed"
    value = c.get(key)
    if value is None:
        return "-"
    lo, hi = c["two_thread_range" if key.startswith("two") else "wall_range"]
    return f"{_wall(value)} [{_wall(lo)}-{_wall(hi)}]"


def _wall(value):
    """A wall time per simulated second to four figures: a range end just above real time
    (1.0034) is not printed as 1."""
    return fmt(value, 4)


def _signed(value):
    """A signed relative error to four places, 'n/a' where none was computed."""
    return "n/a" if value is None else f"{value:+.4f}"


def _engines(runs):
    """The engine versions the bench timed (e.g. 'newton 1.8.0'), or '' where none."""
    got = sorted({r["cost"].get("engine") for r in runs if r["cost"].get("engine")})
    return ", ".join(got)


def build(out, study, s, doc):
    out = Path(out)
    d = Document(f"pbcm report: {study.name}")
    v = doc["verdict"]
    runs = doc["runs"]
    where = machine(doc)
    w = s.loading.words
    d.opening([f"**At a real-time budget.** {doc['answer']}"], w["glossary"])
    d.p(f"{w['question']}: at real time, how large a mesh can each model "
        f"run, and how far from the continuum is it there? The cost is what {w['timer']} "
        f"measured on {where}: wall-clock seconds per simulated second under "
        f"{w['loads_detail']}, each model in its faster mode (serial or two threads), the "
        "explicit models at their own largest stable RK4 step, the implicit presets "
        "(backward Euler, Newton with conjugate gradients) at their own step"
        + (f"; Newton's solvers ({_engines(runs)}, single precision on Warp's CPU backend, "
           "serial: its CPU kernels take one core; no GPU here) at their own step through "
           "pbcm's adapter, each iteration count its own model, their equilibrium run to rest "
           "(docs/simulators.md)" if _engines(runs) else "")
        + f"; at most {REAL_TIME:g} is real time. Each timing sample is checked for a blow-up "
        f"({w['blowup']}), over the steps the samples take from the start of "
        f"{w['load']}, not over the whole of it. The accuracy is each model's static "
        f"equilibrium under {w['load']} (how far a timed run lags it at the end is not "
        "measured here): its distance "
        "from the converged continuum (||u - u_c|| / ||u_c||, "
        "neo-Hookean P2) and its model-form error against FEM P1 with the continuum's law on "
        f"the same tetrahedra ({P1}). The implicit presets have fem-corotated's equilibrium: "
        "they are fem-corotated's other modes, and fem-corotated is ranked once, at the "
        f"largest reach of any of its modes. The accuracy is computed where {w['timing']} "
        f"timed a model: it stops timing a model above {w['stops']}"
        f"{w['solved']}.")
    if v.get("ranks") and not doc["parameters"]["quick"]:
        rows = []
        for k in v["ranks"]:
            m, reach_ = k["model"], v["reach"][k["model"]]
            r = _law_run(runs, m, reach_["tets"])
            mode = _mode(m, reach_)
            p1 = k["score"] - r["disp_form_rel_l2"] if k["score"] is not None else None
            rows.append([k["rank"], m, mode,
                         f"{reach_['tets']} ({reach_['sure'] or 'none'}-{reach_['maybe']})",
                         f"{_wall(reach_['cost'])} [{_wall(reach_['range'][0])}-"
                         f"{_wall(reach_['range'][1])}]", _judged(k["score"], v),
                         _span_cell((v.get("over_range") or v.get("spans", {})).get(m)),
                         err(r["disp_form_rel_l2"]), _judged(p1, v),
                         "; ".join(x for x in (
                             k["tied"] and "tied with " + ", ".join(k["tied"]),
                             k["behind"] and "behind " + ", ".join(k["behind"])) if x)
                         or "-"])
        d.p(f"Each model at the largest mesh it runs in real time on {where}, ranked by its "
            "error bound there: its model-form error plus FEM P1's distance from the continuum "
            "on that mesh (the discretisation error every model there shares; the bound of its "
            "own distance by the triangle inequality, which a model whose error cancels FEM "
            "P1's on a coarse mesh cannot undercut); a failed run or an error not computed "
            "counts against it. Two bounds on different meshes are tied within "
            f"u_val = {err(v['u_two_meshes'])}: u_num the reference's estimate "
            f"{err(v['estimate'])} on each mesh's FEM P1 distance, added (the two meshes' "
            "errors come from one reference, so they are not independent: the triangle "
            "inequality's bound); u_input 0, a stated problem (every model has the same E, nu and "
            f"{w['load'].removeprefix('the ')} on the same family of meshes, so the ranking "
            "holds at those inputs; how "
            f"they move each model is {w['inputs']}); u_D the static "
            f"solve's tolerance, round-off ({fmt(ROUND_OFF)}). The cost's noise enters "
            "through the reach's range over the timing rounds (below), not as a number. Two "
            "bounds on one mesh differ only in model-form error, tied within round-off; "
            "bounds both below "
            f"{err(judged_floor(v['estimate']))} ({_floor_words(v['estimate'], 'the estimate')}) "
            "are not resolved. "
            "The reach's range: from the largest size real time in every round to the "
            "largest real time in some round; the bound over it is the smallest to the "
            "largest bound at the sizes of that range (none where no size is real time in "
            "every round), and two models are tied where the sizes their reaches take over "
            "the rounds give bounds within the uncertainty of those two meshes, or disagree "
            "on which is ahead: that depends on the timing round. "
            "A tie is not transitive (two models on one mesh are ordered within round-off "
            "while each is tied with a third on another mesh): a model's rank is one more "
            "than the number of models resolved ahead of it, so the first are those no model "
            "is resolved ahead of, and every two of them are tied.")
        d.table(["rank", "model", "mode at its reach", "tets (over the rounds, either mode)",
                 f"wall s per simulated s ({where})", "error bound",
                 "bound over the reach's range", "model-form error",
                 "+ FEM P1's distance there", "tied with; resolved behind"], rows)
        d.p("How firm the reaches are, and each model's own distance from the continuum at "
            "its reach (beside the bound, not an order: a distance below FEM P1's own on "
            "that mesh is partly its error cancelling P1's, and one below "
            f"{err(judged_floor(v['estimate']))}, "
            f"{_floor_words(v['estimate'], 'the reference' + chr(39) + 's estimate')}, is not "
            "resolved): the reach at a step "
            f"{100 * MARGIN:g} % of the own stable step (the cost divided by {MARGIN:g}), "
            "and whether the reach is real time in every timing round.")
        d.table(["model", "reach", f"reach at {100 * MARGIN:g} % of the step",
                 "real time in every round there (either mode)",
                 "own distance from the continuum",
                 f"{w['force']}: model-form error (signed)",
                 f"{w['force']}: from the continuum"],
                [[k["model"], v["reach"][k["model"]]["tets"],
                  v["cautious"].get(k["model"]) or "none",
                  fmt(v["reach"][k["model"]]["sure"] == v["reach"][k["model"]]["tets"]),
                  _judged(lr["disp_rel_l2"], v), _signed(lr.get("force_form_rel")),
                  _signed(lr.get("force_rel"))]
                 for k in v["ranks"]
                 for lr in [_law_run(runs, k["model"], v["reach"][k["model"]]["tets"])]])
        d.p(f"The {w['force']} is {w['force_is']}, which the displacement bound "
            f"hardly sees ({w['force_why']}): its model-form error (f - f_P1) / "
            "|f_c| is a law's stiffness against FEM P1's on the same tetrahedra; the pick is "
            f"among the tied first whose force is within {STIFF:g} of FEM P1's, where any is. "
            f"The {STIFF:g} is a tolerance of use (a force {100 * STIFF:g} % off), not an "
            "uncertainty: on one mesh the force's model-form error carries round-off only.")
        if v.get("engines"):
            d.p("Not ranked: Newton's solvers, timed on one core of Warp's CPU backend (the "
                "ranked models on two threads), so their reaches are not compared with the "
                f"ranked ones'; each at its own reach, its error bound and {w['force']} there"
                + ("; not decided for a solver whose static run fails on a larger mesh of "
                   "the family (the equilibrium of a solver the next refinements break)"
                   if any(t and _fails_above(runs, m, t) for m, t in v["engines"].items())
                   else "") + ".")
            d.table(["solver", "reach (tets)", "wall s per simulated s (one core)",
                     "error bound", f"{w['force']}: model-form error (signed)"],
                    [[m, t or "none", "-" if not t else
                      f"{_wall(v['reach'][m]['cost'])} [{_wall(v['reach'][m]['range'][0])}-"
                      f"{_wall(v['reach'][m]['range'][1])}]",
                      "-" if not t else err(v["engine_bounds"].get(m)) + (
                          " (not decided)" if _fails_above(runs, m, t) else ""),
                      "-" if not t else _signed(v["force"].get(m)) + (
                          " (not decided)" if _fails_above(runs, m, t) else "")]
                     for m, t in v["engines"].items()])
        if v.get("modes"):
            d.p("fem-corotated's implicit modes on their own: " + "; ".join(
                f"{m} " + (f"real time up to {t} tetrahedra" if t else
                           "real time at no size timed")
                for m, t in v["modes"].items()) + ".")
        y = v.get("yardstick")
        if y:
            d.p(f"The yardstick, {'not ranked (an identity check here)' if v.get('p1_exact') is not None else 'ranked with the others'}: FEM P1 with the continuum's law "
                f"({P1}), model-form error 0 by definition, runs in real time up to "
                f"{y['tets']} tetrahedra, at distance {_judged(y['distance'], v)} from the "
                "continuum.")
        none = [m for m in ranked_laws(runs) if v["reach"].get(m) is None]
        if none:
            d.p("Not in real time at any size timed: " + ", ".join(none) + ".")
        if v.get("cancels"):
            d.p("Closer to the continuum than to FEM P1 on the same mesh (the model's error "
                "cancels part of FEM P1's discretisation error there, a coarse mesh's luck, "
                "not a property of the model): " + ", ".join(v["cancels"]) + ".")
    d.h(2, "Every size")
    exact = _exact_words({"p1_exact": p1_exact(runs, doc["error_estimate"] or 0.0)})
    if exact and doc["parameters"]["quick"]:        # the full run's answer says it
        d.p(exact.strip())
    shown = [r for r in runs if r["cost"].get("timed") or r["accuracy"]]
    untimed = sorted({r["tets"] for r in runs} - {r["tets"] for r in shown})
    if untimed:
        d.p("Sizes of the family at which no model was timed (every model was over real time "
            f"{w['stopped']}) and nothing was computed: "
            + ", ".join(map(str, untimed)) + " tetrahedra.")
    if v.get("estimate") is not None:
        d.p(f"Errors below {err(judged_floor(v['estimate']))} "
            f"({_floor_words(v['estimate'], 'the reference' + chr(39) + 's estimate')}) are "
            "marked 'not resolved': the reference cannot judge them.")
    rounds = sorted({r["cost"].get("rounds") for r in shown if r["cost"].get("rounds")})
    d.p(f"Wall-clock seconds per simulated second on {where} (median [smallest-largest over "
        f"{w['timing']}'s {' or '.join(map(str, rounds)) or 'n/a'} rounds]), serial and in the "
        "two-thread mode ('-': the model has none); "
        f"the errors are the model's law's static equilibrium. Sizes at which {w['timing']} "
        "did not time a model and no error was computed are left out: "
        + (", ".join(f"{m} above {max(r['tets'] for r in shown if r['model'] == m)}"
                     for m in models(runs) if any(r["model"] == m for r in shown)
                     and any(r["model"] == m and r not in shown for r in runs)) or "none")
        + ".")
    d.table(["model", "tets", "wall s/s serial", "wall s/s two threads", "real time",
             "error bound", "model-form error", "distance from continuum",
             f"{w['force']}: model-form error", "load steps", "failed"],
            [[r["model"], r["tets"], _cost_cell(r, "wall_s_per_simulated_s"),
              _cost_cell(r, "two_thread_wall_s_per_simulated_s"),
              "not timed" if _cost(r)[0] is None else fmt(_cost(r)[0] <= REAL_TIME),
              _judged(bound(runs, r), v) if r["accuracy"] else "not computed",
              err(r["disp_form_rel_l2"]) if r["accuracy"] else "not computed",
              _judged(r["disp_rel_l2"], v) if r["accuracy"] else "not computed",
              _signed(r.get("force_form_rel")) if r["accuracy"] else "not computed",
              r["load_steps"] or "-", r["failed"] or ""] for r in shown], keys=2)
    broke = [r for r in runs if r["cost"].get("failed")]
    if broke:
        d.p(f"Failed in {w['timing']} (not timed there nor above): " + "; ".join(
            f"{r['model']} at {r['tets']} tetrahedra: {r['cost']['failed']}" for r in broke)
            + ".")
    series = []
    for m in laws(runs):
        pts = []
        for r in runs:
            if r["model"] != m or not r["accuracy"]:
                continue
            costs = [c for q in runs if q["law"] == m and q["tets"] == r["tets"]
                     for c in [_cost(q)[0]] if c is not None]
            y = r["disp_rel_l2"] if m == P1 else bound(runs, r)
            if costs and y is not None:
                pts.append((min(costs), y))
        if pts:
            pts.sort()
            series.append((m if m != P1 else f"{m} (yardstick: its distance)",
                           [p[0] for p in pts], [p[1] for p in pts]))
    if series:
        figures.error_against_cost(out / "error_vs_cost.png", series, REAL_TIME,
                                   f"wall s per simulated s, faster mode ({where})",
                                   "error bound (model-form + FEM P1's distance)",
                                   f"Accuracy against cost, {w['figure']}")
        d.img("error_vs_cost.png", "each model's error bound against its wall-clock seconds "
              "per simulated second in its faster mode, every size timed; the yardstick's "
              "distance from the continuum; the dashed line is real time")
    d.p(f"Environment: {doc['environment']}.")
    return d
