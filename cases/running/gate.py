"""The CI gate: measured metrics against gold values, declared as data in the style of
verification harnesses (a small gold file per test, one tolerance policy).

Where the gold lives (``gold/`` of the checkout):

* ``policy.toml``: the tolerance policy, declared once for every value: ``rtol``, the default
  ``atol`` and the metrics whose ``atol`` differs; and where the full-mode gold is.
* ``CASE.quick.jsonl``: one small file per case (or study) in quick mode, what CI runs: a first
  line with the problem parameters and the metric columns, then one line per (mesh, bc, model)
  with each value to 6 significant digits, or null where the run could not give it.
* Full mode: the gold is the committed ``reports/CASE/metrics.json`` itself (nothing stores a
  number twice); ``pbcm bless`` of full-mode metrics installs their case folder there.

The gate is two-sided: every change of result fails until it is blessed on purpose,

    |measured - gold| <= rtol |gold| + atol,

and the metric's direction (max: an error, min: a correlation) only says whether a failure is a
regression or an improvement. A metric that was null and is now a number, or the reverse, is a
failure too: a run that failed now succeeds, or the reverse.
"""
from dataclasses import dataclass, field
import json
import os
import math
from pathlib import Path
import tomllib

from ..measuring import catalogue
from .output import SWEEP_MARK, TMP_TAG

POLICY = "policy.toml"
SUFFIX = ".jsonl"
COMPACT_MODES = ("quick",)        # modes whose gold is a compact file; full: the reports
DIGITS = 6                        # significant digits of a compact gold value
KEY = ("mesh", "bc", "model")     # what names a row of a gold file


class CheckError(Exception):
    """Something is missing or malformed: the check cannot pass (exit 2)."""


@dataclass
class Policy:
    """The tolerance policy: ``rtol`` and ``atol`` for every value, ``atol_of`` per metric
    where the absolute floor differs, ``full``: the folder of the full-mode gold (relative to
    the gold folder)."""

    rtol: float = 0.1
    atol: float = 1e-9
    atol_of: dict = field(default_factory=dict)
    full: str = "../reports"

    def tolerance(self, metric):
        return self.rtol, self.atol_of.get(metric, self.atol)


@dataclass
class Bound:
    """One gold value with its tolerances: the band a measured value must stay inside."""

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
        says which way is worse: 'max' an error, 'min' a correlation, 'signed' neither)."""
        if self.passes(measured):
            return ""
        higher = measured > self.value
        if self.direction == "signed":      # an alternation: neither side is better
            return f"changed ({'higher' if higher else 'lower'}): bless it only if meant"
        worse = higher if self.direction == "max" else not higher
        return ("worse: a regression" if worse else
                "better: bless it on purpose if the change is meant")


@dataclass
class Gold:
    """The gold values: ``rows`` {(case, mode, mesh, bc, model): {metric: value or None}},
    ``problems`` {(case, mode): parameters}, the ``policy`` and the folder it came from."""

    policy: Policy
    rows: dict
    problems: dict
    folder: Path = None

    @property
    def full_root(self):
        return (self.folder / self.policy.full).resolve() if self.folder else None


@dataclass
class Measurements:
    """What a folder of metrics.json holds for the gate: ``values`` {(case, mode, mesh, bc,
    model, metric): value or None}, ``rows`` {(case, mode, mesh, bc, model)}, ``problems``
    {(case, mode): parameters}, ``directions`` {metric: 'max' or 'min'} and ``sources``
    {(case, mode): the metrics.json}."""

    values: dict
    problems: dict
    directions: dict = None
    rows: set = None
    sources: dict = None


def _rounded(v):
    return None if v is None else float(f"{v:.{DIGITS}g}")


def _load_policy(folder, hint):
    path = folder / POLICY
    if not path.is_file():
        where = (f"pass {hint} DIR (e.g. the gold/ folder of a pbcm checkout)" if hint
                 else "give the gold folder")
        raise CheckError(f"gold folder {folder} has no {POLICY}: {where}, or create one from "
                         "measured metrics with `pbcm bless --metrics DIR --gold DIR`")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CheckError(f"{path} is malformed: {exc}") from None
    unknown = set(data) - {"rtol", "atol", "atol_of", "full"}
    if unknown:
        raise CheckError(f"{path}: unknown key(s) {', '.join(sorted(unknown))}; the policy "
                         "takes rtol, atol, atol_of and full")
    policy = Policy(**data)
    nums = [policy.rtol, policy.atol, *policy.atol_of.values()]
    if not all(isinstance(v, (int, float)) and math.isfinite(v) and v >= 0 for v in nums):
        raise CheckError(f"{path}: rtol, atol and atol_of need finite non-negative numbers")
    return policy


def load(folder, hint=None):
    """The gold of a gold folder: its policy, every compact file and the full-mode gold of
    the reports folder the policy names."""
    folder = Path(folder)
    if not folder.is_dir():
        where = (f"pass {hint} DIR (e.g. the gold/ folder of a pbcm checkout)" if hint
                 else "give its path")
        raise CheckError(f"gold folder {folder} is missing: {where}, or create one from "
                         "measured metrics with `pbcm bless --metrics DIR --gold DIR`")
    policy = _load_policy(folder, hint)
    gold = Gold(policy, {}, {}, folder)
    for path in sorted(folder.glob(f"*{SUFFIX}")):
        _read_compact(path, gold)
    full = gold.full_root
    if full is not None and full.is_dir() and any(full.glob("*/metrics.json")):
        m = measured(full)
        for (case, mode), problem in m.problems.items():
            if mode in COMPACT_MODES:
                continue
            gold.problems[(case, mode)] = problem
        for key, v in m.values.items():
            if key[1] not in COMPACT_MODES:
                gold.rows.setdefault(key[:5], {})[key[5]] = v
    if not gold.rows:
        raise CheckError(f"gold folder {folder} holds no gold value; run `pbcm bless`")
    return gold


def _read_compact(path, gold):
    try:
        lines = path.read_text().splitlines()
        head = json.loads(lines[0])
        case, mode, columns = head["case"], head["mode"], head["columns"]
        problem = head["problem"]
    except (IndexError, ValueError, KeyError, TypeError, UnicodeDecodeError) as exc:
        raise CheckError(f"gold file {path} is malformed (its first line must name case, mode, "
                         f"problem and columns: {exc})") from None
    if (case, mode) in gold.problems:
        raise CheckError(f"two gold files for {case} ({mode} mode): keep one")
    gold.problems[(case, mode)] = problem
    seen = {}
    for i, line in enumerate(lines[1:], start=2):
        try:
            row = json.loads(line)
        except ValueError as exc:
            raise CheckError(f"{path}, line {i}: {exc}") from None
        if not (isinstance(row, list) and len(row) == len(KEY) + len(columns)):
            raise CheckError(f"{path}, line {i}: expected [mesh, bc, model] and "
                             f"{len(columns)} values")
        key = (case, mode, *row[:len(KEY)])
        values = row[len(KEY):]
        if not all(v is None or (isinstance(v, (int, float)) and math.isfinite(v))
                   for v in values):
            raise CheckError(f"{path}, line {i}: values must be finite numbers or null")
        if key in seen:
            raise CheckError(f"{path}: lines {seen[key]} and {i} are both for "
                             f"{'/'.join(key[2:])}; keep one")
        seen[key] = i
        gold.rows[key] = dict(zip(columns, values))


def _in_sweep(path, root):
    """True when ``path`` lies in a sweep's folder under ``root`` (the gate reads cases and
    studies, not the runs of a sweep)."""
    return any((d / SWEEP_MARK).is_file() for d in path.parents
               if d == root or root in d.parents)


def _metrics_files(folder):
    """Every metrics.json under ``folder``, sorted, through symbolic links to folders too (a
    reports folder assembled from links: pathlib's ``**`` does not follow them, and the case
    behind a link went unchecked)."""
    found = []
    for root, dirs, files in os.walk(folder, followlinks=True):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))   # hidden: never output
        if "metrics.json" in files:
            found.append(Path(root) / "metrics.json")
    return sorted(found)


def incomplete(folder):
    """The staging folders under ``folder``: runs killed while writing (or still writing),
    whose output is not there to check."""
    out = []
    for root, dirs, _ in os.walk(folder, followlinks=True):
        out += [Path(root) / d for d in dirs if TMP_TAG in d]
        dirs[:] = [d for d in dirs if not d.startswith(".")]
    return sorted(out)


def measured(metrics_dir):
    """The Measurements of every metrics.json under a folder (or of one file)."""
    p = Path(metrics_dir)
    if not p.exists():
        raise CheckError(f"--metrics {p} does not exist; run `pbcm run CASE --out {p}/CASE` "
                         "first, or give the folder that holds the metrics.json files")
    files = [p] if p.is_file() else [f for f in _metrics_files(p) if not _in_sweep(f, p)]
    left = [] if p.is_file() else incomplete(p)
    if left:
        raise CheckError("incomplete run(s) under " + str(p) + ": " + ", ".join(
            str(f) for f in left) + " (a run killed while writing, or one still writing: its "
            "output is not there to check); rerun the case into that folder, which removes "
            "a killed run's staging folder")
    if not files:
        raise CheckError(f"no metrics.json under {p}; run `pbcm run CASE` first")
    values, problems, directions, rows, sources = {}, {}, {}, set(), {}
    for f in files:
        try:
            data = json.loads(f.read_text())
            case, mode = data["case"], "quick" if data["parameters"]["quick"] else "full"
            # a study's rows for the gate (e.g. one per case, bc and mesh size) are its own
            runs = data["gate_runs"] if "gate_runs" in data else data["runs"]
            problem = data["problem"]
            gated = list(data["gated"])
        except (ValueError, KeyError, TypeError) as exc:
            raise CheckError(f"{f} is not a pbcm metrics file of this version (lacks {exc}); "
                             "rerun the case") from None
        if (case, mode) in problems and problems[(case, mode)] != problem:
            raise CheckError(f"two metrics files of {case} ({mode} mode), {sources[(case, mode)]}"
                             f" and {f}, were run at different parameters; check them one at "
                             "a time")
        problems[(case, mode)] = problem
        sources[(case, mode)] = f
        # the file says which metrics are gated; the catalogue says which way
        directions.update({m: _direction(m, data["gated"], f) for m in gated})
        for r in runs:
            rows.add((case, mode, r["mesh"], r["bc"], r["model"]))
            for metric in gated:
                values[(case, mode, r["mesh"], r["bc"], r["model"], metric)] = r.get(metric)
    return Measurements(values, problems, directions, rows, sources)


def _direction(metric, recorded, path):
    """The gate's direction of ``metric``: the catalogue's; for a metric it does not know (a
    quantity a user's problem declares, ``pbcm run --problem``), the one the file recorded."""
    if catalogue.known(metric):
        return catalogue.metric(metric).direction
    given = recorded.get(metric) if isinstance(recorded, dict) else None
    if given not in ("max", "min", "signed"):
        raise CheckError(f"{path} gates {metric!r}, which is not a metric of the catalogue "
                         "and whose direction the file does not record; rerun the case")
    return given


def _same_problem(case, mode, recorded, ran):
    """CheckError naming the first parameter in which a run differs from the gold."""
    for k in sorted(set(recorded) | set(ran)):
        if recorded.get(k) != ran.get(k):
            raise CheckError(
                f"parameter {k} of {case} ({mode} mode) is {ran.get(k, 'absent')!r} in the "
                f"metrics but the gold was measured at {recorded.get(k, 'absent')!r}: run "
                "the case with the gold's parameters, or bless these metrics on purpose")


def _finite(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


NEW = 3   # exit status: every value holds, but some models ran that the gold does not cover


@dataclass
class Verdict:
    """What ``check`` found: ``rows`` (bound, measured, passed) of every value compared,
    ``flips`` (key, gold, measured) where one of the two is null, ``new`` (case, mode, model,
    n_metrics) of models without gold, and the exit ``status``."""

    rows: list
    flips: list
    new: list
    status: int
    aside: int = 0        # gold rows of runs not in the metrics (``only_run``)


def check(gold, measurements, only_run=False, models=None):
    """Every measured metric against its gold value (``Verdict``); ``models``, when given,
    the models gated (the gold's and the measurements' other models are left out, never
    deleted).

    Status 0: every value holds; 1: a metric left its band, or was null in the gold and is a
    number now (or the reverse); NEW (3): every value holds but some (case, mode, model) has
    no gold at all: "new, not gated yet". The gold of a case and mode that was not run is set
    aside. Metrics run at other problem parameters than the gold's, a gold row that was not
    measured (unless ``only_run``: a subset of the gold's runs, the others set aside and
    counted), a metric or row the gold lacks for a model it has, or a value that is not
    finite raise CheckError (exit 2): a missing reference never passes."""
    values, policy = measurements.values, gold.policy
    if models:
        measurements, gold_rows = _only_models(measurements, gold, models)
        values = measurements.values
    else:
        gold_rows = gold.rows
    ran = {k[:2] for k in values} | {k[:2] for k in (measurements.rows or ())}
    # a case or problem the gold has never seen is new, as a model without gold is
    unseen = {c for c in ran if c not in gold.problems and not any(k[:2] == c
                                                                    for k in gold_rows)}
    ran -= unseen
    for k, v in values.items():       # a new case is not gated, but never a NaN either
        if k[:2] in unseen and v is not None and not _finite(v):
            raise CheckError(f"metric {k[5]} of {'/'.join(k[:5])} is {v!r}, not a finite "
                             "number")
    new = {(c, m, "every model"): sum(1 for k, v in values.items()
                                      if k[:2] == (c, m) and v is not None)
           for c, m in unseen}
    rows = {k: v for k, v in gold_rows.items() if k[:2] in ran}
    if not rows and unseen:
        return Verdict([], [], [(*k, n) for k, n in sorted(new.items())], NEW, 0)
    if not rows:
        raise CheckError(f"no gold for the measured {', '.join('/'.join(r) for r in sorted(ran))}"
                         "; run in a mode the gold covers, or bless this one")
    for case, mode in sorted(ran):
        if (case, mode) not in gold.problems:
            raise CheckError(f"the gold does not record the parameters of {case} ({mode} "
                             "mode) it was measured at; bless it again")
        _same_problem(case, mode, gold.problems[(case, mode)],
                      measurements.problems[(case, mode)])
    gated_models = {k[:2] + (k[4],) for k in rows}
    measured_rows = set(measurements.rows or {k[:5] for k in values})
    for k, v in values.items():
        if k[:2] in unseen:
            continue
        if not (k[:2] + (k[4],) in gated_models):
            if v is not None and not _finite(v):
                raise CheckError(f"metric {k[5]} of {'/'.join(k[:5])} is {v!r}, not a "
                                 "finite number")
            if v is not None:
                new[k[:2] + (k[4],)] = new.get(k[:2] + (k[4],), 0) + 1
            continue
        if k[:5] not in rows:
            if v is not None:
                raise CheckError(f"the gold has no row {'/'.join(k[2:5])} of {k[0]} ({k[1]} "
                                 f"mode), measured here: run the gold's selection, or bless "
                                 "this one on purpose")
            continue
        if k[5] not in rows[k[:5]] and v is not None:
            raise CheckError(f"metric {k[5]} of {'/'.join(k[:5])} has no gold value: a "
                             "metric gated since the last bless; bless it on purpose")
    out, flips, status = [], [], 0
    directions = measurements.directions or {}
    if only_run:     # a subset of the gold's runs: gate what was run, set the rest aside
        aside = sum(1 for k in rows if k not in measured_rows)
        rows = {k: v for k, v in rows.items() if k in measured_rows}
    for key5, metrics in sorted(rows.items()):
        if key5 not in measured_rows:
            raise CheckError(f"{'/'.join(key5[2:])} of {key5[0]} ({key5[1]} mode) has gold "
                             "values but was not measured: run the case in that mode, or "
                             "gate what was run (--only-run, or --models for a subset of "
                             "models)")
        for metric, g in sorted(metrics.items()):
            v = values.get((*key5, metric))
            if v is not None and not _finite(v):
                raise CheckError(f"metric {metric} of {'/'.join(key5)} is {v!r}, not a "
                                 "finite number")
            if g is None and v is None:
                continue
            if g is None or v is None:
                flips.append(((*key5, metric), g, v))
                status = 1
                continue
            b = Bound(*key5, metric, g, *policy.tolerance(metric),
                      directions.get(metric) or catalogue.metric(metric).direction)
            ok = b.passes(v)
            out.append((b, v, ok))
            status = max(status, 0 if ok else 1)
    if not out and not flips:
        raise CheckError("no value was compared with its gold (every gated value is n/a in "
                         "both): a check that reads nothing passes nothing")
    if new and status == 0:
        status = NEW
    return Verdict(out, flips, [(*k, n) for k, n in sorted(new.items())], status,
                   aside if only_run else 0)


def _only_models(measurements, gold, models):
    """(the measurements, the gold's rows) of ``models`` only; a model named that neither
    has is refused (a typo gates nothing)."""
    from dataclasses import replace
    known = {k[4] for k in gold.rows} | {k[4] for k in measurements.values}
    unknown = [m for m in models if m not in known]
    if unknown:
        raise CheckError(f"--models {', '.join(unknown)}: no gold and no measurement of "
                         f"{'it' if len(unknown) == 1 else 'them'}; known: "
                         f"{', '.join(sorted(known))}")
    keep = set(models)
    return (replace(measurements,
                    values={k: v for k, v in measurements.values.items() if k[4] in keep},
                    rows=None if measurements.rows is None else
                    type(measurements.rows)(k for k in measurements.rows if k[4] in keep)),
            {k: v for k, v in gold.rows.items() if k[4] in keep})


def flip_message(key, gold, now):
    """The failure line of a metric that was null and is a number, or the reverse."""
    def show(v):
        return "n/a" if v is None else f"{v:.6g}"
    return (f"FAIL {key[5]} of {'/'.join(key[:5])}: was {show(gold)}, now {show(now)}: a run "
            "that failed now succeeds, or the reverse: bless on purpose if intended")


def bless(measurements, gold, rtol=None, prune=False):
    """The gold of the compact modes updated from ``measurements`` and the lines saying what
    changed: ``(Gold, changes)``.

    Every gated metric measured gets its value to 6 significant digits, or null where the run
    could not give it; a gold value the measurement agrees with to that precision is kept as
    it is, so a re-bless that moves only the last digits changes no line. Rows that were not
    measured are kept, unless ``prune`` (then they are removed and listed); keeping them is
    refused when the problem parameters of their case and mode changed. ``rtol`` replaces the
    policy's. Full-mode metrics are not written here: their gold is their case folder
    (``cases.cli`` installs it)."""
    if rtol is not None and not (math.isfinite(rtol) and rtol > 0):
        raise CheckError(f"the margin must be a finite number > 0, got {rtol!r}")
    policy = Policy(**{**gold.policy.__dict__, **({"rtol": rtol} if rtol is not None else {})})
    changes = []
    if rtol is not None and rtol != gold.policy.rtol:
        changes.append(f"policy  rtol {gold.policy.rtol:g} -> {rtol:g}")
    old = {k: v for k, v in gold.rows.items() if k[1] in COMPACT_MODES}
    rows = {}
    measured_rows = set(measurements.rows or {k[:5] for k in measurements.values})
    for key in sorted(measurements.values):
        if key[1] not in COMPACT_MODES or key[:5] not in measured_rows:
            continue
        v = measurements.values[key]
        if v is not None and not _finite(v):
            raise CheckError(f"cannot bless {'/'.join(key)}: measured {v!r}")
        before = old.get(key[:5], {})
        o = before.get(key[5])
        value = _rounded(v)
        if o is not None and value is not None and abs(v - o) <= 10 ** -DIGITS * abs(o):
            value = o                  # the same to the gold's precision: no line changes
        rows.setdefault(key[:5], {})[key[5]] = value
        name = "/".join(key)
        if key[:5] not in old or key[5] not in before:
            changes.append(f"new     {name}: {_show(value)}")
        elif o != value:
            changes.append(f"changed {name}: {_show(o)} -> {_show(value)}")
    problems = {k: v for k, v in gold.problems.items() if k[1] in COMPACT_MODES}
    problems.update({k: v for k, v in measurements.problems.items() if k[1] in COMPACT_MODES})
    unseen = sorted(set(old) - set(rows))
    if prune:
        changes += [f"removed {'/'.join(k)} (not in the metrics blessed)" for k in unseen]
        problems = {k: v for k, v in problems.items() if k in {r[:2] for r in rows}}
    else:
        moved = sorted({k[:2] for k in unseen if k[:2] in measurements.problems
                        and gold.problems.get(k[:2]) != measurements.problems[k[:2]]})
        if moved:
            raise CheckError(f"the parameters of {', '.join('/'.join(k) for k in moved)} differ "
                             "from those of gold rows these metrics do not cover; bless a "
                             "complete run, or pass --prune to drop the rows not measured")
        rows.update({k: old[k] for k in unseen})
        if unseen:
            changes.append(f"kept    {len(unseen)} gold rows of runs not in the metrics "
                           "blessed (--prune removes them)")
    return Gold(policy, rows, problems, gold.folder), changes


def _show(v):
    return "n/a" if v is None else f"{v:.6g}"


def compact_files(gold):
    """{file name: text} of the compact gold files of ``gold`` (one per case and mode)."""
    out = {}
    for case, mode in sorted(gold.problems):
        if mode not in COMPACT_MODES:
            continue
        keys = sorted(k for k in gold.rows if k[:2] == (case, mode))
        columns = sorted({m for k in keys for m in gold.rows[k]})
        head = {"case": case, "mode": mode, "problem": gold.problems[(case, mode)],
                "columns": columns}
        lines = [json.dumps(head)] + [json.dumps([*k[2:], *(gold.rows[k].get(c)
                                                             for c in columns)])
                                      for k in keys]
        out[f"{case}.{mode}{SUFFIX}"] = "\n".join(lines) + "\n"
    return out


def policy_text(policy):
    """policy.toml: the tolerance policy, with what each entry means."""
    import tomli_w
    return ("# The gate's tolerance policy, for every gold value (`pbcm check`):\n"
            "#   |measured - gold| <= rtol |gold| + atol, atol = atol_of[metric] or atol.\n"
            "# atol keeps metrics near zero (momentum residuals, FEM's alternation) from failing\n"
            "# on noise; static displacements are solved to a residual of 1e-9, so their\n"
            "# differences below 1e-8 are the solver's, and so are those of the force errors\n"
            "# of a model exact on its problem (a homogeneous field). full: where the\n"
            "# full-mode gold is (the committed reports/CASE/metrics.json). Rewritten by\n"
            "# `pbcm bless --margin`.\n"
            + tomli_w.dumps(policy.__dict__))


__all__ = ["Policy", "Bound", "Gold", "Measurements", "Verdict", "CheckError", "NEW", "load",
           "measured", "check", "bless", "compact_files", "policy_text", "flip_message"]
