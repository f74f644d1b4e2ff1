"""Cases from outside the package: a Python file given with --case, or the pbcm.cases
entry-point group, run by name like a library case, never added to the library."""
import json

import pytest

from cases.cli import main

CASE_FILE = '''
from cases.library.self_weight import SelfWeight


class Block(SelfWeight):
    name = "my-block"
    quick = {"spacing_mm": 16.0}


CASE = Block()
'''


def test_a_case_file_runs_by_name_on_workers_and_stays_out_of_the_library(tmp_path):
    """`pbcm run NAME --case FILE.py` runs the file's CASE as a case (on two worker
    processes, which import the file again), writes its folder under its name, and leaves
    the library (what the test suite and `pbcm report` run) as it was."""
    from cases.registry import CASES
    f = tmp_path / "block.py"
    f.write_text(CASE_FILE)
    out = tmp_path / "my-block"
    assert main(["run", "my-block", "--case", str(f), "--quick", "--meshes", "five", "six",
                 "--bcs", "sliding", "--models", "fem-linear", "--workers", "2",
                 "--no-cache", "--out", str(out)]) == 0
    data = json.loads((out / "metrics.json").read_text())
    assert data["case"] == "my-block" and {r["mesh"] for r in data["runs"]} == {"five", "six"}
    assert "my-block" not in CASES


@pytest.mark.parametrize("text,words", [
    ("CASE = 3\n", "not a cases.framework.Case"),
    ("x = 1\n", "declares no CASE"),
    ("import nothing_here\n", "failed to import"),
    (CASE_FILE.replace('"my-block"', '"cantilever"'), "a name already taken"),
])
def test_a_bad_case_file_is_refused_before_computing(tmp_path, capsys, text, words):
    """A case file that declares no Case, fails to import or takes a library name is refused
    in one line naming the file, before anything runs."""
    f = tmp_path / "bad.py"
    f.write_text(text)
    assert main(["run", "my-block", "--case", str(f), "--quick", "--out",
                 str(tmp_path / "o")]) == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_an_entry_point_case_is_found_by_name(tmp_path, monkeypatch):
    """A case that a package declares in the pbcm.cases entry-point group is found by name."""
    import importlib.metadata
    from cases import registry
    f = tmp_path / "block.py"
    f.write_text(CASE_FILE)
    case = registry.file_case(f)

    class Point:
        name, value = "my-block", "somewhere:CASE"

        def load(self):
            return case
    real = importlib.metadata.entry_points
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group=None, **kw: [Point()] if group == registry.CASE_GROUP
                        else real(group=group, **kw))
    assert registry.user_cases()["my-block"] is case
