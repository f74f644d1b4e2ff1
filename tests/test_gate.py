"""The CI gate: the gold folder (gold/policy.toml, gold/CASE.quick.jsonl, the committed
full-mode reports), pbcm check and pbcm bless."""
import dataclasses
import json
import re
import shutil
from pathlib import Path

import pytest

from cases.cli import main

ROOT = Path(__file__).resolve().parents[1]
SMALL = ["--quick", "--meshes", "five", "--models", "pbcm-variational", "msm"]


def test_committed_bounds_hold_for_the_quick_run(quick, capsys):
    """The gate CI runs: every gold value against this run's metrics."""
    status = main(["check", "--metrics", str(quick), "--gold",
                   str(ROOT / "gold"), "--allow-new"])
    out = capsys.readouterr().out
    assert status == 0, out
    assert re.search(r"^\d+ passed, 0 failed( \(--verbose prints every value\))?$", out, re.M)


@pytest.fixture(scope="module")
def blessed(tmp_path_factory):
    d = tmp_path_factory.mktemp("gate")
    assert main(["run", "paper-cube", *SMALL, "--out", str(d / "good" / "paper-cube")]) == 0
    assert main(["bless", "--metrics", str(d / "good"), "--gold", str(d / "g")]) == 0
    return d


def check(metrics, gold):
    return main(["check", "--metrics", str(metrics), "--gold", str(gold)])


def edit_gold(src, dst, model, metric, change):
    """Copy the gold folder ``src`` to ``dst`` with ``change(value)`` applied to ``metric`` of
    the first row of ``model``."""
    shutil.copytree(src, dst)
    f = dst / "paper-cube.quick.jsonl"
    lines = f.read_text().splitlines()
    columns = json.loads(lines[0])["columns"]
    i = next(k for k, line in enumerate(lines[1:], 1) if json.loads(line)[2] == model)
    row = json.loads(lines[i])
    row[3 + columns.index(metric)] = change(row[3 + columns.index(metric)])
    lines[i] = json.dumps(row)
    f.write_text("\n".join(lines) + "\n")


def test_bless_then_check_passes(blessed, capsys):
    """A run checked against the gold blessed from it passes; the gold folder holds only
    paper-cube.quick.jsonl and policy.toml, whose header names the case, the quick mode, the
    problem's nu and gated columns such as stress_corr and disp_rel_l2_p2."""
    assert check(blessed / "good", blessed / "g") == 0
    assert sorted(p.name for p in (blessed / "g").iterdir()) == ["paper-cube.quick.jsonl",
                                                                "policy.toml"]
    head = json.loads((blessed / "g" / "paper-cube.quick.jsonl").read_text().splitlines()[0])
    assert head["case"] == "paper-cube" and head["mode"] == "quick" and "nu" in head["problem"]
    assert "stress_corr" in head["columns"] and "disp_rel_l2_p2" in head["columns"]


def test_gold_values_carry_six_digits_and_a_rebless_of_the_last_digits_changes_nothing(
        blessed, tmp_path, capsys):
    """Every compact value has at most 6 significant digits; metrics that moved in their
    10th digit bless to the same bytes."""
    text = (blessed / "g" / "paper-cube.quick.jsonl").read_text()
    for line in text.splitlines()[1:]:
        for v in json.loads(line)[3:]:
            assert v is None or float(f"{v:.6g}") == v
    shutil.copytree(blessed / "good", tmp_path / "m")
    f = tmp_path / "m" / "paper-cube" / "metrics.json"
    data = json.loads(f.read_text())
    for r in data["runs"]:
        for k in data["gated"]:
            if isinstance(r.get(k), float):
                r[k] *= 1 + 3e-10
    f.write_text(json.dumps(data))
    shutil.copytree(blessed / "g", tmp_path / "g")
    assert main(["bless", "--metrics", str(tmp_path / "m"), "--gold", str(tmp_path / "g")]) == 0
    assert "no change" in capsys.readouterr().out
    assert (tmp_path / "g" / "paper-cube.quick.jsonl").read_text() == text


def test_the_committed_gold_is_compact():
    """The gate's files together hold under 4 000 lines (one line per gated row, not one
    threshold per metric), and no per-metric thresholds file exists."""
    lines = sum(len(p.read_text().splitlines()) for p in (ROOT / "gold").iterdir())
    assert lines < 4000
    assert not (ROOT / "thresholds.toml").exists()


def test_every_committed_report_file_stays_under_two_mebibytes():
    """No file the reports commit (Markdown, PNG, JSON) is over 2 MiB: a record that grows
    past it keeps its bulk in a file of its own."""
    kept = {".md", ".png", ".json", ".jsonl", ".csv"}
    big = [str(p.relative_to(ROOT)) for p in (ROOT / "reports").rglob("*")
           if p.is_file() and p.suffix in kept and "runs" not in p.parts
           and p.stat().st_size > 2 * 2 ** 20]
    assert not big


def test_worse_model_fails_and_names_the_metric(blessed, tmp_path, capsys, monkeypatch):
    """Every shear term at half its stiffness (in this process: one mesh, no workers)."""
    from cases.framework import Case
    build = Case.build_model
    monkeypatch.setattr(Case, "build_model", lambda self, name, mesh, s: build(
        self, name, mesh, dataclasses.replace(s, shear_scale=0.5)))
    worse = tmp_path / "worse" / "paper-cube"
    assert main(["run", "paper-cube", *SMALL, "--out", str(worse)]) == 0
    capsys.readouterr()
    assert check(worse.parent, blessed / "g") == 1
    out = capsys.readouterr().out
    assert "FAIL disp_rel_l2_p2 of paper-cube/five/clamped/pbcm-variational" in out
    assert "msm/" not in "".join(l for l in out.splitlines() if l.startswith("FAIL"))
    assert "better: bless" not in out        # beside a regression nothing is an improvement


def test_beside_a_regression_an_improvement_is_said_to_have_moved_with_it(blessed, tmp_path,
                                                                           capsys):
    """One value worse and one better in one check: the better one is listed apart as moved
    with the regression, never offered for blessing."""
    edit_gold(blessed / "g", tmp_path / "g1", "pbcm-variational", "disp_rel_l2_p2",
              lambda v: 2 * v)
    edit_gold(tmp_path / "g1", tmp_path / "g2", "msm", "disp_rel_l2_p2", lambda v: v / 2)
    assert check(blessed / "good", tmp_path / "g2") == 1
    out = capsys.readouterr().out
    assert "FAIL disp_rel_l2_p2 of paper-cube/five/clamped/msm" in out and "worse" in out
    assert "moved with the regression: do not bless" in out
    assert "better: bless" not in out
    assert "margin: how far inside its band" in out


def test_hand_tightened_gold_fails(blessed, tmp_path, capsys):
    """A gold error value halved by hand makes the check exit 1 with a FAIL line for that
    metric."""
    edit_gold(blessed / "g", tmp_path / "g", "pbcm-variational", "disp_rel_l2_p2",
              lambda v: v / 2)
    assert check(blessed / "good", tmp_path / "g") == 1
    assert "FAIL disp_rel_l2_p2" in capsys.readouterr().out


def test_a_null_that_becomes_a_number_fails_and_says_what_changed(blessed, tmp_path, capsys):
    """Gold n/a and a number now, or the reverse: exit 1 naming both, never an invitation
    to bless."""
    edit_gold(blessed / "g", tmp_path / "g", "pbcm-variational", "disp_rel_l2_p2",
              lambda v: None)
    assert check(blessed / "good", tmp_path / "g") == 1
    out = capsys.readouterr().out
    line = next(l for l in out.splitlines() if l.startswith("FAIL disp_rel_l2_p2"))
    assert "was n/a, now 0." in line and "a run that failed now succeeds, or the reverse" in line
    assert "bless on purpose if intended" in line
    shutil.copytree(blessed / "good", tmp_path / "m")
    f = tmp_path / "m" / "paper-cube" / "metrics.json"
    data = json.loads(f.read_text())
    r = next(r for r in data["runs"] if r["model"] == "pbcm-variational")
    was = r["disp_rel_l2_p2"]
    r["disp_rel_l2_p2"] = None
    f.write_text(json.dumps(data))
    assert check(tmp_path / "m", blessed / "g") == 1
    assert f"was {was:.6g}, now n/a" in capsys.readouterr().out


def test_missing_gold_row_exits_2(blessed, tmp_path, capsys):
    """A model with no gold rows at all is listed as NEW and the check exits 3; a gold
    missing one row of a model that has gold makes the check exit 2 saying the gold has no
    row."""
    shutil.copytree(blessed / "g", tmp_path / "g")
    f = tmp_path / "g" / "paper-cube.quick.jsonl"
    lines = [l for l in f.read_text().splitlines() if '"msm"' not in l]
    f.write_text("\n".join(lines) + "\n")
    capsys.readouterr()
    assert check(blessed / "good", tmp_path / "g") == 3     # msm is now a model without gold
    assert "NEW  paper-cube (quick) msm" in capsys.readouterr().out
    shutil.copytree(blessed / "g", tmp_path / "h")
    f = tmp_path / "h" / "paper-cube.quick.jsonl"
    lines = [l for l in f.read_text().splitlines()
             if not l.startswith('["five", "sliding", "pbcm-variational"')]
    f.write_text("\n".join(lines) + "\n")       # one row of a model with gold left out
    assert check(blessed / "good", tmp_path / "h") == 2
    assert "the gold has no row" in capsys.readouterr().err


def test_missing_metrics_file_exits_2(blessed, tmp_path, capsys):
    """The check exits 2 when the metrics folder does not exist or holds no metrics.json,
    saying which."""
    assert check(tmp_path / "absent", blessed / "g") == 2
    assert "absent does not exist" in capsys.readouterr().err
    (tmp_path / "empty").mkdir()
    assert check(tmp_path / "empty", blessed / "g") == 2
    assert "no metrics.json" in capsys.readouterr().err


def test_nan_metric_exits_2(blessed, tmp_path, capsys):
    """A NaN metric in the run makes the check exit 2, naming the metric and saying it is not
    a finite number."""
    shutil.copytree(blessed / "good", tmp_path / "nan")
    f = tmp_path / "nan" / "paper-cube" / "metrics.json"
    data = json.loads(f.read_text())
    data["runs"][0]["alternation_rel"] = float("nan")
    f.write_text(json.dumps(data))
    assert check(tmp_path / "nan", blessed / "g") == 2
    err = capsys.readouterr().err
    assert "alternation_rel" in err and "not a finite number" in err


@pytest.mark.parametrize("name,text,word", [
    ("policy.toml", "rtol = \n", "malformed"),
    ("policy.toml", "rtol = -1\n", "non-negative"),
    ("policy.toml", "margin = 1\n", "unknown key"),
    ("paper-cube.quick.jsonl", "not json\n", "malformed"),
    ("paper-cube.quick.jsonl", None, "no gold value"),
    ("policy.toml", None, "has no policy.toml")])
def test_malformed_or_missing_gold_exits_2(blessed, tmp_path, name, text, word, capsys):
    """A malformed or missing gold file (an empty or negative rtol, an unknown policy key, a
    line that is not JSON, a deleted policy.toml or gold file) makes the check exit 2 with an
    error naming the problem, and so does a gold folder that does not exist."""
    shutil.copytree(blessed / "g", tmp_path / "g")
    if text is None:
        (tmp_path / "g" / name).unlink()
    else:
        (tmp_path / "g" / name).write_text(text)
    assert check(blessed / "good", tmp_path / "g") == 2
    assert word in capsys.readouterr().err
    assert check(blessed / "good", tmp_path / "absent") == 2


def test_the_band_is_two_sided_for_either_sign():
    """A Bound's band is the gold value +- (rtol |value| + atol) for either sign and
    direction: the value passes with margin 1 and values 0.07 away fail. An error (max) is
    worse above and better below, a correlation (min) the reverse, and a signed metric that
    moves is 'changed', never better."""
    from cases.running.gate import Bound
    for value in (-0.6, 0.6):
        for direction in ("min", "max"):
            b = Bound("c", "quick", "m", "b", "x", "alternation_rel", value, 0.1, 0.0, direction)
            low, high = b.band
            assert low == pytest.approx(value - 0.06) and high == pytest.approx(value + 0.06)
            assert b.passes(value) and b.margin(value) == 1.0
            assert not b.passes(value - 0.07) and not b.passes(value + 0.07)
    error = Bound("c", "quick", "m", "b", "x", "disp_rel_l2_p2", 0.5, 0.1, 0.0, "max")
    assert "worse" in error.verdict(0.6) and "better" in error.verdict(0.4)
    corr = Bound("c", "quick", "m", "b", "x", "stress_corr", 0.5, 0.1, 0.0, "min")
    assert "better" in corr.verdict(0.6) and "worse" in corr.verdict(0.4)
    signed = Bound("c", "quick", "m", "b", "x", "alternation_rel", 0.5, 0.1, 0.0, "signed")
    for moved in (0.6, 0.4):    # a signed measure has no better side: either change is news
        assert "changed" in signed.verdict(moved) and "better" not in signed.verdict(moved)


def test_a_better_result_fails_until_blessed(blessed, tmp_path, capsys):
    """A gold value loosened by hand (doubled) sees the measured error as an improvement
    outside the band: that fails too, until blessed."""
    edit_gold(blessed / "g", tmp_path / "g", "pbcm-variational", "disp_rel_l2_p2",
              lambda v: 2 * v)
    assert check(blessed / "good", tmp_path / "g") == 1
    assert "better: bless it on purpose" in capsys.readouterr().out


def test_committed_full_mode_gold_holds_for_the_committed_reports(capsys):
    """`pbcm check` with its defaults on a clean checkout: the committed full-mode report."""
    assert main(["check", "--metrics", str(ROOT / "reports"), "--gold",
                 str(ROOT / "gold"), "--allow-new"]) == 0
    assert "0 failed" in capsys.readouterr().out


def test_a_model_without_bounds_is_new_not_gated_yet(blessed, tmp_path, capsys):
    """A preset or composed model nobody has blessed: its metrics are listed as new (exit 3,
    or 0 with --allow-new), while every blessed bound is still checked; a bounded model's
    metric without a bound stays an error."""
    data = json.loads((blessed / "good" / "paper-cube" / "metrics.json").read_text())
    extra = "shear(reading=variational, c=auto) + normal_tet(c=auto) + volume"
    data["runs"] += [{**r, "model": extra} for r in data["runs"] if r["model"] == "msm"]
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "metrics.json").write_text(json.dumps(data))
    assert check(tmp_path / "m", blessed / "g") == 3
    out = capsys.readouterr().out
    assert f"NEW  paper-cube (quick) {extra}: new, not gated yet" in out
    assert re.search(r"^\d+ passed, 0 failed( \(--verbose prints every value\))?$", out, re.M)
    assert main(["check", "--metrics", str(tmp_path / "m"), "--gold",
                 str(blessed / "g"), "--allow-new"]) == 0
    # a failing bound still fails (1), new models or not
    worse = [dict(r) for r in data["runs"]]
    for r in worse:
        if r["model"] == "msm" and r.get("disp_rel_l2_p2") is not None:
            r["disp_rel_l2_p2"] *= 2
    (tmp_path / "m" / "metrics.json").write_text(json.dumps({**data, "runs": worse}))
    assert main(["check", "--metrics", str(tmp_path / "m"), "--gold",
                 str(blessed / "g"), "--allow-new"]) == 1
    # a new model's NaN is an error, not news
    nan = [dict(r) for r in data["runs"]]
    for r in nan:
        if r["model"] == extra:
            r["disp_rel_l2_p2"] = float("nan")
    (tmp_path / "m" / "metrics.json").write_text(json.dumps({**data, "runs": nan}))
    assert check(tmp_path / "m", blessed / "g") == 2


def test_a_regression_that_turns_a_null_into_a_number_fails(blessed, tmp_path, monkeypatch,
                                                            capsys):
    """msm made to flutter (in this process: --workers 1; its linearised growth rate set far
    above half the damping) on the small paper cube the gold was blessed from: its dynamic
    metrics, numbers in the gold, become n/a (a fluttering run is not scored). The gate fails
    (exit 1) and says what changed; it never answers 'run pbcm bless'."""
    from cases.library import paper_cube
    real = paper_cube.growth_rate

    def fluttering_msm(pm, mesh, bc):
        return 1e3 if pm.name == "msm" else real(pm, mesh, bc)
    monkeypatch.setattr(paper_cube, "growth_rate", fluttering_msm)
    out = tmp_path / "paper-cube"
    assert main(["run", "paper-cube", *SMALL, "--workers", "1", "--out", str(out)]) == 0
    capsys.readouterr()
    assert check(tmp_path, blessed / "g") == 1
    text = capsys.readouterr()
    flips = [l for l in text.out.splitlines() if "a run that failed now succeeds" in l]
    assert flips, text.out[-2000:]
    assert all("/msm" in l.split(": was")[0] for l in flips), flips    # msm's rows alone
    assert all(("was n/a, now " in l) != (", now n/a:" in l) for l in flips)
    assert "pbcm bless` to set" not in text.out + text.err


def test_a_case_folder_behind_a_link_is_checked(quick, tmp_path, capsys):
    """A metrics folder assembled from symbolic links (as a reports folder may be): the case
    behind the link is gated, not skipped."""
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "paper-cube").symlink_to(quick, target_is_directory=True)
    assert main(["check", "--metrics", str(tmp_path / "m"), "--gold", str(ROOT / "gold"),
                 "--allow-new", "--verbose"]) == 0
    assert "paper-cube/five/clamped/" in capsys.readouterr().out


def test_a_run_killed_while_writing_is_an_incomplete_run_until_rerun(blessed, tmp_path,
                                                                      capsys):
    """A run killed (SIGKILL) while its staging folder fills leaves that folder beside the case
    folder: ``pbcm check`` fails naming it (even with a metrics.json inside: hidden folders
    are never output), the case folder holds the earlier complete run, and the next run into
    that folder removes it and passes."""
    import os
    import subprocess
    import sys
    import time
    out = tmp_path / "m"
    shutil.copytree(blessed / "good", out)
    case = out / "paper-cube"
    before = (case / "metrics.json").read_bytes()
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.Popen([sys.executable, "-m", "cases.cli", "run", "paper-cube", *SMALL,
                          "--workers", "1", "--out", str(case)], env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and p.poll() is None:
            staged = [d for d in out.glob(".paper-cube.pbcm-tmp-*") if any(d.iterdir())]
            if staged:
                break
            time.sleep(0.05)
    finally:
        p.kill()
        p.wait()
    assert staged, "the run never wrote into its staging folder"
    (staged[0] / "metrics.json").write_bytes(before)      # as if killed after writing it
    assert (case / "metrics.json").read_bytes() == before
    capsys.readouterr()
    assert check(out, blessed / "g") == 2
    err = capsys.readouterr().err
    assert "incomplete run" in err and staged[0].name in err
    assert main(["run", "paper-cube", *SMALL, "--workers", "1", "--out", str(case)]) == 0
    assert not list(out.glob(".paper-cube.pbcm-tmp-*"))
    assert check(out, blessed / "g") == 0


def test_two_metrics_files_at_different_parameters_are_named(blessed, tmp_path, capsys):
    """Two metrics files of one case and mode run at different parameters: the refusal names
    both."""
    a, b = tmp_path / "m" / "a", tmp_path / "m" / "b"
    shutil.copytree(blessed / "good" / "paper-cube", a)
    shutil.copytree(blessed / "good" / "paper-cube", b)
    data = json.loads((b / "metrics.json").read_text())
    data["problem"]["nu"] = 0.3
    (b / "metrics.json").write_text(json.dumps(data))
    assert check(tmp_path / "m", blessed / "g") == 2
    err = capsys.readouterr().err
    assert str(a / "metrics.json") in err and str(b / "metrics.json") in err


def test_only_a_dead_runs_staging_folder_is_stale(tmp_path):
    """A staging folder is removed only when the run that made it, on this machine, is gone:
    a live run's (two runs into one folder) and another machine's are kept."""
    import socket
    import subprocess
    import sys
    from cases.running.output import stale_staging, staging_prefix
    target = tmp_path / "paper-cube"
    mine = tmp_path / (staging_prefix(target) + "abc")
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    gone = tmp_path / f".paper-cube.pbcm-tmp-{socket.gethostname()}.{dead}.xyz"
    other = tmp_path / f".paper-cube.pbcm-tmp-elsewhere.example.{dead}.xyz"
    for d in (mine, gone, other):
        d.mkdir()
    assert stale_staging(target) == [gone]


def test_a_five_percent_error_in_the_papers_constant_fails_the_quick_gate(tmp_path, capsys,
                                                                           monkeypatch):
    """The mutation probe: the literal reading's shear constant 5 % off (c = 1.05 for the
    paper's 1), run on the quick paper cube with the store off, fails the committed quick
    gold on that particle model's values; the run gates a subset of the gold's runs, the
    others set aside and counted."""
    from model.presets import NAMED
    monkeypatch.setitem(NAMED["pbcm-variational-literal"][0][1], "c", 1.05)
    out = tmp_path / "m" / "paper-cube"
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--bcs", "clamped",
                 "--models", "pbcm-variational-literal", "--workers", "1", "--no-cache",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["check", "--metrics", str(out.parent), "--gold", str(ROOT / "gold"),
                 "--only-run"]) == 1
    text = capsys.readouterr().out
    assert "FAIL " in text and "paper-cube/five/clamped/pbcm-variational-literal" in text
    assert "gold rows of runs not in the metrics set aside" in text


def test_an_rk4_weight_error_fails_the_quick_gate(tmp_path, capsys, monkeypatch):
    """The mutation probe: RK4's end-stage weight 5 % off (dt / 6 x 1.05 for k1 and k4),
    compiled into the step every dynamic run uses, with the store off, fails the committed
    quick gold on a particle model's values: the step convergence of the paper cube's push
    (its order falls from 4). The paper cube's own dynamic metrics move by 1e-4 only (a damped
    quasi-static push ends at equilibrium whatever the weights), so they cannot be the probe."""
    from model import integrate, step_cache
    exact = "h, w1, w2 = 0.5 * dt, dt / 6.0, dt / 3.0"
    assert exact in step_cache.source((), integrate.rk4_ramp)
    original = step_cache.source
    monkeypatch.setattr(step_cache, "source", lambda names, step: original(names, step).replace(
        exact, "h, w1, w2 = 0.5 * dt, 1.05 * dt / 6.0, dt / 3.0"))
    monkeypatch.setenv(step_cache.ENV, str(tmp_path / "steps"))
    step_cache._step_of.cache_clear()
    try:
        out = tmp_path / "m" / "convergence"
        assert main(["run", "convergence", "--quick", "--meshes", "five", "--models",
                     "pbcm-balanced", "--workers", "1", "--no-cache", "--out", str(out)]) == 0
    finally:
        step_cache._step_of.cache_clear()
    capsys.readouterr()
    assert main(["check", "--metrics", str(out.parent), "--gold", str(ROOT / "gold"),
                 "--only-run"]) == 1
    failed = [line for line in capsys.readouterr().out.splitlines() if "FAIL" in line]
    assert any("/pbcm-balanced/dt_order" in line for line in failed), failed


def test_only_run_gates_a_subset_and_a_plain_check_refuses_it(blessed, tmp_path, capsys):
    """A run of one model of a blessed pair passes with --only-run (the other model's gold
    rows set aside, counted) and is refused by a plain check (its gold was not measured)."""
    sub = tmp_path / "sub" / "paper-cube"
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--models", "msm",
                 "--out", str(sub)]) == 0
    capsys.readouterr()
    assert check(sub.parent, blessed / "g") == 2
    assert main(["check", "--metrics", str(sub.parent), "--gold", str(blessed / "g"),
                 "--only-run"]) == 0
    assert "set aside" in capsys.readouterr().out


def test_models_gates_a_subset_of_a_blessed_pair_and_refuses_an_unknown_model(blessed,
                                                                               capsys):
    """--models gates the models named (a two-model gold checked for one of them passes on
    that model's values alone, and prints no other model's); a model that neither the gold
    nor the metrics know is refused, naming the known ones (a typo gates nothing)."""
    assert main(["check", "--metrics", str(blessed / "good"), "--gold", str(blessed / "g"),
                 "--models", "msm", "--verbose"]) == 0
    out = capsys.readouterr().out
    assert "/msm/" in out and "/pbcm-variational/" not in out
    assert main(["check", "--metrics", str(blessed / "good"), "--gold", str(blessed / "g"),
                 "--models", "mms"]) == 2
    err = capsys.readouterr().err
    assert "--models mms" in err and "known: msm, pbcm-variational" in err


def test_check_prints_failures_and_totals_by_default_and_writes_junit(blessed, tmp_path,
                                                                      capsys):
    """By default the check prints the failures, the legend that defines margin and band,
    and the totals, every compared value only with --verbose; --junit writes one test case
    per gated value, a failure for each value out of its band."""
    edit_gold(blessed / "g", tmp_path / "g", "msm", "disp_rel_l2_p2", lambda v: v * 1.5)
    junit = tmp_path / "ci" / "gate.xml"
    assert main(["check", "--metrics", str(blessed / "good"), "--gold", str(tmp_path / "g"),
                 "--junit", str(junit)]) == 1
    out = capsys.readouterr().out
    assert " PASS" not in out and "FAIL" in out
    assert "margin: how far inside its band" in out and "band: the gold value +-" in out
    assert re.search(r"^\d+ passed, 1 failed \(--verbose prints every value\)$", out, re.M)
    import xml.etree.ElementTree as ET
    suite = ET.parse(junit).getroot()
    cases = suite.findall("testcase")
    assert int(suite.get("tests")) == len(cases) > 1 and suite.get("failures") == "1"
    (bad,) = [c for c in cases if c.find("failure") is not None]
    assert bad.get("name") == "disp_rel_l2_p2" and bad.get("classname").endswith("/msm")
    assert main(["check", "--metrics", str(blessed / "good"), "--gold", str(tmp_path / "g"),
                 "--verbose"]) == 1
    assert " PASS" in capsys.readouterr().out


def test_bless_without_metrics_refuses_to_start_a_run_unless_asked(tmp_path, capsys):
    """A bare `pbcm bless` computes nothing and says what to give (--metrics, or --run);
    --run with --metrics is refused too; the gold folder is left untouched."""
    assert main(["bless", "--gold", str(tmp_path / "g")]) == 2
    err = capsys.readouterr().err
    assert "--metrics DIR" in err and "--run" in err and "the whole main job" in err
    assert main(["bless", "--run", "--metrics", str(tmp_path), "--gold",
                 str(tmp_path / "g")]) == 2
    assert not (tmp_path / "g").exists()
