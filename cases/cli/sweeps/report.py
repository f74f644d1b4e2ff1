"""The sweep's report: each metric of ``[report] metrics`` against each swept axis, one line
per model (and FEM P2's own value, dashed, where the runs carry it), one panel per value of the
other swept axes; and what the sweep shows, computed from its rows: how far each model is from
its target (FEM P2's value, a ratio of 1, an error of 0), where it is worst, and whether that
distance grows along each numeric axis.
"""
import io
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from model import PbcmError  # noqa: E402
from ...reporting.document import Document, fmt  # noqa: E402
from ...measuring.catalogue import ref_name  # noqa: E402
from .spec import NUMERIC_AXES  # noqa: E402
from ...running.output import write_atomic  # noqa: E402

MAX_PANELS = 12       # more combinations of the other axes than this: the first ones drawn
MAX_FAILURES = 40     # failed runs listed one by one; the rest counted
CHANGE = 1.25         # "grows" / "shrinks" along an axis: a change by this factor or more
ROUND_OFF = 1e-6      # deviations below this at both ends are solver round-off: no trend
RATIOS = {"reaction_ratio"}   # model over FEM: the target is 1
ERRORS = ("_rel_err", "_rel_l2", "_rel_l2_p1", "_rel_l2_p2", "_max_rel_p1", "_max_rel_p2")
LOG_SPAN = 5.0        # a ratio or error spanning this factor is drawn on a log scale
FLAT = 0.1            # a model "does not follow" an axis that moves FEM's value 10x more
SIGN_FLOOR = 1e-3     # FEM values below this fraction of their largest are zero for the sign
PREFIX = "sweep_"     # every figure's file name starts so (earlier ones are cleaned up)


class MissingMetric(PbcmError):
    """A metric of ``[report] metrics`` that no run has."""


def _value(v):
    return None if v is None or isinstance(v, (bool, str, list, dict)) else float(v)


def target(metric, rows):
    """(name, function row -> target value) of a metric: FEM P2's value where the rows carry
    it, 1 for a ratio to FEM, 0 for an error; None when the metric has no target."""
    fem = ref_name(metric)
    if any(_value(r.get(fem)) is not None for r in rows):
        return "FEM P2", lambda r: _value(r.get(fem))
    if metric in RATIOS:
        return "1 (FEM P2)", lambda r: 1.0
    if metric.endswith(ERRORS):
        return "0", lambda r: 0.0
    return None


def deviations(metric, rows):
    """{model: [(|value - target|, row)]} over the rows that have both."""
    t = target(metric, rows)
    out = {}
    for r in rows:
        v = _value(r.get(metric))
        goal = None if t is None else t[1](r)
        if v is not None and goal is not None:
            out.setdefault(r["model"], []).append((abs(v - goal), r))
    return out


def _where(r, axes):
    return ", ".join(f"{a} {fmt(r[a])}" if a in NUMERIC_AXES else str(r[a]) for a in axes)


def _stat(xs):
    """(median, smallest, largest) of ``xs``, or None: one population's spread, never
    averaged away."""
    return (float(np.median(xs)), float(min(xs)), float(max(xs))) if xs else None


def _spread(st):
    return "n/a" if st is None else f"{fmt(st[0])} [{fmt(st[1])}-{fmt(st[2])}]"


POPULATION = ("case", "bc")   # runs of one kind: one case under one boundary condition


def kind(metric, t):
    """What the deviation of ``metric`` from its target ``t`` measures, in words."""
    if metric.endswith(("_p1", "_rel_l2_p1", "_max_rel_p1")):
        return ("the model-form error (against FEM P1 with the same law on the same "
                "tetrahedra): what replacing FEM by the model costs")
    if (t is not None and "FEM P2" in t[0]) or metric.endswith("_p2"):
        return ("the total error against the converged continuum (FEM P2 refined), the "
                "mesh's own discretisation error included: a model whose error cancels "
                "P1's scores well, so this is not a ranking of models")
    return "the deviation from its target"


def noise(metric, t, rows):
    """The smallest change of a deviation the runs can tell: for a comparison with the
    converged continuum its reference's largest error estimate over the rows
    (``p2_error_estimate``), for one with FEM P1 on the same tetrahedra the solver's
    round-off (ROUND_OFF)."""
    if kind(metric, t).startswith("the total error"):
        est = [_value(r.get("p2_error_estimate")) for r in rows]
        return max([ROUND_OFF] + [e for e in est if e is not None])
    return ROUND_OFF


def _floor_text(metric, t, rows):
    return (f"a change below {fmt(noise(metric, t, rows))} ("
            + ("the reference's largest error estimate over these runs"
               if kind(metric, t).startswith("the total error") else "the solver's round-off")
            + ") is not a trend")


def populations(rows, spec):
    """[(label, rows)] of the runs grouped by case and boundary condition where the sweep has
    more than one of them (a patch test is never pooled with a clamped cube); one group,
    labelled '', otherwise."""
    keys = [a for a in POPULATION if len({r.get(a) for r in rows}) > 1]
    if not keys:
        return [("", rows)]
    groups = {}
    for r in rows:
        groups.setdefault(tuple(str(r.get(a)) for a in keys), []).append(r)
    return [("/".join(k), g) for k, g in groups.items()]


def findings(metric, rows, spec, models):
    """(sentences, table header, table rows) on one metric over the sweep: one block of rows
    and sentences per population (case and boundary condition), none pooled."""
    pops = populations(rows, spec)
    if len(pops) == 1:
        said, header, body = _findings(metric, rows, spec, models, "")
        return _patch_test(metric, rows) + said, header, body
    out, header, body = [], None, []
    t = target(metric, rows)
    if t is not None:
        out.append(f"{metric}: {kind(metric, t)}; each model's |deviation| from {t[0]} per "
                   f"case and boundary condition, {SPREAD}, is in the table, never pooled "
                   "across them; in each, a change below the reference's largest error "
                   "estimate there (a total error) or the solver's round-off (a model-form "
                   f"error), or within {OVERLAP}, is not a trend, and the sweep ranks no "
                   "model.")
    for label, group in pops:
        said, h, b = _findings(metric, group, spec, models, label, lead=False)
        out += _patch_test(f"{metric} on {label}", group) + said
        header = ["population"] + h
        body += [[label] + line for line in b]
    return out, header, body


def _patch_test(pre, rows):
    """A sentence where every run of a population is its case's patch test (a field every
    FEM element reproduces): FEM's rows there check, they do not measure accuracy."""
    from ...registry import CASES
    if not rows or not all(r.get("bc") in getattr(CASES.get(r["case"]), "patch_tests", ())
                           for r in rows):
        return []
    return [f"{pre}: a patch test (a homogeneous field that FEM reproduces on any mesh): the "
            "FEM models' rows there are a check, not accuracy; a particle model's row is its "
            "consistency."]


SPREAD = "median [smallest-largest] over its runs there (meshes and other axes), n of N runs"
OVERLAP = "the spread over the meshes at both ends (the two ranges overlap)"


def _findings(metric, rows, spec, models, label, lead=True):
    """findings() on the rows of one population, its sentences prefixed with ``label``."""
    axes = [a for a in ["case"] + spec.swept() if a not in ("model", *POPULATION)]
    pre = f"{metric} on {label}" if label else metric
    t = target(metric, rows)
    if t is None:
        header = ["model", "runs", "min", "max"]
        body = []
        for m in models:
            vs = [(_value(r.get(metric)), r) for r in rows if r["model"] == m
                  and _value(r.get(metric)) is not None]
            if vs:
                lo, hi = min(vs, key=lambda p: p[0]), max(vs, key=lambda p: p[0])
                body.append([m, len(vs), f"{fmt(lo[0])} ({_where(lo[1], axes)})",
                             f"{fmt(hi[0])} ({_where(hi[1], axes)})"])
        return ([f"{pre} has no target (no FEM value, not a ratio or an error): its range "
                 "per model."] if lead or not label else []), header, body
    dev = deviations(metric, rows)
    numeric = [a for a in spec.swept() if a in NUMERIC_AXES]
    ends = {a: _ends(a, rows, spec) for a in numeric}
    header = ["model", "n of N", f"abs dev from {t[0]}: median [min-max]", "worst", "at"]
    for a in numeric:
        header += [f"at {a} = {fmt(ends[a][0])}", f"at {a} = {fmt(ends[a][1])}"]
    body, trend = [], {a: ([], []) for a in numeric}
    floor = noise(metric, t, rows)
    for m in models:
        d = dev.get(m)
        if not d:
            continue
        planned = sum(r["model"] == m for r in rows)
        worst = max(d, key=lambda p: p[0])
        line = [m, f"{len(d)} of {planned}", _spread(_stat([x for x, _ in d])),
                fmt(worst[0]), _where(worst[1], axes)]
        for a in numeric:
            at = [_stat([x for x, r in d if r[a] == v]) for v in ends[a]]
            line += [_spread(at[0]), _spread(at[1])]
            if None in at:
                continue
            (m0, lo0, hi0), (m1, lo1, hi1) = at
            if (max(m0, m1) < floor or abs(m1 - m0) < floor
                    or (lo1 <= hi0 and lo0 <= hi1)):
                continue               # below the floor, or within the spread: no trend
            said = f"{m} {_spread(at[0])} -> {_spread(at[1])}"
            if m1 > CHANGE * m0:
                trend[a][0].append(said)
            elif m1 * CHANGE < m0:
                trend[a][1].append(said)
        body.append(line)
    out = []
    if lead and dev:
        out.append(f"{pre}: {kind(metric, t)}; each model's |deviation| from {t[0]}, "
                   f"{SPREAD}, is in the table; {_floor_text(metric, t, rows)}, nor is a "
                   f"change within {OVERLAP}, and the sweep ranks no model.")
    for a in numeric:
        grows, shrinks = trend[a]
        first, last = map(fmt, ends[a])
        if grows:
            out.append(f"{pre}: the median |deviation| grows by more than {CHANGE:g}x from "
                       f"{a} = {first} to {a} = {last}, beyond the spread over the meshes: "
                       + ", ".join(grows) + ".")
        if shrinks:
            out.append(f"{pre}: it shrinks by more than {CHANGE:g}x from {a} = {first} to "
                       f"{a} = {last}, beyond the spread over the meshes: "
                       + ", ".join(shrinks) + ".")
    if t[0] == "FEM P2":
        fem = ref_name(metric)
        out += [f"{pre}: {m} {text}" for m in models
                for text in _unfollowed(metric, fem, rows, spec, m, numeric)
                + _opposite(metric, fem, rows, m, axes)]
    return out, header, body


def _unfollowed(metric, fem, rows, spec, model, numeric):
    """Sentences for each numeric axis along which FEM P2's value moves and the model's does
    not (by less than FLAT of FEM's move, in every panel of the other axes)."""
    out = []
    for a in numeric:
        spans = []
        for panel in _groups(rows, spec, a, model):
            mv = [_value(r.get(metric)) for r in panel]
            fv = [_value(r.get(fem)) for r in panel]
            if None in mv or None in fv or len(panel) < 2:
                break
            spans.append((float(np.ptp(mv)), float(np.ptp(fv))))
        else:
            if spans and all(f > 0 and m < FLAT * f for m, f in spans):
                out.append(f"does not follow {a}: it moves by at most "
                           f"{fmt(max(m for m, _ in spans))} across {a} in every panel, where "
                           f"FEM P2's moves by {fmt(min(f for _, f in spans))} to "
                           f"{fmt(max(f for _, f in spans))}.")
    return out


def _opposite(metric, fem, rows, model, axes):
    """A sentence when the model's value has the sign opposite to FEM P2's (where FEM's is
    clearly not zero)."""
    pairs = [(_value(r.get(metric)), _value(r.get(fem)), r) for r in rows if r["model"] == model]
    pairs = [(v, f, r) for v, f, r in pairs if v is not None and f is not None]
    scale = max((abs(f) for _, f, _ in pairs), default=0.0)
    bad = [(v, r) for v, f, r in pairs if v * f < 0 and abs(f) > SIGN_FLOOR * scale]
    if not bad:
        return []
    v, r = max(bad, key=lambda p: abs(p[0]))
    return [f"has the sign opposite to FEM P2's in {len(bad)} of {len(pairs)} runs (as far as "
            f"{fmt(v)} at {_where(r, axes)})."]


def _groups(rows, spec, axis, model):
    """The model's rows grouped by the values of every swept axis but ``axis`` and model
    (and by case), each group ordered along ``axis``."""
    others = ["case"] + [a for a in spec.swept() if a not in (axis, "model")]
    groups = {}
    for r in rows:
        if r["model"] == model:
            groups.setdefault(tuple(r.get(a) for a in others), []).append(r)
    order = {v: i for i, v in enumerate(spec.axes[axis])}
    return [sorted(g, key=lambda r: order.get(r[axis], 0)) for _, g in sorted(
        groups.items(), key=lambda kv: repr(kv[0]))]


def _ends(axis, rows, spec):
    """The first and last values of a swept axis (in the spec's order) that finished runs
    reached."""
    reached = [v for v in spec.axes[axis] if any(r[axis] == v for r in rows)]
    return (reached[0], reached[-1]) if reached else (spec.axes[axis][0], spec.axes[axis][-1])


def _panels(spec, axis):
    """The panels of a figure against ``axis``: the combinations of the other swept axes
    (not model) as dicts, and the numeric axes cut down to their two ends when there would be
    more than MAX_PANELS."""
    others = [a for a in spec.swept() if a not in (axis, "model")]

    def combos(values):
        out = [{}]
        for a in others:
            out = [{**c, a: v} for c in out for v in values(a)]
        return [{"case": c, **k} for c in spec.cases for k in out] if len(spec.cases) > 1 \
            else out
    every = combos(lambda a: spec.axes[a])
    if len(every) <= MAX_PANELS:
        return every, []
    ends = [a for a in others if a in NUMERIC_AXES and len(spec.axes[a]) > 2]
    return combos(lambda a: [spec.axes[a][0], spec.axes[a][-1]] if a in ends
                  else spec.axes[a]), ends


def figure(metric, axis, rows, spec, models, label):
    """PNG bytes of ``metric`` against ``axis``: a panel per combination of the other swept
    axes (at most MAX_PANELS), a line per model, FEM P2 dashed where the rows carry it; the
    number of panels left out; and the axes drawn at their two ends only."""
    panels, ends = _panels(spec, axis)
    shown = panels[:MAX_PANELS]
    xs = spec.axes[axis]
    numeric = axis in NUMERIC_AXES
    x = np.array(xs, float) if numeric else np.arange(len(xs))
    cols = min(4, len(shown))
    nrows = math.ceil(len(shown) / cols)
    fig, axs = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.4 * nrows + 0.8),
                            squeeze=False)
    fem = ref_name(metric)
    for k, combo in enumerate(shown):
        ax = axs.flat[k]
        sel = [r for r in rows if all(r.get(a) == v for a, v in combo.items())]
        for i, m in enumerate(models):
            y = [_pick(sel, m, axis, v, metric) for v in xs]
            if any(v is not None for v in y):
                ax.plot(x, [np.nan if v is None else v for v in y], marker="o", ms=3,
                        lw=1.2, label=m, color=plt.get_cmap("tab10")(i % 10))
        y = [_pick(sel, None, axis, v, fem) for v in xs]
        if any(v is not None for v in y):
            ax.plot(x, [np.nan if v is None else v for v in y], "k--", lw=1.5, label="FEM P2")
        if metric in RATIOS:
            ax.axhline(1.0, color="0.5", lw=0.8)
        drawn = [v for line in ax.get_lines() for v in line.get_ydata() if np.isfinite(v)]
        if (metric in RATIOS or metric.endswith(ERRORS)) and drawn and min(drawn) > 0 \
                and max(drawn) >= LOG_SPAN * min(drawn):
            ax.set_yscale("log")     # a ratio or an error spanning decades
            for set_formatter in (ax.yaxis.set_major_formatter, ax.yaxis.set_minor_formatter):
                set_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        if not numeric:
            ax.set_xticks(x, [str(v) for v in xs])
        elif min(xs) > 0 and max(xs) / min(xs) >= 100:
            ax.set_xscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel(metric)
        ax.set_title(", ".join(str(v) if a not in NUMERIC_AXES else f"{a} {fmt(v)}"
                               for a, v in combo.items()) or spec.cases[0], fontsize=9)
        ax.grid(alpha=0.3)
    for ax in list(axs.flat)[len(shown):]:
        ax.set_visible(False)
    handles, labels = axs.flat[0].get_legend_handles_labels()
    for ax in list(axs.flat)[1:len(shown)]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=min(5, len(labels)), fontsize=8)
    fig.suptitle(f"{metric} against {label}", fontsize=11)
    fig.tight_layout(rect=(0, 0.06 + 0.02 * math.ceil(len(labels) / 5), 1, 0.97))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue(), len(panels) - len(shown), ends


def _pick(rows, model, axis, value, metric):
    """The metric of the row at ``axis`` = ``value`` (of ``model``; None: the first row
    there that has it)."""
    for r in rows:
        if r.get(axis) == value and (model is None or r["model"] == model):
            v = _value(r.get(metric))
            if v is not None or model is not None:
                return v
    return None


def write(spec, rows, out, registry, table_path):
    """Write ``report.md`` and its figures into ``out``; return the figure names. Raises
    MissingMetric (after writing) when a metric of the spec has no value in any run."""
    models = list(dict.fromkeys(r["model"] for r in rows))
    ok = [r for r in rows if r["status"] != "failed"]      # partial runs have statics
    doc = Document(spec.title)
    doc.p(f"Drawn by `pbcm sweep {spec.source}` from its {len(rows)} runs "
          f"({len(rows) - len(ok)} failed, "
          f"{sum(r['status'] == 'partial' for r in rows)} partial). Every parameter and metric of every run is in "
          f"[{table_path.name}]({table_path.name}); each run's metrics.json is kept beside it "
          "under runs/<run key>/ where the sweep ran (not committed).")
    doc.h(2, "What was run")
    items = [f"cases: {', '.join(spec.cases)} ({'quick' if spec.quick else 'full'} settings"
             f"{'; static problem only, no dynamics or modes' if spec.static_only else ''})"]
    items += [f"{a}: {', '.join(fmt(v) if a in NUMERIC_AXES else str(v) for v in vs)}"
              for a, vs in spec.axes.items()]
    items += [f"{k} = {fmt(v)} (fixed)" for k, v in spec.fixed.items()]
    doc.ul(items)
    missing = [m for m in spec.metrics if not any(_value(r.get(m)) is not None for r in ok)]
    shows, sections, names = [], [], []
    for metric in spec.metrics:
        if metric in missing:
            continue
        sentences, header, body = findings(metric, ok, spec, models)
        shows += sentences
        sections.append((metric, header, body))
    doc.h(2, "What it shows")
    doc.ul(shows or ["No run finished, so there is nothing to show."])
    case = registry[spec.cases[0]]
    for metric, header, body in sections:
        doc.h(2, metric)
        doc.table(header, body)
        for axis in [a for a in spec.swept() if a != "model"]:
            png, left, ends = figure(metric, axis, ok, spec, models, spec.label(axis, case))
            name = f"{PREFIX}{metric}_vs_{axis}.png"
            write_atomic(out / name, png)
            names.append(name)
            doc.img(name, f"{metric} against {spec.label(axis, case)}")
            if ends:
                doc.p("Panels at the two ends of " + ", ".join(
                    f"{a} ({fmt(spec.axes[a][0])} and {fmt(spec.axes[a][-1])})" for a in ends)
                    + " only; the table has every value.")
            if left:
                doc.p(f"{left} more panels (other combinations of the swept axes) are not "
                      f"drawn; the table has them.")
    if missing:
        doc.h(2, "Metrics without values")
        doc.p(f"No finished run has {', '.join(missing)}: check the names against the "
              f"columns of {table_path.name}.")
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        doc.h(2, "Failed runs")
        doc.p("failed: no static result; partial: the static result is plotted, a later "
              "phase (dynamics) failed.")
        doc.table(["case", "mesh", "bc", "model", "status", "point", "error"],
                  [[r["case"], r["mesh"], r["bc"], r["model"], r["status"],
                    ", ".join(f"{a} {fmt(r[a])}" for a in NUMERIC_AXES if a in spec.axes),
                    str(r["error"]).replace("|", "/")] for r in failed[:MAX_FAILURES]])
        if len(failed) > MAX_FAILURES:
            doc.p(f"... and {len(failed) - MAX_FAILURES} more (status failed or partial in the "
                  "table).")
    for old in out.glob(f"{PREFIX}*.png"):
        if old.name not in names:
            old.unlink()
    write_atomic(out / "report.md", doc.markdown() + "\n")
    if missing:
        raise MissingMetric(f"no finished run has metric(s) {', '.join(missing)} named in "
                            f"[report] metrics of {spec.source}; valid names are the columns "
                            f"of {table_path}")
    return names


__all__ = ["write", "findings", "populations", "kind", "target", "deviations", "figure",
           "MissingMetric"]
