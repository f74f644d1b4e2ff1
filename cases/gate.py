"""Error bounds for CI, declared as data (thresholds.toml) in the style of verification
harnesses: a stored value with a relative tolerance and an absolute floor. The gate is
two-sided: every change of result fails until it is blessed on purpose,

    |measured - value| <= rtol |value| + atol,

and ``direction`` only says which way is worse (max: an error, min: a correlation), so that a
failure reads as a regression or as an improvement to bless.
"""
from dataclasses import dataclass
import datetime
import json
import math
from pathlib import Path
import tomllib

from .output import SWEEP_MARK

# the gated metrics and their direction; correlations must stay above, errors below
GATED = {"disp_rel_l2_p1": "max", "disp_rel_l2_p2": "max", "disp_max_rel_p2": "max",
         "reaction_rel_err": "max", "stress_corr": "min", "stress_rel_err": "max",
         "pressure_rel_err": "max", "zigzag": "max", "net_force_rel": "max",
         "reaction_time_rel_l2": "max", "disp_end_push_rel_l2": "max", "rest_time_s": "max",
         "modal_rel_err": "max", "modal_rel_err_free": "max", "rigid_modes_free": "max"}
ATOL = 1e-9  # floor: metrics near zero (momentum residuals, zig-zag of FEM) never fail on noise
# static displacements are solved to a residual of 1e-9 (model.static), so differences below
# about 1e-8 are the solver's, not the model's: fem-linear equals P1 to that level
FLOORS = {"disp_rel_l2_p1": 1e-8, "disp_rel_l2_p2": 1e-8, "disp_max_rel_p2": 1e-8}
RTOL = 0.1   # default margin of bless


class CheckError(Exception):
    """Something is missing or malformed: the check cannot pass (exit 2)."""


@dataclass
class Bound:
    case: str
    mode: str
    mesh: str
    bc: str
    model: str
    metric: str
    value: float
    rtol: float
    atol: float
    direction: str
    measured_on: str = ""

    @property
    def key(self):
        return (self.case, self.mode, self.mesh, self.bc, self.model, self.metric)

    @property
    def slack(self):
        return self.rtol * abs(self.value) + self.atol

    @property
    def band(self):
        """(low, high): a measured value must stay inside, in either direction."""
        return self.value - self.slack, self.value + self.slack

    def passes(self, measured):
        low, high = self.band
        return low <= measured <= high

    def margin(self, measured):
        """How far inside the band, as a fraction of its half-width (negative: outside)."""
        return 1.0 - abs(measured - self.value) / max(self.slack, 1e-300)

    def verdict(self, measured):
        """'' inside the band; else whether the metric got worse or better (``direction``
        says which way is worse: 'max' an error, 'min' a correlation)."""
        if self.passes(measured):
            return ""
        higher = measured > self.value
        worse = higher if self.direction == "max" else not higher
        return ("worse: a regression" if worse else
                "better: bless it on purpose if the change is meant")


FIELDS = ("case", "mode", "mesh", "bc", "model", "metric", "value", "rtol", "atol", "direction")
HEADER = """\
# pbcm error bounds, read by `pbcm check` and rewritten only by `pbcm bless`.
# Two-sided: |measured - value| <= rtol |value| + atol; direction says which way is worse.
# mode: the run mode the bound belongs to (quick runs in CI). The problem tables at the end
# hold the parameters each case and mode was measured at; `pbcm check` refuses other ones.
"""


@dataclass
class Measurements:
    """What a folder of metrics.json holds for the gate: ``values`` {(case, mode, mesh, bc,
    model, metric): value or None} and ``problems`` {(case, mode): parameters of the problem}."""

    values: dict
    problems: dict
    directions: dict = None


@dataclass
class Thresholds:
    """A thresholds file: ``bounds`` (Bound list) and ``problems`` {(case, mode): parameters}."""

    bounds: list
    problems: dict


def load(path, hint=None):
    """The bounds and problem parameters of a thresholds file (a ``Thresholds``)."""
    path = Path(path)
    if not path.is_file():
        where = (f"pass {hint} PATH (e.g. the thresholds.toml of a pbcm checkout)"
                 if hint else "give its path")
        raise CheckError(f"thresholds file {path} is missing: {where}, or create one from "
                         "measured metrics with `pbcm bless --metrics DIR`")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CheckError(f"thresholds file {path} is malformed: {exc}") from None
    bounds, seen = [], {}
    for i, b in enumerate(data.get("bound", [])):
        missing = [f for f in FIELDS if f not in b]
        if missing:
            raise CheckError(f"{path}: bound {i + 1} lacks {', '.join(missing)}")
        if b["direction"] not in ("max", "min"):
            raise CheckError(f"{path}: bound {i + 1} has direction {b['direction']!r}; "
                             "use 'max' (stay below) or 'min' (stay above)")
        nums = [b[k] for k in ("value", "rtol", "atol")]
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in nums) \
                or b["rtol"] < 0 or b["atol"] < 0:
            raise CheckError(f"{path}: bound {i + 1} needs finite value and non-negative "
                             "rtol, atol")
        bound = Bound(**{f: b[f] for f in FIELDS}, measured_on=b.get("measured_on", ""))
        if bound.key in seen:
            raise CheckError(f"{path}: bounds {seen[bound.key] + 1} and {i + 1} are both for "
                             f"{'/'.join(bound.key)}; keep one")
        seen[bound.key] = i
        bounds.append(bound)
    if not bounds:
        raise CheckError(f"thresholds file {path} holds no [[bound]]; run `pbcm bless`")
    problems = {}
    for i, p in enumerate(data.get("problem", [])):
        if not {"case", "mode"} <= set(p):
            raise CheckError(f"{path}: [[problem]] {i + 1} lacks case or mode")
        key = (p["case"], p["mode"])
        if key in problems:
            raise CheckError(f"{path}: two [[problem]] tables for {'/'.join(key)}; keep one")
        problems[key] = {k: v for k, v in p.items() if k not in ("case", "mode")}
    return Thresholds(bounds, problems)



def _in_sweep(path, root):
    """True when ``path`` lies in a sweep's folder under ``root`` (the gate reads cases and
    studies, not the runs of a sweep)."""
    return any((d / SWEEP_MARK).is_file() for d in path.parents
               if d == root or root in d.parents)


def measured(metrics_dir):
    """The Measurements of every metrics.json under a folder (or of one file)."""
    p = Path(metrics_dir)
    if not p.exists():
        raise CheckError(f"--metrics {p} does not exist; run `pbcm run CASE --out {p}/CASE` "
                         "first, or give the folder that holds the metrics.json files")
    files = [p] if p.is_file() else [f for f in sorted(p.glob("**/metrics.json"))
                                      if not _in_sweep(f, p)]
    if not files:
        raise CheckError(f"no metrics.json under {p}; run `pbcm run CASE` first")
    values, problems, directions = {}, {}, {}
    for f in files:
        try:
            data = json.loads(f.read_text())
            case, mode = data["case"], "quick" if data["parameters"]["quick"] else "full"
            # a study's rows for the gate (e.g. one per case, bc and mesh size) are its own
            runs = data["gate_runs"] if "gate_runs" in data else data["runs"]
            problem = data["problem"]
            gated = data.get("gated", GATED)
        except (ValueError, KeyError, TypeError) as exc:
            raise CheckError(f"{f} is not a pbcm metrics file of this version (lacks {exc}); "
                             "rerun the case") from None
        if (case, mode) in problems and problems[(case, mode)] != problem:
            raise CheckError(f"two metrics files of {case} ({mode} mode) under {p} were run at "
                             "different parameters; check them one at a time")
        problems[(case, mode)] = problem
        directions.update(gated)
        for r in runs:
            for metric in gated:
                values[(case, mode, r["mesh"], r["bc"], r["model"], metric)] = r.get(metric)
    return Measurements(values, problems, directions)


def _same_problem(case, mode, recorded, ran):
    """CheckError naming the first parameter in which a run differs from the bounds."""
    for k in sorted(set(recorded) | set(ran)):
        if recorded.get(k) != ran.get(k):
            raise CheckError(
                f"parameter {k} of {case} ({mode} mode) is {ran.get(k, 'absent')!r} in the "
                f"metrics but the bounds were measured at {recorded.get(k, 'absent')!r}: run "
                "the case with the bounds' parameters, or bless these metrics on purpose")


NEW = 3   # exit status: every bound holds, but some models ran that no bound covers yet


def check(thresholds, measurements):
    """Rows (bound, measured, passed), the exit status and the new models.

    Status 0: every bound holds; 1: a metric left its bound; NEW (3): every bound holds but
    some (case, mode, model) has no bound at all: "new, not gated yet" (a preset or user term
    nobody has blessed), listed as ``new`` [(case, mode, model, n_metrics)]. Bounds of a case
    and mode that were not run are set aside; metrics run at other problem parameters than the
    bounds', a bound without a measured value, a value that is not finite, or a measured metric
    without a bound for a model that has bounds raise CheckError (exit 2): a missing reference
    never passes."""
    values = measurements.values
    rows, status = [], 0
    runs = {k[:2] for k in values}            # (case, mode) pairs that were measured
    bounds = [b for b in thresholds.bounds if b.key[:2] in runs]
    if not bounds:
        raise CheckError(f"no bound for the measured {', '.join('/'.join(r) for r in sorted(runs))}"
                         "; run in a mode the thresholds cover, or bless this one")
    for case, mode in sorted(runs):
        if (case, mode) not in thresholds.problems:
            raise CheckError(f"the thresholds do not record the parameters of {case} ({mode} "
                             "mode) their bounds were measured at; bless them again")
        _same_problem(case, mode, thresholds.problems[(case, mode)],
                      measurements.problems[(case, mode)])
    keys = {b.key for b in bounds}
    gated_models = {(b.case, b.mode, b.model) for b in bounds}
    unbounded = [k for k in values if k not in keys and values[k] is not None]
    new = {}
    for k in unbounded:
        if (k[0], k[1], k[4]) not in gated_models:
            new[(k[0], k[1], k[4])] = new.get((k[0], k[1], k[4]), 0) + 1
    unbounded = [k for k in unbounded if (k[0], k[1], k[4]) in gated_models]
    if unbounded:
        raise CheckError(f"no bound for {len(unbounded)} measured metric(s), e.g. "
                         f"{'/'.join(unbounded[0])}: run `pbcm bless` to set them")
    for b in bounds:
        if b.key not in values or values[b.key] is None:
            raise CheckError(f"metric {b.metric} of {b.case}/{b.mesh}/{b.bc}/{b.model} "
                             f"({b.mode} mode) has a bound but no measured value: run the "
                             "case in that mode, or remove the bound")
        v = values[b.key]
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise CheckError(f"metric {b.metric} of {b.case}/{b.mesh}/{b.bc}/{b.model} is "
                             f"{v!r}, not a finite number")
        ok = b.passes(v)
        rows.append((b, v, ok))
        status = max(status, 0 if ok else 1)
    for k in values:           # a new model's metrics must be numbers too
        if (k[0], k[1], k[4]) in new and values[k] is not None and not (
                isinstance(values[k], (int, float)) and math.isfinite(values[k])):
            raise CheckError(f"metric {k[5]} of {'/'.join(k[:5])} is {values[k]!r}, not a "
                             "finite number")
    if new and status == 0:
        status = NEW
    return rows, status, [(*k, n) for k, n in sorted(new.items())]


def bless(measurements, old=None, rtol=None, prune=False, today=None):
    """New thresholds from ``measurements`` and the lines saying what changed.

    Every gated metric measured gets a bound at its value (metrics that are None, e.g. an
    undefined correlation, get none) with ``rtol`` when given, else the old bound's
    tolerances, else RTOL and ATOL. Bounds that were not measured are kept, unless ``prune``
    (then they are removed and listed); keeping them is refused when the problem parameters of
    their case and mode changed, since they would then gate another problem.
    """
    if rtol is not None and not (math.isfinite(rtol) and rtol > 0):
        raise CheckError(f"the margin must be a finite number > 0, got {rtol!r}")
    today = today or datetime.date.today().isoformat()
    old = old or Thresholds([], {})
    values = measurements.values
    prev = {b.key: b for b in old.bounds}
    bounds, changes = [], []
    for key in sorted(values):
        v = values[key]
        if v is None:
            continue
        if not math.isfinite(v):
            raise CheckError(f"cannot bless {'/'.join(key)}: measured {v!r}")
        o = prev.get(key)
        floor = FLOORS.get(key[-1], ATOL)
        tol = (rtol if rtol is not None else o.rtol if o else RTOL, max(o.atol, floor) if o else floor)
        direction = {**GATED, **(measurements.directions or {})}[key[-1]]
        b = Bound(*key, float(v), *tol, direction, today)
        if o is None:
            changes.append(f"new     {'/'.join(key)}: {v:.6g}")
        elif o.value != b.value or (o.rtol, o.atol) != tol:
            changes.append(f"changed {'/'.join(key)}: {o.value:.6g} -> {v:.6g}"
                           + (f" (rtol {o.rtol:g} -> {tol[0]:g})" if o.rtol != tol[0] else ""))
        bounds.append(b)
    problems = {**old.problems, **measurements.problems}
    unseen = sorted(set(prev) - {b.key for b in bounds})
    if prune:
        changes += [f"removed {'/'.join(key)} (not in the metrics blessed)" for key in unseen]
        live = {b.key[:2] for b in bounds}
        problems = {k: v for k, v in problems.items() if k in live}
    else:
        moved = sorted({k[:2] for k in unseen if k[:2] in measurements.problems
                        and old.problems.get(k[:2]) != measurements.problems[k[:2]]})
        if moved:
            raise CheckError(f"the parameters of {', '.join('/'.join(k) for k in moved)} differ "
                             "from those of bounds these metrics do not cover; bless a complete "
                             "run, or pass --prune to drop the bounds not measured")
        bounds += [prev[key] for key in unseen]
        if unseen:
            changes.append(f"kept    {len(unseen)} bounds of runs or metrics not in the metrics "
                           "blessed (--prune removes them)")
    return Thresholds(sorted(bounds, key=lambda b: b.key), problems), changes


def dumps(thresholds):
    """TOML text of ``thresholds`` (bounds sorted by key, then the problem parameters)."""
    import tomli_w
    data = {"bound": [{**{f: getattr(b, f) for f in FIELDS}, "measured_on": b.measured_on}
                      for b in sorted(thresholds.bounds, key=lambda b: b.key)],
            "problem": [{"case": c, "mode": m, **p}
                        for (c, m), p in sorted(thresholds.problems.items())]}
    return HEADER + "\n" + tomli_w.dumps(data)
