"""`pbcm bench`: what it measures and how its ratios are taken. No test here asserts
a wall-clock time: timings are the benchmark's output, not a pass condition."""
import json

import numba
import pytest
import numpy as np

from cases.reporting import costs
from cases.tools import bench
from cases.cli import main


def test_bench_writes_table_figure_and_in_round_ratios(tmp_path):
    """`pbcm bench` writes bench.json, bench.md and the step-time figure on the five cubes nearest
    the sizes asked; every row has finite positive timings, memory and in-round ratios (a model
    against itself exactly 1, each median inside its rounds' range), its roofline (counted
    operations, compulsory bytes, the fraction of the rate attainable at the peaks measured in
    the same run), calibration time only for the calibrated model, a two-thread speed-up for every preset with two numba threads, and
    each optional engine timed or reported as not installed. A rerun replaces the folder's
    rows and keeps the folders inside it that another command wrote."""
    out = tmp_path / "bench"
    assert main(["bench", "--sizes", "100", "700", "--rounds", "3", "--models", "msm",
                 "pbcm-variational", "fem-linear", "--out", str(out)]) == 0
    for f in ("bench.json", "bench.md", "step_time.png"):
        assert (out / f).stat().st_size > 0, f
    data = json.loads((out / "bench.json").read_text())
    rows = {(r["model"], r["tets"]): r for r in data["rows"]}
    assert {t for _, t in rows} == {135, 625}          # the 'five' cubes closest to the sizes
    for (model, _), r in rows.items():
        for k in ("ns_per_tet", "us_per_step", "step_over_4_forces", "step_vs_msm",
                  "force_vs_fem-linear", "memory_mb"):
            assert np.isfinite(r[k]) and r[k] > 0, (model, k)
        # a model against itself within one round is exactly 1: the ratios are in-round
        if model in ("msm", "fem-linear"):
            assert r[f"step_vs_{model}"] == 1.0 and r[f"force_vs_{model}"] == 1.0
        # the rounds' range of a ratio brackets its median
        lo, hi = r["step_vs_fem-linear_range"]
        assert lo <= r["step_vs_fem-linear"] <= hi
        lo, hi = r["us_per_step_range"]
        assert lo <= r["us_per_step"] <= hi
        if r.get("cpu_s_per_simulated_s") is not None:
            lo, hi = r["cpu_s_per_simulated_s_range"]
            assert lo <= r["cpu_s_per_simulated_s"] <= hi
        # the kernels it was timed on: this checkout's, so nothing is said stale
        assert r["kernels"] == costs.checkout_sources(model)
    assert costs.stale(data) == ([], False) and costs.stale_words(data) == ""
    assert rows[("pbcm-variational", 625)]["calibration_s"] > 0
    # the roofline: the peaks of this run, each row's counted operations (fem-linear's 189,
    # tests/test_roofline.py), compulsory bytes and its fraction of the attainable rate
    assert data["peaks"]["copy_gb_s"] > 0 and data["peaks"]["fma_gflop_s"] > 0
    assert rows[("fem-linear", 625)]["flops_per_tet"] == 189.0
    for r in rows.values():
        assert r["flops_per_tet"] > 0 and r["bytes_per_tet"] > 0
        assert r["gflop_s"] == pytest.approx(r["flops_per_tet"] / r["ns_per_tet"])
        assert 0 < r["roofline_fraction"] and np.isfinite(r["roofline_fraction"])
    assert rows[("msm", 625)]["calibration_s"] == 0
    # every preset has a two-thread mode; where numba has two threads its speed-up is a
    # measured positive number
    for model in ("msm", "pbcm-variational"):
        two = rows[(model, 625)]["two_thread_speedup"]
        assert (two is None) == (numba.config.NUMBA_NUM_THREADS < 2)
        assert two is None or (np.isfinite(two) and two > 0)
    # optional engines: "not installed", or timed beside fem-neohookean in the same rounds
    from cases.tools.engines import ENGINES
    assert set(data["engines"]) == {"newton", "warp-lang"}
    md = (out / "bench.md").read_text()
    for name, engine in ENGINES.items():
        timed = [r for r in data["engine_rows"] if r["engine"] == name]
        if engine.installed():
            assert data["engines"][name].startswith("timed") and len(timed) == 2
            assert all(r["force_vs_fem-neohookean"] > 0 and r["ns_per_tet"] > 0 for r in timed)
            assert f"| {name} | 625 |" in md
        else:
            assert data["engines"][name] == "not installed" and not timed
            assert f"{name}: not installed" in md
    assert "pbcm-variational" in md and "step vs msm" in md
    # a second run replaces its own folder (bench.json marks it as pbcm's), and keeps the
    # folders inside it that another command wrote (the Warp device timings)
    (out / "cuda").mkdir()
    (out / "cuda" / "warp_forces.md").write_text("device timings")
    assert main(["bench", "--sizes", "100", "--rounds", "1", "--models", "msm",
                 "--out", str(out)]) == 0
    assert {r["tets"] for r in json.loads((out / "bench.json").read_text())["rows"]} == {135}
    assert (out / "cuda" / "warp_forces.md").read_text() == "device timings"


def test_merge_adds_a_composed_model_and_keeps_every_other_row(tmp_path):
    """`pbcm bench --merge`: the new model's rows, with its in-process ratios, join the rows
    already there, which stay as they were (the baselines included)."""
    out = tmp_path / "b"
    assert main(["bench", "--sizes", "100", "--rounds", "1", "--models", "msm", "fem-linear",
                 "--out", str(out)]) == 0
    before = json.loads((out / "bench.json").read_text())
    tet = "pbcm-variational + normal_tet(c=auto)"
    assert main(["bench", "--merge", "--sizes", "100", "--rounds", "2", "--models", tet,
                 "msm", "--out", str(out)]) == 0
    after = json.loads((out / "bench.json").read_text())
    assert after["rows"][:len(before["rows"])] == before["rows"]
    new = after["rows"][len(before["rows"]):]
    assert [r["model"] for r in new] == ["shear(reading=variational, c=auto) + volume + "
                                         "normal_tet(c=auto)"]
    assert new[0]["step_vs_fem-linear"] > 1 and new[0]["rounds"] == 2
    assert after["engines"] == before["engines"]
    assert main(["bench", "--merge", "--models", "msm", "--out", str(tmp_path / "none")]) == 2


def test_cost_rows_come_from_the_nearest_bench_size():
    """A case's cost table comes from the bench size nearest its own on a log scale (1080 tetrahedra
    for 500) and gives the step ratios to msm and fem-linear, the own stable step and the CPU
    seconds per simulated second, also over msm's as every cost ratio is taken: the in-round
    step ratio (with its range over the rounds) times the stable steps' ratio, never the
    ratio of two medians; with no bench it says to run `pbcm bench`."""
    def row(m, t, r):
        own = r if m == "a" else 1.0
        return {"model": m, "tets": t, "rounds": 5, "step_vs_msm": own,
                "step_vs_msm_range": [own * 0.9, own * 1.1], "step_vs_fem-linear": own / 2,
                "cpu_s_per_simulated_s": 2 * own, "stable_dt_us": 100.0 if m == "a" else 200.0}
    data = {"rows": [row(m, t, r) for t, r in ((135, 3.0), (1080, 7.0), (10985, 9.0))
                     for m in ("a", "msm")]}
    (table,) = costs.cost_items(data, ["a"], 500)
    assert "1080 tetrahedra" in table.title
    # per simulated second over msm's: a's step 7 [6.3-7.7] x msm's, its stable step half of
    # msm's, so 14 [12.6-15.4] (the medians' ratio, 14 s over 2 s, would say 7)
    assert table.rows == [["a", "7 [6.3-7.7]", "3.5", "100", "14", "14 [12.6-15.4]"]]
    assert "run `pbcm bench`" in costs.cost_items(None, ["a"], 500)[0]


def test_cpu_seconds_carry_the_rounds_range_where_recorded():
    """A CPU time per simulated second is said as its median round with the rounds'
    [smallest-largest] where the bench recorded them, the median alone where it did not, and
    'n/a' where there is none."""
    row = {"cpu_s_per_simulated_s": 1.59, "cpu_s_per_simulated_s_range": [1.52, 1.71]}
    assert costs.cpu_seconds(row) == "1.59 [1.52-1.71]"
    assert costs.cpu_seconds({"cpu_s_per_simulated_s": 1.59}) == "1.59"
    assert costs.cpu_seconds({}) == "n/a"


def test_bench_mesh_is_the_closest_five_cube():
    """The bench mesh for a requested size is the five-scheme cube with the nearest tetrahedron
    count: 1080 for 1000 and 135 for 100."""
    assert bench.bench_mesh(1e3).n_tets == 1080 and bench.bench_mesh(1e2).n_tets == 135


def test_a_rerun_writes_the_same_committed_files(tmp_path):
    """Running a case again with nothing changed rewrites metrics.json, report.md and every
    figure byte for byte (commit, date and wall times go to run.json, which git ignores), so
    the main job on a clean checkout leaves `git status` clean."""
    argv = ["run", "paper-cube", "--quick", "--meshes", "five", "--bcs", "clamped", "--models",
            "msm", "fem-linear"]
    for name in ("a", "b"):
        assert main(argv + ["--out", str(tmp_path / name / "paper-cube")]) == 0
    a, b = tmp_path / "a" / "paper-cube", tmp_path / "b" / "paper-cube"
    files = sorted(p.name for p in a.iterdir() if p.suffix in (".json", ".md", ".png")
                   and p.name != "run.json")
    assert "metrics.json" in files and "report.md" in files
    for name in files:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_warp_engine_computes_our_neohookean_forces():
    """Where warp-lang is installed, bench times pbcm's fem-neohookean law written as a Warp
    kernel: it must be the same computation (equal forces), or the ratio compares apples and
    pears. Skipped where warp-lang is not installed (it is an optional extra)."""
    pytest.importorskip("warp")
    from model import Material, build
    from model.mesh import cube
    from cases.tools.warp_neohookean import WarpNeoHookean
    mesh = cube(4, 0.02, "six")
    pm = build("fem-neohookean", mesh, Material(1e4, 0.4))
    x = mesh.points * (1.0, 0.97, 1.01) + 1e-4 * np.sin(mesh.points * 300)
    ours = pm.forces(x)
    assert np.abs(WarpNeoHookean(pm.terms[0], x)().numpy() - ours).max() < 1e-12 * np.abs(
        ours).max()


def test_own_stable_step_is_rk4s_limit_of_the_highest_frequency():
    """fem-linear's own step is 2 sqrt 2 / omega_max with omega_max^2 the largest eigenvalue
    of M^-1 K, K the P1 stiffness assembled by the reference (an independent route to the
    model's finite-difference Jacobian) and M the lumped mass."""
    import numpy as np
    from cases.tools.bench import own_stable_step
    from model import Material, build
    from model.mesh import cube
    from reference.linear import p1_stiffness
    mat = Material(10e3, 0.45, 1000.0)
    mesh = cube(3, 0.032, "five")
    pm = build("fem-linear", mesh, mat)
    K = p1_stiffness(mesh, mat).toarray()
    m = np.repeat(pm.mass, 3)
    w2 = np.linalg.eigvals(K / m[:, None]).real.max()
    assert own_stable_step(pm) == pytest.approx(2 * np.sqrt(2) / np.sqrt(w2), rel=1e-6)


def test_bench_refuses_a_device_it_cannot_time_on_before_timing(tmp_path, capsys):
    """`pbcm bench --device` with a device Warp does not have (or without warp-lang) is a
    usage error naming the option and the device, given before anything is timed or
    written."""
    out = tmp_path / "bench"
    assert main(["bench", "--device", "nonsense", "--sizes", "100", "--rounds", "1",
                 "--models", "msm", "--out", str(out)]) == 2
    said = capsys.readouterr()
    assert "--device nonsense" in said.err and "bench:" not in said.out
    assert not out.exists()


def test_the_implicit_presets_are_timed_per_simulated_second_beside_the_explicit_ones():
    """An implicit preset named to the bench is timed a step per round on the bench's push
    (positive time, at least one Newton iteration and one CG iteration per Newton system) and
    its CPU time per simulated second is its step's time over its own step; it is not timed
    as an explicit model."""
    from cases.tools import bench
    data = bench.run(sizes=(100,), models=["msm", "fem-corotated-implicit-frame"], rounds=2,
                     progress=lambda *_: None, with_engines=False)
    assert {r["model"] for r in data["rows"]} == {"msm"}
    (row,) = data["implicit_rows"]
    assert row["model"] == "fem-corotated-implicit-frame" and row["tets"] == 135
    assert row["us_per_step"] > 0 and row["newton_per_step"] >= 1 and row["cg_per_newton"] >= 1
    assert row["cpu_s_per_simulated_s"] == pytest.approx(row["us_per_step"] * 1e-6 * 60.0)


def test_real_time_is_the_largest_size_measured_at_one_cpu_second_per_simulated_second():
    """A model runs in real time at a size where its CPU time per simulated second is at most
    1; its reach is the largest such size measured, None where no size is; a row without a
    measured cost per simulated second is not read."""
    from cases.tools import bench
    data = {"rows": [{"model": "a", "tets": 100, "cpu_s_per_simulated_s": 0.1},
                     {"model": "a", "tets": 1000, "cpu_s_per_simulated_s": 1.0},
                     {"model": "a", "tets": 10000, "cpu_s_per_simulated_s": 9.0},
                     {"model": "a", "tets": 100000},
                     {"model": "b", "tets": 100, "cpu_s_per_simulated_s": 1.5}],
            "implicit_rows": [{"model": "c", "tets": 100, "cpu_s_per_simulated_s": 0.5}]}
    assert bench.real_time_reach(data) == {"a": 1000, "b": None, "c": 100}


def test_the_real_time_family_stops_timing_a_model_after_two_sizes_over_real_time(
        tmp_path, monkeypatch):
    """The real-time family times each model under the paper's push at its own step, wall
    clock, serial and (where it has one) in its two-thread mode, and stops timing a model
    after two sizes in a row over real time: the larger sizes are rows marked not timed;
    the implicit preset carries its Newton and CG iterations; a row's faster mode is the
    one `best` reads."""
    from cases.reporting import costs
    from cases.tools import realtime_bench as RB
    monkeypatch.setattr(costs, "QUICK_CELLS", (2, 3, 4))
    monkeypatch.setattr(RB, "REAL_TIME", 0.0)        # every size is over real time
    rows = RB.run(models=("msm", "fem-corotated-implicit-frame"), quick=True, rounds=2,
                  progress=lambda *_: None)
    by = {(r["model"], r["tets"]): r for r in rows}
    assert sorted({t for _, t in by}) == [40, 135, 320]
    for m in ("msm", "fem-corotated-implicit-frame"):
        assert by[(m, 40)]["timed"] and by[(m, 135)]["timed"] and not by[(m, 320)]["timed"]
        r = by[(m, 135)]
        lo, hi = r["wall_range"]
        assert 0 < lo <= r["wall_s_per_simulated_s"] <= hi and r["dt_us"] > 0
    assert by[("fem-corotated-implicit-frame", 135)]["newton_per_step"] >= 1
    assert by[("msm", 135)]["newton_per_step"] is None
    assert costs.best(by[("msm", 320)]) == (None, None)
    two = {"model": "msm", "timed": True, "wall_s_per_simulated_s": 2.0,
           "two_thread_wall_s_per_simulated_s": 1.5}
    assert costs.best(two) == (1.5, "two threads")
    assert costs.best({**two, "two_thread_wall_s_per_simulated_s": None}) == (2.0, "serial")


def test_bench_family_refuses_other_selections_and_a_missing_bench_before_timing(tmp_path):
    """`pbcm bench --family` times the family alone into an existing bench.json: with
    --models, --sizes or --merge, or without a bench.json in --out, it fails before timing."""
    assert main(["bench", "--family", "--models", "msm", "--out", str(tmp_path)]) == 2
    assert main(["bench", "--family", "--out", str(tmp_path / "none")]) == 2
    assert not (tmp_path / "none").exists()


def test_the_real_time_family_times_every_preset():
    """The real-time family's models are every preset and every implicit preset: no model a
    user could pick is left out of the real-time study."""
    from model import PRESETS
    from model.presets import IMPLICIT_STEP
    assert set(costs.FAMILY_MODELS) == {*PRESETS, *IMPLICIT_STEP}


def test_the_real_time_family_times_newtons_solvers_up_their_ladder_where_installed(
        monkeypatch):
    """With the engines extra the family holds Newton's solvers at every count of their
    ladder (the quick family at their defaults), each timed through its adapter at its own
    step; without it, the presets alone."""
    from model.simulators import newton
    if newton.installed():
        assert costs.family_models() == costs.FAMILY_MODELS + newton.ladder_models()
        assert costs.family_models(True) == costs.FAMILY_MODELS + newton.ladder_models(1)
        from cases.tools import realtime_bench as RB
        monkeypatch.setattr(costs, "QUICK_CELLS", (2,))
        rows = RB.run(models=("newton-semi-implicit",), quick=True, rounds=2,
                      progress=lambda *_: None)
        (r,) = rows
        assert r["timed"] and r["wall_range"][0] > 0 and r["two_thread_range"] is None
        from model import build
        from cases.framework import DEFAULT_MATERIAL
        from cases.library.common import bench_mesh
        sim = build("newton-semi-implicit", bench_mesh(r["tets"]), DEFAULT_MATERIAL)
        assert r["dt_us"] == pytest.approx(sim.stable_dt() * 1e6)
    monkeypatch.setattr(newton, "installed", lambda: False)
    assert costs.family_models() == costs.FAMILY_MODELS


def test_bench_rewrite_draws_the_report_again_without_timing(tmp_path):
    """`pbcm bench --rewrite` draws bench.md and the figure again from the bench.json in
    --out, which it leaves byte for byte as it was; with a timing option, or without a
    bench.json, it fails before writing anything."""
    from pathlib import Path
    import shutil
    src = Path(__file__).resolve().parents[1] / "reports" / "bench"
    out = tmp_path / "bench"
    shutil.copytree(src, out)
    (out / "bench.md").write_text("stale\n")
    before = (out / "bench.json").read_bytes()
    assert main(["bench", "--rewrite", "--out", str(out)]) == 0
    assert (out / "bench.json").read_bytes() == before
    assert (out / "bench.md").read_text().startswith("# ")
    assert main(["bench", "--rewrite", "--family", "--out", str(out)]) == 2
    assert main(["bench", "--rewrite", "--out", str(tmp_path / "none")]) == 2
    assert not (tmp_path / "none").exists()


def test_an_implicit_step_is_timed_with_blas_on_one_thread(monkeypatch):
    """The implicit presets' step runs with BLAS limited to one thread: its thread CPU time
    is then a serial model's, and no BLAS thread is left spinning on the second core when the
    next model's two-thread speed-up is sampled."""
    from types import SimpleNamespace
    from threadpoolctl import threadpool_info
    from cases.framework import DEFAULT_MATERIAL
    from cases.tools import timers
    from model.mesh import cube
    seen = []

    def step(pm, ramp, t_end, dt, damping, frames, x0, v0, t0, stats, f_ext=None):
        seen.append([i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"])
        stats.update(newton_iterations=1, cg_iterations=1)
        return SimpleNamespace(x=[x0], v=v0)

    monkeypatch.setattr(timers, "backward_euler", step)
    t = timers.ImplicitTimed("fem-corotated-implicit-frame", cube(3, 0.032, "five"),
                             DEFAULT_MATERIAL)
    t.sample()
    assert len(seen) == 2 and all(n == [1] * len(n) for n in seen)
    assert any(seen)            # numpy's BLAS was seen, on one thread



def test_a_target_verdict_reads_the_rounds_range():
    """Against an upper target: a range below it is met, above it missed, holding it not
    resolved; without a range, the value is read against a relative band (the bench's spread
    at its size); a lower target (a speed-up) the same way round; a step ratio below 1 in any
    round is not resolved; the fraction of attainable carries its ns/tet's range; a range is
    printed to four figures."""
    v = bench.verdict
    assert v(24.0, [23.0, 25.0], 30.0, True) == "met"
    assert v(34.0, [31.0, 35.0], 30.0, True) == "missed"
    assert v(29.0, [28.0, 31.0], 30.0, True).startswith("not resolved")
    assert v(29.0, None, 30.0, True, band=0.1).startswith("not resolved")
    assert v(20.0, None, 30.0, True, band=0.1) == "met"
    assert v(40.0, None, 30.0, True, band=0.1) == "missed"
    assert v(1.9, [1.85, 1.95], 1.8, False) == "met"
    assert v(1.7, [1.6, 1.75], 1.8, False) == "missed"
    assert v(1.82, [1.78, 1.86], 1.8, False).startswith("not resolved")
    big = bench.bench_mesh(1e5).n_tets
    data = {"rows": [
        {"model": "pbcm-corner", "tets": big, "ns_per_tet": 33.0,
         "ns_per_tet_range": [32.0, 34.0], "two_thread_speedup": 1.9,
         "two_thread_speedup_range": [1.85, 1.95], "roofline_fraction": 0.3,
         "step_over_4_forces": 0.95, "step_over_4_forces_range": [0.94, 0.96],
         "step_vs_msm_range": [4.0, 4.4]},
        {"model": "pbcm-corner", "tets": 1080, "ns_per_tet": 99.0}]}
    assert bench.spread_band(data, big) == pytest.approx(0.1)
    assert [(r[0], r[-1][:12]) for r in bench.target_rows(data)] == [
        ("serial ns/tet", "missed"), ("two-thread speed-up", "met"),
        ("fraction of attainable", "missed"), ("step / 4 forces", "not resolved")]
    # the fraction's range is its ns/tet's over the rounds (fraction ~ 1 / ns)
    frac = next(r for r in bench.target_rows(data) if r[0] == "fraction of attainable")
    assert frac[4] == "0.3 [0.291-0.309]"
    # a step ratio whose range dips below 1 is not resolved, whatever its median
    data["rows"][0].update(step_over_4_forces=1.03, step_over_4_forces_range=[0.98, 1.04])
    step = next(r for r in bench.target_rows(data) if r[0] == "step / 4 forces")
    assert step[-1].startswith("not resolved (the step ran faster")
    # four figures: a range ending just short of the target shows it
    data["rows"][0].update(two_thread_speedup=1.795, two_thread_speedup_range=[1.13, 1.7966])
    two = next(r for r in bench.target_rows(data) if r[0] == "two-thread speed-up")
    assert two[4] == "1.795 [1.13-1.797]" and two[-1] == "missed"


def test_the_machine_is_named_with_what_a_bare_processor_name_leaves_out():
    """A virtual machine's bare 'AMD EPYC' is printed with its family and model, its clock and
    its widest SIMD from /proc/cpuinfo, each left out where cpuinfo lacks it."""
    from cases.tools.bench import cpu_name
    info = {"model name": "AMD EPYC", "cpu family": "26", "model": "2", "cpu MHz": "2596.1",
            "flags": "fpu sse2 avx2 avx512f fma"}
    assert cpu_name(info) == "AMD EPYC (family 26 model 2, 2.6 GHz, AVX-512)"
    assert cpu_name({"model name": "X", "flags": "sse2 avx2"}) == "X (AVX2)"
    assert cpu_name({"model name": "X"}) == "X"
    assert cpu_name({}) is None


def test_the_bench_report_opens_with_the_targets_and_tabulates_the_largest_size(tmp_path):
    """bench.md opens with the verdict against the kernel targets, and gives the largest cube
    as a table row per model (force ns/tet and the step against msm and fem-linear, each with
    its range over the rounds), saying how much msm's own step exceeds four force
    evaluations there."""
    from pathlib import Path
    from cases.reporting.document import fmt
    data = json.loads((Path(__file__).resolve().parents[1] / "reports" / "bench" /
                       "bench.json").read_text())
    top, table = bench.largest_size(data)
    row = next(r for r in data["rows"] if r["tets"] == top and r["model"] == "msm")
    lo, hi = row["ns_per_tet_range"]
    assert top == max(r["tets"] for r in data["rows"])
    assert table[[t[0] for t in table].index("msm")][1] == (
        f"{fmt(row['ns_per_tet'])} [{fmt(lo, 3)}-{fmt(hi, 3)}]")
    bench.write(data, tmp_path)
    md = (tmp_path / "bench.md").read_text().split("\n\n")
    assert md[1].startswith("Against the kernel targets on this machine")
    said = next(p for p in md if p.startswith(f"At {top} tetrahedra"))
    assert f"msm's own step costs {fmt(row['step_over_4_forces'])} times its four" in said


def test_a_row_timed_on_other_kernels_is_said_stale():
    """A bench row whose recorded kernel sources differ from the checkout's is named, a row
    recording none makes the bench's provenance unknown, and the sentence says which (for
    some rows or for all); the
    fingerprint is the same for two builds of one model and differs between models with other
    term files."""
    same = costs.checkout_sources("msm")
    assert same is not None and same == costs.checkout_sources("msm")
    assert same != costs.checkout_sources("fem-linear")
    now = {"rows": [{"model": "msm", "kernels": same},
                    {"model": "fem-linear", "kernels": costs.checkout_sources("fem-linear")}]}
    assert costs.stale(now) == ([], False) and costs.stale_words(now) == ""
    old = {"rows": [{"model": "msm", "kernels": "0" * 16}, *now["rows"][1:]],
           "realtime_rows": [{"model": "fem-linear", "timed": False},
                             {"model": "newton-vbd", "engine": "newton"}]}
    assert costs.stale(old) == (["msm"], False)
    assert costs.stale_words(old).startswith("Timed on other kernels than this checkout's: msm;")
    unknown = {"rows": now["rows"], "realtime_rows": [{"model": "msm", "timed": True}]}
    assert costs.stale(unknown) == ([], "some")
    assert "records no kernel sources for some of its rows" in costs.stale_words(unknown)
    none = {"rows": [{"model": "msm"}]}
    assert costs.stale(none) == ([], "all")
    assert "records no kernel sources for any of its rows" in costs.stale_words(none)
