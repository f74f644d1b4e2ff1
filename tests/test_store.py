"""The run store: a second run on an unchanged checkout computes nothing and writes
the same files; a change to any source file of the package misses every entry; a run killed
while writing leaves no entry a later run trusts; a static-only study run takes the rows of
the cases' full runs."""
import filecmp
import re
import time
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from cases.running import runner, store as S
from cases.cli import main
from cases.registry import CASES

ROOT = Path(__file__).resolve().parents[1]
CASE = "paper-cube"        # its quick references are the cheapest of the library's
SMALL = ["--quick", "--meshes", "five", "--bcs", "clamped", "--models", "pbcm-variational",
         "msm"]


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """The store on, in a folder of this test's own."""
    monkeypatch.delenv(S.ENV_OFF, raising=False)
    monkeypatch.delenv(S.ENV_KINDS, raising=False)
    monkeypatch.setenv(S.ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def _refuse(*args, **kw):
    raise AssertionError("computed although every result is stored")


def test_a_second_run_computes_nothing_and_writes_the_same_files(cache, tmp_path,
                                                                 monkeypatch):
    """A second run of a case on an unchanged checkout takes every result from the store and
    computes nothing, and its metrics.json, report.md and errors.png are byte-identical to those
    of the first run and of a fresh run with the store off."""
    assert main(["run", CASE, *SMALL, "--out", str(tmp_path / "first")]) == 0
    assert any(cache.iterdir())
    with monkeypatch.context() as m:
        m.setattr(runner, "_compute", _refuse)
        assert main(["run", CASE, *SMALL, "--out", str(tmp_path / "second")]) == 0
    # and a run that computes everything afresh writes the same bytes
    monkeypatch.setenv(S.ENV_OFF, "1")
    assert main(["run", CASE, *SMALL, "--out", str(tmp_path / "fresh"),
                 "--no-cache"]) == 0
    for name in ("metrics.json", "report.md", "errors.png"):
        assert filecmp.cmp(tmp_path / "first" / name, tmp_path / "second" / name,
                           shallow=False), name
        assert filecmp.cmp(tmp_path / "fresh" / name, tmp_path / "second" / name,
                           shallow=False), name


def test_no_cache_neither_reads_nor_fills_the_store(cache, tmp_path, monkeypatch):
    """A run with --no-cache leaves the store empty, and a store that is switched off serves none of
    the entries another run kept, so the run computes afresh. A first run into an enabled store
    keeps three entries (the run, its reference fields, its references) and finds none."""
    assert main(["run", CASE, *SMALL, "--out", str(tmp_path / "a"), "--no-cache"]) == 0
    assert not cache.exists() or not any(cache.iterdir())
    s = CASES[CASE].settings(quick=True, meshes=("five",), bcs=("clamped",),
                                     models=("msm",))
    store = S.RunStore(cache)
    runner.run(CASES[CASE], s, log=False, store=store)
    assert store.kept == 3 and store.found == 0    # the run, the reference fields and references
    calls = []
    monkeypatch.setattr(runner, "_compute", lambda *a, **k: calls.append(a) or _refuse())
    with pytest.raises(AssertionError, match="computed"):
        runner.run(CASES[CASE], s, log=False, store=S.RunStore(cache, enabled=False))
    assert calls


def test_a_static_only_run_reuses_the_full_runs_and_computes_only_the_new_model(
        cache, monkeypatch):
    """A static-only run with reuse_full takes the stored full run's row and references unchanged
    and computes only the model not yet stored, whose row equals that of a fresh static-only run;
    without reuse_full a static-only run does not take the full run's row and computes it again."""
    case = CASES[CASE]
    full = case.settings(quick=True, meshes=("five",), bcs=("clamped",),
                         models=("pbcm-variational",))
    store = S.RunStore(cache)
    [done], _ = runner.run(case, full, log=False, store=store)
    ran = []
    real = runner.model_run
    monkeypatch.setattr(runner, "model_run",
                        lambda case, mesh_name, mesh, bc, model, s, ref:
                        ran.append(model) or real(case, mesh_name, mesh, bc, model, s, ref))
    static = case.settings(quick=True, meshes=("five",), bcs=("clamped",),
                           models=("pbcm-variational", "msm"), static_only=True)
    with monkeypatch.context() as m:     # the full run's references serve the new model
        m.setattr(runner, "reference", _refuse)
        runs, _ = runner.run(case, static, log=False, store=store, reuse_full=True)
    assert ran == ["msm"]
    assert runs[0] == done
    # the stored references give the new model the metrics that solving them gives
    fresh, _ = runner.run(case, static, log=False)
    assert runs[1] == fresh[1]
    # without reuse_full a static-only run is its own result
    ran.clear()
    runner.run(case, static, log=False, store=S.RunStore(cache), reuse_full=False)
    assert ran == ["pbcm-variational"]


def _tree(tmp_path):
    root = tmp_path / "checkout"
    for package in S.PACKAGES:
        shutil.copytree(ROOT / package, root / package,
                        ignore=shutil.ignore_patterns("__pycache__"))
    return root


@pytest.mark.parametrize("edited", ["model/terms/shear.py", "reference/linear.py",
                                    "cases/running/runner.py", "cases/cli/sweeps/nu.toml"])
def test_a_change_to_any_source_file_changes_the_source_hash(tmp_path, edited):
    """Appending a line to any source file of the packages (a term, a reference solver, the runner,
    a sweep file) changes the source hash, and restoring the file's bytes restores the hash."""
    root = _tree(tmp_path)
    before = S.source_hash(root)
    path = root / edited
    path.write_text(path.read_text() + "\n# an edit\n")
    assert S.source_hash(root) != before
    path.write_text(path.read_text().removesuffix("\n# an edit\n"))
    assert S.source_hash(root) == before          # the same source, the same key


def test_a_term_files_edit_misses_the_store(tmp_path, monkeypatch):
    """The key covers every term file a run loads: a user term whose factor goes from 2 to 1
    gives another key, and the same bytes give the same key again."""
    def key():              # as a new process takes it (one process keeps what it loaded)
        S._fingerprint.cache_clear()
        return S.key(kind="run", case="cantilever")
    term = tmp_path / "my_term.py"
    term.write_text("FACTOR = 2\n")
    monkeypatch.setenv("PBCM_TERMS", str(term))
    before = key()
    term.write_text("FACTOR = 1\n")
    assert key() != before
    term.write_text("FACTOR = 2\n")
    assert key() == before
    monkeypatch.delenv("PBCM_TERMS")
    assert key() != before                        # without the file


def test_an_entry_point_packages_source_is_in_the_key(tmp_path, monkeypatch):
    """The key covers the packages of the ``pbcm.terms`` entry points: an edit to any module
    of such a package gives another key."""
    import importlib.metadata
    pkg = tmp_path / "site" / "myterms"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "spring.py").write_text("K = 2\n")
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    ep = importlib.metadata.EntryPoint("spring", "myterms.spring", "pbcm.terms")
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group=None: [ep] if group == "pbcm.terms" else [])
    assert (pkg / "spring.py").resolve() in S.term_sources()
    S._fingerprint.cache_clear()
    before = S.key(kind="run")
    (pkg / "spring.py").write_text("K = 1\n")
    S._fingerprint.cache_clear()                  # a new process
    assert S.key(kind="run") != before
    S._fingerprint.cache_clear()


def test_keys_depend_on_what_determines_a_result():
    """A store key is the same for the same inputs and differs when any one of the mesh, boundary
    condition, model, Young's modulus or entry kind changes."""
    base = dict(kind="run", case="cantilever", mesh="five", bc="clamped", model="msm",
                E_Pa=10e3)
    k = S.key(**base)
    assert S.key(**base) == k
    for change in ({"mesh": "six"}, {"bc": "sliding"}, {"model": "pbcm-variational"},
                   {"E_Pa": 11e3}, {"kind": "reference-fields"}):
        assert S.key(**{**base, **change}) != k, change


KILLED = textwrap.dedent("""
    import sys, time
    import diskcache.core
    from cases.running.store import RunStore
    real = diskcache.core.Disk.store
    def store_then_hang(self, value, read, key=diskcache.core.UNKNOWN):
        out = real(self, value, read, key)      # the value's file is on disk ...
        print("written", flush=True)
        time.sleep(600)                         # ... and the entry not committed yet
        return out
    diskcache.core.Disk.store = store_then_hang
    RunStore(sys.argv[1]).put("the-key", {"rows": list(range(100000))})
""")


def test_a_run_killed_while_writing_leaves_no_entry(cache):
    """A process killed after writing an entry's value file but before committing the entry leaves
    no entry that a later store returns; that store stays enabled and the same key can then be
    written and read back."""
    folder = cache
    env = {k: v for k, v in os.environ.items() if k != S.ENV_OFF}
    env["PYTHONPATH"] = str(ROOT)
    p = subprocess.Popen([sys.executable, "-c", KILLED, str(folder)], stdout=subprocess.PIPE,
                         env=env, text=True)
    try:
        assert p.stdout.readline().strip() == "written"
    finally:
        p.kill()
        p.wait()
    assert p.returncode != 0
    assert any(f.is_file() for f in folder.rglob("*.val"))   # the orphaned value's file
    s = S.RunStore(folder)
    assert s.enabled
    assert s.get("the-key") is None                           # ... is trusted by no one
    s.put("the-key", [1, 2])
    assert S.RunStore(folder).get("the-key") == [1, 2]


def test_the_store_folder_follows_the_environment(monkeypatch, tmp_path):
    """The store folder is $PBCM_CACHE when that is set and a per-user folder for pbcm otherwise,
    and a store opened with $PBCM_NO_CACHE set is disabled."""
    monkeypatch.setenv(S.ENV, str(tmp_path / "here"))
    assert S.default_folder() == tmp_path / "here"
    monkeypatch.delenv(S.ENV)
    assert "pbcm" in str(S.default_folder())
    monkeypatch.setenv(S.ENV_OFF, "1")
    assert not S.RunStore(tmp_path).enabled


def test_a_study_run_again_computes_nothing(cache, monkeypatch):
    """The convergence study's runs, its reference and its elasticity entries come from the
    store the second time, equal to the first; a model added later is the only thing
    computed (the extensions study's case: the P2 reference ladder is not solved again)."""
    from cases.registry import studies
    from cases.studies.convergence import elasticity, manufactured, patch, steps, study as conv
    st = studies()["convergence"]
    s = st.settings(quick=True, problems=("cantilever",), meshes=("five",), models=("msm",),
                    h_mm=(8.0, 4.0), patch_n=3)
    first = st.run(s, log=False, store=S.RunStore(cache))
    with monkeypatch.context() as m:
        m.setattr(conv, "solve_reference", _refuse)
        m.setattr(conv, "build", _refuse)
        m.setattr(conv.linear, "solve", _refuse)
        m.setattr(elasticity, "entry", _refuse)
        m.setattr(manufactured.mms, "solve", _refuse)
        m.setattr(patch, "solve", _refuse)
        m.setattr(steps, "push", _refuse)
        again = S.RunStore(cache)
        assert st.run(s, log=False, store=again) == first
    assert again.kept == 0
    # each run is looked up twice (its reference unit asks whether it needs the reference's
    # values there, its family unit reads it), the reference's summary, the elasticity and
    # each row of the verification once
    assert again.found == 2 * len(first["runs"]) + 1 + sum(
        len(first[k]) for k in ("elasticity", "manufactured", "patch", "steps"))
    assert len(first["patch"]) == 4 and len(first["steps"]) == 1
    monkeypatch.setattr(conv, "solve_reference", _refuse)
    built = []
    real = conv.build
    monkeypatch.setattr(conv, "build", lambda name, *a: built.append(name) or real(name, *a))
    more = st.run(st.settings(quick=True, problems=("cantilever",), meshes=("five",),
                              models=("msm", "pbcm-variational"), h_mm=(8.0, 4.0), patch_n=3),
                  log=False, store=S.RunStore(cache))
    assert set(built) == {"pbcm-variational"}
    old = [r for r in more["runs"] if r["model"] != "pbcm-variational"]
    assert old == first["runs"]


def test_kinds_keep_and_find_only_entries_of_those_kinds(tmp_path, monkeypatch):
    """`PBCM_CACHE_KINDS` (the test suite's setting: the FEM references only): a key of another
    kind is neither kept nor found; the restriction survives pickling to a worker."""
    import pickle
    ref, run = S.key(kind="reference", mesh="five"), S.key(kind="run", mesh="five")
    assert S.kind_of(ref) == "reference" and S.kind_of(run) == "run"
    store = S.RunStore(tmp_path, kinds=["reference"])
    store.put(ref, {"u": 1})
    store.put(run, {"u": 2})
    assert store.kept == 1
    assert store.get(ref) == {"u": 1} and store.get(run) is None
    everything = S.RunStore(tmp_path, kinds=None)
    assert everything.get(ref) == {"u": 1} and everything.get(run) is None   # never kept
    monkeypatch.setenv(S.ENV_KINDS, "run, reference-fields")
    from_env = S.RunStore(tmp_path)
    assert from_env.kinds == {"run", "reference-fields"}
    assert from_env.get(ref) is None
    assert pickle.loads(pickle.dumps(from_env)).kinds == from_env.kinds


def test_a_corrupt_store_is_moved_aside_and_the_run_goes_on(cache, tmp_path, capsys):
    """A store whose index is not a database is moved aside (kept, never rebuilt over its
    value files) with one warning naming where, and a new empty store takes its place."""
    folder = tmp_path / "store"
    s = S.RunStore(folder)
    s.put("k", [1])
    s.close()
    (folder / "cache.db").write_bytes(b"not a database" * 100)
    s = S.RunStore(folder)
    assert s.get("k") is None
    s.put("k2", [2])
    assert S.RunStore(folder).get("k2") == [2]
    aside = [p for p in tmp_path.iterdir() if p.name.startswith("store.broken-")]
    assert len(aside) == 1 and (aside[0] / "cache.db").is_file()
    err = capsys.readouterr().err
    assert err.count("pbcm: warning:") == 1 and str(aside[0]) in err


def test_a_store_that_cannot_keep_a_result_warns_once_and_the_run_goes_on(cache, tmp_path,
                                                                          capsys, monkeypatch):
    """A full disk under the optional store never stops a run: the first failed write warns
    once, the store is off for the rest of the process, and the value is returned."""
    import diskcache
    s = S.RunStore(tmp_path / "store")

    def full(*a, **k):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(diskcache.Cache, "set", full)
    assert s.put("a", 1) == 1 and s.put("b", 2) == 2
    assert not s.enabled and s.get("a") is None
    err = capsys.readouterr().err
    assert err.count("pbcm: warning:") == 1 and "No space left on device" in err


def test_an_output_fault_is_one_line_with_exit_2(tmp_path, capsys, monkeypatch):
    """A fault of the environment while writing (a full disk) ends with one line
    'pbcm: error: ...' naming the fix, exit 2, no traceback."""
    from cases.tools import bench

    def full(data, out):
        raise OSError(28, "No space left on device", str(out / "bench.json"))
    monkeypatch.setattr(bench, "write", full)
    status = main(["bench", "--sizes", "100", "--rounds", "1", "--models", "msm",
                   "--out", str(tmp_path / "bench")])
    err = capsys.readouterr().err
    assert status == 2 and err.startswith("pbcm: error:") and "Traceback" not in err
    assert "No space left on device" in err and "choose another --out" in err


def test_cache_info_counts_kinds_and_stale_entries_and_clear_stale_keeps_the_current(
        tmp_path, monkeypatch, capsys):
    """`pbcm cache info` prints the store's size, cap and entries by kind, counting as stale
    the entries computed under another source; `clear --stale` removes those only, `clear`
    every entry; each entry expires KEEP_DAYS after it was stored or last found."""
    from cases.running import store as S
    from cases.cli import main
    monkeypatch.setenv(S.ENV, str(tmp_path / "store"))
    monkeypatch.delenv(S.ENV_KINDS, raising=False)       # every kind kept
    st = S.RunStore()
    st.put("reference:a", 1)
    st.put("run:b", 2)
    st._open().set("run:old", 3, tag="another source")       # as an older checkout left it
    st._open().set("run:untagged", 4)
    expires = st._open().get("run:b", expire_time=True)[1]
    assert expires == pytest.approx(time.time() + S.KEEP_DAYS * 86400, abs=60)
    st.close()
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    assert "4 entries, 2 stale" in out and "GiB cap" in out
    assert re.search(r"^  reference\s+1$", out, re.M) and re.search(r"^  run\s+3$", out, re.M)
    assert main(["cache", "clear", "--stale"]) == 0
    assert "removed 2 stale entries" in capsys.readouterr().out
    st = S.RunStore()
    assert st.get("reference:a") == 1 and st.get("run:b") == 2 and st.get("run:old") is None
    st.close()
    assert main(["cache", "clear"]) == 0
    assert "removed 2 entries" in capsys.readouterr().out


def test_the_store_cap_is_diskcaches_lru_eviction_and_a_bad_cap_is_refused(tmp_path,
                                                                          monkeypatch):
    """The store is capped by diskcache's own least-recently-used eviction at
    $PBCM_CACHE_SIZE_GB (default SIZE_GB); a cap that is not a number > 0 is refused with a
    message naming the variable, before anything runs."""
    from cases.running import store as S
    from cases.cli import main
    assert S.settings() == {"size_limit": int(S.SIZE_GB * 2 ** 30),
                            "eviction_policy": "least-recently-used"}
    monkeypatch.setenv(S.ENV_SIZE, "0.5")
    assert S.settings()["size_limit"] == 2 ** 29
    monkeypatch.setenv(S.ENV, str(tmp_path / "store"))
    monkeypatch.setenv(S.ENV_SIZE, "-1")
    assert main(["run", "paper-cube", "--quick", "--out", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()
