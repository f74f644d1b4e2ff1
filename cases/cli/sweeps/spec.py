"""A sweep, declared: the TOML spec of ``pbcm sweep``, checked whole before any computing, and
the runs it asks for.

A spec names the cases, the settings held fixed and the axes swept::

    title = "Every model on the paper cube over Poisson's ratio"
    cases = ["paper-cube"]
    quick = false           # the cases' full settings (true: their quick ones)
    static_only = true      # the static problem only: no dynamics, no modes
    table = "auto"          # auto (Parquet when pyarrow is present) | csv | parquet

    [fixed]                 # case settings held at one value
    p2_levels = 1

    [axes]                  # lists, or ranges {from, to, num[, log]} or {from, to, step}
    nu = [0.0, 0.3, 0.45]
    E = {from = 1e3, to = 1e5, num = 3, log = true}
    mesh = ["five", "six"]
    bc = "all"
    model = "all"

    [report]
    metrics = ["reaction_ratio", "apparent_poisson"]

Axes: ``E`` [Pa], ``nu``, ``rho`` [kg/m^3], ``resolution`` and ``load`` (the case's own
setting and unit, its ``Case.resolution`` / ``Case.load`` knob: nodes per side, spacing in mm,
push in mm, load in N), ``mesh``, ``bc`` and ``model`` (presets or composed terms; "all": the
case's own). An axis not given takes the case's default. The names, types and choices are
checked here; a value the physics refuses (nu = 0.5, a lattice too coarse) fails its own runs,
which the sweep records and goes on.
"""
import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from model import ModelError
from model.compose import checked

NUMERIC_AXES = ("E", "nu", "rho", "resolution", "load")
CHOICE_AXES = ("mesh", "bc", "model")
AXES = NUMERIC_AXES + CHOICE_AXES
PLURAL = {"mesh": "meshes", "bc": "bcs"}    # the Case attribute listing an axis' choices
# a settings field's type: the TOML values it takes, and how to say so
KINDS = {int: (lambda v: isinstance(v, int) and not isinstance(v, bool), "a whole number"),
         float: (lambda v: isinstance(v, (int, float)) and not isinstance(v, bool), "a number"),
         bool: (lambda v: isinstance(v, bool), "true or false"),
         str: (lambda v: isinstance(v, str), "a string")}
TABLES = ("auto", "csv", "parquet")
TOP_KEYS = {"title", "cases", "quick", "static_only", "table", "fixed", "axes", "report"}
UNITS = {"E": "E [Pa]", "nu": "nu", "rho": "rho [kg/m^3]", "mesh": "mesh", "bc": "bc",
         "model": "model"}


class SpecError(ModelError):
    """A sweep spec that cannot run: it names the key and what to write instead."""


@dataclass(frozen=True)
class Unit:
    """One task: a case's (mesh, bc) at one point of the numeric axes, with the models to
    run on its FEM references. ``point`` holds the swept and fixed values by axis name;
    ``settings`` the case's Settings keywords they become."""

    case: str
    mesh: str
    bc: str
    models: tuple
    point: dict
    settings: dict
    problem: object = None   # the case's problem() at these settings (or why they fail)

    def run_key(self, model):
        """The run's identity: a hash of everything that defines it, the case's whole problem
        included (a rerun of the same spec finds it; a changed value, here or in a case's
        defaults, makes a new run)."""
        text = json.dumps({"case": self.case, "mesh": self.mesh, "bc": self.bc,
                           "model": model, "settings": self.settings,
                           "problem": self.problem}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass
class Spec:
    """A checked sweep spec (see the module docstring)."""

    title: str
    cases: tuple
    quick: bool
    static_only: bool
    table: str
    fixed: dict
    axes: dict          # axis name -> list of values (only the axes the spec gives)
    metrics: tuple
    source: str = ""

    def swept(self):
        """The axes that take more than one value, in AXES order."""
        return [a for a in AXES if len(self.axes.get(a, ())) > 1]

    def units(self, registry):
        """Every task of the sweep, in a fixed order (cases, then the numeric axes, then mesh
        and bc), each with the models of its point."""
        out = []
        for name in self.cases:
            case = registry[name]
            base = case.settings(quick=self.quick)
            numeric = [a for a in NUMERIC_AXES if a in self.axes]
            meshes = self.axes.get("mesh") or list(base.meshes)
            bcs = self.axes.get("bc") or list(base.bcs)
            models = tuple(self.axes.get("model") or base.models)
            for values in itertools.product(*(self.axes[a] for a in numeric)):
                point = dict(zip(numeric, values))
                kw = {**self.fixed, **point}
                settings = _settings_keywords(case, kw, self)
                try:
                    problem = case.settings(**settings).problem()
                except Exception as exc:    # the runs of this point will fail and say why
                    problem = f"settings refused: {exc}"
                for mesh, bc in itertools.product(meshes, bcs):
                    out.append(Unit(name, mesh, bc, models, point, settings, problem))
        return out

    def label(self, axis, case):
        """The axis' label with its unit (resolution and load: the case's knob)."""
        knob = getattr(case, axis, None) if axis in ("resolution", "load") else None
        return knob.label if knob is not None else UNITS.get(axis, axis)


def _settings_keywords(case, kw, spec):
    """The case's Settings keywords of a point: generic axes mapped to the case's fields."""
    out = {"quick": spec.quick, "static_only": spec.static_only}
    for key, value in kw.items():
        if key in ("resolution", "load"):
            out[getattr(case, key).field] = value
        else:
            out[key] = value
    return out


def load(path, registry):
    """The Spec of a TOML file, checked against the case ``registry`` ({name: Case})."""
    path = Path(path)
    if not path.is_file():
        raise SpecError(f"sweep spec {path} does not exist (or is not a file); give a .toml "
                        "file (e.g. cases/cli/sweeps/nu.toml)")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"sweep spec {path} is not valid TOML: {exc}") from None
    return parse(data, registry, source=str(path))


def parse(data, registry, source="<spec>"):
    """The Spec of a parsed TOML document (see ``load``)."""
    where = source
    unknown = set(data) - TOP_KEYS
    if unknown:
        raise SpecError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}; valid: "
                        f"{', '.join(sorted(TOP_KEYS))}")
    cases = _strings(data.get("cases"), f"{where}: cases")
    if not cases:
        raise SpecError(f"{where}: cases must list at least one case, e.g. "
                        f"cases = [\"paper-cube\"]; valid: {', '.join(registry)}")
    bad = [c for c in cases if c not in registry]
    if bad:
        raise SpecError(f"{where}: unknown case(s) {', '.join(bad)}; valid: "
                        f"{', '.join(registry)} (studies cannot be swept)")
    quick = _bool(data.get("quick", False), f"{where}: quick")
    static_only = _bool(data.get("static_only", False), f"{where}: static_only")
    table = data.get("table", "auto")
    if table not in TABLES:
        raise SpecError(f"{where}: table must be one of {', '.join(TABLES)}, got {table!r}")
    for name in cases:
        if static_only and not registry[name].static:
            raise SpecError(f"{where}: case {name} has no static problem, so static_only = "
                            "true leaves it nothing to run; set static_only = false or drop it")
    axes = _axes(data.get("axes", {}), cases, registry, where)
    fixed = _fixed(data.get("fixed", {}), cases, registry, axes, where)
    report = data.get("report", {})
    if not isinstance(report, dict) or set(report) - {"metrics"}:
        raise SpecError(f"{where}: [report] takes one key, metrics = [\"...\"]")
    metrics = _strings(report.get("metrics", ["disp_rel_l2_p2", "reaction_ratio"]),
                       f"{where}: report.metrics")
    title = data.get("title", Path(source).stem)
    if not isinstance(title, str):
        raise SpecError(f"{where}: title must be a string")
    spec = Spec(title, tuple(cases), quick, static_only, table, fixed, axes, tuple(metrics),
                source)
    for name in cases:    # every point's settings must build (types; values are the runs')
        try:
            registry[name].settings(**_settings_keywords(
                registry[name], {**fixed, **{a: v[0] for a, v in axes.items()
                                            if a in NUMERIC_AXES}}, spec))
        except TypeError as exc:
            raise SpecError(f"{where}: the settings of case {name} do not take these values "
                            f"({exc})") from None
        except Exception:   # a value the settings refuse (nu = 0.5): that point's runs fail
            pass
    return spec


def _strings(value, where):
    if value is None:
        return []
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise SpecError(f"{where} must be a list of strings, got {value!r}")
    return list(value)


def _bool(value, where):
    if not isinstance(value, bool):
        raise SpecError(f"{where} must be true or false, got {value!r}")
    return value


def _number(v, where):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SpecError(f"{where} takes finite numbers, got {v!r}")
    return v


def _range(r, where):
    """The values of a range table: {from, to, num[, log]} (num values, ends included, evenly
    or geometrically spaced) or {from, to, step} (ends included when on the step)."""
    keys = set(r)
    if keys not in ({"from", "to", "num"}, {"from", "to", "num", "log"}, {"from", "to", "step"}):
        raise SpecError(f"{where}: a range is {{from, to, num}}, {{from, to, num, log = true}} "
                        f"or {{from, to, step}}; got keys {', '.join(sorted(keys))}")
    lo, hi = _number(r["from"], where), _number(r["to"], where)
    if "step" in r:
        step = _number(r["step"], where)
        if step <= 0 or hi < lo:
            raise SpecError(f"{where}: a stepped range needs step > 0 and from <= to")
        n = int(math.floor((hi - lo) / step * (1 + 1e-12))) + 1
        ints = all(isinstance(x, int) for x in (lo, hi, step))
        return [lo + k * step if ints else round(lo + k * step, 12) for k in range(n)]
    num = r["num"]
    if isinstance(num, bool) or not isinstance(num, int) or num < 1:
        raise SpecError(f"{where}: num must be a whole number >= 1, got {num!r}")
    if r.get("log", False):
        if lo <= 0 or hi <= 0:
            raise SpecError(f"{where}: a log range needs from > 0 and to > 0")
        values = np.geomspace(lo, hi, num)
    else:
        values = np.linspace(lo, hi, num)
    return [float(np.format_float_positional(v, precision=12, unique=True)) for v in values]


def _axes(table, cases, registry, where):
    if not isinstance(table, dict):
        raise SpecError(f"{where}: [axes] must be a table of axis = values")
    unknown = set(table) - set(AXES)
    if unknown:
        raise SpecError(f"{where}: unknown axis {', '.join(sorted(unknown))}; valid: "
                        f"{', '.join(AXES)}")
    out = {}
    for axis in AXES:
        if axis not in table:
            continue
        v, at = table[axis], f"{where}: axes.{axis}"
        if axis in NUMERIC_AXES:
            values = _range(v, at) if isinstance(v, dict) else [
                _number(x, at) for x in (v if isinstance(v, list) else [v])]
        else:
            values = _choices(axis, v, cases, registry, at)
        if not values:
            raise SpecError(f"{at} is empty; give at least one value")
        if len(set(map(repr, values))) != len(values):
            raise SpecError(f"{at} repeats a value: {values}")
        out[axis] = values
    for axis in ("resolution", "load"):
        for name in cases if axis in out else ():
            knob = getattr(registry[name], axis)
            if knob is None:
                raise SpecError(f"{where}: case {name} has no {axis} setting to sweep; drop "
                                f"axes.{axis} or the case (cases with one: " + ", ".join(
                                    n for n, c in registry.items()
                                    if getattr(c, axis) is not None) + ")")
            if _field_type(registry[name], knob.field) is int and not all(
                    float(x).is_integer() for x in out[axis]):
                raise SpecError(f"{where}: axes.{axis} of case {name} is {knob.label}, a whole "
                                f"number; got {out[axis]}")
            if _field_type(registry[name], knob.field) is int:
                out[axis] = [int(x) for x in out[axis]]
    return out


def _field_type(case, name):
    for f in fields(case.settings_class):
        if f.name == name:
            return f.type if isinstance(f.type, type) else {
                "int": int, "float": float, "bool": bool, "str": str}.get(f.type, object)
    raise SpecError(f"case {case.name} names the setting {name}, which its settings lack")


def _choices(axis, v, cases, registry, where):
    if v == "all":
        if axis == "model":
            return list(dict.fromkeys(m for c in cases for m in registry[c].models))
        return list(dict.fromkeys(x for c in cases for x in getattr(registry[c], PLURAL[axis])))
    values = _strings(v, where)
    if axis == "model":
        try:
            return list(dict.fromkeys(checked(m) for m in values))
        except ModelError as exc:
            raise SpecError(f"{where}: {exc}") from None
    for name in cases:
        valid = getattr(registry[name], PLURAL[axis])
        bad = [x for x in values if x not in valid]
        if bad:
            raise SpecError(f"{where}: case {name} has no {axis} {', '.join(bad)}; valid: "
                            f"{', '.join(valid)}")
    return values


def _fixed(table, cases, registry, axes, where):
    if not isinstance(table, dict):
        raise SpecError(f"{where}: [fixed] must be a table of setting = value")
    both = set(table) & set(axes)
    if both:
        raise SpecError(f"{where}: {', '.join(sorted(both))} is both fixed and swept; keep "
                        "one")
    selection = {"meshes", "bcs", "models", "quick", "static_only", "mesh", "bc", "model"}
    bad = set(table) & selection
    if bad:
        raise SpecError(f"{where}: fixed.{', fixed.'.join(sorted(bad))}: the selection is "
                        "swept under [axes] (mesh, bc, model) or set at the top (quick, "
                        "static_only)")
    for name in cases:
        case = registry[name]
        names = {f.name for f in fields(case.settings_class) if f.init}
        for key, value in table.items():
            target = getattr(case, key).field if key in ("resolution", "load") and getattr(
                case, key) is not None else key
            if target not in names:
                raise SpecError(f"{where}: fixed.{key} is not a setting of case {name}; its "
                                f"settings: " + ", ".join(sorted(names - selection)))
            if isinstance(value, (dict, list)):
                raise SpecError(f"{where}: fixed.{key} takes one value, got {value!r}")
            kind = _field_type(case, target)
            if kind in KINDS and not KINDS[kind][0](value):
                raise SpecError(f"{where}: fixed.{key} of case {name} takes "
                                f"{KINDS[kind][1]}, got {value!r}")
    return dict(table)


__all__ = ["Spec", "Unit", "SpecError", "load", "parse", "AXES", "NUMERIC_AXES"]
