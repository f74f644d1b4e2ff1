"""The Warp kernels of cases.tools.warp_forces (what `pbcm bench --device` times) compute pbcm's
own forces, on Warp's CPU backend."""
import pytest

wp = pytest.importorskip("warp")

import numpy as np  # noqa: E402

from model import Material, build  # noqa: E402
from model.mesh import cube  # noqa: E402
from cases.tools import warp_forces  # noqa: E402

MESH = cube(4, 0.02, "five")
MATERIAL = Material(1e4, 0.45, 1000.0)


@pytest.fixture(scope="module")
def state():
    """A stretched, sheared and randomly perturbed state of the mesh (fixed seed)."""
    return warp_forces.deformed(MESH, seed=1)


@pytest.mark.parametrize("preset", warp_forces.COVERED)
def test_warp_forces_equal_pbcms_numba_forces(preset, state):
    """Each covered preset's forces (the sum of its terms) by Warp on the CPU equal pbcm's
    numba forces at a perturbed state: to round-off in float64 (max error below 1e-11 of the
    largest force) and within 1e-4 of it in float32."""
    pm = build(preset, MESH, MATERIAL)
    ours = pm.forces(state)
    scale = np.abs(ours).max()
    assert scale > 0
    f64 = warp_forces.WarpForces(pm, state, "cpu", "float64").forces()
    assert np.abs(f64 - ours).max() < 1e-11 * scale
    f32 = warp_forces.WarpForces(pm, state, "cpu", "float32").forces()
    assert np.abs(f32 - ours).max() < 1e-4 * scale


def test_every_preset_is_covered_or_named_as_not():
    """Every preset is either covered by a Warp kernel or listed as not covered, and a model
    with a term without a kernel is refused with its term named."""
    from model import PRESETS
    assert set(warp_forces.COVERED) | set(warp_forces.NOT_COVERED) == set(PRESETS)
    pm = build("fem-corotated", MESH, MATERIAL)
    with pytest.raises(ValueError, match="fem_corotated"):
        warp_forces.WarpForces(pm, MESH.points, "cpu", "float64")


def test_a_flattened_tetrahedron_is_an_error_as_in_pbcm():
    """A flattened tetrahedron stops a Warp evaluation with the error pbcm's kernels raise."""
    from model.errors import DegenerateTetError
    pm = build("pbcm-variational", MESH, MATERIAL)
    x = MESH.points.copy()
    t = MESH.tets[0]
    x[t[3]] = x[t[0]]                   # corner 3 onto corner 0: zero volume
    with pytest.raises(DegenerateTetError):
        pm.forces(x)
    with pytest.raises(DegenerateTetError):
        warp_forces.WarpForces(pm, x, "cpu", "float64").forces()


def test_script_writes_timings_and_differences(tmp_path, capsys):
    """The script entry times the covered presets on a device, on the bench's meshes, and
    writes, per preset and dtype, ns per tetrahedron and the max relative difference from
    pbcm's numba forces."""
    import json
    from cases.tools.bench import bench_mesh
    assert all(warp_forces.bench_mesh(n).n_tets == bench_mesh(n).n_tets for n in (1e2, 1e4))
    assert warp_forces.main(["--device", "cpu", "--sizes", "100", "--models", "fem-linear",
                             "msm", "--min-seconds", "0.001", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "warp_forces.json").read_text())
    assert {(r["model"], r["dtype"]) for r in data["rows"]} == {
        (m, d) for m in ("fem-linear", "msm") for d in ("float32", "float64")}
    for r in data["rows"]:
        assert r["ns_per_tet"] > 0 and r["numba_cpu_ns_per_tet"] > 0
        assert r["max_rel_diff_vs_numba"] < (1e-11 if r["dtype"] == "float64" else 1e-4)
    assert "fem-linear" in capsys.readouterr().out
    assert warp_forces.main(["--device", "nonsense", "--sizes", "100"]) == 2
    assert "nonsense" in capsys.readouterr().err


def test_bench_times_the_warp_kernels_on_a_device(tmp_path):
    """`pbcm bench --device cpu` adds, for each covered model timed, a row per dtype with its
    ns per tetrahedron on that device and its forces' difference from pbcm's numba forces,
    and bench.md shows them in a table naming the device; a model without Warp kernels has
    no such row."""
    import json
    from cases.cli import main
    out = tmp_path / "bench"
    assert main(["bench", "--device", "cpu", "--sizes", "100", "--rounds", "1", "--models",
                 "fem-linear", "pbcm-corner", "fem-corotated", "--out", str(out)]) == 0
    data = json.loads((out / "bench.json").read_text())
    rows = data["device_rows"]
    assert {(r["model"], r["dtype"]) for r in rows} == {
        (m, d) for m in ("fem-linear", "pbcm-corner") for d in ("float32", "float64")}
    for r in rows:
        assert r["device"] == "cpu" and r["ns_per_tet"] > 0 and r["force_vs_numba"] > 0
        assert r["max_rel_diff_vs_numba"] < (1e-11 if r["dtype"] == "float64" else 1e-4)
    md = (out / "bench.md").read_text()
    assert f"Warp kernels on device {data['device']}" in md
    assert "| pbcm-corner | 135 | cpu (CPU) | float32 |" in md
