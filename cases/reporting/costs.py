"""What a model costs, as `pbcm bench` measured it: the one reader of ``bench.json``.

The bench (``cases.tools.bench``) writes ``reports/bench/bench.json``; cases and studies never
time anything themselves, they read their cost sentences and step costs from here. The cost of
a step on a mesh of T tetrahedra is fem-linear's step time interpolated in T (log-log between
the bench sizes) times the model's step ratio to fem-linear at T, itself interpolated: the
ratios are medians of interleaved rounds (one process), steadier than either time alone.
Outside the bench sizes the nearest size's values are used.
"""
import hashlib
import inspect
import json
from functools import lru_cache
from pathlib import Path

import numpy as np

import model as _model
from model.mesh import cube
from model.presets import IMPLICIT_STEP

from .document import Table, fmt, fmt_span

FILE = "bench.json"
FOLDER = "bench"                 # beside the case folders: reports/bench/bench.json
SOURCE = f"reports/{FOLDER}/{FILE}"
BASE = "fem-linear"              # the baseline every ratio is taken against
COST_TETS = 1e4                  # the mesh size at which costs are compared (tetrahedra)
REAL_TIME = 1.0                  # CPU seconds per simulated second at which a model runs in real time
CHECKOUT = Path(__file__).resolve().parents[2] / "reports" / FOLDER / FILE


def read(path):
    """The bench document at ``path``, or None when there is none (or it is not JSON)."""
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


def load(root=None):
    """The bench document of the reports folder ``root`` (``root/bench/bench.json``), else the
    checkout's, else None."""
    here = Path(root) / FOLDER / FILE if root is not None else None
    return read(here) if here is not None and here.is_file() else read(CHECKOUT)


def kernel_sources(pm):
    """A fingerprint of the source a built model's force evaluation and RK4 step run: its
    terms' own files, the kernel files they share (``model/terms/_*.py``, the base class) and
    the integrator. The bench records it with each row, so that a row timed on other kernels
    than the checkout's is said to be so (``stale``)."""
    root = Path(_model.__file__).resolve().parent
    files = {root / "integrate.py", root / "terms" / "base.py", *root.glob("terms/_*.py")}
    files |= {Path(inspect.getsourcefile(type(t))).resolve() for t in pm.terms}
    h = hashlib.sha256()
    for f in sorted(files):
        h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


@lru_cache(maxsize=None)
def checkout_sources(name):
    """``kernel_sources`` of the model ``name`` as this checkout builds it (on a two-cell
    cube: only its terms' classes matter), or None where it does not build."""
    try:
        mesh = cube(2, 0.01, "five")
        return kernel_sources(_model.build(name, mesh, _model.Material(E=1e4, nu=0.3)))
    except Exception:       # a model of a file not loaded here: its sources are not known
        return None


def stale(bench):
    """(models whose rows were timed on other kernels than this checkout's, sorted; 'all' or
    'some' where rows record no kernel sources, else False): what a cost sentence must say
    before it is read."""
    rows = [r for key in ("rows", "realtime_rows") for r in (bench or {}).get(key, [])
            if r.get("timed", True) and "engine" not in r]      # pbcm's own kernels, timed
    other = sorted({r["model"] for r in rows if r.get("kernels") is not None
                    and checkout_sources(r["model"]) not in (None, r["kernels"])})
    missing = sum(r.get("kernels") is None for r in rows)
    return other, ("all" if missing == len(rows) else "some") if missing else False


def stale_words(bench):
    """The sentence a report built on ``bench`` says about its kernels: '' where every row
    was timed on the checkout's."""
    other, unknown = stale(bench)
    if other:
        return (f"Timed on other kernels than this checkout's: {', '.join(other)}; their costs "
                "are the earlier kernels' until `pbcm bench` is run again.")
    if unknown:
        return (f"This bench records no kernel sources for {'some' if unknown == 'some' else 'any'} "
                "of its rows: whether they were timed on this checkout's kernels is not known "
                "until `pbcm bench` is run again.")
    return ""


def sim_ratio(row, base):
    """(ratio, [smallest, largest] or None): the cost of one simulated second of ``row``'s
    model over ``base``'s (a bench row each): the in-round step-time ratio times the ratio of
    their stable steps, its range the rounds' (the bench's ``step_vs_fem-linear_range``)."""
    dt = base["stable_dt_us"] / row["stable_dt_us"]
    key = f"step_vs_{base['model']}"
    if key not in row:            # the base itself, or a bench without in-round ratios
        return row["cpu_s_per_simulated_s"] / base["cpu_s_per_simulated_s"], None
    rng = row.get(f"{key}_range")
    return row[key] * dt, ([rng[0] * dt, rng[1] * dt] if rng else None)


def near(bench, model, key, tets=COST_TETS):
    """The bench row of ``model`` at the size it ran closest to ``tets`` (in log) among those
    with ``key``, or None: a size the bench ran, never an interpolation between two."""
    rows = [r for r in (bench or {}).get("rows", []) if r["model"] == model
            and r.get(key) is not None]
    return min(rows, key=lambda r: abs(np.log(r["tets"] / tets))) if rows else None


def step_cost_us(bench, model, tets):
    """Microseconds per RK4 step of ``model`` on ``tets`` tetrahedra, or None when the bench
    lacks the model (or there is no bench)."""
    if not bench:
        return None
    rows = [r for r in bench["rows"] if r["model"] == model]
    base = [r for r in bench["rows"] if r["model"] == BASE]
    if not rows or not base:
        return None
    rows, base = sorted(rows, key=lambda r: r["tets"]), sorted(base, key=lambda r: r["tets"])
    lt = np.log(tets)
    t_base = np.exp(np.interp(lt, np.log([r["tets"] for r in base]),
                              np.log([r["us_per_step"] for r in base])))
    ratio = np.exp(np.interp(lt, np.log([r["tets"] for r in rows]),
                             np.log([r[f"step_vs_{BASE}"] for r in rows])))
    return float(t_base * ratio)


def per_simulated_second(bench, model, tets):
    """CPU seconds ``model`` takes per simulated second on the bench's mesh of ``tets``
    tetrahedra (its own stable RK4 step, or an implicit preset's own step), as the bench
    measured it there; None where it did not (another size, a size above the one it measures
    the stable step or the implicit step to, or no bench)."""
    for r in list((bench or {}).get("rows", [])) + list((bench or {}).get("implicit_rows", [])):
        if r["model"] == model and r["tets"] == tets:
            return r.get("cpu_s_per_simulated_s")
    return None


def cpu_seconds(row):
    """'1.59 [1.52-1.71]': a bench row's CPU seconds per simulated second, the median round
    with the rounds' range where the bench recorded it (the median alone where not)."""
    own, span = row.get("cpu_s_per_simulated_s"), row.get("cpu_s_per_simulated_s_range")
    if own is None:
        return "n/a"
    return fmt_span(own, span)


def cost_items(data, models, tets):
    """What a case report states about cost: a table of each model's RK4 step against msm's
    and fem-linear's, and at its own stable step the cost of one simulated second, from the
    bench size closest to ``tets``; a sentence naming the command where there is no bench."""
    if not data:
        return [f"No benchmark found beside this report ({SOURCE}): run `pbcm bench` for "
                "the cost of each model."]
    sizes = sorted({r["tets"] for r in data["rows"]}, key=lambda n: abs(np.log(n / tets)))
    near = [r for r in data["rows"] if r["tets"] == sizes[0] and r["model"] in models]
    if not near:
        return []
    msm = next((r for r in data["rows"] if r["model"] == "msm" and r["tets"] == sizes[0]
                and r.get("cpu_s_per_simulated_s")), None)

    def per_second(r):
        if not (r.get("cpu_s_per_simulated_s") and msm):
            return cpu_seconds(r), "n/a"
        ratio, span = sim_ratio(r, msm)     # in-round, as every cost over another model's
        return cpu_seconds(r), fmt_span(ratio, span)

    def step(r, base):
        key = f"step_vs_{base}"
        span = r.get(f"{key}_range")
        return fmt_span(r[key], span if r[key] != 1.0 else None)
    return [Table(
        f"From `pbcm bench` at {sizes[0]} tetrahedra (median of {near[0]['rounds']} "
        "interleaved rounds [smallest-largest over them]; a ratio is taken within each round; "
        "the paper reports a step over 10x msm's). The own stable step is 2 sqrt 2 / "
        "omega_max, undamped: a stiffer model needs smaller steps, which the cost per step "
        "hides; per simulated second over msm's is the in-round step ratio times the stable "
        "steps' ratio.",
        ["model", "step / msm", "step / fem-linear", "own stable step [us]",
         "CPU s per simulated s", "per simulated s / msm"],
        [[r["model"], step(r, "msm"), step(r, "fem-linear"),
          fmt(r.get("stable_dt_us")), *per_second(r)] for r in near])]


# ------------------------------------------------ the real-time family (``realtime_rows``)
# what `pbcm bench` times wall clock under the paper's push (cases.tools.realtime_bench) and
# `pbcm run realtime` reads
# cells per side of the 'five' cubes (5 k^3 tetrahedra): the paper's 4 (125 nodes) up to 28
# (109760 tetrahedra), neighbours at most 1.5 times apart in tetrahedra
CELLS = (4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 15, 17, 19, 22, 25, 28)
QUICK_CELLS = (4, 6)
FAMILY_MODELS = ("pbcm-corner", "pbcm-balanced", "pbcm-variational", "pbcm-variational+normal",
                 "msm", "msm+volume", "fem-linear", "fem-corotated", "fem-neohookean",
                 *IMPLICIT_STEP)     # every preset


def family_models(quick=False):
    """The real-time family's models: every preset and, where the engines extra is installed,
    Newton's solvers at the iteration counts the engines study runs them (the quick family:
    at their defaults)."""
    from model.simulators import newton
    engines = newton.ladder_models(1 if quick else None) if newton.installed() else ()
    return FAMILY_MODELS + engines


def sizes(quick=False):
    """The family's tetrahedron counts."""
    return [5 * k ** 3 for k in (QUICK_CELLS if quick else CELLS)]


def best(row):
    """(wall seconds per simulated second, mode) of a row's faster mode, or (None, None) for a
    size not timed."""
    if not row.get("timed"):
        return None, None
    two = row.get("two_thread_wall_s_per_simulated_s")
    if two is not None and two < row["wall_s_per_simulated_s"]:
        return two, "two threads"
    return row["wall_s_per_simulated_s"], ("implicit" if row["model"] in IMPLICIT_STEP
                                           else "serial")


__all__ = ["FILE", "FOLDER", "SOURCE", "read", "load", "step_cost_us", "cost_items",
           "FAMILY_MODELS", "family_models", "sizes", "best"]
