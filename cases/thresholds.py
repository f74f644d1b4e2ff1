"""Error bounds for CI, declared as data (thresholds.toml) in the style of verification
harnesses: a stored value with a relative tolerance and an absolute floor, and a direction.

    max: measured <= value + rtol |value| + atol     (an error must stay below)
    min: measured >= value - rtol |value| - atol     (a correlation must stay above)
"""
from dataclasses import dataclass
import datetime
import json
import math
from pathlib import Path
import tomllib

# the gated metrics and their direction; correlations must stay above, errors below
GATED = {"disp_rel_l2_p1": "max", "disp_rel_l2_p2": "max", "disp_max_rel_p2": "max",
         "reaction_rel_err": "max", "stress_corr": "min", "stress_rel_err": "max",
         "pressure_rel_err": "max", "zigzag": "max", "net_force_rel": "max"}
ATOL = 1e-9  # floor: metrics near zero (momentum residuals, zig-zag of FEM) never fail on noise
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
    def limit(self):
        slack = self.rtol * abs(self.value) + self.atol
        return self.value + slack if self.direction == "max" else self.value - slack

    def passes(self, measured):
        return measured <= self.limit if self.direction == "max" else measured >= self.limit

    def margin(self, measured):
        """How far inside the bound, as a fraction of the limit (negative: outside)."""
        gap = self.limit - measured if self.direction == "max" else measured - self.limit
        return gap / max(abs(self.limit), self.atol)


FIELDS = ("case", "mode", "mesh", "bc", "model", "metric", "value", "rtol", "atol", "direction")


def load(path):
    path = Path(path)
    if not path.is_file():
        raise CheckError(f"thresholds file {path} is missing; create it with `pbcm bless`")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise CheckError(f"thresholds file {path} is malformed: {exc}") from None
    bounds = []
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
        bounds.append(Bound(**{f: b[f] for f in FIELDS}, measured_on=b.get("measured_on", "")))
    if not bounds:
        raise CheckError(f"thresholds file {path} holds no [[bound]]; run `pbcm bless`")
    return bounds


def measured(metrics_dir):
    """{(case, mode, mesh, bc, model, metric): value} from every metrics.json under a folder
    (or one file)."""
    p = Path(metrics_dir)
    files = [p] if p.is_file() else sorted(p.glob("**/metrics.json"))
    if not files:
        raise CheckError(f"no metrics.json under {p}; run `pbcm run CASE` first")
    out = {}
    for f in files:
        try:
            data = json.loads(f.read_text())
            case, mode = data["case"], "quick" if data["parameters"]["quick"] else "full"
            runs = data["runs"]
        except (ValueError, KeyError) as exc:
            raise CheckError(f"{f} is not a pbcm metrics file: {exc}") from None
        for r in runs:
            for metric in GATED:
                out[(case, mode, r["mesh"], r["bc"], r["model"], metric)] = r.get(metric)
    return out


def check(bounds, values):
    """Rows (bound, measured, passed) and the exit status: 0 all pass, 1 any fails. Bounds of
    a case and mode that were not run are set aside; among the others, a bound without a
    measured value, a value that is not finite, or a measured metric without a bound raises
    CheckError (exit 2): a missing reference never passes."""
    rows, status = [], 0
    runs = {k[:2] for k in values}            # (case, mode) pairs that were measured
    bounds = [b for b in bounds if b.key[:2] in runs]
    if not bounds:
        raise CheckError(f"no bound for the measured {', '.join('/'.join(r) for r in sorted(runs))}"
                         "; run in a mode the thresholds cover, or bless this one")
    keys = {b.key for b in bounds}
    unbounded = [k for k in values if k not in keys and values[k] is not None]
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
    return rows, status


def bless(values, old=None, rtol=RTOL, atol=ATOL, today=None):
    """Bounds for every gated metric measured (metrics that are None, e.g. an undefined
    correlation, get none), keeping an old bound's tolerances; and what changed."""
    today = today or datetime.date.today().isoformat()
    prev = {b.key: b for b in (old or [])}
    bounds, changes = [], []
    for key in sorted(values):
        v = values[key]
        if v is None:
            continue
        if not math.isfinite(v):
            raise CheckError(f"cannot bless {'/'.join(key)}: measured {v!r}")
        case, mode, mesh, bc, model, metric = key
        o = prev.get(key)
        b = Bound(case, mode, mesh, bc, model, metric, float(v), rtol, atol, GATED[metric],
                  today)
        if o is None:
            changes.append(f"new     {'/'.join(key)}: {v:.6g}")
        elif o.value != b.value or (o.rtol, o.atol) != (rtol, atol):
            changes.append(f"changed {'/'.join(key)}: {o.value:.6g} -> {v:.6g}")
        bounds.append(b)
    for key in sorted(set(prev) - {b.key for b in bounds}):
        changes.append(f"removed {'/'.join(key)}")
    return bounds, changes


def dumps(bounds):
    lines = ["# pbcm error bounds, read by `pbcm check` and rewritten only by `pbcm bless`.",
             "# max: measured <= value + rtol |value| + atol;  min: measured >= value - rtol |value|"
             " - atol.", "# mode: the run mode the bound belongs to (quick runs in CI).", ""]
    for b in bounds:
        lines += ["[[bound]]", f"# measured {b.value:.6g} on {b.measured_on}"]
        for f in FIELDS:
            v = getattr(b, f)
            lines.append(f"{f} = {json.dumps(v) if isinstance(v, str) else repr(float(v))}")
        lines += [f"measured_on = {json.dumps(b.measured_on)}", ""]
    return "\n".join(lines)
