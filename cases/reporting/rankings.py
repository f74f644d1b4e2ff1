"""Sentences that rank the models of a case's runs, computed from the runs: one population per
aggregate (each boundary condition apart), each cell 'median [min-max], n of N runs', a run
without a value counted against its model (``error_model.standings``), ties within the
reference's u_num of a group's first, the closest and farthest model, failures of every
phase, and the case's load against the neo-Hookean reference."""
import math

import numpy as np

from ..measuring.catalogue import err_name, ref_name
from .document import Table, rel, rel_range
from ..measuring.error_model import JUDGES, P1_FINITE, P1_LINEAR, standings, u_num

# what a ranking by a case's own metric measures: the total error, the mesh's own included
# (the model-form ranking is the error model's, cases.reporting.scorecard)
AGAINST = (" against its reference (total error, the mesh's discretisation error included: "
           "not a ranking of the models, which the model-form error is)")


def populations(runs):
    """The runs split by boundary condition: each (case, bc) is one population (a patch test
    and a clamped cube are never pooled); {bc: runs}, in the runs' order."""
    out = {}
    for r in runs:
        out.setdefault(r["bc"], []).append(r)
    return out


def cell(values, total):
    """'median [min-max], n of N runs' of one aggregate."""
    if not values:
        return f"no result, 0 of {total} runs"
    return (f"median {rel(np.median(values))} [{rel_range(min(values), max(values))}], "
            f"{len(values)} of {total} runs")


def estimate(runs, key="p2_error_estimate"):
    """The reference's error estimate a ranking of ``runs`` respects: the largest of their
    references' (one per mesh and bc; None where the reference has none); ``key`` the
    reference's (nh_error_estimate for the neo-Hookean one)."""
    est = [r[key] for r in runs if r.get(key) is not None]
    return max(est) if est else None


def _labelled(runs, line_of):
    """``line_of(population runs)`` per boundary condition, prefixed by the bc when there are
    several populations."""
    pops = populations(runs)
    if len(pops) == 1:
        return [line_of(next(iter(pops.values())))]
    return [f"[{bc}] {line_of(rs)}" for bc, rs in pops.items()]


# the continuum's value behind a relative error whose quantity is not named after it
CONTINUUM_OF = {"reaction_rel_err": "reaction_fem_p2_n",
                "reaction_rel_err_nh": "reaction_fem_nh_n",
                "force_rel_err_max": "force_steps_fem_n",
                "lateral_rel_err_max": "lateral_strain_fem_steps"}


def _continuum_key(runs, metric):
    """The run key of the continuum's value whose relative error ``metric`` is, or None (an
    error that is a norm has none)."""
    if metric in CONTINUUM_OF:
        return CONTINUUM_OF[metric]
    keys = {k for r in runs for k in r}
    return next((ref_name(q) for q in sorted(keys)
                 if err_name(q) == metric and ref_name(q) in keys and ref_name(q) != q), None)


def uncertainty(runs, metric, estimate_key="p2_error_estimate", per_mesh=False,
                spread_keys=()):
    """(u_num, the spread exceeds the estimate) of a comparison of ``metric`` over ``runs`` (one
    continuum problem on several meshes): the reference's largest estimate combined in
    quadrature with the spread of the continuum's value across the meshes
    (``error_model.u_num``); ``spread_keys``: for a field (a metric without one continuum
    value), the run keys of the same reference's scalar values, whose largest spread over the
    meshes it takes (a reference that disagrees with itself on a quantity is that uncertain
    on the field it gives; a scalar reads its own spread); ``per_mesh``:
    each mesh poses its own continuum problem, so the values' spread is no uncertainty and
    u_num is the estimate alone."""
    if per_mesh:
        return u_num(estimate(runs, estimate_key), [])
    own = _continuum_key(runs, metric)
    keys = [own] if own else list(spread_keys)
    est = estimate(runs, estimate_key)
    found = [u_num(est, _last_values(runs, k)) for k in dict.fromkeys(keys)]
    return max(found) if found else u_num(est, [])


def _last_values(runs, key):
    """The continuum's value under ``key`` per mesh (a sequence's last step)."""
    values = {}
    for r in runs:
        v = r.get(key)
        if v is not None:
            values[r["mesh"]] = float(v[-1]) if isinstance(v, (list, tuple)) else float(v)
    return list(values.values())


def _standings(runs, metric, u, lost_key=None):
    """``error_model.standings`` of ``metric`` over one population: every run a model had
    counts, a run without a value as infinitely wrong; ``lost_key`` the run key counting the
    parts a run lost (unpaired modes): a run that lost one is a failed run, as in the error
    model."""
    by = {}
    for r in runs:
        by.setdefault(r["model"], []).append(
            None if lost_key and r.get(lost_key) else r.get(metric))
    # ordered by the parts lost first, as the error model's tables are
    return standings(by, u, _lost(runs, lost_key))


def _not_judged(standings, u):
    """The standings whose finite median is below JUDGES times the reference's u_num: errors
    the reference cannot order."""
    return [s for _, s, _ in standings if math.isfinite(s.score) and s.score < JUDGES * u]


def _lost(runs, lost_key):
    """{model: parts lost over its runs} (unpaired modes), the models that lost none left
    out."""
    lost = {}
    for r in runs:
        if lost_key and r.get(lost_key):
            lost[r["model"]] = lost.get(r["model"], 0) + r[lost_key]
    return lost


def _u_text(u, defect, field=False, per_mesh=False):
    """'u_num U' and what it holds: the reference's estimate and its spread over the meshes
    in quadrature, or the estimate alone (a field has no one value to spread; each mesh its
    own continuum problem)."""
    held = (" (the estimate alone: each mesh its own continuum problem, its value read at "
            "the mesh's own nodes)" if per_mesh else
            " (the reference's estimate: a field has no one value to spread over the meshes)"
            if field else ", mostly the continuum's spread over the meshes" if defect else "")
    return f"u_val {rel(u, 2)}, which is u_num here{held}"


def ranking(runs, metric, label, estimate_key="p2_error_estimate", lost_key=None,
            per_mesh=(), spread_keys=()):
    """A table (one item of a report's findings): per population (boundary condition) the
    models by median ``metric`` over every run they had (a run without a value, or one that
    lost a part, counts against its model, as infinitely wrong), best first, with the range
    and 'n of N runs'; a model within the reference's u_num (``uncertainty``) and the two
    medians' spread of the first of the last group shares its order, and every model names
    those within it, whatever their order (the comparison cannot order them); ``per_mesh``:
    the boundary conditions where
    each mesh poses its own continuum problem."""
    rows = []
    for bc, rs in populations(runs).items():
        u, defect = uncertainty(rs, metric, estimate_key, bc in per_mesh, spread_keys)
        lost = _lost(rs, lost_key)
        st = _standings(rs, metric, u, lost_key)
        blind = [s.model for s in _not_judged(st, u)]
        for rank, s, tie in st:
            note = []
            if s.model in blind:
                rank = 1
                note.append(f"below {JUDGES} times u_num ({rel(JUDGES * u, 2)}): not judged, "
                            "not ordered from the models there")
            if lost.get(s.model):
                note.append(f"{lost[s.model]} unpaired modes (each run with one failed)")
            if tie.tied:
                held = _u_text(u, defect, _continuum_key(rs, metric) is None and not spread_keys,
                               bc in per_mesh)
                note.append(f"tied with {', '.join(tie.tied)} (within {held})")
            if tie.unresolved:
                note.append(f"not resolved from {', '.join(tie.unresolved)} (beyond u_val, "
                            "within both medians' spread over the meshes)")
            if s.failed:
                note.append(f"{s.failed} failed, counted against it")
            rows.append([bc, rank, s.model, *_stats(s), "; ".join(note)])
    return [Table(f"{label[0].upper()}{label[1:]} ({metric}){AGAINST} per model, median over "
                  "the meshes, a failed run counted against its model:",
                  ["bc", "order", "model", "median", "range", "runs", "note"], rows)]


def _stats(s):
    """(median, range, 'n of N') of a Standing: the median over every run it had."""
    if not s.values:
        return "failed", "", f"0 of {s.runs}"
    med = "failed at the median" if math.isinf(s.score) else rel(s.score)
    return (med, f"{rel_range(min(s.values), max(s.values))}",
            f"{len(s.values)} of {s.runs}")


def _cell(s):
    med, rng, n = _stats(s)
    if math.isinf(s.score):     # more runs failed than gave a number: no median to give
        return (f"{med}: {len(s.values)} of {s.runs} runs gave "
                + ", ".join(rel(v) for v in s.values) if s.values else f"{med}, {n} runs")
    return f"median {med}" + (f" [{rng}]" if rng else "") + f", {n} runs"


def best_and_worst(runs, metric, what, exact=False, estimate_key="p2_error_estimate",
                   lost_key=None, per_mesh=(), spread_keys=()):
    """Per population (boundary condition), one line naming the model closest to FEM and the
    farthest by median ``metric`` over every run (a run without a value counts against its
    model); the models within the reference's u_num (``uncertainty``) and the two medians'
    spread of the closest are named tied with it, the line says so where u_num exceeds a
    fifth of the smallest error it ranks (``exact``: the metric is against a closed form,
    which has no estimate), and it names the models with failed runs; ``lost_key``: the run
    key of the parts a run lost (unpaired modes): such a run is a failed run, and named;
    ``per_mesh``: the boundary conditions where each mesh poses its own continuum problem."""
    def line_of(rs):
        own = rs[0]["bc"] in per_mesh
        u, defect = (0.0, False) if exact else uncertainty(rs, metric, estimate_key, own,
                                                            spread_keys)
        st = _standings(rs, metric, u, lost_key)
        if not st or not any(s.values for _, s, _ in st):
            return f"No model gave {what}."
        best, worst = st[0][1], st[-1][1]
        failed = [s for _, s, _ in st if s.failed]
        twin = [s for _, s, _ in st if s.model in (P1_LINEAR, P1_FINITE)]
        if twin and all(math.isinf(s.score) for s in twin):
            # FEM P1 itself fails here: the meshes do not resolve the quantity, and an order of
            # the other models would measure the meshes, not the models
            return (f"{what}{AGAINST}: not ranked: FEM P1 itself fails at the median ("
                    + ", ".join(f"{s.model} {s.failed} of {s.runs}" for s in twin)
                    + "), so these meshes do not resolve it. Failed runs, counted against "
                    "their model: " + ", ".join(f"{s.model} ({s.failed} of {s.runs})"
                                                for s in failed) + ".")
        blind = [] if exact else _not_judged(st, u)
        if blind:    # a reference orders no error below five times its own u_num
            above = [s for _, s, _ in st if s not in blind]
            line = (f"{what}{AGAINST}: not judged below {JUDGES} times the reference's u_num "
                    f"({rel(JUDGES * u, 2)}): " + ", ".join(f"{s.model} ({rel(s.score)})"
                                                          for s in blind)
                    + (f"; above it, from {above[0].model} ({_cell(above[0])}) to "
                       f"{worst.model} ({_cell(worst)})." if len(above) > 1 else
                       f"; above it, {worst.model} ({_cell(worst)})." if above else "."))
        elif best is worst:
            line = f"{what}{AGAINST}: {best.model} alone ({_cell(best)})."
        else:
            line = (f"{what}{AGAINST}: from {best.model} ({_cell(best)}) to "
                    f"{worst.model} ({_cell(worst)}).")
        if failed:
            line += (" Failed runs, counted against their model: " + ", ".join(
                f"{s.model} ({s.failed} of {s.runs})" for s in failed) + ".")
        unpaired = [f"{m} ({k})" for m, k in _lost(rs, lost_key).items()]
        if unpaired:
            line += (" Unpaired modes (a run with one is a failed run): "
                     + ", ".join(unpaired) + ".")
        if exact:
            return line
        if blind:
            return line
        if st[0][2].tied:
            line += (f" Tied with {best.model} within the reference's "
                     f"{_u_text(u, defect, _continuum_key(rs, metric) is None and not spread_keys, own)}: "
                     f"{', '.join(st[0][2].tied)}.")
        if st[0][2].unresolved:
            line += (f" {best.model} is not resolved from {', '.join(st[0][2].unresolved)}: "
                     "beyond u_val, within both medians' spread over the meshes.")
        # the medians are what is ranked (judged, above five times u_num: nothing to add)
        return line
    return " ".join(_labelled(runs, line_of))


def per_run(runs, holds, what):
    """'what' said run by run, never of a median: the models for which ``holds(run)`` is true
    in every run that gave an answer, those for which it is true in some (with where), and
    those for which it never is."""
    by = {}
    for r in runs:
        v = holds(r)
        if v is not None:
            by.setdefault(r["model"], []).append((f"{r['mesh']}/{r['bc']}", bool(v)))
    every = [m for m, vs in by.items() if all(v for _, v in vs)]
    some = [f"{m} (on {', '.join(w for w, v in vs if v)}, {sum(v for _, v in vs)} of {len(vs)})"
            for m, vs in by.items() if any(v for _, v in vs) and not all(v for _, v in vs)]
    never = [m for m, vs in by.items() if not any(v for _, v in vs)]
    return (f"{what} in every run: {', '.join(every) or 'none'}; in some runs: "
            f"{'; '.join(some) or 'none'}; in none: {', '.join(never) or 'none'}.")


def failures(runs, key=None, where="in the linear regime"):
    """One line on the runs that found no equilibrium: of phase ``key`` (``where`` it is), or
    by default of every phase (the linear regime, the case's load where a reference of it
    exists, and the runs that could not start); or that none failed."""
    if key is not None:
        bad = [f"{r['model']} on {r['mesh']}/{r['bc']}" for r in runs if r.get(key)]
        return (f"No converged static solve {where} for " + ", ".join(bad) + "." if bad
                else f"Every model's static solve converged {where} on every mesh run.")
    phases = (("static_failed", "in the linear regime", runs),
              ("finite_failed", "at the case's load",
               [r for r in runs if r.get("nh_error_estimate") is not None]),
              ("failed", "could not start", runs))
    said, checked = [], []
    for k, label, rs in phases:
        bad = [f"{r['model']} on {r['mesh']}/{r['bc']}" for r in rs if r.get(k)]
        if bad:
            said.append(("Could not start: " if k == "failed" else
                         f"No converged static solve {label} for ") + ", ".join(bad))
        elif rs and any(k in r for r in rs) and k != "failed":
            checked.append(label)
    if not said:
        return ("Every model's static solve converged " + " and ".join(checked)
                + " on every mesh run.")
    return "; ".join(said) + (f". Every model's static solve converged "
                              f"{' and '.join(checked)} on every mesh run" if checked
                              else "") + "."


def _linearisation(runs):
    """Per boundary condition, fem-linear's linearisation error at the case's load: its
    displacement against neo-Hookean P1 on the same mesh (both P1 on the same tetrahedra, so
    the discretisation error both carry cancels: ``disp_rel_l2_nh_p1``, its model-form error
    at the load), beside its total against the neo-Hookean reference."""
    said = []
    for bc, rs in populations(runs).items():
        mine = [r for r in rs if r["model"] == "fem-linear"]
        lin = [r["disp_rel_l2_nh_p1"] for r in mine if r.get("disp_rel_l2_nh_p1") is not None]
        tot = [r["disp_rel_l2_nh"] for r in mine if r.get("disp_rel_l2_nh") is not None]
        if lin and tot:
            said.append(f"[{bc}] fem-linear at the case's load: its displacement field's distance "
                        f"to neo-Hookean P1 on the same mesh (a field norm; the index's "
                        f"linearisation error is the case's quantity instead) "
                        f"{cell(lin, len(mine))}; its total against the neo-Hookean "
                        f"reference {cell(tot, len(mine))}, which holds P1's discretisation "
                        "error too (the two are norms: they bound the total, they do not "
                        "add).")
    return said


def finite_load(runs):
    """{group title: sentences} on the case's load against the neo-Hookean reference, or {}
    where no run has one: the ranking by displacement (and reaction), fem-linear's error
    split into its linearisation (against fem-neohookean on the same mesh) and the rest, per
    boundary condition, and the failures."""
    if not any(r.get("nh_error_estimate") is not None or r.get("finite_failed")
               for r in runs):
        return {}
    nh = "nh_error_estimate"
    out = [best_and_worst(runs, "disp_rel_l2_nh", "Displacement at the case's load",
                          estimate_key=nh)]
    out += ranking(runs, "disp_rel_l2_nh", "displacement error", nh)
    if any(r.get("reaction_rel_err_nh") is not None for r in runs):
        out += ranking(runs, "reaction_rel_err_nh", "reaction error", nh)
    out += _linearisation(runs)
    refs = sorted({f"{r['mesh']}/{r['bc']}" for r in runs if r.get(nh) is None
                   and r.get("finite_failed")})
    if refs:
        out.append("No neo-Hookean reference on " + ", ".join(refs) + ".")
    out.append(failures([r for r in runs if r.get(nh) is not None], "finite_failed",
                        "at the case's load"))
    return {"At the case's load, against the neo-Hookean reference": out}
