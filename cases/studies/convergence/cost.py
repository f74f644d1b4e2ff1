"""Accuracy per cost: each run's displacement error against what one RK4 step of its model
costs on its mesh (``cases.reporting.costs``, from `pbcm bench`), and the Pareto front of the models: for
a given cost budget, the least error any model reaches.
"""
import numpy as np

from ...reporting.costs import SOURCE, step_cost_us
from .extrapolation import blind_levels

FEM_P1 = "FEM P1"              # the yardstick's name in the runs (the study's)


def pareto(points, tol=0.0):
    """The indices of the points (cost, error) no other point beats in both (lower cost and
    lower error, one of them strictly), in increasing cost; an error that improves on a cheaper
    point's by ``tol`` or less (what the reference resolves) does not beat it."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], np.inf
    for i in order:
        if points[i][1] < best - tol:
            front.append(i)
            best = points[i][1]
    return front


def accuracy_per_cost(runs, bench, exact=0.0, cancelling=(), u_ref=None):
    """{"source", "groups": [{case, bc, points: [...], front: [...]}], "front_counts"}: every
    model run with its step cost, grouped by (case, bc), and how often each model is on the
    front (``judge``). None without a bench."""
    if not bench:
        return None
    groups = []
    for case, bc in dict.fromkeys((r["case"], r["bc"]) for r in runs):
        pts = []
        for r in runs:
            if (r["case"], r["bc"]) != (case, bc) or r.get("disp_rel_l2") is None:
                continue
            c = step_cost_us(bench, r["model"], r["tets"])
            if c is not None:
                pts.append({"model": r["model"], "mesh": r["mesh"], "h_mm": r["h_mm"],
                            "tets": r["tets"], "cost_us": c, "disp_rel_l2": r["disp_rel_l2"]})
        groups.append({"case": case, "bc": bc, "points": pts})
    return judge({"source": SOURCE, "groups": groups}, runs, exact, cancelling, u_ref)


def judge(cost, runs, exact=0.0, cancelling=(), u_ref=None):
    """The cost document ``cost`` with each point's flags and each group's front (re)drawn
    from the ``runs``: errors below ``exact`` count as equal (the reference's own level), so
    that no rounding puts a point on the front; a run of a series that may cancel
    (``cancelling``: (case, mesh, bc, model) whose error is not monotone or whose stiffness
    ratio crosses 1) is marked ``cancellation``; ``p1_error`` is FEM P1's error on the same
    mesh and level, and a run below it by more than the reference's estimate (``u_ref``:
    {(case, bc): estimate}) is marked ``below_p1``: its lead over the discretisation error
    every model on that mesh shares is its model-form error offsetting it; a run at a level
    that tests nothing (``blind_levels``) is marked ``blind``. None of these is ever on the
    front, and a run joins it only by an error below the cheaper ones' by more than the
    reference's estimate (a smaller gain is not resolved)."""
    u_ref = u_ref or {}
    p1 = {(r["case"], r["bc"], r["mesh"], r["h_mm"]): r["disp_rel_l2"] for r in runs
          if r["model"] == FEM_P1 and r.get("disp_rel_l2") is not None}
    blind = blind_levels(runs)
    counts = {}
    for g in cost["groups"]:
        u = u_ref.get((g["case"], g["bc"]), 0.0)
        for p in g["points"]:
            p["cancellation"] = (g["case"], p["mesh"], g["bc"], p["model"]) in cancelling
            e1 = p1.get((g["case"], g["bc"], p["mesh"], p["h_mm"]))
            p["p1_error"] = e1
            p["blind"] = (g["case"], g["bc"], p["mesh"], p["h_mm"]) in blind
            p["below_p1"] = (e1 is not None and max(e1, exact) - max(p["disp_rel_l2"], exact)
                             > u)
        pts = g["points"]
        eligible = [i for i, p in enumerate(pts) if not p["cancellation"]
                    and not p["below_p1"] and not p["blind"]]
        g["front"] = [eligible[i] for i in pareto([(pts[i]["cost_us"],
                                                    max(pts[i]["disp_rel_l2"], exact))
                                                   for i in eligible], tol=u)]
        for i in g["front"]:
            counts[pts[i]["model"]] = counts.get(pts[i]["model"], 0) + 1
    cost["front_counts"] = dict(sorted(counts.items(), key=lambda kv: -kv[1]))
    return cost


def by_cancellation(p, target):
    """Whether the run ``p`` (a cost point) reaches the error ``target`` only by cancellation:
    its error at or below the target on a mesh where FEM P1's is above it. The discretisation
    error alone, shared by every model on that mesh, exceeds the target; the model gets below
    it only because its model-form error (at least the difference of the two errors) offsets
    it."""
    e1 = p.get("p1_error")
    return p["disp_rel_l2"] <= target and e1 is not None and e1 > target


def cheapest(points, target, u=0.0, margin=5.0):
    """(the cheapest point reaching ``target`` that is neither cancelling, below FEM P1, at a
    level that tests nothing nor there only by cancellation, or None; the points that reach
    it only by cancellation); (None, None) where the target is below ``margin`` times the
    reference's estimate ``u``: that reference cannot judge which run reaches it."""
    if target < margin * u:
        return None, None
    by_c = [p for p in points if by_cancellation(p, target)]
    ok = [p for p in points if p["disp_rel_l2"] <= target and not p.get("cancellation")
          and not p.get("below_p1") and not p.get("blind") and not by_cancellation(p, target)]
    return (min(ok, key=lambda p: p["cost_us"]) if ok else None), by_c


__all__ = ["pareto", "accuracy_per_cost", "judge", "by_cancellation", "cheapest"]
