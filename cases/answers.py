"""The answers that open reports/index: which reading the paper used, how far each model is
from the continuum and from a measured body, at what cost, and what causes the bulge/neck
artefact; then one
compact table, model by the numbers behind them. Every number is read from the metrics the
studies, the cases and the bench wrote under the reports folder; an answer whose source is
missing says which command writes it."""
import json
from pathlib import Path

import numpy as np

from .costs import FILE as BENCH_FILE, FOLDER as BENCH_FOLDER
from .document import fmt
from .metrics import PATCH_TOL

COST_TETS = 1e4          # the mesh size of the cost column (tetrahedra)
CONSISTENCY = ("paper-cube", "sliding")     # the patch test whose converged limit is the error
FINITE = "large-compression"                 # the finite-strain case (neo-Hookean reference)
MEASURED = "truth-cube"                      # the study against measured beads


def _load(root, *parts):
    path = Path(root).joinpath(*parts)
    return json.loads(path.read_text()) if path.is_file() else None


LIMITED = ("exact", "converges", "floor")   # fit verdicts whose e_inf is a limit


REGULAR = ("five", "six", "bcc")     # the lattices as generated; the rest is irregular


def consistency(conv, model):
    """{lattice: the converged limit e_inf of the sliding-cube patch test in the linear
    regime, or the fit's verdict where it has no limit (diverging, not asymptotic)}."""
    out = {}
    for f in (conv or {}).get("fits", []):
        if (f["case"], f["bc"]) == CONSISTENCY and f["model"] == model:
            limited = f["verdict"] in LIMITED and f.get("e_inf") is not None
            out[f["mesh"]] = f["e_inf"] if limited else f["verdict"]
    return out


def worst(values):
    """'largest (lattice)' over the numeric entries, and the lattices without a limit."""
    nums = {k: v for k, v in values.items() if isinstance(v, (int, float))}
    other = [f"{v} on {k}" for k, v in values.items() if not isinstance(v, (int, float))]
    if not nums:
        return ", ".join(other) or "n/a"
    k = max(nums, key=nums.get)
    return f"{fmt(nums[k])} ({k})" + (f"; {', '.join(other)}" if other else "")


def _median(rows, key):
    v = [r[key] for r in rows if r.get(key) is not None]
    return float(np.median(v)) if v else None


def _bench_row(bench, model):
    """The bench row of ``model`` at the size closest to COST_TETS that has the cost per
    simulated second."""
    rows = [r for r in (bench or {}).get("rows", []) if r["model"] == model
            and r.get("cpu_s_per_simulated_s") is not None]
    return min(rows, key=lambda r: abs(np.log(r["tets"] / COST_TETS))) if rows else None


def table(root, models):
    """(header, rows): one row per model of the scorecard."""
    conv = _load(root, "convergence", "metrics.json")
    cube = _load(root, "paper-cube", "metrics.json")
    finite = _load(root, FINITE, "metrics.json")
    bench = _load(root, BENCH_FOLDER, BENCH_FILE)
    measured = (_load(root, MEASURED, "metrics.json") or {}).get("headline")
    header = ["model", "consistency error (largest limit)", "finite-load error",
              "worst isotropy error", "largest |alternation|", "RK4 run",
              "s per simulated s", "Truth Cube bead RMS [mm]"]
    rows = []
    for m in models:
        el = [e["moduli_rel_err"] for e in (conv or {}).get("elasticity", [])
              if e["model"] == m and e.get("moduli_rel_err") is not None]
        mine = [r for r in (cube or {}).get("runs", []) if r["model"] == m]
        alt = [abs(r["alternation_rel"]) for r in mine if r.get("alternation_rel") is not None]
        flutter = sum(r.get("dyn_verdict") == "unstable (flutter)" for r in mine
                      if r["bc"] == "clamped")
        clamped = sum(r["bc"] == "clamped" for r in mine)
        fin = [r for r in (finite or {}).get("runs", []) if r["model"] == m]
        b = _bench_row(bench, m)
        rows.append([m, worst(consistency(conv, m)) if conv else "n/a",
                     fmt(_median(fin, finite["headline"])) if finite else "n/a",
                     fmt(max(el)) if el else "n/a", fmt(max(alt)) if alt else "n/a",
                     ("flutters" if flutter else "stable") + f" ({clamped - flutter} of "
                     f"{clamped} clamped runs stable)" if clamped else "n/a",
                     fmt(b["cpu_s_per_simulated_s"]) if b else "n/a",
                     _bead(measured, m)])
    return header, rows


def _bead(measured, model):
    v = (measured or {}).get("models", {}).get(model)
    return f"{fmt(v['bead_rms_mm'])} at {fmt(100 * measured['strain'], 4)} %" if v else "n/a"


def lines(root, models):
    """At most six short lines: the answers."""
    art = _load(root, "artefact", "metrics.json")
    conv = _load(root, "convergence", "metrics.json")
    bench = _load(root, BENCH_FOLDER, BENCH_FILE)
    out = []
    if art and art["verdict"]["sure"] == "undecided":
        v = art["verdict"]
        out.append(f"**Which reading?** Undecided between {', '.join(v['tied'])} "
                   f"([artefact study](artefact/report.md)): "
                   + ("each " if len({json.dumps(r["matches"], sort_keys=True)
                                      for r in art["readings"] if r["model"] in v["tied"]}) == 1
                      else f"{v['model']} ") + _decisive(art))
    elif art:
        v = art["verdict"]
        out.append(f"**Which reading?** {v['model']} ({v['sure']} verdict, "
                   f"[artefact study](artefact/report.md)): it {_decisive(art)}")
    else:
        out.append("**Which reading?** Not computed: run `pbcm run artefact`.")
    if conv:
        limits = {m: consistency(conv, m) for m in models}
        passed = [m for m, v in limits.items() if v and all(
            isinstance(x, (int, float)) and x < PATCH_TOL for x in v.values())]
        rest = sorted((m for m in models if m not in passed),
                      key=lambda m: _largest(limits[m]))
        nolimit = sorted({k for m in rest for k, v in limits[m].items()
                          if not isinstance(v, (int, float))})
        out.append("**How far from the continuum?** Consistency error, the sliding cube's limit "
                   "under refinement (a patch test with traction-free sides; largest over "
                   "lattices): "
                   + ", ".join(f"{m} {fmt(_largest(limits[m])[1])}" for m in rest)
                   + (f"; below {PATCH_TOL:g}: {', '.join(passed)}" if passed else "")
                   + (f"; no limit on {', '.join(nolimit)}" if nolimit else "")
                   + _irregular(conv, models)
                   + " ([convergence](convergence/report.md)).")
    measured = (_load(root, MEASURED, "metrics.json") or {}).get("headline")
    if measured:
        out.append(_measured_line(measured, models))
    rows = {m: _bench_row(bench, m) for m in models}
    if all(rows.get(k) for k in ("fem-linear", "msm")):
        fl = rows["fem-linear"]["cpu_s_per_simulated_s"]
        out.append(f"**At what cost?** One simulated second at about "
                   f"{fmt(rows['fem-linear']['tets'])} "
                   "tetrahedra, at each model's own stable RK4 step, over fem-linear's: "
                   + ", ".join(f"{m} {fmt(r['cpu_s_per_simulated_s'] / fl, 2)}"
                               for m, r in rows.items() if r and m != "fem-linear")
                   + " ([bench](bench/bench.md)).")
    if art:
        out.append(f"**What causes the bulge/neck?** {art['answer']['cause'][0].upper()}"
                   f"{art['answer']['cause'][1:]}. {_cause_numbers(art)}")
    return out


def _measured_line(h, models):
    NH = h["continuum"]
    v = h["models"]
    mine = sorted((m for m in models if m in v), key=lambda m: v[m]["bead_rms_mm"])
    within = [m for m in mine if v[m]["states_within"] == h["states"]]
    said = (f"**How far from a measured body?** On the Truth Cube's 343 beads at "
            f"{fmt(100 * h['strain'], 4)} % compression (bonded plates, {h['mesh']} mesh; the "
            f"measurement's floor {fmt(h['floor_mm'])} mm): ")
    if NH in v:
        said += f"the neo-Hookean continuum is {fmt(v[NH]['bead_rms_mm'])} mm RMS off; "
    if mine:
        said += (f"the models from {fmt(v[mine[0]]['bead_rms_mm'])} mm ({mine[0]}) to "
                 f"{fmt(v[mine[-1]]['bead_rms_mm'])} mm ({mine[-1]}); ")
    return said + (f"within the floor at every state: {', '.join(within) or 'none'} "
                   f"([truth-cube]({MEASURED}/report.md)).")


def _irregular(conv, models):
    """'; on irregular patches ...': each model's worst patch-test error over the families
    whose patch is irregular (perturbed lattices, unstructured), where the study ran it."""
    worst_of = {}
    for r in conv.get("patch", []):
        if r["mesh"] in REGULAR or r.get("patch_error") is None or r["model"] not in models:
            continue
        worst_of[r["model"]] = max(worst_of.get(r["model"], 0.0), r["patch_error"])
    if not worst_of:
        return ""
    return ("; the patch test with every boundary node prescribed, on irregular patches "
            "(worst): " + ", ".join(f"{m} {fmt(v)}" for m, v in sorted(
                worst_of.items(), key=lambda kv: kv[1])))


def _largest(limit):
    nums = [v for v in limit.values() if isinstance(v, (int, float))]
    return (len(nums) < len(limit), max(nums, default=np.inf))


def _decisive(art):
    best = next(r for r in art["readings"] if r["model"] == art["verdict"]["model"])
    said = {"pattern": "the paper's pattern on a 374-tetrahedron mesh",
            "cost": "a step over 10x msm's", "stable": "no flutter"}
    yes = [said[k] for k, v in best["matches"].items() if v]
    no = [said[k] for k, v in best["matches"].items() if not v]
    return ("has " + (", ".join(yes) or "none of the paper's observables")
            + (f"; lacks {', '.join(no)}" if no else "") + ".")


def _cause_numbers(art):
    a = art["answer"]
    five, other, msm = a["five"], a["other_splits"], a["msm"]
    return (f"The layers alternate in {five[0]} of {five[1]} cells on the mirrored five split "
            f"and in {other[0]} of {other[1]} on the other splits; in {msm[0]} of {msm[1]} of "
            "msm's, whose forces are all normal ([artefact study](artefact/report.md)).")


__all__ = ["lines", "table"]
