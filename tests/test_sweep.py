"""`pbcm sweep`: the spec is checked whole before computing, every run lands in one table and
its own metrics.json, a rerun resumes, failing points are rows, serial and distributed runs
agree, and a killed worker's task is run again."""
import json
import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from cases.cli import main
from cases.registry import CASES
from cases.cli.sweeps import engine, report, spec as specs, table

SMALL = """
title = "small"
cases = ["paper-cube"]
quick = true
static_only = true
table = "{table}"
[fixed]
p2_levels = 1
[axes]
nu = [0.0, 0.3, 0.5]
mesh = ["five"]
bc = ["sliding"]
model = ["pbcm-variational", "fem-linear"]
[report]
metrics = ["reaction_ratio", "apparent_poisson"]
"""
TIMING = {"task_wall_s"}


def _spec(tmp_path, text=SMALL, table="csv", name="small.toml"):
    path = tmp_path / name
    path.write_text(text.format(table=table) if "{table}" in text else text)
    return path


def _values(rows):
    """The rows without their timing columns (what must not depend on where they ran)."""
    return [{k: v for k, v in r.items() if k not in TIMING} for r in rows]


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The small sweep run serially through the command line, and its folder."""
    root = tmp_path_factory.mktemp("sweep")
    path = _spec(root)
    out = root / "serial"
    assert main(["sweep", str(path), "--serial", "--out", str(out)]) == 0
    return path, out


# ------------------------------------------------------------------ the spec
def _parse(text):
    import tomllib
    return specs.parse(tomllib.loads(text), CASES)


def test_ranges_are_the_values_written_out():
    """A range axis expands to its values: num evenly spaced, log=true geometric, step inclusive
    of the end, and swept() lists the swept axes in the canonical order."""
    s = _parse('cases = ["paper-cube"]\n[axes]\nnu = {from = 0.0, to = 0.4, num = 5}\n'
               'E = {from = 1e3, to = 1e5, num = 3, log = true}\n'
               'resolution = {from = 3, to = 7, step = 2}\nload = {from = 0.5, to = 1.0, '
               'step = 0.25}')
    assert s.axes["nu"] == [0.0, 0.1, 0.2, 0.3, 0.4]
    assert s.axes["E"] == [1e3, 1e4, 1e5]
    assert s.axes["resolution"] == [3, 5, 7]
    assert s.axes["load"] == [0.5, 0.75, 1.0]
    assert s.swept() == ["E", "nu", "resolution", "load"]


def test_units_map_generic_axes_to_each_cases_settings():
    """The resolution and load axes become each case's own settings, units come in case then axis
    order, and a run key changes with the model and the case's defaults but is equal for the same
    definition."""
    s = _parse('cases = ["paper-cube", "cantilever"]\nstatic_only = true\n[axes]\n'
               'resolution = [4, 8]\nload = [2.0]\nmesh = ["five"]\nbc = ["clamped"]\n'
               'model = ["msm"]')
    units = s.units(CASES)
    assert [(u.case, u.point["resolution"]) for u in units] == [
        ("paper-cube", 4), ("paper-cube", 8), ("cantilever", 4), ("cantilever", 8)]
    assert units[1].settings == {"quick": False, "static_only": True, "nodes_per_side": 8,
                                 "push_mm": 2.0}
    assert units[3].settings["spacing_mm"] == 8 and units[3].settings["load_N"] == 2.0
    # a run key is the run's definition: another model, another key; the same, the same
    assert units[0].run_key("msm") != units[0].run_key("fem-linear")
    # and a case default the spec does not name is part of the run too
    assert units[0].problem["p2_levels"] == CASES["paper-cube"].settings().p2_levels
    assert units[0].run_key("msm") == _parse(
        'cases = ["paper-cube"]\nstatic_only = true\n[axes]\nresolution = [4]\nload = [2.0]\n'
        'mesh = ["five"]\nbc = ["clamped"]\nmodel = ["msm"]').units(CASES)[0].run_key("msm")


@pytest.mark.parametrize("text, says", [
    ('cases = ["paper-cube"]\ncolour = 1', "unknown key(s) colour"),
    ('cases = ["no-such"]', "unknown case(s) no-such"),
    ('cases = ["convergence"]', "studies cannot be swept"),
    ('cases = []', "at least one case"),
    ('cases = ["paper-cube"]\n[axes]\nnuu = [0.1]', "unknown axis nuu"),
    ('cases = ["paper-cube"]\n[axes]\nnu = ["a"]', "takes finite numbers"),
    ('cases = ["paper-cube"]\n[axes]\nnu = []', "is empty"),
    ('cases = ["paper-cube"]\n[axes]\nnu = [0.1, 0.1]', "repeats a value"),
    ('cases = ["paper-cube"]\n[axes]\nnu = {from = 0, to = 1}', "a range is"),
    ('cases = ["paper-cube"]\n[axes]\nE = {from = 0, to = 1, num = 3, log = true}',
     "log range needs"),
    ('cases = ["paper-cube"]\n[axes]\nresolution = [4.5]', "whole number"),
    ('cases = ["modes"]\n[axes]\nload = [1.0]', "has no load setting"),
    ('cases = ["modes"]\nstatic_only = true', "has no static problem"),
    ('cases = ["paper-cube"]\n[axes]\nmesh = ["hex"]', "has no mesh hex"),
    ('cases = ["paper-cube"]\n[axes]\nbc = ["free"]', "has no bc free"),
    ('cases = ["paper-cube"]\n[axes]\nmodel = ["shear(c=auto) + nosuchterm"]', "nosuchterm"),
    ('cases = ["paper-cube"]\n[fixed]\nnu = 0.3\n[axes]\nnu = [0.1]', "both fixed and swept"),
    ('cases = ["paper-cube"]\n[fixed]\nspacing_mm = 2.0', "not a setting of case paper-cube"),
    ('cases = ["paper-cube"]\n[fixed]\nmeshes = ["five"]', "the selection is swept"),
    ('cases = ["paper-cube"]\n[fixed]\np2_levels = 1.5', "takes a whole number, got 1.5"),
    ('cases = ["paper-cube"]\n[fixed]\ndamping = "high"', "takes a number, got 'high'"),
    ('cases = ["paper-cube"]\ntable = "xlsx"', "table must be one of"),
    ('cases = ["paper-cube"]\nquick = "yes"', "quick must be true or false"),
])
def test_a_bad_spec_is_refused_naming_what_is_wrong(text, says):
    """Each malformed spec raises SpecError whose message names the offending key, value, case or
    axis."""
    with pytest.raises(specs.SpecError) as err:
        _parse(text)
    assert says in str(err.value)


def test_plan_counts_without_computing(serial, tmp_path, capsys):
    """`pbcm sweep --plan` prints the tasks, runs and runs to compute without creating the output
    folder, and with --retry-failed on a finished sweep counts only the 2 failed runs to compute."""
    path, out = serial
    assert main(["sweep", str(path), "--plan", "--out", str(tmp_path / "new")]) == 0
    said = capsys.readouterr().out.splitlines()
    assert said == [f"paper-cube: 3 tasks, 6 runs, 6 to compute (0 found in "
                    f"{tmp_path / 'new' / 'runs'})",
                    "in all: 3 tasks to run, 6 runs; swept: nu (3), model (2)"]
    assert not (tmp_path / "new").exists()
    assert main(["sweep", str(path), "--plan", "--out", str(out), "--retry-failed"]) == 0
    assert "6 runs, 2 to compute (4 found" in capsys.readouterr().out


def test_a_bad_argument_fails_before_any_computing(tmp_path, capsys):
    """A missing or invalid spec, an --out folder that is not a sweep's, --workers with
    --scheduler and an unreachable scheduler each exit 2 with a message saying so, leaving no
    output or runs folder."""
    assert main(["sweep", str(tmp_path / "none.toml")]) == 2
    assert "does not exist" in capsys.readouterr().err
    path = _spec(tmp_path, 'cases = ["paper-cube"]\n[axes]\nnu = [0.7')
    assert main(["sweep", str(path)]) == 2
    assert "not valid TOML" in capsys.readouterr().err
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    good = _spec(tmp_path)
    assert main(["sweep", str(good), "--out", str(tmp_path / "mine")]) == 2
    assert "not a sweep's" in capsys.readouterr().err
    assert main(["sweep", str(good), "--scheduler", "tcp://127.0.0.1:1", "--workers", "2",
                 "--out", str(tmp_path / "o")]) == 2
    assert "drop --workers" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
    assert main(["sweep", str(good), "--scheduler", "tcp://127.0.0.1:9", "--out",
                 str(tmp_path / "o2")]) == 2
    assert "no Dask scheduler answers" in capsys.readouterr().err
    assert not (tmp_path / "o2" / "runs").exists()


# ------------------------------------------------------------------ runs, table, report
def test_every_run_is_a_row_and_a_metrics_json(serial):
    """The serial sweep writes one table row per (nu, model) in spec order, each with its
    runs/<run_key>/metrics.json, and every parameter column filled (the case defaults resolution
    5, load 1.7, E 1e4 included)."""
    _, out = serial
    rows = table.read(out / "table.csv")
    assert len(rows) == 3 * 2
    assert [(r["nu"], r["model"]) for r in rows] == [
        (0.0, "pbcm-variational"), (0.0, "fem-linear"), (0.3, "pbcm-variational"),
        (0.3, "fem-linear"), (0.5, "pbcm-variational"), (0.5, "fem-linear")]
    for r in rows:
        stored = json.loads((out / "runs" / r["run_key"] / "metrics.json").read_text())
        assert stored["model"] == r["model"] and stored["nu"] == r["nu"]
        for k in ("case", "mesh", "bc", "E", "rho", "resolution", "load", "p2_levels"):
            assert r[k] is not None, k
        assert r["resolution"] == 5 and r["load"] == 1.7 and r["E"] == 1e4


def test_a_failing_point_is_a_row_with_its_error(serial):
    """Runs at nu = 0.5 are failed rows whose error names nu and whose metrics are empty, the
    others are ok with no error, and the report lists the two failures and no partial runs."""
    rows = table.read(serial[1] / "table.csv")
    bad = [r for r in rows if r["nu"] == 0.5]
    assert all(r["status"] == "failed" and "nu" in r["error"] and r["reaction_ratio"] is None
               for r in bad)
    assert all(r["status"] == "ok" and r["error"] is None for r in rows if r["nu"] != 0.5)
    text = (serial[1] / "report.md").read_text()
    assert "## Failed runs" in text and text.count("| paper-cube | five | sliding |") == 2
    assert "0 partial" in text


def test_a_blown_up_dynamic_run_is_a_partial_row():
    """A run whose dynamic phase blew up after a static result is a partial row keeping its
    metrics, its error naming the phase; a failed static solve makes the row failed with its
    error; no failure makes it ok."""
    params = {"case": "paper-cube", "mesh": "five", "bc": "clamped"}
    r = engine.row(params, {"model": "m", "failed": None, "static_failed": None,
                            "dyn_failed": "time integration blew up at step 12",
                            "dyn_failed_dt4": None, "reaction_ratio": 1.2}, "k", 1.0)
    assert r["status"] == "partial" and r["reaction_ratio"] == 1.2
    assert r["error"] == "dyn_failed: time integration blew up at step 12"
    r = engine.row(params, {"model": "m", "failed": None, "static_failed": "no equilibrium",
                            "dyn_failed": "blew up"}, "k", 1.0)
    assert r["status"] == "failed" and r["error"] == "no equilibrium"
    assert engine.row(params, {"model": "m", "failed": None, "static_failed": None,
                               "dyn_failed": None}, "k", 1.0)["status"] == "ok"


def test_the_table_holds_no_timing_so_the_same_sweep_writes_the_same_table(serial):
    """The table records what determines and measures each run, never how long it took."""
    rows = table.read(serial[1] / "table.csv")
    assert rows and not set(rows[0]) & TIMING


def test_apparent_poisson_of_linear_fem_on_the_sliding_base_is_nu(serial):
    """Uniaxial stress: the lateral strain is -nu times the axial one, exactly for P1 and
    P2 (the solution is linear), so the FEM reference and the fem-linear model show nu."""
    for r in table.read(serial[1] / "table.csv"):
        if r["status"] == "ok":
            assert r["apparent_poisson_fem"] == pytest.approx(r["nu"], abs=1e-7)
            if r["model"] == "fem-linear":
                assert r["apparent_poisson"] == pytest.approx(r["nu"], abs=1e-7)
                assert r["reaction_ratio"] == pytest.approx(1.0, abs=1e-7)


def test_report_draws_each_metric_against_each_axis(serial):
    """The sweep report embeds a figure file of each metric against nu, states the
    apparent_poisson finding, and ranks no model as closest or farthest."""
    out = serial[1]
    text = (out / "report.md").read_text()
    for metric in ("reaction_ratio", "apparent_poisson"):
        assert (out / f"sweep_{metric}_vs_nu.png").is_file()
        assert f"![{metric} against nu](sweep_{metric}_vs_nu.png)" in text
    assert "apparent_poisson: the total error against the converged continuum" in text
    assert "closest" not in text and "farthest" not in text


def test_a_rerun_resumes_and_rewrites_the_same_files(serial, tmp_path):
    """A rerun of a finished sweep finds all 6 runs, computes none, leaves every stored
    metrics.json untouched and rewrites the same files byte for byte; --retry-failed computes the
    2 failed runs and only them."""
    path, out = serial
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    stored = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/metrics.json")}
    outcome = engine.run(specs.load(path, CASES), CASES, out, serial=True, log=False)
    assert outcome.computed == 0 and outcome.found == 6
    assert main(["sweep", str(path), "--serial", "--out", str(out)]) == 0
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert {p: p.stat().st_mtime_ns for p in stored} == stored    # nothing recomputed
    # --retry-failed computes the failed points again, and only them
    again = engine.run(specs.load(path, CASES), CASES, out, serial=True, log=False,
                       retry_failed=True)
    assert again.computed == 2 and again.found == 4


def test_an_interrupted_sweep_resumes_where_it_stopped(serial, tmp_path):
    """A sweep folder holding three of the six runs finds those three and computes the other
    three, and its table equals the full serial table apart from timing."""
    path, done = serial
    out = tmp_path / "cut"
    (out / "runs").mkdir(parents=True)
    keep = sorted((done / "runs").iterdir())[:3]      # as if stopped after three runs
    for k in keep:
        (out / "runs" / k.name).mkdir()
        (out / "runs" / k.name / "metrics.json").write_bytes((k / "metrics.json").read_bytes())
    outcome = engine.run(specs.load(path, CASES), CASES, out, serial=True, log=False)
    assert outcome.found == 3 and outcome.computed == 3
    now = table.read(table.write(outcome.rows, out, "csv", engine.PARAMS))
    assert _values(now) == _values(table.read(done / "table.csv"))


def test_parquet_and_csv_hold_the_same_rows(serial, tmp_path):
    """The serial table written as Parquet reads back with case, mesh, bc and model as its first
    columns and, row by row, the same keys and values as the CSV."""
    pytest.importorskip("pyarrow")
    rows = table.read(serial[1] / "table.csv")
    path = table.write(rows, tmp_path, "parquet", engine.PARAMS)
    back = table.read(path)
    assert [list(r) for r in back][0][:4] == ["case", "mesh", "bc", "model"]
    assert len(back) == len(rows)
    for a, b in zip(rows, back):
        assert a.keys() == b.keys()
        for k in a:
            assert a[k] == b[k], k


def test_table_columns_take_one_type_each(tmp_path):
    """A Parquet column holds one type (ints with floats become floats, lists and mixed values
    become text, None stays None), and the CSV reads back each value as it was written."""
    pytest.importorskip("pyarrow")
    rows = [{"a": 1, "b": None, "c": [1, 2], "d": True, "e": "x"},
            {"a": 2.5, "b": 3, "c": None, "d": None, "e": 1}]
    back = table.read(table.write(rows, tmp_path, "parquet"))
    assert back == [{"a": 1.0, "b": None, "c": "[1, 2]", "d": True, "e": "x"},
                    {"a": 2.5, "b": 3, "c": None, "d": None, "e": "1"}]
    csv_back = table.read(table.write(rows, tmp_path, "csv"))
    assert csv_back[0] == {"a": 1, "b": None, "c": "[1, 2]", "d": True, "e": "x"}
    assert csv_back[1]["a"] == 2.5


# ------------------------------------------------------------------ what the report computes
def test_findings_measure_each_model_against_its_target():
    """The report's findings give each model's deviation from its target as median
    [min-max], n of N runs, and its worst, rank no model, say where the median grows with nu
    beyond the spread over the meshes (and not where the two ends' ranges overlap), keep the
    clamped and sliding populations apart, call the sliding cube a patch test, and take
    FEM's value as the target where present."""
    spec = _parse('cases = ["paper-cube"]\n[axes]\nnu = [0.0, 0.4]\nmodel = ["a", "b"]'
                  .replace('["a", "b"]', '["msm", "fem-linear"]'))
    rows = [{"case": "paper-cube", "model": m, "nu": nu, "reaction_ratio": v}
            for m, nu, v in [("msm", 0.0, 1.1), ("msm", 0.4, 0.6), ("fem-linear", 0.0, 1.0),
                             ("fem-linear", 0.4, 1.02)]]
    sentences, header, body = report.findings("reaction_ratio", rows, spec,
                                              ["msm", "fem-linear"])
    # msm: |1.1 - 1| = 0.1 and |0.6 - 1| = 0.4, median 0.25, worst 0.4 at nu 0.4; grows 4x
    assert body[0] == ["msm", "2 of 2", "0.25 [0.1-0.4]", "0.4", "nu 0.4", "0.1 [0.1-0.1]",
                       "0.4 [0.4-0.4]"]
    assert body[1][:4] == ["fem-linear", "2 of 2", "0.01 [0-0.02]", "0.02"]
    assert sentences[0].startswith("reaction_ratio: the total error against the converged "
                                   "continuum")
    assert "ranks no model" in sentences[0]
    assert sentences[1] == ("reaction_ratio: the median |deviation| grows by more than 1.25x "
                            "from nu = 0 to nu = 0.4, beyond the spread over the meshes: msm "
                            "0.1 [0.1-0.1] -> 0.4 [0.4-0.4], fem-linear 0 [0-0] -> 0.02 "
                            "[0.02-0.02].")
    # two meshes: medians 0.3 -> 0.5 (1.7x) but ranges [0.1-0.5] and [0.45-0.55] overlap
    said, _, body = report.findings("reaction_ratio", [
        {**r, "reaction_ratio": v} for r, v in zip(rows[:2] * 2, (1.1, 1.45, 1.5, 1.55))],
        spec, ["msm"])
    assert body[0][1] == "4 of 4" and not any("grows" in x for x in said)
    # the patch test (sliding) and the clamped cube are never pooled: one block each
    both = [{**r, "bc": bc} for r in rows for bc in ("clamped", "sliding")]
    said, header, body = report.findings("reaction_ratio", both, spec, ["msm", "fem-linear"])
    assert header[0] == "population" and [b[0] for b in body] == ["clamped"] * 2 + ["sliding"] * 2
    assert body[0][1:3] == ["msm", "2 of 2"]
    assert any(x.startswith("reaction_ratio on sliding: the median |deviation| grows")
               for x in said)
    assert any(x.startswith("reaction_ratio on sliding: a patch test") for x in said)
    assert not any(x.startswith("reaction_ratio on clamped: a patch test") for x in said)
    # a model-form error is named as such
    assert report.kind("disp_rel_l2_p1", ("0", None)).startswith("the model-form error")
    # with an FEM column the target is FEM's value, row by row
    rows = [{"case": "paper-cube", "model": "msm", "nu": 0.4, "apparent_poisson": 0.16,
             "apparent_poisson_fem": 0.4}]
    assert report.deviations("apparent_poisson", rows)["msm"][0][0] == pytest.approx(0.24)


# ------------------------------------------------------------------ on Dask
def test_distributed_runs_equal_serial_runs(serial, tmp_path, capsys):
    """The same spec on two local worker processes gives the same rows, every non-timing
    value equal (on a Dask cluster: test_a_killed_workers_task_runs_again)."""
    path, out = serial
    dist = tmp_path / "dist"
    assert main(["sweep", str(path), "--workers", "2", "--out", str(dist)]) == 0
    said = capsys.readouterr().err
    assert "sweep: 6 runs: 6 to compute" in said and "sweep: 100% after" in said
    a, b = table.read(out / "table.csv"), table.read(dist / "table.csv")
    assert _values(a) == _values(b)
    assert (out / "report.md").read_text() == (dist / "report.md").read_text()


def _sweep_killing_a_busy_worker(spec, cluster, watcher, out):
    """Run ``spec`` on ``cluster`` into ``out`` while a thread SIGKILLs the first worker
    seen executing a task; return (outcome, {worker, pid, tasks executing} of the kill)."""
    killed = {}

    def executing(dask_worker):    # local, so that cloudpickle sends it by value
        return len(dask_worker.state.executing)

    def kill():
        deadline = time.time() + 120
        while time.time() < deadline:
            busy = {w: n for w, n in watcher.run(executing).items() if n}
            if busy:
                worker = sorted(busy)[0]
                pid = watcher.run(os.getpid, workers=[worker])[worker]
                os.kill(pid, signal.SIGKILL)
                killed.update(worker=worker, pid=pid, tasks=busy[worker])
                return
            time.sleep(0.05)

    killer = threading.Thread(target=kill)
    killer.start()
    outcome = engine.run(spec, CASES, out, scheduler=cluster.scheduler_address, log=False)
    killer.join()
    return outcome, killed


def test_a_killed_workers_task_runs_again(serial, tmp_path):
    """SIGKILL a worker process while it runs a task: the scheduler gives the task to a
    worker again and the sweep ends with every run, equal to the serial ones."""
    from distributed import Client, LocalCluster
    path, out = serial
    spec = specs.load(path, CASES)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as watcher:
        outcome, killed = _sweep_killing_a_busy_worker(spec, cluster, watcher, tmp_path / "k")
        assert killed["tasks"], "the killed worker was running a task"
        # the nanny started a new process in its place
        watcher.wait_for_workers(2, timeout=60)
        assert killed["pid"] not in watcher.run(os.getpid).values()
    assert outcome.lost == 0 and outcome.computed == 6
    now = table.read(table.write(outcome.rows, tmp_path, "csv", engine.PARAMS))
    assert _values(now) == _values(table.read(out / "table.csv"))


def test_the_shipped_spec_parses_and_names_every_model(capsys):
    """`pbcm list` describes the shipped nu sweep and the sweep axes, and nu.toml parses to its
    seven nu values, the paper cube's models, both metrics and 28 units."""
    assert main(["list"]) == 0
    listed = capsys.readouterr().out
    assert "nu (sweep, pbcm sweep nu): Every model on the paper cube over Poisson's ratio" \
        in listed
    assert "sweep axes: resolution: nodes per side (nodes_per_side); load: push [mm]" in listed
    s = specs.load(Path(__file__).resolve().parents[1] / "cases" / "cli" / "sweeps"
                   / "nu.toml", CASES)
    assert s.axes["nu"] == [0.0, 0.1, 0.2, 0.3, 0.4, 0.45, 0.49]
    assert s.axes["model"] == list(CASES["paper-cube"].models)
    assert {"reaction_ratio", "apparent_poisson"} <= set(s.metrics)
    assert len(s.units(CASES)) == 7 * 2 * 2


def test_case_knobs_name_settings_the_case_reads():
    """Each declared knob is a field of the case's settings and changes its problem: twice
    the paper cube's push gives twice fem-linear's reaction (a linear model)."""
    for case in CASES.values():
        for knob in (case.resolution, case.load):
            if knob is not None:
                v = getattr(case.settings(), knob.field)
                turned = case.settings(**{knob.field: 2 * v}).problem()
                assert turned != case.settings().problem(), (case.name, knob.field)
    from cases.running import runner
    case = CASES["paper-cube"]
    force = []
    for push in (1.7, 3.4):
        s = case.settings(quick=True, meshes=("five",), bcs=("sliding",),
                          models=("fem-linear",), push_mm=push, static_only=True, p2_levels=1)
        runs, _ = runner.unit(case, s, "five", "sliding")
        force.append(runs[0]["reaction_n"])
    assert force[1] == pytest.approx(2 * force[0], rel=1e-9)
    s = case.settings(quick=True, nodes_per_side=4, static_only=True)
    assert case.mesh("five", s).n_nodes == 4 ** 3
    assert np.allclose(s.problem()["layers_mm"], [0, 32 / 3, 64 / 3, 32])


def test_a_task_no_worker_finishes_is_lost_for_this_sweep_only(serial, tmp_path):
    """With no retry allowed, a killed worker's task ends as KilledWorker: its runs are
    failed rows that are not stored, and a rerun computes exactly them."""
    import dask
    from distributed import Client, LocalCluster
    path, out = serial
    spec = specs.load(path, CASES)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                         dashboard_address=":0") as cluster, Client(cluster) as watcher:
        outcome, killed = _sweep_killing_a_busy_worker(spec, cluster, watcher, tmp_path / "l")
    assert killed["tasks"]
    lost = [r for r in outcome.rows if r["error"] and r["error"].startswith("worker:")]
    assert outcome.lost == len(lost) >= 2      # a task holds both models of its point
    assert all(r["status"] == "failed" and "rerun the sweep" in r["error"] for r in lost)
    assert not any((tmp_path / "l" / "runs" / r["run_key"]).exists() for r in lost)
    again = engine.run(spec, CASES, tmp_path / "l", serial=True, log=False)
    assert again.computed == outcome.lost and again.lost == 0
    now = table.read(table.write(again.rows, tmp_path, "csv", engine.PARAMS))
    assert _values(now) == _values(table.read(out / "table.csv"))


def test_the_gate_does_not_read_a_sweeps_runs(serial, tmp_path):
    """A sweep folder under reports/ holds runs/<key>/metrics.json: rows, not case metrics."""
    from cases.running import gate
    root = tmp_path / "reports"
    import shutil
    shutil.copytree(serial[1], root / "sweeps" / "small")
    assert list(root.glob("**/metrics.json"))
    with pytest.raises(gate.CheckError, match="no metrics.json under"):
        gate.measured(root)


def test_a_sweep_on_a_cluster_started_as_the_readme_says(serial, tmp_path):
    """`dask scheduler` and `dask worker ADDRESS --nworkers 2 --nthreads 1` in their own
    processes (as on other machines), then `pbcm sweep --scheduler ADDRESS`: the same rows."""
    import subprocess
    path, out = serial
    info = tmp_path / "scheduler.json"
    procs = [subprocess.Popen(["dask", "scheduler", "--port", "0", "--dashboard-address", ":0",
                               "--scheduler-file", str(info)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)]
    try:
        deadline = time.time() + 60
        while not info.is_file() and time.time() < deadline:
            time.sleep(0.1)
        time.sleep(0.2)
        address = json.loads(info.read_text())["address"]
        procs.append(subprocess.Popen(["dask", "worker", address, "--nworkers", "2",
                                       "--nthreads", "1"], stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL))
        from distributed import Client
        with Client(address) as c:
            c.wait_for_workers(2, timeout=60)
        assert main(["sweep", str(path), "--scheduler", address, "--out",
                     str(tmp_path / "c")]) == 0
    finally:
        for p in reversed(procs):
            p.terminate()
            p.wait(timeout=60)
    assert _values(table.read(tmp_path / "c" / "table.csv")) == _values(
        table.read(out / "table.csv"))


def test_the_table_is_parquet_with_pyarrow_and_csv_without(tmp_path, monkeypatch):
    """The auto table kind writes table.parquet when pyarrow is present and table.csv when not,
    and a spec asking for Parquet without pyarrow exits 2 before creating its output folder."""
    pytest.importorskip("pyarrow")
    assert table.write([{"a": 1.5}], tmp_path, "auto").name == "table.parquet"
    monkeypatch.setattr(table, "parquet_available", lambda: False)
    assert table.write([{"a": 1.5}], tmp_path, "auto").name == "table.csv"
    # a spec that asks for Parquet where there is no pyarrow: refused before computing
    assert main(["sweep", str(_spec(tmp_path, table="parquet")), "--out",
                 str(tmp_path / "p")]) == 2
    assert not (tmp_path / "p").exists()


@pytest.mark.parametrize("sig,status,word", [(signal.SIGINT, 130, "interrupted"),
                                             (signal.SIGTERM, 143, "terminated")])
def test_a_stopped_sweep_says_how_to_resume_and_resumes(sig, status, word, tmp_path):
    """Ctrl-C or SIGTERM while a LocalCluster computes: one line, exit 130 / 143, the runs
    finished are on disk, and the same command then computes only the rest."""
    import subprocess
    import sys
    path = _spec(tmp_path, SMALL.replace('nu = [0.0, 0.3, 0.5]', 'nu = [0.0, 0.1, 0.2, 0.3]'))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "cases.cli", "sweep", str(path),
                             "--workers", "2", "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    deadline = time.monotonic() + 180
    while len(list(out.glob("runs/*/metrics.json"))) < 2:
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == status, err
    last = [line for line in err.splitlines() if line.strip()][-1]
    assert last == f"pbcm: {word}; every run finished is kept in the sweep's runs/ folder: " \
                  "rerun the same command to resume"
    kept = len(list(out.glob("runs/*/metrics.json")))
    assert 2 <= kept < 8
    again = engine.run(specs.load(path, CASES), CASES, out, serial=True, log=False)
    assert again.found == kept and again.computed == 8 - kept

