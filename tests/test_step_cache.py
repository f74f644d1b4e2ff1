"""The RK4 step of a composition, generated as a module and cached on disk (model.step_cache):
the same bits as the step that takes first-class kernels, loaded from the disk by a new
process without compiling, a new module when a kernel's file changes, and the first-class
step kept for a kernel that no module names."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from model import build, step_cache
from model.bc import bc_arrays
from model.integrate import rk4_ramp
from cases.library import paper_cube as pc

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def steps(tmp_path, monkeypatch):
    monkeypatch.setenv(step_cache.ENV, str(tmp_path / "steps"))
    step_cache._step_of.cache_clear()
    yield tmp_path / "steps"
    step_cache._step_of.cache_clear()


def _push(model, mat, step):
    mesh = pc.make_mesh("five", 4)
    pm = build(model, mesh, mat)
    ramp = pc.dynamic_bc(mesh, "clamped", 1.7)
    x, v = mesh.points.copy(), np.zeros_like(mesh.points)
    _, start, moving = ramp.parts(mesh.n_nodes)
    mask, _ = bc_arrays(ramp(0.0), mesh.n_nodes)
    fn, kernels = step(pm.kernels())
    status = fn(kernels, x, v, 0.0, 1e-4, 300, mesh.points, pm.mass, np.zeros_like(x), 5.0,
                mask, start, moving, ramp.t_ramp, mesh.tets, False, 1e9,
                np.empty((6,) + x.shape))
    return status, x, v


@pytest.mark.parametrize("model", ["pbcm-variational"])   # two kernels
def test_the_generated_step_is_the_first_class_step_to_the_bit(steps, mat, model):
    """For pbcm-variational (two kernels) 300 RK4 steps of the generated, disk-cached step module
    end with the same successful status and bit-identical positions and velocities as the first-
    class step, and exactly one step module is written."""
    status_g, x_g, v_g = _push(model, mat, lambda k: step_cache.step_for(k, rk4_ramp))
    status_f, x_f, v_f = _push(model, mat, lambda k: (rk4_ramp, k))
    assert status_g == status_f and status_g[0] == 0
    assert np.array_equal(x_g, x_f) and np.array_equal(v_g, v_f)
    assert len(list(steps.glob("pbcm_step_*.py"))) == 1


def test_a_new_process_loads_the_step_without_compiling(steps):
    """A second process asking for the same composition's step loads the module the first process
    compiled and wrote: the same pbcm_step_ module name, one cache hit and no miss, where the
    first process had one miss and no hit."""
    code = ("import json; from model import build, Material, step_cache;"
            "from cases.library import paper_cube as pc;"
            "m = pc.make_mesh('five', 3); pm = build('msm', m, Material(1e4, 0.45, 1e3));"
            "r = pc.dynamic_bc(m, 'clamped', 1.7); pm.simulate(r, 0.01, frames=2);"
            "from model.integrate import rk4_ramp;"
            "fn, _ = step_cache.step_for(pm.kernels(), rk4_ramp);"
            "print(json.dumps([fn.__module__, fn.stats.cache_hits and sum(fn.stats.cache_hits"
            ".values()), sum(fn.stats.cache_misses.values())]))")
    env = {**os.environ, step_cache.ENV: str(steps)}
    first, second = (json.loads(subprocess.run(
        [sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True,
        check=True).stdout.strip().splitlines()[-1]) for _ in range(2))
    assert first[0] == second[0] and first[0].startswith("pbcm_step_")
    assert first[2] == 1 and not first[1]           # compiled and written by the first
    assert second[1] == 1 and second[2] == 0        # read from the disk by the second


def test_a_changed_kernel_file_makes_a_new_module(steps, tmp_path, monkeypatch):
    """The generated step module changes when a kernel's source file changes, and is the first one
    again once the file's content is restored."""
    from model.terms import springs
    names = ((springs.__name__, "x", str(tmp_path / "k.py")),)
    (tmp_path / "k.py").write_text("a = 1\n")
    monkeypatch.setattr(step_cache, "_load", lambda path, name: type("M", (), {
        "rk4_ramp": name}))
    first = step_cache._step_of(names, rk4_ramp)
    step_cache._step_of.cache_clear()
    step_cache._file_digest.cache_clear()
    (tmp_path / "k.py").write_text("a = 2\n")
    assert step_cache._step_of(names, rk4_ramp) != first
    step_cache._step_of.cache_clear()
    step_cache._file_digest.cache_clear()
    (tmp_path / "k.py").write_text("a = 1\n")
    assert step_cache._step_of(names, rk4_ramp) == first


def test_a_kernel_no_module_names_keeps_the_first_class_step(steps):
    """A kernel that no importable module names (a function jitted inside a function, a builtin)
    keeps the first-class step with its kernels unchanged, and nothing is written to the step
    folder."""
    def made_here(x, out):
        return -1
    local = njit(made_here)
    kernels = ((local, ()),)
    assert step_cache.step_for(kernels, rk4_ramp) == (rk4_ramp, kernels)
    assert step_cache.step_for(((len, ()),), rk4_ramp) == (rk4_ramp, ((len, ()),))
    assert not steps.exists()
