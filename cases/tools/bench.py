"""`pbcm bench`: what each model costs, measured so that the ratios hold on a shared machine.

For every preset on cubes of about 1e2 ... 1e6 tetrahedra: the force evaluation (ns per
tetrahedron), the compiled RK4 step (microseconds), the calibration of fitted constants
(seconds) and the peak of the numpy memory building the model takes. Times are thread CPU
times, so another process on the machine slows a sample less than a wall clock would. The
presets are timed round-robin, one sample of each per round, and a ratio (to msm, to
fem-linear) is taken within each round, then the median over rounds: drift of the machine
between rounds cancels. Every cost sentence of the reports comes from these ratios.
With ``--device`` the covered presets' forces are also timed as Warp kernels on that device
(cases.tools.warp_forces), in a table of their own.
"""
import json
import time

import numpy as np

from model import PRESETS, build
from model.presets import IMPLICIT_STEP
from model.candidates import CANDIDATES

from ..framework import DEFAULT_MATERIAL
from ..library.common import bench_mesh
from ..reporting import figures
from ..running import stop
from .engines import ENGINES
from ..reporting.costs import FILE, REAL_TIME, best, cpu_seconds, kernel_sources, stale_words
from . import flops, realtime_bench, roofline
from .timers import DAMPING, SAMPLE_S, ImplicitTimed, Timed, own_stable_step
from ..reporting.document import Document, fmt

SIZES = (1e2, 3.2e2, 1e3, 1e4, 1e5, 1e6)   # 3.2e2: the paper's 125-node cube (five split)
STABLE_STEP_TETS = 2e5      # the own stable step is measured up to this size (an eigenvalue)
QUICK_SIZES = (1e2, 1e3)
BASELINES = ("msm", "fem-linear")
ENGINE_REFERENCE = "fem-neohookean"   # what the optional engines' forces are compared with
# the implicit presets' steps are timed up to this size: each solves a Newton system by
# conjugate gradients whose iterations grow with the mesh
IMPLICIT_TETS = 2e5
# what the kernels are held to (serial ns per tetrahedron per force evaluation from the bench's
# 1e5 cube up; every preset's two-thread speed-up there; its fraction of the attainable
# rate there; its RK4 step over four force evaluations from the 1e4 cube up)
KERNEL_TARGETS = {"pbcm-corner": 30.0, "pbcm-balanced": 30.0, "pbcm-variational": 40.0,
                  "pbcm-variational+normal": 60.0, "fem-linear": 10.0, "fem-corotated": 25.0,
                  "msm": 4.0}
TWO_THREAD_TARGET, ROOFLINE_TARGET, STEP_TARGET = 1.8, 0.5, 1.1


def implicit_row(name, mesh, samples, rounds):
    """The bench row of an implicit preset from its samples (seconds, Newton, CG) per round."""
    own = np.array(samples, dtype=float)
    dt = IMPLICIT_STEP[name]
    step = float(np.median(own[:, 0]))
    return {"model": name, "tets": mesh.n_tets, "nodes": mesh.n_nodes,
            "us_per_step": step * 1e6, "dt_us": dt * 1e6,
            "cpu_s_per_simulated_s": step / dt,
            "newton_per_step": float(np.median(own[:, 1])),
            "cg_per_newton": float(np.median(own[:, 2] / np.maximum(own[:, 1], 1))),
            "rounds": rounds}


class _EngineTimed:
    """An optional engine's force evaluation on the mesh of a built fem-neohookean model."""

    def __init__(self, engine, pm, x):
        self.call = engine.force_evaluation(pm, x)
        self.call()                                   # compile outside the timings
        t0 = time.thread_time()
        self.call()
        self.reps = max(1, int(SAMPLE_S / max(time.thread_time() - t0, 1e-7)))

    def sample(self):
        """Seconds per force evaluation, thread CPU time (Warp runs CPU kernels on the
        calling thread)."""
        t0 = time.thread_time_ns()
        for _ in range(self.reps):
            self.call()
        return (time.thread_time_ns() - t0) * 1e-9 / self.reps


def _engine_timers(mesh, timed, progress):
    """The installed engines' timers at this size, and a status line per engine."""
    timers, status = {}, {}
    for name, engine in ENGINES.items():
        if not engine.installed():
            status[name] = "not installed"
            continue
        if engine.max_tets is not None and mesh.n_tets > engine.max_tets:
            status[name] = (f"not timed above {engine.max_tets} tetrahedra (building its model "
                            "loops in Python)")
            continue
        try:
            timers[name] = _EngineTimed(engine, timed[ENGINE_REFERENCE].pm, timed[
                ENGINE_REFERENCE].x)
            status[name] = f"timed: {engine.law}"
        except Exception as exc:    # an optional engine must not stop the benchmark
            status[name] = f"installed, failed: {type(exc).__name__}: {exc}"
            progress(f"bench: {name} not timed: {exc}")
    return timers, status


def _device_rows(timed, models, rows, device, progress):
    """The Warp kernels of the covered models among ``models`` timed on ``device`` in float32
    and float64 (cases.tools.warp_forces), with their ratio to the numba row of the same model
    and size."""
    from . import warp_forces
    out = []
    for name in models:
        pm = timed[name].pm
        if not warp_forces.covered(pm):
            continue
        cpu = next(r for r in rows if r["model"] == name and r["tets"] == pm.mesh.n_tets)
        for r in warp_forces.time_model(pm, device, min_s=10 * SAMPLE_S):
            r["force_vs_numba"] = r["ns_per_tet"] / cpu["ns_per_tet"]
            out.append(r)
            progress(f"bench: {name} on {r['device']} {r['dtype']}: "
                     f"{fmt(r['ns_per_tet'])} ns/tet")
    return out


def run(sizes=SIZES, models=None, rounds=7, progress=print, with_engines=True, device=None,
        family=None):
    """Measure every model at every size; returns the bench document (plain data). The
    baselines (msm, fem-linear) are always timed, for the ratios; the other engines only with
    ``with_engines``. With a Warp ``device`` (``cpu``, ``cuda``, ``cuda:1`` ...) the Warp
    kernels of the covered models are timed there too (``device_rows``). The implicit
    presets' steps (every one without ``models``, else those it names) are timed in the same
    rounds up to IMPLICIT_TETS (``implicit_rows``). With ``family`` ("full" or "quick") the
    real-time family is timed too (cases.tools.realtime_bench, ``realtime_rows``)."""
    if not models:      # every preset and the normal-stress candidates of `pbcm run extensions`
        models = [*PRESETS, *CANDIDATES, *IMPLICIT_STEP]
    implicit = [m for m in models if m in IMPLICIT_STEP]
    models = [m for m in models if m not in IMPLICIT_STEP]
    timed_models = models + [b for b in BASELINES if b not in models]
    if with_engines and any(e.installed() for e in ENGINES.values()) \
            and ENGINE_REFERENCE not in timed_models:
        timed_models.append(ENGINE_REFERENCE)
    mat = DEFAULT_MATERIAL
    for name in timed_models:   # load every module once, so that memory counts the model only
        build(name, bench_mesh(1), mat)
    rows, engine_rows, engines, device_rows, implicit_rows = [], [], {}, [], []
    # the roofline: this machine's peaks in this run, each model's counted operations
    peak = roofline.peaks()
    flop_counts = flops.counts(models)
    for target in sizes:
        mesh = bench_mesh(target)
        progress(f"bench: {mesh.n_tets} tetrahedra, {len(timed_models)} models")
        timed = {name: Timed(name, mesh, mat) for name in timed_models}
        timers, status = _engine_timers(mesh, timed, progress) if with_engines \
            else ({}, {})
        for name, line in status.items():
            if line not in engines.setdefault(name, []):
                engines[name].append(line)
        stepped = {name: ImplicitTimed(name, mesh, mat) for name in implicit
                   if mesh.n_tets <= IMPLICIT_TETS}
        samples = {name: [] for name in timed}
        engine_samples = {name: [] for name in timers}
        implicit_samples = {name: [] for name in stepped}
        for _ in range(rounds):       # round-robin: one sample of every model per round
            stop.checkpoint()
            for name, t in timed.items():
                samples[name].append(t.sample())
            for name, t in timers.items():
                engine_samples[name].append(t.sample())
            for name, t in stepped.items():
                implicit_samples[name].append(t.sample())
        implicit_rows += [implicit_row(name, mesh, got, rounds)
                          for name, got in implicit_samples.items()]
        for name, own in engine_samples.items():
            own, ref = np.array(own), np.array(samples[ENGINE_REFERENCE])[:, 0]
            engine_rows.append({"engine": name, "tets": mesh.n_tets,
                                "ns_per_tet": float(np.median(own) / mesh.n_tets * 1e9),
                                f"force_vs_{ENGINE_REFERENCE}": float(np.median(own / ref)),
                                "law": ENGINES[name].law, "rounds": rounds})
        for name in models:
            own = np.array(samples[name])
            row = {"model": name, "tets": mesh.n_tets, "nodes": mesh.n_nodes,
                   "ns_per_tet": float(np.median(own[:, 0]) / mesh.n_tets * 1e9),
                   "ns_per_tet_range": [float(own[:, 0].min() / mesh.n_tets * 1e9),
                                        float(own[:, 0].max() / mesh.n_tets * 1e9)],
                   "us_per_step": float(np.median(own[:, 1]) * 1e6),
                   "us_per_step_range": [float(own[:, 1].min() * 1e6),
                                         float(own[:, 1].max() * 1e6)],
                   "step_over_4_forces": float(np.median(own[:, 1] / (4 * own[:, 0]))),
                   "step_over_4_forces_range": [float(np.min(own[:, 1] / (4 * own[:, 0]))),
                                                float(np.max(own[:, 1] / (4 * own[:, 0])))],
                   "calibration_s": timed[name].calibration,
                   "two_thread_speedup": (float(np.median(own[:, 2]))
                                          if timed[name].kernels_2 is not None else None),
                   "two_thread_speedup_range": ([float(own[:, 2].min()), float(own[:, 2].max())]
                                                if timed[name].kernels_2 is not None
                                                else None),
                   "memory_mb": timed[name].memory / 1e6, "rounds": rounds,
                   "kernels": kernel_sources(timed[name].pm),
                   "flops_per_tet": flop_counts.get(name),
                   "bytes_per_tet": roofline.bytes_per_tet(timed[name].pm)}
            row.update(zip(("gflop_s", "attainable_gflop_s", "roofline_fraction"),
                           roofline.fraction(row["flops_per_tet"], row["bytes_per_tet"],
                                             row["ns_per_tet"], peak)))
            if mesh.n_tets <= STABLE_STEP_TETS:
                dt = own_stable_step(timed[name].pm)
                row.update(stable_dt_us=dt * 1e6,
                           cpu_s_per_simulated_s=row["us_per_step"] * 1e-6 / dt,
                           cpu_s_per_simulated_s_range=[u * 1e-6 / dt
                                                        for u in row["us_per_step_range"]])
            for base in BASELINES:
                ref = np.array(samples[base])
                row[f"force_vs_{base}"] = float(np.median(own[:, 0] / ref[:, 0]))
                row[f"step_vs_{base}"] = float(np.median(own[:, 1] / ref[:, 1]))
                # the rounds' spread of the ratio: the uncertainty every cost ratio carries
                row[f"step_vs_{base}_range"] = [float(np.min(own[:, 1] / ref[:, 1])),
                                                float(np.max(own[:, 1] / ref[:, 1]))]
            rows.append(row)
        if device is not None:
            device_rows += _device_rows(timed, models, rows, device, progress)
        del timed, timers
    data = {"machine": machine(), "peaks": peak, "sizes": [int(s) for s in sizes], "rows": rows,
            "engines": {k: "; ".join(v) for k, v in engines.items()},
            "engine_rows": engine_rows, "implicit_rows": implicit_rows}
    if device is not None:
        from . import warp_forces
        data.update(device=warp_forces.device_name(device), device_rows=device_rows)
    if family is not None:
        data.update(realtime_rows=realtime_bench.run(quick=family == "quick",
                                                     progress=progress),
                    realtime_machine=data["machine"])
    return data


def merge(old, new):
    """``old`` with the model rows of ``new`` added (replacing rows of the same model and size).
    Each row's ratios were taken in its own process against the baselines timed with it, so
    rows of separate runs stay comparable; the baselines' own rows, and the engines, stay
    ``old``'s, so that costs computed from them elsewhere do not move."""
    def merged(key):
        got = new.get(key, [])
        keys = {(r["model"], r["tets"]) for r in got}
        return [r for r in old.get(key, []) if (r["model"], r["tets"]) not in keys] + got
    sizes = sorted(set(old["sizes"]) | set(new["sizes"]))
    return {**old, "sizes": sizes, "rows": merged("rows"),
            "implicit_rows": merged("implicit_rows")}


def machine():
    """The processor as /proc/cpuinfo names it, with what a virtual machine's bare name leaves
    out (family and model, clock, the widest SIMD), its cores and the Python version."""
    import os
    import platform
    cpu = platform.processor() or platform.machine()
    try:
        info = {}
        for line in open("/proc/cpuinfo"):
            k, _, v = line.partition(":")
            info.setdefault(k.strip(), v.strip())
        cpu = cpu_name(info) or cpu
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version()}


def cpu_name(info):
    """'AMD EPYC (family 26 model 2, 2.6 GHz, AVX-512)' from /proc/cpuinfo's first entries
    ``info``; None without a model name."""
    name = info.get("model name")
    if not name:
        return None
    flags = set(info.get("flags", "").split())
    simd = next((w for f, w in (("avx512f", "AVX-512"), ("avx2", "AVX2"), ("sse2", "SSE2"))
                 if f in flags), None)
    said = [f"family {info['cpu family']} model {info['model']}"
            if "cpu family" in info and "model" in info else None,
            f"{float(info['cpu MHz']) / 1000:.1f} GHz" if info.get("cpu MHz") else None, simd]
    said = [x for x in said if x]
    return f"{name} ({', '.join(said)})" if said else name


def _ranged(row, key, digits=2):
    """'median [smallest-largest over the rounds]' of a ratio (the median alone where the
    bench predates the range), the range to ``digits`` significant figures."""
    rng = row.get(f"{key}_range")
    return fmt(row[key]) + (f" [{fmt(rng[0], digits)}-{fmt(rng[1], digits)}]" if rng else "")


def write(data, out):
    """bench.json, bench.md (+ html) and step_time.png into the folder ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / FILE).write_text(json.dumps(data, indent=1) + "\n")
    rows = data["rows"]
    models = list(dict.fromkeys(r["model"] for r in rows))
    figures.loglog(out / "step_time.png",
                   [(m, [r["tets"] for r in rows if r["model"] == m],
                     [r["us_per_step"] for r in rows if r["model"] == m]) for m in models],
                   "tetrahedra", "one RK4 step [us] (thread CPU time)",
                   "Step time against mesh size (the paper's Figure 2)")
    doc = Document("pbcm bench")
    m = data["machine"]
    _targets_table(doc, data)     # the answer first: the presets against their targets
    doc.p(f"Measured on {m['cpu']} ({m['cores']} cores), Python {m['python']}, serial kernels. "
          f"Times are medians over {rows[0]['rounds']} rounds of thread CPU time; ratios are "
          "the medians of per-round ratios (models timed round-robin), so drift between "
          "rounds cancels from each ratio; [smallest-largest] over the rounds beside them, "
          "what remains. The two-thread speed-up (`build(..., threads=2)`, forces equal bit for bit "
          "to serial) is the median ratio of wall-clock times of the serial and the threaded "
          "force evaluation run back to back; '-' where a model has no threaded term."
          + (f" {said}" if (said := stale_words(data)) else ""))
    _largest_size(doc, data)
    doc.table(["model", "tets", "ns/tet (force)", "us/step", "step / 4 forces",
               "step vs msm", "step vs fem-linear", "calibration [s]", "memory [MB]",
               "2-thread force speed-up"],
              [[r["model"], r["tets"], fmt(r["ns_per_tet"]), fmt(r["us_per_step"]),
                fmt(r["step_over_4_forces"]), _ranged(r, "step_vs_msm"),
                _ranged(r, "step_vs_fem-linear"), fmt(r["calibration_s"], 2),
                fmt(r["memory_mb"], 3),
                "-" if r.get("two_thread_speedup") is None else fmt(r["two_thread_speedup"])]
               for r in rows])
    if data.get("peaks"):
        _roofline_table(doc, data)
    per_second = per_simulated_second(data)
    if per_second:
        doc.p("One simulated second (the bench's push, 1 % of the side in one second, base "
              f"held, mass damping {DAMPING:g} 1/s): CPU seconds each model takes on this "
              f"machine ({m['cpu']}, one core), the explicit models at their own largest "
              "stable RK4 step (2 sqrt 2 over the largest frequency at rest, measured up to "
              f"{STABLE_STEP_TETS:g} tetrahedra), the implicit ones (backward Euler, Newton "
              "with conjugate gradients) at their own step, with the Newton iterations per "
              f"step and CG iterations per Newton system; at most {REAL_TIME:g}: real time.")
        doc.table(["model", "tets", "dt [us]", "us per step", "CPU s per simulated s",
                   "real time", "Newton / step", "CG / Newton"], per_second)
        fastest = real_time_reach(data)
        if fastest:
            doc.p("The largest of these sizes at which each model runs in real time on this "
                  "machine (serial, CPU time, the bench's 1 % push): " + "; ".join(
                      f"{m_} {t} tetrahedra" if t else f"{m_} none of the sizes measured"
                      for m_, t in fastest.items()) + ". The real-time family below steps "
                  "the size finer, under the paper's push, wall clock, serial or two "
                  "threads: `pbcm run realtime` reads it.")
    if data.get("realtime_rows"):
        _family_table(doc, data)
    doc.p("Optional engines' force evaluations, timed on the same meshes in the same rounds "
          "as the force evaluations above (`pip install 'pbcm[engines]'`; as that run found "
          "them, whatever the real-time family, timed apart, found), with the ratio of their "
          f"force evaluation to pbcm's {ENGINE_REFERENCE} kernel taken in-round:")
    doc.ul([f"{name}: {state}" for name, state in sorted(data["engines"].items())])
    if data.get("engine_rows"):
        doc.table(["engine", "tets", "ns/tet (force)", f"force vs pbcm {ENGINE_REFERENCE}"],
                  [[r["engine"], r["tets"], fmt(r["ns_per_tet"]),
                    fmt(r[f"force_vs_{ENGINE_REFERENCE}"])] for r in data["engine_rows"]])
    if data.get("device_rows"):
        doc.p(f"Warp kernels on device {data['device']} (`pbcm bench --device`): each covered "
              "model's internal forces (the sum of its terms) as Warp kernels, wall-clock time "
              "per force evaluation after a warm-up launch, the device synchronised around "
              "the timed launches; 'vs numba' is that time over the model's serial numba "
              "force evaluation above (thread CPU time), and the last column the largest "
              "force difference from pbcm's numba forces at a perturbed state, relative to "
              "the largest force.")
        doc.table(["model", "tets", "device", "dtype", "ns/tet (force)", "vs numba",
                   "max rel. diff. from numba"],
                  [[r["model"], r["tets"], r["device_name"], r["dtype"], fmt(r["ns_per_tet"]),
                    fmt(r["force_vs_numba"]), f"{r['max_rel_diff_vs_numba']:.1e}"]
                   for r in data["device_rows"]])
    doc.img("step_time.png", "RK4 step time against tetrahedra, every model")
    doc.write(out, stem="bench")


def verdict(value, spread, target, at_most, band=0.0):
    """'met', 'missed' or 'not resolved ...' for ``value`` against ``target`` (``at_most``:
    the value must not exceed it, else not fall below it): not resolved where the rounds'
    range ``spread`` holds the target, or, without a range, where the target lies within the
    relative ``band`` of the value."""
    if spread:
        lo, hi = spread
        why = "its range holds the target"
    else:
        lo, hi = value / (1.0 + band), value * (1.0 + band)
        why = "its range not recorded: within the bench's spread of the target"
    if lo <= target <= hi and lo != hi:
        return f"not resolved ({why})"
    return "met" if (value <= target if at_most else value >= target) else "missed"


def spread_band(data, tets):
    """The widest relative [smallest-largest] of the in-round step ratios at ``tets``: the
    spread of this bench's rounds there, which a value recorded without its own range is
    read against."""
    widths = [r[key][1] / r[key][0] - 1.0 for r in data["rows"] if r["tets"] == tets
              for key in ("step_vs_msm_range", "step_vs_fem-linear_range")
              if r.get(key) and r[key][0] > 0]
    return max(widths, default=0.0)


QUANTITIES = ["serial ns/tet", "two-thread speed-up", "fraction of attainable",
              "step / 4 forces"]


def target_rows(data):
    """[quantity, target, model, tets, measured [range], verdict] for every preset against
    the kernel targets, at every bench size they apply to."""
    rows = data["rows"]
    big, mid = bench_mesh(1e5).n_tets, bench_mesh(1e4).n_tets
    out = []

    def add(what, target, at_most, r, key, spread_key, digits=4):
        value, spread = r.get(key), r.get(spread_key) if spread_key else None
        if value is None:
            return
        if key == "roofline_fraction" and r.get("ns_per_tet_range"):
            # the peaks are measured once: the fraction moves as 1 / its ns/tet over the rounds
            lo, hi = r["ns_per_tet_range"]
            spread = [value * r["ns_per_tet"] / hi, value * r["ns_per_tet"] / lo]
        # enough figures that a range ending near the target shows on which side it ends
        shown = fmt(value, digits) + (f" [{fmt(spread[0], digits)}-{fmt(spread[1], digits)}]"
                                      if spread else " [not recorded]")
        if key == "step_over_4_forces" and min([value, *(spread or [])]) < 1.0:
            said = ("not resolved (the step ran faster than four standalone evaluations in "
                    "some round: the denominator is not the step's own)")
        else:
            said = verdict(value, spread, target, at_most,
                           0.0 if key == "roofline_fraction" else spread_band(data, r["tets"]))
        out.append([what, ("<= " if at_most else ">= ") + fmt(target), r["model"], r["tets"],
                    shown, said])

    for r in rows:
        if r["model"] not in PRESETS:
            continue
        if r["tets"] >= big and r["model"] in KERNEL_TARGETS:
            add("serial ns/tet", KERNEL_TARGETS[r["model"]], True, r, "ns_per_tet",
                "ns_per_tet_range")
        if r["tets"] >= big:
            add("two-thread speed-up", TWO_THREAD_TARGET, False, r, "two_thread_speedup",
                "two_thread_speedup_range")
            add("fraction of attainable", ROOFLINE_TARGET, False, r, "roofline_fraction",
                None, 3)
        if r["tets"] >= mid:
            add("step / 4 forces", STEP_TARGET, True, r, "step_over_4_forces",
                "step_over_4_forces_range")
    return sorted(out, key=lambda row: (QUANTITIES.index(row[0]), row[3]))


def _short(said):
    return "n.r." if said.startswith("not resolved") else said


def _targets_table(doc, data):
    """The presets against the kernel targets: per preset and quantity its verdicts, then
    every row with its criterion."""
    got = target_rows(data)
    if not got:
        return
    m = data["machine"]
    sizes = sorted({r[3] for r in got})
    counts = {q: {v: sum(1 for r in got if r[0] == q and r[-1].startswith(v))
                  for v in ("met", "missed", "not resolved")} for q in QUANTITIES}
    clean = [p for p in PRESETS if all(r[-1] == "met" for r in got if r[2] == p)
             and any(r[2] == p for r in got)]
    met_all = ("no preset meets every target" if not clean
               else "every target met by " + ", ".join(clean))
    doc.p(f"Against the kernel targets on this machine ({m['cpu']}, {m['cores']} cores): "
          f"{met_all}. Verdicts, one per preset and size: "
          + "; ".join(f"{q}: {c['met']} met, {c['missed']} missed, {c['not resolved']} not "
                      "resolved" for q, c in counts.items()) + ". The targets: serial ns per "
          "tetrahedron per force evaluation ("
          + ", ".join(f"{k} {fmt(v)}" for k, v in KERNEL_TARGETS.items())
          + f") and, for every preset, a two-thread speed-up of at least "
          f"{fmt(TWO_THREAD_TARGET)} and at least {fmt(ROOFLINE_TARGET)} of the attainable "
          f"rate (the roofline below) from the bench's 1e5 cube ({bench_mesh(1e5).n_tets} "
          f"tetrahedra) up; an RK4 step of at most {fmt(STEP_TARGET)} times four force "
          f"evaluations from its 1e4 cube ({bench_mesh(1e4).n_tets}) up. The presets are held "
          "to them; the normal-stress candidates of `pbcm run extensions` are not. A verdict "
          "is not resolved where the rounds' [smallest-largest] holds the target; a value "
          "whose range this bench did not record is read against the widest relative range "
          "of the in-round step ratios at its size (" + ", ".join(
              f"{t}: {spread_band(data, t):.0%}" for t in sizes) + "); the fraction of "
          "attainable's range is its ns/tet's over the rounds (the peaks are measured once). "
          "A step ratio below 1 in any round (the step's own four force evaluations ran "
          "faster than the standalone one timed for ns/tet; the two are compiled apart, its "
          "cause not measured here) is not resolved. In the first table '-' is a quantity "
          "with no target for that preset.")
    doc.table(["preset"] + QUANTITIES,
              [[p] + [", ".join(f"{r[3]}: {_short(r[-1])}" for r in got
                                if r[2] == p and r[0] == q) or "-" for q in QUANTITIES]
               for p in PRESETS if any(r[2] == p for r in got)])
    doc.table(["quantity", "target", "model", "tets", "measured [range]", "verdict"], got)


def _roofline_table(doc, data):
    """Each row's roofline: its counted operations and compulsory bytes per tetrahedron, its
    rate, the rate attainable at its intensity on this machine and the fraction it reaches."""
    pk, m = data["peaks"], data["machine"]
    doc.p(f"The roofline on this machine ({m['cpu']}, one core), its peaks measured in the same "
          f"run: a STREAM-like copy at {fmt(pk['copy_gb_s'])} GB/s and a fused multiply-add loop "
          f"at {fmt(pk['fma_gflop_s'])} GFLOP/s. Operations per tetrahedron are counted (each "
          "kernel run uncompiled on counting numbers: an FMA is two), bytes are the compulsory "
          "traffic (every array the kernels take, once; positions read, forces read and "
          "written); the attainable rate is min(FMA peak, bandwidth x operations / byte), and "
          "the fraction the kernel's serial force evaluation reaches of it; '-' where a "
          "kernel's operations could not be counted.")
    doc.table(["model", "tets", "ns/tet (force)", "flops/tet", "bytes/tet", "GFLOP/s",
               "attainable GFLOP/s", "fraction of attainable"],
              [[r["model"], r["tets"], fmt(r["ns_per_tet"]),
                "-" if r.get("flops_per_tet") is None else fmt(r["flops_per_tet"], 4),
                fmt(r.get("bytes_per_tet")),
                "-" if r.get("gflop_s") is None else fmt(r["gflop_s"]),
                "-" if r.get("attainable_gflop_s") is None else fmt(r["attainable_gflop_s"]),
                "-" if r.get("roofline_fraction") is None else fmt(r["roofline_fraction"], 2)]
               for r in data["rows"]])


def _family_table(doc, data):
    """The real-time family: each model's wall-clock seconds per simulated second at each
    size, its faster mode (serial, two threads, implicit), the rounds' range beside it."""
    rows = data["realtime_rows"]
    models = list(dict.fromkeys(r["model"] for r in rows))
    by = {(r["model"], r["tets"]): r for r in rows}
    m = data.get("realtime_machine") or data["machine"]

    def cell(r):
        cost, mode = best(r)
        if cost is None:
            return "not timed"
        two = mode == "two threads"
        lo, hi = r["two_thread_range" if two else "wall_range"]
        return f"{fmt(cost)} [{fmt(lo)}-{fmt(hi)}]" + (" (2 threads)" if two else "")
    doc.p(f"The real-time family (read by `pbcm run realtime`): wall-clock seconds per "
          f"simulated second on this machine ({m['cpu']}, {m['cores']} cores) under the "
          "paper's push (1.7 mm on the 32 mm cube at 1.7 mm/s, clamped base, mass damping "
          f"{DAMPING:g} 1/s), the median of {rows[0].get('rounds', '?')} rounds taken "
          "round-robin [smallest-largest], each model in its faster mode (serial or two "
          "threads, named where two threads are faster): the explicit models at their own "
          "largest stable RK4 step, the implicit presets at their own step from the push's "
          "start, Newton's solvers (where the engines extra is installed) at their own step "
          "through pbcm's adapter (model.simulators.newton), single precision on Warp's CPU "
          f"backend. A model is not timed above two sizes in a row over {REAL_TIME:g} (real "
          "time): its cost grows with the mesh.")
    doc.table(["tets", *models], [[t, *(cell(by[(mo, t)]) for mo in models)]
                                  for t in sorted({r["tets"] for r in rows})])


def per_simulated_second(data):
    """Table rows of every model's CPU time per simulated second, where measured."""
    out = []
    for r in data["rows"]:
        if r.get("cpu_s_per_simulated_s") is not None:
            c = r["cpu_s_per_simulated_s"]
            out.append([r["model"], r["tets"], fmt(r["stable_dt_us"]), fmt(r["us_per_step"]),
                        cpu_seconds(r), "yes" if c <= REAL_TIME else "no", "-", "-"])
    for r in data.get("implicit_rows", []):
        c = r["cpu_s_per_simulated_s"]
        out.append([r["model"], r["tets"], fmt(r["dt_us"]), fmt(r["us_per_step"]), fmt(c),
                    "yes" if c <= REAL_TIME else "no", fmt(r["newton_per_step"], 2),
                    fmt(r["cg_per_newton"], 3)])
    return out


def real_time_reach(data):
    """{model: the largest tetrahedron count measured at which it runs in real time, or
    None}, over the sizes where its cost per simulated second was measured."""
    reach = {}
    for r in list(data["rows"]) + list(data.get("implicit_rows", [])):
        c = r.get("cpu_s_per_simulated_s")
        if c is None:
            continue
        best = reach.setdefault(r["model"], None)
        if c <= REAL_TIME and (best is None or r["tets"] > best):
            reach[r["model"]] = r["tets"]
    return reach


def largest_size(data):
    """(tetrahedra, rows): the largest size measured and, per model there, its ns/tet and its
    step against each baseline, each with its [smallest-largest] over the rounds."""
    rows = data["rows"]
    top = max(r["tets"] for r in rows)
    return top, [[r["model"], _ranged(r, "ns_per_tet", 3), _ranged(r, "step_vs_msm"),
                  _ranged(r, "step_vs_fem-linear")] for r in rows if r["tets"] == top]


def _largest_size(doc, data):
    """The largest size's table, with what an 'x msm' ratio is relative to: msm's step, itself
    its step over four force evaluations times msm's forces."""
    top, table = largest_size(data)
    base = next((r for r in data["rows"] if r["tets"] == top and r["model"] == "msm"), None)
    doc.p(f"At {top} tetrahedra, the largest cube measured: each model's force evaluation and "
          "its RK4 step against msm's and fem-linear's [smallest-largest over the rounds]"
          + (f"; msm's own step costs {fmt(base['step_over_4_forces'])} times its four force "
             "evaluations, so a step 'x msm' reads lower than the ratio of forces by about "
             "that factor for a model whose step costs four of its force evaluations"
             if base and base.get("step_over_4_forces") else "") + ".")
    doc.table(["model", "ns/tet (force)", "step x msm", "step x fem-linear"], table)
