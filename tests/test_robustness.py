"""Every input a user can give ends in a result or a clear error, and nothing is lost."""
import json
import os
import shutil
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from cases.running import runner
from cases.cli import main
from cases.running.output import StagedFolder, OutputError
from model.errors import ConvergenceError, MeshError
from model.mesh import cube, read

ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------------------------------ a failing phase is a finding

@pytest.mark.parametrize("nu", [0.3, 0.0])
def test_blow_ups_are_findings_and_the_report_is_complete(nu, tmp_path, capsys):
    """A run that blows up (the balanced reading on six/clamped at nu = 0.3) is a finding:
    exit 0, every file written, the failures recorded per run. The blow-up needs the literal
    reading (c = 1: the calibrated presets are softer and do not blow up here)."""
    out = tmp_path / "paper-cube"
    assert main(["run", "paper-cube", "--quick", "--nu", str(nu), "--models",
                 "pbcm-balanced-literal", "pbcm-corner-literal", "msm", "--out", str(out)]) == 0
    runs = json.loads((out / "metrics.json").read_text())["runs"]
    assert len(runs) == 2 * 2 * 3
    blown = [r for r in runs if r["dyn_failed"]]
    assert {r["model"] for r in blown} == {"pbcm-balanced-literal", "pbcm-corner-literal"}
    assert all("blew up" in r["dyn_failed"] and r["dyn_vs_static_rel_l2"] is None for r in blown)
    # a blow-up at dt is run again at dt/4 (is the step to blame?), the others are not (quick)
    assert all((r["verdict_changes_dt4"] is None) == (r not in blown) for r in runs)
    md = (out / "report.md").read_text()
    # a table row, not a sentence per run: model, mesh/bc, when it blew up at dt
    assert "| pbcm-balanced-literal | six/clamped | t = " in md
    for name in [line.split("](")[1].rstrip(")") for line in md.splitlines()
                 if line.startswith("![")]:
        assert (out / name).stat().st_size > 0


def test_a_failed_static_solve_is_recorded_and_the_case_goes_on(tmp_path, monkeypatch):
    """A static solve that raises ConvergenceError for msm is recorded in its run's static_failed
    with empty static metrics, its other phases and the other model still run, the run exits 0,
    and the report says so."""
    from model.system import ParticleModel
    real = ParticleModel.solve_static

    def fails_for_msm(self, bc, **kw):
        if self.name == "msm":
            raise ConvergenceError("static solve did not converge (planted by the test)")
        return real(self, bc, **kw)

    monkeypatch.setattr(ParticleModel, "solve_static", fails_for_msm)
    out = tmp_path / "paper-cube"
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--bcs", "clamped",
                 "--models", "msm", "pbcm-variational", "--out", str(out)]) == 0
    runs = {r["model"]: r for r in json.loads((out / "metrics.json").read_text())["runs"]}
    assert "planted" in runs["msm"]["static_failed"]
    assert runs["msm"]["disp_rel_l2_p2"] is None and runs["msm"]["alternation_rel"] is None
    assert runs["msm"]["growth_rate_1_s"] is not None     # the other phases still ran
    assert runs["pbcm-variational"]["static_failed"] is None
    md = (out / "report.md").read_text()
    assert "No converged static solve for msm on five/clamped" in md and "n/a" in md


# ------------------------------------------------------------ paths checked before computing

@pytest.fixture
def no_computing(monkeypatch):
    """Any attempt to run a case fails the test: errors must come before computing."""
    def refuse(case, cfg, log=True):
        raise AssertionError("the case started computing")
    monkeypatch.setattr(runner, "run", refuse)


def one_error_line(capsys):
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("pbcm: error: ")
    return err


@pytest.mark.parametrize("where", ["file", "under-a-file", "foreign-folder"])
def test_bad_out_fails_before_computing(where, tmp_path, capsys, no_computing):
    """An --out that is a file, lies under a file or is a folder pbcm did not write makes `run`
    (and `report`) exit 2 with one error line naming --out and the path, before computing and
    without touching the folder's files."""
    precious = tmp_path / "mine"
    precious.mkdir()
    (precious / "thesis.tex").write_text("do not lose me")
    (tmp_path / "afile").write_text("x")
    out = {"file": tmp_path / "afile", "under-a-file": tmp_path / "afile" / "sub",
           "foreign-folder": precious}[where]
    # `report --out` names the folder that holds case folders: only `run` replaces it
    for command in ("run",) if where == "foreign-folder" else ("run", "report"):
        argv = [command, "paper-cube"] if command == "run" else [command]
        assert main([*argv, "--quick", "--out", str(out)]) == 2
        err = one_error_line(capsys)
        assert "--out" in err and str(out if where != "under-a-file" else out.parent) in err
    assert (precious / "thesis.tex").read_text() == "do not lose me"


def test_bad_numbers_and_names_fail_before_computing(capsys, no_computing):
    """Out-of-range --nu, --E, --rho, `mesh cube --n 1` and a negative --size each exit 2 with
    one error line naming the flag and its limit or unit, before computing; nu = -1 is not blamed
    on incompressibility."""
    for argv, words in [(["--nu", "0.7"], ["--nu", "incompressible"]),
                        (["--nu", "-1"], ["--nu", "above -1"]),
                        (["--E", "-3"], ["--E", "Pa"]), (["--rho", "nan"], ["--rho"])]:
        assert main(["run", "paper-cube", "--quick", *argv]) == 2
        err = one_error_line(capsys)
        assert all(w in err for w in words), err
    assert main(["run", "paper-cube", "--nu", "-1"]) == 2
    assert "incompressible" not in capsys.readouterr().err
    assert main(["mesh", "cube", "--n", "1"]) == 2
    err = one_error_line(capsys)
    assert "--n" in err and "nx" not in err
    assert main(["mesh", "cube", "--size", "-3"]) == 2
    assert "mm" in one_error_line(capsys)


# ------------------------------------------------------------ atomic case folders

def test_staged_folder_keeps_the_earlier_set_until_commit(tmp_path):
    """A staged folder left by an exception keeps the earlier files unchanged and leaves no
    staging folder; a commit replaces the whole set; a folder holding files pbcm did not write is
    refused with OutputError."""
    target = tmp_path / "case"
    target.mkdir()
    for name in ("metrics.json", "report.md", "old.png"):
        (target / name).write_text("earlier")
    with pytest.raises(RuntimeError):
        with StagedFolder(target) as s:
            (s.path / "metrics.json").write_text("new")
            raise RuntimeError("interrupted while writing")
    assert sorted(p.name for p in target.iterdir()) == ["metrics.json", "old.png", "report.md"]
    assert (target / "metrics.json").read_text() == "earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case"]   # no staging folder left
    with StagedFolder(target) as s:
        (s.path / "metrics.json").write_text("new")
        (s.path / "report.md").write_text("new")
        s.commit()
    assert sorted(p.name for p in target.iterdir()) == ["metrics.json", "report.md"]
    assert (target / "metrics.json").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case"]
    (tmp_path / "foreign").mkdir()
    (tmp_path / "foreign" / "x").write_text("x")
    with pytest.raises(OutputError, match="did not write"):
        StagedFolder(tmp_path / "foreign")


def test_out_refuses_another_cases_folder_and_the_reports_root_before_computing(tmp_path,
                                                                                capsys):
    """--out naming a folder another case wrote is refused, naming that case, and the folder
    is left as it was; the reports root (its index.md) is recognised as pbcm's and the case's
    own folder in it named; both before any computing (no staging folder appears)."""
    other = tmp_path / "paper-cube"
    other.mkdir()
    (other / "metrics.json").write_text(json.dumps({"case": "paper-cube", "runs": []}))
    (other / "report.md").write_text("the paper cube's")
    assert main(["run", "cantilever", "--quick", "--out", str(other)]) == 2
    err = capsys.readouterr().err
    assert "holds the output of paper-cube, not of cantilever" in err
    assert (other / "report.md").read_text() == "the paper cube's"
    (tmp_path / "index.md").write_text("# pbcm reports")
    assert main(["run", "cantilever", "--quick", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "is the root of pbcm's reports" in err and str(tmp_path / "cantilever") in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["index.md", "paper-cube"]
    with StagedFolder(other, owner="paper-cube") as s:     # its own case is welcome
        s.discard()


def test_out_on_a_mount_point_is_refused_before_computing(tmp_path, monkeypatch):
    """A mount point cannot be swapped by a rename: --out on one is refused at once, naming a
    folder inside it, rather than failing after the computing."""
    import os.path
    target = tmp_path / "volume"
    target.mkdir()
    real = os.path.ismount
    monkeypatch.setattr(os.path, "ismount", lambda p: Path(p) == target or real(p))
    with pytest.raises(OutputError, match="is a mount point") as exc:
        StagedFolder(target, owner="paper-cube")
    assert str(target / "paper-cube") in str(exc.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["volume"]


def test_a_narrower_rerun_leaves_no_stale_files(quick, tmp_path):
    """A narrower rerun into a full run's folder removes the figures and .vtu files it did not
    write again, keeping only its own."""
    out = tmp_path / "paper-cube"
    shutil.copytree(quick, out)
    assert (out / "fig1_six_sliding.png").is_file()
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--bcs", "clamped",
                 "--models", "msm", "--out", str(out)]) == 0
    files = {p.name for p in out.iterdir()}
    assert "fig1_six_sliding.png" not in files and "fig1_five_clamped.png" in files
    assert {p.name for p in (out / "vtu").iterdir()} == {"five_clamped_msm.vtu",
                                                          "five_clamped_fem-p2.vtu"}


@pytest.mark.parametrize("sig,status,word", [(signal.SIGINT, 130, "interrupted"),
                                             (signal.SIGTERM, 143, "terminated")])
def test_ctrl_c_prints_one_line_exits_130_and_keeps_the_earlier_set(sig, status, word,
                                                                     tmp_path):
    """SIGINT or SIGTERM during a run exits 130 or 143 with one line naming the signal (progress
    lines aside), keeps the earlier metrics.json and report.md as they were, and leaves no
    staging folder."""
    out = tmp_path / "paper-cube"
    out.mkdir()
    (out / "metrics.json").write_text("{}")
    (out / "report.md").write_text("earlier complete run")
    proc = subprocess.Popen([sys.executable, "-m", "cases.cli", "run", "paper-cube", "--quick",
                             "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path)
    deadline = time.monotonic() + 120
    while not any(p.name.startswith(".paper-cube") for p in tmp_path.iterdir()):
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(2.0)   # well into the computing
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == status
    # the progress display aside (a bar on a terminal, a line per tenth of the work on a log,
    # however much was done before the signal): the signal itself is said in one line
    progress = re.compile(r"^\S+: \d+% after \d+ s, about \d+ s left$")
    lines = [line for line in err.replace("\r", "\n").splitlines()
             if line.strip() and not line.startswith("[") and not progress.match(line)]
    assert len(lines) == 1 and word in lines[0], err
    assert sorted(p.name for p in out.iterdir()) == ["metrics.json", "report.md"]
    assert (out / "report.md").read_text() == "earlier complete run"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper-cube"]


class _SignalsInItsFinaliser:
    """Sends a signal from ``__del__``: the handler's exception is raised inside the
    finaliser, where Python reports it as "Exception ignored" and drops it (as when it lands
    in llvmlite's ctypes callback while numba compiles: seen on CI)."""

    def __init__(self, sig):
        self.sig = sig

    def __del__(self):
        os.kill(os.getpid(), self.sig)
        time.sleep(0.5)


@pytest.mark.parametrize("how", ["caught", "finaliser"])
@pytest.mark.parametrize("sig,status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_whose_exception_a_library_swallows_still_stops_the_run(sig, status, how,
                                                                         tmp_path, monkeypatch,
                                                                         capfd):
    """A handler's exception raised inside a finaliser or a C callback is dropped by Python
    (or caught by a library): the run must stop at the next checkpoint anyway, without
    swapping in output, and say so in one line, without Python's "Exception ignored"."""
    out = tmp_path / "paper-cube"
    out.mkdir()
    (out / "metrics.json").write_text("{}")
    real = runner.model_run
    calls = []

    def swallowing(*args, **kw):
        calls.append(args[4])
        if how == "finaliser":
            obj = _SignalsInItsFinaliser(sig)
            del obj
        else:
            try:
                os.kill(os.getpid(), sig)
                time.sleep(0.5)   # the handler runs here; its exception is dropped below
            except BaseException:
                pass
        return real(*args, **kw)

    monkeypatch.setattr(runner, "model_run", swallowing)
    monkeypatch.setattr(sys, "unraisablehook", sys.__unraisablehook__)   # pytest's collects
    capfd.readouterr()
    hook = sys.unraisablehook
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--bcs", "clamped",
                 "--models", "msm", "fem-linear", "--out", str(out)]) == status
    err = capfd.readouterr().err
    assert "Exception ignored" not in err and "Traceback" not in err, err
    assert calls == ["msm"]   # stopped before the next model
    assert sorted(p.name for p in out.iterdir()) == ["metrics.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper-cube"]
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL   # handlers restored
    assert sys.unraisablehook is hook


def test_a_reader_that_leaves_early_gets_no_traceback(quick):
    """`pbcm check | head -0`: the pipe is closed before the table is written; exit 141
    (SIGPIPE's status), nothing on stderr."""
    proc = subprocess.Popen([sys.executable, "-m", "cases.cli", "check", "--metrics",
                             str(quick), "--gold", str(ROOT / "gold")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141 and "Traceback" not in err, err


# ------------------------------------------------------------ unreadable meshes

def _gmsh_text(tmp_path):
    m = cube(3, 0.032, "six")
    path = tmp_path / "ok.msh"
    meshio.write(path, meshio.Mesh(m.points, [("tetra", m.tets)]), file_format="gmsh22",
                 binary=False)
    return path.read_text()


@pytest.mark.parametrize("name,content,words", [
    ("garbage.msh", b"\x00\x01 not a mesh at all", ["garbage.msh", "gmsh"]),
    ("empty.msh", b"", ["empty.msh", "empty"]),
    ("truncated.msh", None, ["truncated.msh", "gmsh"]),
    ("mesh.xyz", b"1 2 3\n", ["mesh.xyz", "extension '.xyz'"]),
    ("missing.msh", False, ["missing.msh", "does not exist"]),
])
def test_unreadable_mesh_files_raise_mesh_error(name, content, words, tmp_path):
    """A garbage, empty, truncated, unknown-extension or missing mesh file raises MeshError
    (never SystemExit) whose message names the file and the problem."""
    path = tmp_path / name
    if content is None:
        text = _gmsh_text(tmp_path)
        path.write_text(text[: len(text) // 2])
    elif content is not False:
        path.write_bytes(content)
    with pytest.raises(MeshError) as info:   # never SystemExit (meshio calls sys.exit)
        read(path)
    assert all(w in str(info.value) for w in words), str(info.value)


def test_pbcm_mesh_on_garbage_exits_2_with_one_line(tmp_path, capsys):
    """`pbcm mesh` on a garbage file exits 2 with one error line naming the file."""
    path = tmp_path / "garbage.msh"
    path.write_bytes(b"\x00\x01 not a mesh")
    assert main(["mesh", str(path)]) == 2
    assert "garbage.msh" in one_error_line(capsys)


# ------------------------------------------------------------ bless and check

SMALL = ["--quick", "--meshes", "five", "--bcs", "clamped", "--models", "msm"]


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("small")
    assert main(["run", "paper-cube", *SMALL, "--out", str(d / "paper-cube")]) == 0
    return d


@pytest.mark.parametrize("margin", ["-1", "0", "nan", "inf"])
def test_bless_refuses_a_bad_margin(margin, small_run, tmp_path, capsys):
    """`pbcm bless` with a margin of -1, 0, nan or inf exits 2 with one error line naming
    --margin and creates no gold folder."""
    assert main(["bless", "--metrics", str(small_run), "--margin", margin,
                 "--gold", str(tmp_path / "g")]) == 2
    assert "--margin" in one_error_line(capsys)
    assert not (tmp_path / "g").exists()


def test_bless_keeps_unseen_rows_and_the_policy_unless_told(small_run, tmp_path, capsys,
                                                           monkeypatch):
    """Bless keeps gold rows the metrics do not cover and the edited policy, saying so and
    pointing to --prune; with --prune and --margin only the measured row and the new rtol remain,
    each removal is said, and no temporary files are left."""
    import tempfile
    from cases.running.gate import load
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    g = tmp_path / "g"
    shutil.copytree(ROOT / "gold", g)
    before = load(g)
    policy = g / "policy.toml"
    policy.write_text(policy.read_text().replace("rtol = 0.02", "rtol = 0.25"))
    assert main(["bless", "--metrics", str(small_run), "--gold", str(g)]) == 0
    out = capsys.readouterr().out
    after = load(g)
    assert set(after.rows) == set(before.rows)               # nothing dropped
    assert after.policy.rtol == 0.25                         # the policy kept
    assert "kept" in out and "--prune" in out
    assert main(["bless", "--metrics", str(small_run), "--gold", str(g), "--prune",
                 "--margin", "0.2"]) == 0
    out = capsys.readouterr().out
    pruned = load(g)
    assert set(pruned.rows) == {("paper-cube", "quick", "five", "clamped", "msm")}
    assert pruned.policy.rtol == 0.2
    assert out.count("removed ") == len(before.rows) - len(pruned.rows)
    assert sorted(p.name for p in g.iterdir()) == ["paper-cube.quick.jsonl", "policy.toml"]
    assert list((tmp_path / "tmp").iterdir()) == []          # no temporary files left
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g", "tmp"]


def test_check_refuses_metrics_run_at_other_parameters(small_run, tmp_path, capsys):
    """Check passes metrics against gold blessed from them, and exits 2 naming the parameter and
    its value for metrics whose E_Pa, nu or push_mm differ."""
    g = tmp_path / "g"
    assert main(["bless", "--metrics", str(small_run), "--gold", str(g)]) == 0
    assert main(["check", "--metrics", str(small_run), "--gold", str(g)]) == 0
    capsys.readouterr()
    for key, value in (("E_Pa", 20e3), ("nu", 0.3), ("push_mm", 2.0)):
        other = tmp_path / key / "paper-cube"
        shutil.copytree(small_run / "paper-cube", other)
        data = json.loads((other / "metrics.json").read_text())
        data["problem"][key] = value
        (other / "metrics.json").write_text(json.dumps(data))
        assert main(["check", "--metrics", str(other.parent), "--gold", str(g)]) == 2
        err = capsys.readouterr().err
        assert f"parameter {key}" in err and repr(value) in err


def test_check_refuses_duplicate_rows(small_run, tmp_path, capsys):
    """Check exits 2 on a gold file that holds one row twice, naming the two lines that are both
    for the same row."""
    g = tmp_path / "g"
    assert main(["bless", "--metrics", str(small_run), "--gold", str(g)]) == 0
    f = g / "paper-cube.quick.jsonl"
    lines = f.read_text().splitlines()
    f.write_text("\n".join(lines + [lines[1]]) + "\n")
    assert main(["check", "--metrics", str(small_run), "--gold", str(g)]) == 2
    assert "both for" in capsys.readouterr().err


def test_check_outside_a_checkout_points_to_the_gold_flag(small_run, tmp_path, capsys,
                                                          monkeypatch):
    """Check without --gold outside a checkout exits 2 with an error that points to the --gold
    flag."""
    monkeypatch.chdir(tmp_path)
    assert main(["check", "--metrics", str(small_run)]) == 2
    err = capsys.readouterr().err
    assert "--gold" in err


# ------------------------------------------------------------ help speaks the user's terms

def test_help_and_list(capsys):
    """The top-level help opens with a two-line description of the particle model, bless and
    check help name full mode and the gold in the current folder, and `pbcm list` opens with its
    summary sentence."""
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    desc = out.split("\n\n")[1].strip().splitlines()
    assert len(desc) == 2 and "particle" in desc[0]
    assert main(["bless", "--help"]) == 0
    assert "full mode" in " ".join(capsys.readouterr().out.split())
    assert main(["check", "--help"]) == 0
    assert "gold in the current folder" in " ".join(capsys.readouterr().out.split())
    assert main(["list"]) == 0
    first = capsys.readouterr().out.split("  meshes:")[0]
    assert " ".join(first.split()).endswith("boundary condition and model.")


def test_after_a_stop_a_finaliser_cut_off_half_way_is_not_reported(monkeypatch, capfd):
    """`pbcm` stopped by a signal: a __del__ that fails again later (llvmlite's, when Ctrl-C
    landed while numba compiled) prints nothing after the one-line message; other unraisable
    exceptions are still reported."""
    import gc
    from cases.running import stop
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", seen.append)
    stop.quiet_finalisers()

    class HalfClosed:
        def __del__(self):
            raise AttributeError("'PassBuilder' object has no attribute '_as_parameter_'")
    HalfClosed()
    gc.collect()
    assert seen == []
    elsewhere = type("U", (), {"object": print, "exc_value": ValueError("x")})()
    sys.unraisablehook(elsewhere)
    assert seen == [elsewhere]


def test_the_progress_bar_keeps_its_numbers_at_80_columns(monkeypatch):
    """At 80 columns the description gives way (cut with an ellipsis) so that the bar, the
    percentage, the time spent and the time left keep their room."""
    import io
    from rich.console import Console
    from cases.running import progress
    monkeypatch.setattr(progress, "Console", lambda stderr: Console(
        file=io.StringIO(), width=80, force_terminal=True))
    p = progress.Progress("paper-cube", 10, width=56)
    assert p.width == 80 - progress.NUMBERS
    assert progress.shorten("x" * 60, p.width) == "x" * (p.width - 1) + "\u2026"
    assert progress.shorten("short", p.width) == "short"


def test_a_stress_panels_scale_is_robust_to_one_slivers_spike(tmp_path, monkeypatch):
    """The stress figure's colour scale is the 99th percentile of max |tau|, not its maximum:
    one tetrahedron with a spike 1000 times the rest leaves the scale near the rest's, and
    the colour bar says which percentile."""
    from cases.reporting import figures
    mesh = cube(4, 0.032, "five")
    tau = np.full(mesh.n_tets, 1e3)
    tau[0] = 1e6
    labels = []
    real = figures.plt.Figure.colorbar
    monkeypatch.setattr(figures.plt.Figure, "colorbar",
                        lambda self, *a, **k: labels.append(k["label"]) or real(self, *a, **k))
    figures.stress_panels(tmp_path / "s.png", [("a", mesh, np.zeros((mesh.n_nodes, 3)), tau)],
                          "max |tau|", 1.0)
    assert labels[0].startswith("max |tau| / 1000 Pa, the 99th percentile")


def test_a_signal_inside_numba_or_llvmlite_is_recorded_and_raised_at_the_next_checkpoint():
    """A signal whose handler runs in numba's or llvmlite's Python code (where an exception
    can leave LLVM objects half-freed) is recorded, not raised there; the next checkpoint
    raises it. Elsewhere it raises at once."""
    import types
    from cases.running import stop
    native = types.SimpleNamespace(f_globals={"__name__": "llvmlite.binding.ffi"}, f_back=None)
    own = types.SimpleNamespace(f_globals={"__name__": "cases.running.runner"}, f_back=None)
    with stop.handling():
        stop._handler(signal.SIGINT, native)            # recorded only
        with pytest.raises(KeyboardInterrupt):
            stop.checkpoint()
    with stop.handling():
        with pytest.raises(KeyboardInterrupt):
            stop._handler(signal.SIGINT, own)


def test_the_main_jobs_wall_time_is_said_per_case_and_study():
    """`pbcm report` ends with what its wall time is made of: the cases' sum and each case,
    the studies' sum and each study, and the whole, from the times measured."""
    from cases.cli.pipeline import timing_line
    assert timing_line({"paper-cube": 12.4, "torsion": 3.0, "artefact": 60.2}) == (
        "wall time: cases 15 s (paper-cube 12, torsion 3), studies 60 s (artefact 60), "
        "in all 76 s")
    assert timing_line({"artefact": 1.0}) == "wall time: studies 1 s (artefact 1), in all 1 s"
