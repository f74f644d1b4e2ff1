"""The CI error gate: thresholds.toml, pbcm check and pbcm bless (issue 5)."""
import json
import re
import shutil
from pathlib import Path

import pytest

from cases.cli import main

ROOT = Path(__file__).resolve().parents[1]
SMALL = ["--quick", "--meshes", "five", "--models", "pbcm-variational", "msm"]


def test_committed_bounds_hold_for_the_quick_run(quick, capsys):
    """The gate CI runs: every bound in thresholds.toml against this run's metrics."""
    status = main(["check", "--metrics", str(quick), "--thresholds",
                   str(ROOT / "thresholds.toml"), "--allow-new"])
    out = capsys.readouterr().out
    assert status == 0, out
    assert re.search(r"^\d+ passed, 0 failed$", out, re.M)


@pytest.fixture(scope="module")
def blessed(tmp_path_factory):
    d = tmp_path_factory.mktemp("gate")
    assert main(["run", "paper-cube", *SMALL, "--out", str(d / "good" / "paper-cube")]) == 0
    assert main(["bless", "--metrics", str(d / "good"), "--thresholds", str(d / "t.toml")]) == 0
    return d


def check(metrics, thresholds):
    return main(["check", "--metrics", str(metrics), "--thresholds", str(thresholds)])


def test_bless_then_check_passes(blessed, capsys):
    assert check(blessed / "good", blessed / "t.toml") == 0
    text = (blessed / "t.toml").read_text()
    assert "[[problem]]" in text and 'direction = "min"' in text and 'direction = "max"' in text


def test_worse_model_fails_and_names_the_metric(blessed, tmp_path, capsys):
    worse = tmp_path / "worse" / "paper-cube"
    assert main(["run", "paper-cube", *SMALL, "--shear-scale", "0.5", "--out", str(worse)]) == 0
    capsys.readouterr()
    assert check(worse.parent, blessed / "t.toml") == 1
    out = capsys.readouterr().out
    assert "FAIL disp_rel_l2_p2 of paper-cube/five/clamped/pbcm-variational" in out
    assert "msm/" not in "".join(l for l in out.splitlines() if l.startswith("FAIL"))


def test_hand_tightened_bound_fails(blessed, tmp_path, capsys):
    text = (blessed / "t.toml").read_text()
    blocks = text.split("[[bound]]")
    i = next(k for k, b in enumerate(blocks) if 'metric = "disp_rel_l2_p2"' in b)
    value = float(re.search(r"^value = (.*)$", blocks[i], re.M).group(1))
    blocks[i] = blocks[i].replace(f"value = {value!r}", f"value = {value / 2!r}")
    (tmp_path / "t.toml").write_text("[[bound]]".join(blocks))
    assert check(blessed / "good", tmp_path / "t.toml") == 1
    assert "FAIL disp_rel_l2_p2" in capsys.readouterr().out


def test_missing_bound_exits_2(blessed, tmp_path, capsys):
    bounds, problems = (blessed / "t.toml").read_text().split("\n[[problem]]", 1)
    blocks = bounds.split("[[bound]]")
    (tmp_path / "t.toml").write_text("[[bound]]".join(blocks[:-1]) + "\n[[problem]]" + problems)
    assert check(blessed / "good", tmp_path / "t.toml") == 2
    assert "no bound for" in capsys.readouterr().err


def test_missing_metrics_file_exits_2(blessed, tmp_path, capsys):
    assert check(tmp_path / "absent", blessed / "t.toml") == 2
    assert "absent does not exist" in capsys.readouterr().err
    (tmp_path / "empty").mkdir()
    assert check(tmp_path / "empty", blessed / "t.toml") == 2
    assert "no metrics.json" in capsys.readouterr().err


def test_nan_metric_exits_2(blessed, tmp_path, capsys):
    shutil.copytree(blessed / "good", tmp_path / "nan")
    f = tmp_path / "nan" / "paper-cube" / "metrics.json"
    data = json.loads(f.read_text())
    data["runs"][0]["zigzag"] = float("nan")
    f.write_text(json.dumps(data))
    assert check(tmp_path / "nan", blessed / "t.toml") == 2
    err = capsys.readouterr().err
    assert "zigzag" in err and "not a finite number" in err


@pytest.mark.parametrize("text,word", [("[[bound]\nvalue = ", "malformed"),
                                       ("# nothing\n", "no [[bound]]"),
                                       ('[[bound]]\ncase = "paper-cube"\n', "lacks")])
def test_malformed_or_missing_thresholds_exit_2(blessed, tmp_path, text, word, capsys):
    (tmp_path / "t.toml").write_text(text)
    assert check(blessed / "good", tmp_path / "t.toml") == 2
    assert word in capsys.readouterr().err
    assert check(blessed / "good", tmp_path / "absent.toml") == 2


def test_the_band_is_two_sided_for_either_sign():
    from cases.gate import Bound
    for value in (-0.6, 0.6):
        for direction in ("min", "max"):
            b = Bound("c", "quick", "m", "b", "x", "zigzag", value, 0.1, 0.0, direction)
            low, high = b.band
            assert low == pytest.approx(value - 0.06) and high == pytest.approx(value + 0.06)
            assert b.passes(value) and b.margin(value) == 1.0
            assert not b.passes(value - 0.07) and not b.passes(value + 0.07)
    error = Bound("c", "quick", "m", "b", "x", "zigzag", 0.5, 0.1, 0.0, "max")
    assert "worse" in error.verdict(0.6) and "better" in error.verdict(0.4)
    corr = Bound("c", "quick", "m", "b", "x", "stress_corr", 0.5, 0.1, 0.0, "min")
    assert "better" in corr.verdict(0.6) and "worse" in corr.verdict(0.4)


def test_a_better_result_fails_until_blessed(blessed, tmp_path, capsys):
    """A bound loosened by hand (its value doubled) sees the measured error as an improvement
    outside the band: that fails too, until blessed."""
    text = (blessed / "t.toml").read_text()
    blocks = text.split("[[bound]]")
    i = next(k for k, b in enumerate(blocks) if 'metric = "disp_rel_l2_p2"' in b)
    value = float(re.search(r"^value = (.*)$", blocks[i], re.M).group(1))
    blocks[i] = blocks[i].replace(f"value = {value!r}", f"value = {2 * value!r}")
    (tmp_path / "t.toml").write_text("[[bound]]".join(blocks))
    assert check(blessed / "good", tmp_path / "t.toml") == 1
    assert "better: bless it on purpose" in capsys.readouterr().out


def test_committed_full_mode_bounds_hold_for_the_committed_reports(capsys):
    """`pbcm check` with its defaults on a clean checkout: the committed full-mode report."""
    assert main(["check", "--metrics", str(ROOT / "reports"), "--thresholds",
                 str(ROOT / "thresholds.toml"), "--allow-new"]) == 0
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
    assert check(tmp_path / "m", blessed / "t.toml") == 3
    out = capsys.readouterr().out
    assert f"NEW  paper-cube (quick) {extra}: new, not gated yet" in out
    assert re.search(r"^\d+ passed, 0 failed$", out, re.M)
    assert main(["check", "--metrics", str(tmp_path / "m"), "--thresholds",
                 str(blessed / "t.toml"), "--allow-new"]) == 0
    # a failing bound still fails (1), new models or not
    worse = [dict(r) for r in data["runs"]]
    for r in worse:
        if r["model"] == "msm" and r.get("disp_rel_l2_p2") is not None:
            r["disp_rel_l2_p2"] *= 2
    (tmp_path / "m" / "metrics.json").write_text(json.dumps({**data, "runs": worse}))
    assert main(["check", "--metrics", str(tmp_path / "m"), "--thresholds",
                 str(blessed / "t.toml"), "--allow-new"]) == 1
    # a new model's NaN is an error, not news
    nan = [dict(r) for r in data["runs"]]
    for r in nan:
        if r["model"] == extra:
            r["disp_rel_l2_p2"] = float("nan")
    (tmp_path / "m" / "metrics.json").write_text(json.dumps({**data, "runs": nan}))
    assert check(tmp_path / "m", blessed / "t.toml") == 2
