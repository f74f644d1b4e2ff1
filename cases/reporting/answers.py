"""The answers that open reports/index: which reading the paper used, how far each model is
from the continuum and from a measured body, at what cost, and what causes the bulge/neck
artefact; then one
compact table, model by the numbers behind them. Every number is read from the metrics the
studies, the cases and the bench wrote under the reports folder; an answer whose source is
missing says which command writes it."""
import json
import math
from pathlib import Path

import numpy as np

from .costs import BASE, FILE as BENCH_FILE, FOLDER as BENCH_FOLDER, cpu_seconds, near, \
    sim_ratio
from .costs import stale as costs_stale
from .document import fmt, fmt_span, rel, rel_range
from ..measuring.error_model import JUDGES, P1_LINEAR, ROUND_OFF, input_spread
from ..measuring.metrics import PATCH_TOL

CONSISTENCY = ("paper-cube", "sliding")     # the patch test whose converged limit is the error
FINITE = "large-compression"                 # the finite-strain case (neo-Hookean reference)
MEASURED = "truth-cube"                      # the study against measured beads


def _load(root, *parts):
    path = Path(root).joinpath(*parts)
    return json.loads(path.read_text()) if path.is_file() else None


def _record(root, study):
    """A study's record (its metrics.json and the files beside it), or None where not run."""
    from ..registry import studies
    from .report import read_study
    folder = Path(root) / study
    return read_study(folder, studies()[study]) if (folder / "metrics.json").is_file() else None


LIMITED = ("exact", "converges", "floor")   # fit verdicts whose e_inf is a limit


REGULAR = ("five", "six", "bcc")     # the lattices as generated; the rest is irregular


def limits(conv, model):
    """{lattice: (limit, its fit's +-, 'displacement' or 'stiffness') of the sliding-cube
    patch test, the larger of its two limits, or the fit's verdict where the displacement has
    no limit}. The top face's displacement is prescribed, so the displacement error alone is
    blind to the stiffness: a model half as stiff as the continuum can match its shape; the
    stiffness error, the reaction ratio's limit's distance from 1, reads what it misses."""
    out = {}
    for f in (conv or {}).get("fits", []):
        if (f["case"], f["bc"]) == CONSISTENCY and f["model"] == model:
            # an irregular family is never extrapolated: its verdict, not a limit
            limited = (f["verdict"] in LIMITED and f.get("e_inf") is not None
                       and f["mesh"] in REGULAR)
            stiff = ((abs(f["ratio_inf"] - 1.0), f.get("ratio_inf_err") or 0.0, "stiffness")
                     if f.get("ratio_inf") is not None and f["mesh"] in REGULAR else None)
            if f["verdict"] == "exact" and stiff and stiff[0] < PATCH_TOL:
                # the reference's own level (the nonlinearity left at the scaled load): FEM
                stiff = None
            if f["mesh"] in REGULAR and f.get("ratio_inf") is None and \
                    (f.get("ratio_why") or "").startswith("not asymptotic"):
                # a stiffness error growing under refinement: at least its finest value (the
                # floor rule's +-, 1.25 x its last change); one that moves otherwise, no limit
                out[f["mesh"]] = _growing_stiffness(conv, f) or "not asymptotic (stiffness)"
                continue
            if not limited:
                # a stiffness error resolved from 0 bounds the limit from below: said, with
                # the displacement's verdict beside it
                out[f["mesh"]] = ((*stiff[:2], f"stiffness; displacement {f['verdict']}")
                                  if stiff and stiff[0] - stiff[1] > PATCH_TOL
                                  else f["verdict"])
                continue
            disp = (f["e_inf"], f.get("e_inf_err") or 0.0, "displacement")
            out[f["mesh"]] = stiff if stiff and stiff[0] > disp[0] else disp
    return out


def _whole(v):
    """Whether a lattice's entry is a limit of both quantities (not a verdict, nor a
    stiffness bound beside a displacement with no limit)."""
    return isinstance(v, tuple) and "; " not in (v[2] if len(v) > 2 else "")


def _growing_stiffness(conv, fit):
    """(finest |ratio - 1|, 1.25 x its last change, 'stiffness, growing: at least') of a fit
    whose stiffness error grows at every refinement, or None."""
    rs = sorted((r for r in conv.get("runs", [])
                 if (r["case"], r["bc"], r["mesh"], r["model"])
                 == (fit["case"], fit["bc"], fit["mesh"], fit["model"])
                 and r.get("reaction_ratio") is not None), key=lambda r: -r["h_mm"])
    d = [abs(r["reaction_ratio"] - 1.0) for r in rs]
    if len(d) < 3 or not all(b > a for a, b in zip(d, d[1:])):
        return None
    return (d[-1], 1.25 * (d[-1] - d[-2]), GROWING)


def _pm(v):
    """'limit +- its uncertainty', or the limit alone where both are round-off."""
    if rel(v[0] + v[1]).startswith("<"):
        return rel(v[0] + v[1])
    return f"{rel(v[0], 2)} +- {rel(v[1], 1)}"


def _shown(verdict):
    """A fit's verdict as said beside a limit: 'exact' with the level it means."""
    return "exact (every error at the reference's own level)" if verdict == "exact" else verdict


def worst(values):
    """'largest +- its fit's (lattice)' over the entries with a limit, and the lattices
    without one."""
    nums = {k: v for k, v in values.items() if isinstance(v, tuple)}
    other = [f"{_shown(v)} on {k}" for k, v in values.items() if not isinstance(v, tuple)]
    if not nums:
        return ", ".join(other) or "n/a"
    k = max(nums, key=lambda k: nums[k][0])
    return _limit_text((*nums[k], k)) + (f"; {', '.join(other)}" if other else "")


def _median(rows, key):
    v = [r[key] for r in rows if r.get(key) is not None]
    return float(np.median(v)) if v else None


def _bench_row(bench, model):
    """The bench row of ``model`` at the size closest to the costs' comparison size that has
    the cost per simulated second."""
    return near(bench, model, "cpu_s_per_simulated_s")


def ratio_text(row, base):
    """'r [lo-hi]' of ``sim_ratio``."""
    r, rng = sim_ratio(row, base)
    return fmt_span(r, rng, 2)


def ratio_parts(row, base):
    """'its step s [lo-hi] x, its stable step d x': the two factors of ``sim_ratio`` (a model
    cheap per simulated second by a larger stable step, not a cheaper step, says so); '' where
    the bench has no in-round step ratio."""
    key = f"step_vs_{base['model']}"
    if key not in row:
        return ""
    rng = row.get(f"{key}_range")
    return (f"its step {fmt(row[key], 2)}"
            + (f" [{fmt(rng[0], 2)}-{fmt(rng[1], 2)}]" if rng else "")
            + f" x, its stable step {fmt(row['stable_dt_us'] / base['stable_dt_us'], 2)} x")


# a quick run's cell for a verdict the full run decides
QUICK_CELL = "quick: not decided"


def table(root, models, pops=(), quick=False):
    """(header, rows): one row per model of the scorecard; ``quick``: the verdicts (model-form
    rankings, limits, whether a run comes to rest) say 'quick: not decided', the measurements
    stay."""
    from . import scorecard
    conv = _load(root, "convergence", "metrics.json")
    cube = _load(root, "paper-cube", "metrics.json")
    bench = _load(root, BENCH_FOLDER, BENCH_FILE)
    truth = _load(root, MEASURED, "metrics.json")
    measured = (truth or {}).get("headline")
    truth_u = validation(truth)["u_val"] if measured and not truth["parameters"]["quick"] \
        else None
    linear, finite = scorecard.overall(pops, models), scorecard.overall(pops, models, True)
    spread = {f: scorecard.spread(pops, models, f) for f in (False, True)}
    stale = set(costs_stale(bench)[0])
    header = ["model", "model-form error, linear regime", "model-form error, finite load",
              "consistency limit (largest, +- fit)", "worst isotropy error",
              "alternation on the mirrored five split, 5-layer view, linear regime (signed, the "
              "larger over the bases; decides nothing)", "RK4 run",
              "CPU s per simulated s", "Truth Cube bead RMS [mm]"]
    rows = []
    for m in models:
        el = [e["moduli_rel_err"] for e in (conv or {}).get("elasticity", [])
              if e["model"] == m and e.get("moduli_rel_err") is not None]
        mine = [r for r in (cube or {}).get("runs", []) if r["model"] == m]
        # the mirrored five split alone: the paper's lattice, one mesh (the others' 5-layer
        # scores are smooth barrels to this view, and the unstructured mesh is not conforming)
        alt = [r["alternation_rel"] for r in mine
               if r["mesh"] == "five" and r.get("alternation_rel") is not None]
        flutter = sum(r.get("dyn_verdict") == "unstable (flutter)" for r in mine
                      if r["bc"] == "clamped")
        clamped = sum(r["bc"] == "clamped" for r in mine)
        b, fl = _bench_row(bench, m), _bench_row(bench, BASE)
        conv_quick = bool(conv and conv["parameters"]["quick"])
        rows.append([m, QUICK_CELL if quick else
                     _overall_cell(linear, m, pops, False, spread[False]),
                     QUICK_CELL if quick else _overall_cell(finite, m, pops, True, spread[True]),
                     QUICK_CELL if conv_quick else worst(limits(conv, m)) if conv else "n/a",
                     fmt(max(el)) if el else "n/a",
                     fmt(max(alt, key=abs)) if alt else "n/a",
                     QUICK_CELL if quick and clamped else
                     f"{clamped - flutter} of {clamped} clamped runs come to rest"
                     + (f", {flutter} {'grows' if flutter == 1 else 'grow'} beyond the "
                        "damping" if flutter else "")
                     if clamped else "n/a",
                     (f"{cpu_seconds(b)} ({ratio_text(b, fl)} x fem-linear: "
                      f"{ratio_parts(b, fl)})"
                      + (" (timed on earlier kernels)" if m in stale or BASE in stale else "")
                      if b and fl and b is not fl else
                      cpu_seconds(b) if b else "n/a"),
                     _bead(measured, m, truth_u)])
    return header, rows


def _overall_cell(means, model, pops, finite, spread):
    from . import scorecard
    if any(p.quantity.p1 == model and p.finite == finite for p in pops):
        return "FEM P1 itself"
    if any(model in p.identity and p.finite == finite for p in pops):
        return "identity check (P1's law in this regime)"
    said = scorecard.describe(means[model], spread.get(model)) if model in means else "n/a"
    # a failure in a population the ranking leaves out is the model's all the same; it ranks
    # the model only where it fails its median there, as in a ranked population
    out = [f"{st.failed} of {st.runs} in {p.label}"
           + ("" if model not in means else " (ranked)" if scorecard.failure_ranks(p, model)
              else " (counted, below its median: no rank)")
           for p in pops if p.finite == finite and not p.ranked and not p.patch_test
           for _, st, _ in p.standings() if st.model == model and st.failed]
    if not out:
        return said
    return said + (f"; where the numbers are left out: {', '.join(out)}"
                   if model in means else f"; failed outside the ranking: {', '.join(out)}")


def _bead(measured, model, u_val=None):
    """'rms at strain % (u_val u)': a model's bead RMS at the headline state with the
    uncertainty it is read against."""
    v = (measured or {}).get("models", {}).get(model)
    if not v:
        return "n/a"
    u = (u_val or {}).get(model)
    return (f"{fmt(v['bead_rms_mm'])} at {fmt(100 * measured['strain'], 4)} %"
            + (f" (u_val {fmt(u, 2)})" if u is not None else ""))


def lines(root, models, pops=(), quick=False):
    """The answers, each a short paragraph, the last what to pick."""
    art = _record(root, "artefact")
    conv = _load(root, "convergence", "metrics.json")
    bench = _load(root, BENCH_FOLDER, BENCH_FILE)
    out = []
    if art and art["parameters"]["quick"]:
        out.append("**Which reading?** Quick: not decided (`pbcm run artefact` decides).")
    elif art:
        out.append(f"**Which reading?** {_decisive(art)}")
    else:
        out.append("**Which reading?** Not computed: run `pbcm run artefact`.")
    # a quick run's imbalance holds for its few meshes only: said by the full run
    out.append(_cost_of_replacing(pops, models, quick)
               + ("" if quick else _imbalance(root, models)))
    if conv:
        lim = {m: limits(conv, m) for m in models}
        # below the patch tolerance on every lattice, and converging on the irregular ones
        passed = [m for m, v in lim.items() if v and all(
            x[0] + x[1] < PATCH_TOL if isinstance(x, tuple) else x in LIMITED
            for x in v.values())]
        rest = sorted((m for m in models if m not in passed), key=lambda m: _largest(lim[m]))
        nolimit = sorted({k for m in rest for k, v in lim[m].items() if not _whole(v)})
        ranked = sorted(((m, _worst_limit(lim[m])) for m in rest if _worst_limit(lim[m])),
                        key=lambda x: x[1][0])
        if conv["parameters"]["quick"]:     # the patches are the full run's: said
            out.append("**How far from the continuum?** Quick: not decided (`pbcm run "
                       "convergence` decides, on its finer levels); on the same patches as "
                       "the full run" + _irregular(conv, models)
                       + " ([convergence](convergence/report.md)).")
        else:
            out.append("**How far from the continuum?** "
                       + "The consistency limit, the sliding cube's error as the mesh is "
                       "refined (a patch test; per lattice the larger of its displacement "
                       "error and its stiffness error |reaction ratio - 1|, which the "
                       "prescribed top displacement hides; the largest over the lattices, +- the "
                       "extrapolation's uncertainty, its u_val (the reference is exact); beside "
                       "it each family where the "
                       "model has no limit, and what its fit found there): "
                       + ", ".join(f"{m} {_limit_text(_worst_limit(lim[m]), _limit_count(lim[m]))}"
                                   + _no_limit(lim[m])
                                   for m in rest if _worst_limit(lim[m]))
                       + _limit_ties(ranked, "tied within their +- on the lattices (limits "
                                     "of one quantity only), whatever each does "
                                     "on the families where it has no limit")
                       + _unordered(ranked)
                       + (f"; below {PATCH_TOL:g}: {', '.join(passed)}" if passed else "")
                       + (f"; no limit on {', '.join(nolimit)}" if nolimit else "")
                       + _diverging(lim)
                       + _finest(conv, {m: lim[m] for m in rest}, nolimit)
                       + _irregular(conv, models)
                       + _beyond_the_patch(conv, models)
                       + " ([convergence](convergence/report.md)).")
    truth = _load(root, MEASURED, "metrics.json")
    if truth and truth.get("headline"):
        out.append(_measured_line(truth, models) if not truth["parameters"]["quick"] else
                   "**How far from a measured body?** Quick: not decided (`pbcm run "
                   "truth-cube` decides: a quick run has no variants of the inputs nobody "
                   "measured, so no u_input to read the beads against).")
    rows = {m: _bench_row(bench, m) for m in models}
    if all(rows.get(k) for k in ("fem-linear", "msm")):
        fl = rows["fem-linear"]
        where = (bench or {}).get("machine") or {}
        out.append(f"**At what cost?** One simulated second on the bench's "
                   f"{fmt(rows['fem-linear']['tets'])}-tetrahedron cube, at each model's own "
                   "stable RK4 step, over fem-linear's, in serial CPU time on "
                   f"{where.get('cpu', 'an unnamed processor')} (one of its "
                   f"{where.get('cores', '?')} cores; the median over rounds of the in-round "
                   "step-time ratio, "
                   "times the "
                   "stable-step ratio [its range over the rounds]; not a ratio of median "
                   "times): "
                   + ", ".join(f"{m} {ratio_text(r, fl)}"
                               for m, r in rows.items() if r and m != "fem-linear")
                   + " ([bench](bench/bench.md)).")
    if art and art["parameters"]["quick"]:
        out.append("**What causes the bulge/neck?** Quick: not decided (`pbcm run artefact` "
                   "decides).")
    elif art:
        out.append(f"**What causes the bulge/neck?** {_cause_numbers(art)}")
    out += recommendation(root, models, pops, quick, rows)
    return out


def _beyond_the_patch(conv, models):
    """'; beyond the patch test ...': per model, where the convergence study's other problems
    (bending, torsion, the clamped cube: every fit but the sliding cube's) diverge or stop at
    a floor under refinement, so that no patch-test limit is read as the model's distance to
    the continuum everywhere."""
    # a verdict on two levels observes no order: only three levels or more decide one
    # nor one the study calls not resolved (its finest error below what its reference judges)
    loose = {tuple(k) for k in conv.get("not_resolved", [])}
    fits = [f for f in conv.get("fits", []) if f["model"] in models
            and not (f["case"] == "paper-cube" and f["bc"] == "sliding")
            and (f.get("levels") or 0) >= 3
            and (f["case"], f["bc"], f["mesh"], f["model"]) not in loose]

    def where(m, verdict):
        cases = {}
        for f in fits:
            if f["model"] == m and f["verdict"] == verdict:
                cases.setdefault(f["case"], []).append(f["mesh"])
        return "; ".join(f"{c} on {', '.join(v)}" for c, v in cases.items())
    if not fits:
        return ""
    n = {m: sum(f["model"] == m for f in fits) for m in models}
    div = {m: w for m in models if (w := where(m, "diverges"))}
    floor = {m: sum(f["model"] == m and f["verdict"] == "floor" for f in fits) for m in models}
    return ("; beyond the patch test (the study's bending, torsion and clamped-cube fits of "
            "three levels or more, one per problem and mesh family, those it calls not "
            "resolved left out: a subset of the convergence report's counts, which hold the "
            "sliding cube's too), the error grows under refinement for "
            + (", ".join(f"{m} ({v})" for m, v in div.items()) if div else "no model")
            + ("; stops at a floor in " + ", ".join(f"{floor[m]} of those {n[m]} for {m}"
                                                    for m in models if floor[m])
               if any(floor.values()) else ""))


def _limit_ties(limits_, said="tied within their +-"):
    """' (tied within their +-: a, b; b, c)': the longest runs of neighbours (in the order
    given, by limit) in which every pair differs by less than their uncertainties combined
    (sqrt(u_a^2 + u_b^2)); a model may share a group with each of two models that are resolved
    from each other (ties are not transitive)."""
    def tied(i, j):
        (_, (a, ua, *wa)), (_, (b, ub, *wb)) = limits_[i], limits_[j]
        # a displacement limit and a stiffness limit are two quantities: never tied
        same = [w.split(";")[0] for w in wa[:1]] == [w.split(";")[0] for w in wb[:1]]
        return same and abs(a - b) < (ua ** 2 + ub ** 2) ** 0.5
    groups = []
    for i in range(len(limits_)):
        j = i
        while j + 1 < len(limits_) and all(tied(k, j + 1) for k in range(i, j + 1)):
            j += 1
        if j > i and not any(g[0] <= i and j <= g[1] for g in groups):
            groups.append((i, j))
    return (f" ({said}: " + "; ".join(
        ", ".join(m for m, _ in limits_[i:j + 1]) for i, j in groups) + ")" if groups else "")


def _unordered(limits_):
    """' (overlapping within their +- but limits of different quantities, so not ordered:
    a, b)': neighbours (in the order given, by limit) whose values overlap within their
    uncertainties combined while one is a displacement limit and the other a stiffness limit,
    which no tie can join and no order ranks."""
    pairs = []
    for (ma, (a, ua, *wa)), (mb, (b, ub, *wb)) in zip(limits_, limits_[1:]):
        qa, qb = (w[0].split(";")[0] if w else "" for w in (wa, wb))
        if qa != qb and abs(a - b) < (ua ** 2 + ub ** 2) ** 0.5:
            pairs.append(f"{ma} ({qa}), {mb} ({qb})")
    return (" (overlapping within their +- but limits of different quantities, so not "
            "ordered: " + "; ".join(pairs) + ")" if pairs else "")


def _no_limit(values):
    """' (diverges on x; not asymptotic on y)': the families without a limit, with the fit's
    verdict there ('' where every family has one)."""
    other = [f"{_shown(v)} on {k}" for k, v in values.items() if not isinstance(v, tuple)]
    other += [f"{v[2].split('; ', 1)[1]} on {k} (its stiffness {_pm(v)} there)"
              for k, v in values.items() if isinstance(v, tuple) and "; " in v[2]]
    return f" ({'; '.join(other)})" if other else ""


def _diverging(lim):
    """' (diverging, a failure: a on x; ...)' for the fits whose error grows as h falls."""
    bad = [f"{m} on {k}" for m, v in lim.items() for k, x in v.items() if x == "diverges"]
    return f" (diverging there, a failure: {', '.join(bad)})" if bad else ""


def _single_runs_u(values, u, what):
    """'one run each, so no spread over meshes (n = 1) ...; u_num U (what): ...': single-run
    errors [(model, error)] carry no spread over meshes, so an order among them holds for that
    mesh only; against the uncertainty they are read at (floored at round-off), the models it
    ties (the longest runs, in order of error, within u pair by pair) or none."""
    u = max(u, ROUND_OFF)
    vals = sorted(values, key=lambda kv: kv[1])
    groups, i = [], 0
    while i < len(vals):
        j = i
        while j + 1 < len(vals) and all(abs(vals[k][1] - vals[j + 1][1]) < u
                                        for k in range(i, j + 1)):
            j += 1
        if j > i:
            groups.append(", ".join(m for m, _ in vals[i:j + 1]))
        i = j + 1 if j > i else i + 1
    return (f"one run each, so no spread over meshes (n = 1): an order among them holds for "
            f"this mesh only; u_val {rel(u)}, which is u_num here ({what}; a computed "
            "comparison has no unmeasured input or data): "
            + (f"tied: {'; '.join(groups)}" if groups else "no two within it"))


def _finest(conv, lims, lattices):
    """'; there, the error on the finest level: on x: ...': per lattice, each model without a
    limit there (``lims`` {model: its limits by family}) at the smallest h it ran there (a
    number where no limit exists), read against the reference's stated estimate."""
    est = [r.get("error_estimate") or 0.0 for r in conv.get("references", [])
           if (r["case"], r["bc"]) == CONSISTENCY]
    per = []
    for lattice in lattices:
        said, values = [], []
        for m in [m for m, v in lims.items() if not _whole(v.get(lattice))]:
            rs = [r for r in conv.get("runs", []) if (r["case"], r["bc"]) == CONSISTENCY
                  and r["mesh"] == lattice and r["model"] == m
                  and r.get("disp_rel_l2") is not None]
            if rs:
                r = min(rs, key=lambda r: r["h_mm"])
                e, which = finest_error(r)
                said.append(f"{m} {fmt(e, 2)} ({which}) at {fmt(r['h_mm'], 3)} mm")
                values.append((m, e))
        if said:
            per.append(f"on {lattice}: {', '.join(said)} ("
                       + _single_runs_u(values, max(est, default=0.0),
                                        "the reference's estimate") + ")")
    return ("; there, the error at the finest level (no limit: not a consistency limit): "
            + "; ".join(per)) if per else ""


def finest_error(run):
    """(error, 'displacement' or 'stiffness'): a sliding-cube run's error as its limit is
    read, the larger of its displacement error and |reaction ratio - 1|."""
    e = run["disp_rel_l2"]
    s = abs(run["reaction_ratio"] - 1.0) if run.get("reaction_ratio") is not None else -1.0
    return (s, "stiffness") if s > e else (e, "displacement")


def _worst_limit(lim):
    """(limit, +-, which, lattice): the largest of a model's limits over the lattices."""
    nums = [(*v, k) for k, v in lim.items() if isinstance(v, tuple)]
    return max(nums, key=lambda v: v[0]) if nums else None


GROWING = "stiffness, growing: at least"


def _limit_text(w, n=None):
    """'0.45 +- 3e-05 (stiffness, six; 3 lattices)': the largest limit with what
    it measures and where, and of how many lattices' limits (``n``) it is the largest; a
    stiffness error growing under refinement is no limit but a bound from below: 'at least
    0.7 +- 0.02 (stiffness growing under refinement on six: no limit, its finest value +-
    1.25 x its last change)'."""
    of = f"; {n} lattices" if n and n > 1 else ""
    if w[2] == GROWING:     # a finest value, +- 1.25 times its last change (the glossary's)
        return (f"at least {_pm(w)} (stiffness growing under refinement on {w[3]}: no "
                f"limit, its finest value +- 1.25 x its last change{of})")
    return f"{_pm(w)} ({w[2]}, {w[3]}{of})"


def _limit_count(lim):
    """How many lattices give a model a limit or a bound (its entries that are numbers)."""
    return sum(isinstance(v, tuple) for v in lim.values())


def _cost_of_replacing(pops, models, quick):
    """The model-form answer: what replacing FEM P1 by each model costs, per regime."""
    from . import scorecard
    if quick:
        return ("**What does replacing FEM cost?** Quick: not decided (`pbcm report` "
                "decides, on every mesh).")
    said = []
    for finite, regime in ((False, "linear regime"), (True, "finite load")):
        ranked = scorecard.ranked(scorecard.overall(pops, models, finite))
        rng = scorecard.spread(pops, models, finite)
        if ranked:
            used = [p for p in pops if p.finite == finite and p.ranked]
            n, c = len(used), len({p.case for p in used})
            us = [p.u_model_form for p in used]
            checked = [p.label for p in pops
                       if p.finite == finite and scorecard.counts_failures(p)]
            said.append(f"{regime} (over {c} case{'s' if c > 1 else ''}, {n} case/bc "
                        f"population{'s' if n > 1 else ''}"
                        + (", so one case decides it" if c == 1 else "")
                        + (f"; their u_val {_span(us, ' to ')}, each score floored at "
                           "its own"
                           if us else "")
                        + (f"; and {len(checked)} more case/bc population"
                           f"{'s' if len(checked) > 1 else ''} ranked for failures alone "
                           f"(their cases weighing one each too): {', '.join(checked)}"
                           if checked else "")
                        + "): " + ", ".join(
                f"{m} " + (f"failed ({e[3]} of {e[4]} populations failed at the median"
                           + (f"; {fmt(e[1])} over the others" if e[1] is not None else "")
                           + ")" if e[3] else fmt(e[1]) if e[1] is not None else "n/a")
                + (f" [{fmt(rng[m][0], 2)}-{fmt(rng[m][1], 2)}]" if m in rng and not e[3]
                   else "")
                + (f" ({scorecard.failed_text(e)})" if scorecard.failed(e) else "")
                + (f" (the same mean rank as {tie})" if tie else "")
                + _rank_against_mean(ranked, k)
                for k, (_, m, e, tie) in enumerate(ranked))
                # the order where it holds: every pair a unit left out reverses or levels
                + _resolved_groups([m for _, m, _, _ in ranked],
                                   scorecard.unresolved_pairs(pops, models, finite)))
    if not said:
        return "**What does replacing FEM cost?** No case has a decomposed quantity."
    return ("**What does replacing FEM cost?** The model-form error, each model against FEM P1 "
            "with the same law on the same tetrahedra, in order of mean rank over the cases "
            "(each case weighing one, its boundary conditions averaged), beside it the geometric mean over the cases of the median over the "
            "meshes [its range when one mesh family is left out]; a failed run (no number; at "
            "the load, no converged solve) counts against its model once, as infinitely wrong "
            "in its population's median (where the numbers are left out, it ranks only if "
            "infinite: a failure-only ranking; the table below names where): "
            + "; ".join(said) + _left_out(pops) + " (the scorecard below).")


def _rank_against_mean(ranked, k):
    """' (mean rank 4.4, after b's 3.4)' where the k-th of ``ranked`` has a smaller geometric
    mean than the one before it, b (the mean rank orders them, the failures in it): said, so
    that the order is not read as a misprint; '' elsewhere."""
    if k == 0:
        return ""
    (_, before, prev, _), (_, _, e, tie) = ranked[k - 1], ranked[k]
    if tie or e[1] is None or prev[1] is None or e[1] >= prev[1]:
        return ""
    return f" (mean rank {e[0]:.3g}, after {before}'s {prev[0]:.3g})"


def _resolved_groups(order, loose):
    """' (resolved: {a, b} before {c}; within a group, not every pair resolved)': the order
    broken only where every model before the break is resolved from every model after it,
    ``loose`` every pair (either way round) a unit left out reverses, levels or ties. One
    group: 'no order resolved'."""
    apart = {frozenset(p) for p in loose}
    groups, i = [], 0
    while i < len(order):
        j = i
        k = i
        while k <= j:
            j = max([j] + [x for x in range(j + 1, len(order))
                           if frozenset((order[k], order[x])) in apart])
            k += 1
        groups.append(order[i:j + 1])
        i = j + 1
    if len(order) < 2:
        return ""
    if len(groups) == 1:
        return (" (no order resolved among them: each gap reverses, levels or ties when one "
                "mesh family or one case is left out)")
    return (" (resolved: " + " before ".join("{" + ", ".join(g) + "}" for g in groups)
            + "; within a group, not every pair resolved)")


def _left_out(pops):
    """'; left out of the ranking ...': the locking-prone populations, with how far their twin
    is from the continuum, and the finite-load populations the linear law meets within the
    scorecard's NEARLY_LINEAR: shown in the scorecard, never pooled (their failed runs: each
    model's row of the summary table)."""
    from .scorecard import NEARLY_LINEAR
    out = []
    for p in pops:
        if p.locking and not p.patch_test:
            d = p.discretisation()
            out.append(p.label + (f" (FEM P1 up to {rel(max(d))} from the continuum there)"
                                  if d else ""))
    near = [p.label for p in pops if p.nearly_linear and not p.patch_test and not p.locking]
    return (("; numbers left out, locking-prone (FEM P1, the twin, locks there: "
             "its model-form error ranks closeness to a locked mesh): " + ", ".join(out)
             if out else "")
            + (f"; numbers left out at finite load, nearly linear ({P1_LINEAR} within "
               f"{NEARLY_LINEAR:g} of neo-Hookean P1 there: no test of finite strain): "
               + ", ".join(near) if near else ""))


# a model's internal forces balance where their net sum is round-off against their sizes
BALANCE_TOL = 1e-8


def _imbalance(root, models):
    """' Internal forces that do not balance ...': the models whose net internal force or
    torque (net_force_rel, net_torque_rel, at the continuum's deformed state) exceeds
    BALANCE_TOL in some run of a case folder under ``root``, with the largest and where: such
    a model creates momentum or angular momentum, whatever its errors."""
    from ..registry import CASES
    said = []
    for key, what in (("net_force_rel", "force"), ("net_torque_rel", "torque")):
        worst = {}
        for case in CASES:
            for r in (_load(root, case, "metrics.json") or {}).get("runs", []):
                v = r.get(key)
                if r["model"] in models and v is not None and v > BALANCE_TOL and \
                        v > worst.get(r["model"], (0.0, ""))[0]:
                    worst[r["model"]] = (v, f"{case}/{r['mesh']}/{r['bc']}")
        if worst:
            said.append(f"net {what}: " + ", ".join(f"{m} up to {rel(v)} ({w})"
                                                   for m, (v, w) in sorted(worst.items())))
    if not said:
        return ""
    return (f" Internal forces that do not balance (net force or torque above {BALANCE_TOL:g} "
            "of their sum at the continuum's deformed state: momentum created, whatever the "
            "errors): " + "; ".join(said)
            + f"; every other model balances both to {BALANCE_TOL:g}.")


ACCURACY = 0.05     # the stated accuracy of the cost recommendation (model-form, linear)


def recommendation(root, models, pops, quick, bench_rows):
    """A head and at most six lines: what to pick for each stated use, from the model-form
    errors, the Truth Cube's comparison, the costs, the real-time study and the artefact
    study's mesh pick."""
    from . import scorecard
    head = "**What to pick?**"
    if quick:
        return [f"{head} Quick: not decided (`pbcm report` decides)."]
    out = [head]
    lin, fin = scorecard.overall(pops, models), scorecard.overall(pops, models, True)
    p1_lin = next((p.quantity.p1 for p in pops if not p.finite), None)
    p1_fin = next((p.quantity.p1 for p in pops if p.finite), None)

    def best(means, finite):
        """The first of the ranking and what it is not resolved from, pair by pair: the
        models tied with it, and those level with it or before it when one mesh family or
        one case is left out."""
        order = scorecard.ranked(means)
        if not order:
            return None, []
        top = order[0][1]
        others = [m for _, m, _, tie in order if tie == top]
        loose = scorecard.not_resolved_from(pops, list(means), top, finite)
        return top, others + [m for _, m, _, _ in order if m in loose and m not in others]

    conv = _load(root, "convergence", "metrics.json")

    def named(means, b, others, finite=False):
        rng = scorecard.spread(pops, list(means), finite).get(b)
        said = (f"{b}, model-form error {fmt(means[b][1])} (geometric mean over the cases"
                + (f"; {fmt(rng[0], 2)}-{fmt(rng[1], 2)} leaving one mesh family out"
                   if rng else "") + f"){cost(b)}")
        limit = _worst_limit(limits(conv, b)) if conv else None
        if limit and limit[0] >= PATCH_TOL:
            said += f", consistency limit {_limit_text(limit)}"
        if others:
            said += (f", not resolved from {', '.join(others)} (level with it or before it "
                     "when one mesh family or one case is left out, and not below it paired "
                     "under every leave-out)")
        return said

    def cost(m):
        r, fl = bench_rows.get(m), bench_rows.get(p1_lin)
        return (f", {ratio_text(r, fl)} times "
                f"{p1_lin}'s CPU cost per simulated second") if r and fl else ""
    if lin and p1_lin:
        same = sorted({m for p in pops if not p.finite for m in p.identity if m in p.parts}
                      - {p1_lin})
        b, others = best(lin, False)
        out.append(f"- Linear regime: FEM P1 ({p1_lin}"
                   + (f"; {', '.join(same)} coincide with it there" if same else "")
                   + ": 0 model-form error by construction, an identity check)"
                   + _discretisation(pops, False)
                   + (f"; the closest approximation is {named(lin, b, others)}" if b else "")
                   + (_cheaper_contender(b, others, bench_rows, p1_lin, conv) if b else "")
                   + ".")
    if fin and p1_fin:
        b, others = best(fin, True)
        n = len([p for p in pops if p.finite and p.ranked])
        order = [m for _, m, _, _ in scorecard.ranked(lin)] if lin else []
        linear = (f"; in the linear regime it ranks {order.index(b) + 1} of {len(order)}"
                  + (f" with {scorecard.failed_text(lin[b])}" if scorecard.failed(lin[b]) else "")
                  if b in order else "")
        said = (f"; not decided on {n} case/bc population{'s' if n > 1 else ''} between "
                f"{', '.join([b] + others)} (tied, or level or reversed when one mesh family "
                "or one case is left out)" if others else
                f"; the closest other, on {n} case/bc population{'s' if n > 1 else ''}, is "
                f"{named(fin, b, others, True)}{linear}") if b else ""
        # the geometric means may order the models otherwise than the mean ranks: said, so
        # that the order shown is never read as the only one the data allow
        if b and fin[b][1] is not None:
            lower = [m for m, e in fin.items() if m != b and not scorecard.failed(e)
                     and e[1] is not None and not e[3] and e[1] < fin[b][1]]
            if lower:
                said += ("; by geometric mean " + ", ".join(
                    f"{m} ({rel(fin[m][1])})" for m in sorted(lower, key=lambda m: fin[m][1]))
                    + f" come before {b} ({rel(fin[b][1])}): mean rank and geometric mean "
                    "disagree, so neither order decides")
        said += _how_finite(pops, p1_lin)
        cands = [b] + others if b else []
        failing = [f"{m} ({scorecard.failed_text(fin[m])})" for m in cands
                   if scorecard.failed(fin[m])]
        # the other models with a failed run in a ranked population, named with how many
        # failed (those failing only where the numbers are left out: the ranking's line)
        left = [f"{m} ({scorecard.failed_text(e)})"
                for m, e in fin.items() if e[2] and m not in cands]
        out.append(f"- Finite strain: {p1_fin} (the reference's law on P1, the identity "
                   "check of this comparison, not a measured accuracy"
                   + _discretisation(pops, True)
                   + ": on these meshes the mesh, not the law, sets the distance to the "
                   f"continuum; refine before choosing){said}"
                   + ("; with failed runs (no converged solve at the load): " + "; ".join(failing)
                      if failing else "")
                   + ("; other models with failed runs (no converged solve at the load): "
                      + "; ".join(left)
                      if left else "") + ".")
    truth = _load(root, MEASURED, "metrics.json")
    if truth and truth.get("headline"):
        v = validation(truth)
        tied = [m for m in v["tied"] if m in models]
        out.append(f"- Near incompressibility (the Truth Cube, nu {fmt(truth['parameters']['nu'])}"
                   f"): not decided by a measurement: {', '.join(tied)} are tied within "
                   f"u_val ({_span(v['u_val'].values())} mm); no verdict here compares a "
                   "model with FEM P1 at nu 0.49 or above (a `pbcm sweep` over nu on today's "
                   "presets would).")
    if lin and bench_rows.get(p1_lin):
        # the accuracy holds on every case, not on average: a model's largest case median
        worst_of = {m: scorecard.largest(pops, m) for m in lin}
        within = [m for m in lin if worst_of[m] is not None and worst_of[m] <= ACCURACY] \
            + [p1_lin]
        costed = [m for m in within if bench_rows.get(m)]
        cheap = min(costed, key=lambda m: bench_rows[m]["cpu_s_per_simulated_s"])
        cheapest = min((m for m in lin if bench_rows.get(m) and worst_of[m] is not None),
                       key=lambda m: bench_rows[m]["cpu_s_per_simulated_s"], default=None)
        line = (f"- Cost at a stated accuracy (model-form error within {ACCURACY:g} on every "
                f"case of the linear regime, the median over its meshes): {cheap}"
                + (" (FEM P1 itself, the yardstick of this accuracy: no approximation "
                   "comes within it of FEM P1 on every case, so none replaces it there)"
                   if cheap == p1_lin else f" (at most {fmt(worst_of[cheap])})")
                + f", {cpu_seconds(bench_rows[cheap])} CPU s per simulated s on "
                f"the bench's machine (serial CPU time at its own stable RK4 step on the "
                f"bench's {bench_rows[cheap]['tets']}-tetrahedron cube, the cost line's; its "
                "median round [the rounds' range where recorded]; a time moves with the "
                "machine, the ratios to fem-linear are the comparison)")
        if cheapest and bench_rows[cheapest]["cpu_s_per_simulated_s"] < \
                bench_rows[cheap]["cpu_s_per_simulated_s"]:
            line += (f"; {cheapest} is cheaper ("
                     f"{cpu_seconds(bench_rows[cheapest])} CPU s per simulated s, "
                     f"{ratio_text(bench_rows[cheapest], bench_rows[p1_lin])} x {p1_lin}'s) "
                     + (f"at model-form error up to {fmt(worst_of[cheapest])} on a case"
                        if math.isfinite(worst_of[cheapest]) else
                        "but failed at the median on a case (a run with no number, or an "
                        "unpaired mode)")
                     # a failed run is never left out of what the pick says of a model
                     + (f", with {scorecard.failed_text(lin[cheapest])} (no number, or a "
                        "mode unpaired)" if scorecard.failed(lin[cheapest]) else ""))
        out.append(line + ".")
    rt = _load(root, "realtime", "metrics.json")
    if rt and not rt["parameters"]["quick"]:
        out.append(f"- A real-time budget ([realtime](realtime/report.md)): "
                   f"{rt.get('index_answer') or rt['answer']}")
    eng = _load(root, "engines", "metrics.json")
    if eng and not eng["parameters"]["quick"]:
        out.append(f"- A physics engine instead (Newton; [engines](engines/report.md)): "
                   f"{eng['answer']}.")
    art = _record(root, "artefact")
    pick = None if not art or art["parameters"]["quick"] else art["answer"].get("mesh_pick")
    if pick:
        out.append("- Meshing a cube lattice for a particle model (the bulge/neck pattern; "
                   f"[artefact study](artefact/report.md)): {pick}.")
    return out[:8] if len(out) > 1 else []


def _cheaper_contender(best, others, bench_rows, base, conv=None):
    """'; of those not resolved from it, X costs ... : the pick at the accuracy the data
    resolve': among the first and the models it is not resolved from, one whose cost per
    simulated second (its range over the bench's rounds) lies wholly below the first's."""
    fl = bench_rows.get(base)
    if not others or not fl or not bench_rows.get(best):
        return ""
    def span(m):
        r, rng = sim_ratio(bench_rows[m], fl)
        return rng or [r, r]
    hi_best = span(best)[0]
    cheaper = [m for m in others if bench_rows.get(m) and span(m)[1] < hi_best]
    if not cheaper:
        return ""
    m = min(cheaper, key=lambda m: span(m)[1])
    limit = _worst_limit(limits(conv, m)) if conv else None
    return (f"; {m}, not resolved from it in model-form error, costs "
            f"{ratio_text(bench_rows[m], fl)} times {base}'s, wholly below {best}'s range"
            + (f" (its consistency limit {_limit_text(limit)})"
               if limit and limit[0] >= PATCH_TOL else "")
            + f": at the model-form accuracy the data resolve, {m} is the cheaper pick")


def _how_finite(pops, linear_law):
    """'; how far each load is from the linear regime: ...': per population at finite load,
    the linear law's model-form error there (``linear_law`` against P1 with the reference's
    law on the same tetrahedra: its linearisation error), so that a load the linear law
    meets within the scorecard's NEARLY_LINEAR is named as testing a nearly linear response,
    shown and not pooled at finite load."""
    from .scorecard import NEARLY_LINEAR, linearisation
    at, locked = {}, set()
    for p in pops:
        if p.finite and not p.patch_test and linear_law in p.parts:
            v = linearisation(p)
            if v is not None:
                at[p.label] = v
                if p.locking:
                    locked.add(p.label)
    if not at:
        return ""
    near = sorted((k for k, v in at.items() if v <= NEARLY_LINEAR), key=at.get)
    far = sorted((k for k, v in at.items() if v > NEARLY_LINEAR), key=at.get)

    def short(k):
        return k.replace(" at the load", "") + (
            " (locking-prone: against a locked twin, so its locking too)" if k in locked
            else "")
    return (f"; {linear_law}'s model-form error at each load, on the case's own quantity (its "
            "linearisation there; median over the meshes): "
            + (f"nearly linear, within {NEARLY_LINEAR:g} (not pooled at finite load): "
               + ", ".join(f"{short(k)} {rel(at[k])}" for k in near) if near else
               f"none within {NEARLY_LINEAR:g}")
            + (f"; beyond: {', '.join(f'{short(k)} {rel(at[k])}' for k in far)}" if far else ""))


def _discretisation(pops, finite):
    """', whose discretisation error ...': FEM P1's discretisation error per population (the
    median over its meshes [their range]), the smallest and largest population named, never
    pooled."""
    meds = []
    for p in pops:
        d = p.discretisation()
        if p.finite != finite or not p.ranked or not d:
            continue
        med, u = float(np.median(d)), p.u_continuum
        meds.append((med, f"[{rel_range(min(d), max(d))} over the meshes]",
                     p.label + (f", not resolved from zero: the continuum's u_val {rel(u)} "
                                "there is as large" if u >= med else
                                f", beyond what its reference judges: the continuum's u_val "
                                f"{rel(u)} exceeds a fifth of it" if u > med / JUDGES else "")))
    if not meds:
        return ""
    (lo, lo_range, a), (hi, hi_range, b) = min(meds), max(meds)
    if len(meds) == 1:
        return (f", whose discretisation error there is {rel(lo)} {lo_range} (median over "
                f"the meshes, {a})")
    return (f", whose discretisation error, the median over the meshes of each ranked case, "
            f"runs from {rel(lo)} {lo_range} ({a}) to {rel(hi)} {hi_range} ({b}): what every "
            "model on those meshes pays as well")

def u_vals(truth, strain, floor):
    """The Truth Cube's u_val (ASME V&V 20) of each model at ``strain`` (and of the neo-Hookean
    continuum, read as the models are), with its parts: u_D the beads' noise ``floor``, u_input
    the neo-Hookean continuum's bead RMS over its references' variants of the inputs nobody
    measured (plate friction, travel, nu), each input's half range combined in quadrature
    (``input_spread``): the inputs' own effect, the same for every model (a model's response
    beyond it, a P1 mesh locking near incompressibility, is its error, never uncertainty);
    where the continuum has no variants, each model's own spread over them (on the mesh they
    ran on); u_num the neo-Hookean reference's change over its last refinement.
    Returns ({model: u_val}, u_num, {model: u_input}, the variants' mesh)."""
    from ..measuring.error_model import u_val
    nh = truth["headline"].get("continuum")
    at = [r for r in truth.get("references", []) if abs(r.get("strain", -1) - strain) < 1e-9
          and r.get("model") == nh and not r.get("failed")]
    # the continuum every model approximates: the neo-Hookean reference, not the linear one
    u_num = max((r.get("bead_change_mm") or 0.0 for r in at if r.get("variant") == "bonded"),
                default=0.0)
    rows = [r for r in truth.get("rows", []) if abs(r.get("strain", -1) - strain) < 1e-9
            and r.get("bead_rms_mm") is not None]
    variants = truth["parameters"].get("variants", {})
    mesh = next((r["mesh"] for r in rows if r["variant"] != "bonded"), None)
    u_input, u = {}, {}
    for m in truth["parameters"]["models"]:
        u_input[m] = input_spread({r["variant"]: r["bead_rms_mm"] for r in rows
                                   if r["model"] == m and r["mesh"] == mesh}, variants)
    cont = {r["variant"]: r["bead_rms_mm"] for r in at if r.get("bead_rms_mm") is not None}
    if nh and len(cont) > 1:
        u_input = dict.fromkeys([*u_input, nh], input_spread(cont, variants))
    for m, ui in u_input.items():
        u[m] = u_val(u_num, ui, floor)
    return u, u_num, u_input, mesh


def validation(truth):
    """The Truth Cube's comparison error read against each model's u_val (``u_vals``) at the
    headline state: the models within their u_val, and those tied with the closest (a
    difference below the larger of the two u_val)."""
    h = truth["headline"]
    u_all, u_num, u_in, mesh = u_vals(truth, h["strain"], h["floor_mm"])
    own = [m for m in h["models"] if m in truth["parameters"]["models"]]
    u = {m: u_all[m] for m in own}
    rms = {m: h["models"][m]["bead_rms_mm"] for m in own}
    best = min(own, key=rms.get) if own else None
    return {"u_val": u, "u_num": u_num, "u_input": {m: u_in[m] for m in own},
            "u_d": h["floor_mm"], "mesh": mesh, "best": best,
            "continuum_u_val": u_all.get(h.get("continuum")),
            "tied": [m for m in sorted(own, key=rms.get)
                     if rms[m] - rms[best] < max(u[m], u[best])],
            "within": [m for m in own if rms[m] <= u[m]]}


def _span(values, between="-"):
    """'lo-hi' of the values to two figures, one value where they agree."""
    v = list(values)
    if not v:
        return "n/a"
    lo, hi = fmt(min(v), 2), fmt(max(v), 2)
    return lo if lo == hi else f"{lo}{between}{hi}"


def _measured_line(truth, models):
    h = truth["headline"]
    NH = h["continuum"]
    v = h["models"]
    val = validation(truth)
    mine = sorted((m for m in models if m in v), key=lambda m: v[m]["bead_rms_mm"])
    said = (f"**How far from a measured body?** On the Truth Cube's 343 beads at "
            f"{fmt(100 * h['strain'], 4)} % compression (bonded plates, {h['mesh']} mesh), each "
            f"model read against its u_val = sqrt(u_D^2 + u_input^2 + u_num^2), "
            f"{_span(val['u_val'].values())} mm (u_D the beads' noise "
            f"{fmt(val['u_d'], 2)}; u_input each unmeasured input's half range of the "
            f"neo-Hookean continuum's bead RMS (plate friction, travel, nu) in quadrature, the "
            f"same for every model, {_span(val['u_input'].values())}; u_num the reference's "
            f"last refinement, {fmt(val['u_num'], 2)}): ")
    if NH in v:
        u_nh = val.get("continuum_u_val")
        said += (f"the neo-Hookean continuum is {fmt(v[NH]['bead_rms_mm'])} mm RMS off"
                 + (f", {'within' if v[NH]['bead_rms_mm'] <= u_nh else 'beyond'} its u_val "
                    f"{fmt(u_nh, 2)} mm (its spread over the plate assumptions included)"
                    if u_nh else "") + "; ")
    if mine:
        said += (f"the models from {fmt(v[mine[0]]['bead_rms_mm'])} to "
                 f"{fmt(v[mine[-1]]['bead_rms_mm'])} mm; within their u_val: "
                 f"{', '.join(val['within']) or 'none'}; tied (a difference below u_val): "
                 f"{', '.join(val['tied'])}"
                 + (f"; apart: {', '.join(m for m in mine if m not in val['tied'])}"
                    if len(val["tied"]) < len(mine) else "") + ". ")
    sens = _nu_sensitivity(truth, h["strain"])
    if sens:
        blind = [m for m, d in sens[1] if d == 0]
        said += ("Moving nu over its unmeasured range moves the models' bead RMS on the "
                 f"{sens[0]} mesh by " + ", ".join(f"{m} {fmt(d, 2)} mm" for m, d in sens[1])
                 + (f" ({', '.join(blind)}: blind to nu, a finding, not a certainty)"
                    if blind else "") + ". ")
    return said + ("The plates prescribe displacement, so the beads test the deformed shape, "
                   f"not the stiffness ([truth-cube]({MEASURED}/report.md)).")


def _nu_sensitivity(truth, strain):
    """(mesh, [(model, |bead RMS at the largest nu - at the smallest|)]) over the study's nu
    variants at ``strain``, or None where it ran none."""
    variants = {k: v for k, v in truth["parameters"].get("variants", {}).items()
                if k.startswith("nu=")}
    if len(variants) < 2:
        return None
    lo, hi = min(variants, key=lambda k: variants[k][2]), max(variants,
                                                              key=lambda k: variants[k][2])
    rows = [r for r in truth.get("rows", []) if abs(r.get("strain", -1) - strain) < 1e-9
            and r.get("bead_rms_mm") is not None]
    mesh = next((r["mesh"] for r in rows if r["variant"] == hi), None)
    at = {(r["model"], r["variant"]): r["bead_rms_mm"] for r in rows if r["mesh"] == mesh}
    out = [(m, abs(at[(m, hi)] - at[(m, lo)])) for m in truth["parameters"]["models"]
           if (m, hi) in at and (m, lo) in at]
    return (mesh, out) if out else None


def _irregular(conv, models):
    """'; on irregular patches ...': each model's worst patch-test error over the families
    whose patch is irregular (perturbed lattices, unstructured), where the study ran it, read
    against FEM P1's error on the same patches (the exact answer's numerical floor)."""
    worst_of, floor, where, ran = {}, 0.0, {}, set()
    for r in conv.get("patch", []):
        if r["mesh"] in REGULAR or r.get("patch_error") is None:
            continue
        ran.add(r["mesh"])
        if r["model"] == "FEM P1":
            floor = max(floor, r["patch_error"])
        if r["model"] in models and r["patch_error"] >= worst_of.get(r["model"], 0.0):
            worst_of[r["model"]], where[r["model"]] = r["patch_error"], r["mesh"]
    if not worst_of:
        return ""
    ordered = sorted(worst_of.items(), key=lambda kv: kv[1])
    return ("; the patch test with every boundary node prescribed, on irregular patches "
            f"({', '.join(sorted(ran))}; each model's worst, on the patch "
            "named, against the exact linear field; "
            + _single_runs_u(ordered, floor, "FEM P1's own error there").replace(
                "this mesh only", "these patches only") + "): "
            + ", ".join(f"{m} {rel(v)} ({where[m]})" for m, v in ordered))


def _largest(limit):
    """The order of the consistency answer: the models diverging on a lattice last, then by
    their largest limit."""
    nums = [v[0] for v in limit.values() if isinstance(v, tuple)]
    return ("diverges" in limit.values(), max(nums, default=np.inf))


def _decisive(art):
    """The artefact study's reading verdict as its report states it, from its own table: decided
    or not (and why), whether no reading, or no timed one, reproduces all the paper's
    observables, and per reading each observable's call with the numbers that make it (the
    cost's ratio with its range over the bench's rounds at the paper's 320 tetrahedra, the
    call held at every size the bench ran; the growth rate on each mesh it was measured on, clamped base only, a rate
    above 0 a flutter: a reading stable on one mesh and growing on another is not stable);
    the readings with a normal-stress term apart (their cost not decided)."""
    v = art["verdict"]
    names = {r["model"]: r["name"] for r in art["readings"]}
    words = {True: "matched", False: "missed", None: "not decided"}
    said = {"cost": "the cost (the paper's Figure 2: a step over 10x msm's; the bench's "
                    "in-round ratio on the 320-tetrahedron five split of the paper's 125 nodes "
                    "(the paper's own mesh had 374 tetrahedra), read on its range "
                    "over the bench's rounds; missed where the whole range is below the 20 % "
                    "band around 10 at that size and at every other size the bench ran, each "
                    "its own population, else not decided)",
            "stable": "stability (the linearised growth rate at rest on each conforming split "
                      "of the paper's lattice, clamped base only, as the paper fixes its nodes "
                      "at y = 0; a rate above 0 flutters, stable means rate 0 on every mesh, the "
                      "damping the paper does not state deciding only between the two)"}

    def cost(r):
        span = r.get("step_range")
        if not r.get("timed"):
            return "not timed"
        why = r.get("cost_why") or ""
        return (fmt(r["step_vs_msm"], 3) + (f" [{fmt(span[0], 3)}-{fmt(span[1], 3)}]" if span
                                             else ", no range")
                + (" at 320 tetrahedra; " + why.split("; ")[-1].replace(": not decided", "")
                   if "not at every size" in why else ""))

    def stable(r):
        by = r.get("growth_by_mesh") or {}
        return r.get("stable_why") or (", ".join(f"{m} {fmt(x, 3)} 1/s" for m, x in by.items())
                                       or "no growth rate")
    rows = [r for r in art["readings"] if r["in_paper"]]
    per = "; ".join(
        f"{r['name']}: cost {words[r['matches']['cost']]} ({cost(r)}), stable "
        f"{words[r['matches']['stable']]} ({stable(r)})" for r in rows)
    head = ((f"Plainly: {v['plain']}. " if v.get("plain") else "")
            + (f"{names.get(v['model'], v['model'])} ({v['why']})" if v.get("decided") else
               f"Not decided ({v['why']})"))
    return (head + " ([artefact study](artefact/report.md)). "
            + ("No reading reproduces all the paper's observables. "
               if v.get("none_reproduces") else
               "No timed reading reproduces all the paper's observables ("
               + ", ".join(v.get("cost_miss", [])) + " each miss the cost; the literal "
               "readings were not timed). " if v.get("none_reproduces_timed") else "")
            + f"Observables: {said['cost']} and {said['stable']}; per reading: {per}."
            + (f" Stable (rate 0) on every mesh, clamped base: "
               f"{', '.join(v['stable']) or 'none'}; not decided (on the mesh or the damping): "
               f"{', '.join(v['stability_depends']) or 'none'}"
               + (f"; growing beyond the damping on every mesh: {', '.join(v['unstable'])}"
                  if v.get("unstable") else "") + "." if "stable" in v else "")
            + (" With a normal-stress term the paper's equations lack, the cost is not "
               "decided (this implementation's added term): no such variant is evidence "
               "for a reading." if v.get("with_normal_term") else ""))


def _cause_numbers(art):
    """The artefact study's answer to what causes the bulge/neck pattern, as its report
    opens (what is resolved, then what is not), with its own statement of how sure; 'quick:
    not decided' where the run lacks the meshes that decide (9 and 17 nodes per side)."""
    a = art["answer"]
    decisive = a.get("decisive", 9)
    if not any(c["nodes_per_side"] >= decisive for c in art.get("cells", [])):
        return (f"Quick: not decided (this run lacks the meshes of {decisive} and more nodes "
                "per side; `pbcm run artefact` decides) ([artefact study](artefact/report.md)).")
    # the study's plain answer; its numbers, evidence and how sure in its report
    said = " ".join(a.get("short") or a.get("verdicts") or []) or a.get("text")
    return (said + " " if said else "") + ("The numbers that decide each answer, the "
                                          "evidence and how sure: the [artefact "
                                          "study](artefact/report.md).")


__all__ = ["lines", "table"]
