"""The Truth Cube: the loader against numbers worked from the file by hand, the measurement's
corrections and floor against closed forms, the boundary-value problem against the neo-Hookean
closed form, the bead field's independence of E, and the quick study against its gold."""
import csv
import json
from pathlib import Path

import numpy as np
import pytest

from model.material import Material
from model import build
from model.bc import load_fractions
from model.errors import MeshError, ModelError
from model.mesh import cube
from reference import hyperelastic
from reference import truthcube as T
from cases.studies.truthcube import beads as B
from cases.studies.truthcube import specimen as P

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tc():
    return T.load()


def _by_hand():
    """The file read with the csv module alone: {(i, j, k): [x0, y0, z0, ..., z3]} in mm."""
    with open(T.DATA, newline="") as f:
        rows = list(csv.reader(f))[T.HEADER_LINES:]
    return {tuple(int(v) for v in r[:3]): [float(v) for v in r[3:15]] for r in rows}


def test_the_data_travels_with_its_attribution():
    """The data folder's README credits Kerdok et al. in Medical Image Analysis and names the
    OpenSurgSim source and its Apache licence."""
    readme = (T.DATA.parent / "README.md").read_text()
    assert "Kerdok" in readme and "Medical Image Analysis" in readme
    assert "opensurgsim" in readme.lower() and "Apache" in readme


def test_loader_reads_343_beads_at_4_states_in_metres(tc):
    """The loader reads 343 beads at the four nominal strains (0, 5, 12.5, 18.25 %), every
    position equal to the csv file's millimetres converted to metres, the first bead (1, 1, 1) at
    its known coordinates."""
    assert tc.index.shape == (343, 3) and tc.positions.shape == (4, 343, 3)
    assert tc.strains == (0.0, 0.05, 0.125, 0.1825)
    raw = _by_hand()
    assert len(raw) == 343
    first = tc.index[0]
    assert tuple(first) == (1, 1, 1)
    # the file's first bead: -29.69, -28.86, 12.62 mm at rest; 14.38 mm z at 18.25 %
    assert tc.positions[0, 0] == pytest.approx([-0.02969, -0.02886, 0.01262], abs=1e-12)
    assert tc.positions[3, 0, 2] == pytest.approx(0.01438, abs=1e-12)
    for n, ijk in enumerate(tc.index):
        assert np.allclose(tc.positions[:, n].ravel(), np.array(raw[tuple(ijk)]) * 1e-3,
                           atol=1e-15)


def test_layer_means_worked_from_the_file(tc):
    """The mean z displacement at 18.25 % of layers k = 7 and k = 1, worked from the csv by hand
    (15.02 and 1.47 mm), is the loader's, and layer 7 moves 4.34, 10.16 and 15.02 mm at the three
    compressed states."""
    raw = _by_hand()
    # by hand: the k = 7 and k = 1 layers' mean z displacement at 18.25 %, from the csv
    k7 = np.mean([v[11] - v[2] for ijk, v in raw.items() if ijk[2] == 7])
    k1 = np.mean([v[11] - v[2] for ijk, v in raw.items() if ijk[2] == 1])
    assert round(k7, 2) == 15.02 and round(k1, 2) == 1.47
    u = tc.displacement(3)
    assert u[tc.layer(7), 2].mean() * 1e3 == pytest.approx(k7, abs=1e-9)
    assert u[tc.layer(1), 2].mean() * 1e3 == pytest.approx(k1, abs=1e-9)
    # the data's README: the k = 7 layer moves 4.34 / 10.16 / 15.02 mm
    assert [round(tc.displacement(s)[tc.layer(7), 2].mean() * 1e3, 2) for s in (1, 2, 3)] \
        == [4.34, 10.16, 15.02]


def test_bad_files_and_states_are_refused(tmp_path, tc):
    """A missing data file, a file cut short of 343 rows and a displacement asked for state 0
    each raise ModelError saying which."""
    with pytest.raises(ModelError, match="not found"):
        T.load(tmp_path / "missing.csv")
    short = tmp_path / "short.csv"
    short.write_text("\n".join(T.DATA.read_text().splitlines()[:20]))
    with pytest.raises(ModelError, match="expected 343 rows"):
        T.load(short)
    with pytest.raises(ModelError, match="state must be 1..3"):
        tc.displacement(0)


def test_model_frame_puts_the_beads_inside_the_cube_and_the_moving_plate_at_z0(tc):
    """In the model's frame every bead lies within 5 to 75 mm, layer k = 7 sits about 10 mm and
    layer k = 1 about 70 mm above z = 0, and over 95 % of the beads move toward +z at 18.25 %."""
    X = tc.in_model_frame(tc.rest)
    assert X.min() > 0.005 and X.max() < 0.075
    # the k = 7 layer (next to the moving plate) about 10 mm above z = 0, k = 1 below 80 mm
    assert X[tc.layer(7), 2].mean() == pytest.approx(0.010, abs=1e-3)
    assert X[tc.layer(1), 2].mean() == pytest.approx(0.070, abs=1e-3)
    # compression moves every layer toward the fixed plate: +z in the model's frame
    u = tc.displacement_in_model_frame(tc.displacement(3))
    assert (u[:, 2] > 0).mean() > 0.95


def _rotate(points, theta, t, c):
    rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    out = points.copy()
    out[:, :2] = (points[:, :2] - c) @ rot.T + c + t
    return out


def test_rigid_inplane_motion_recovered_exactly():
    """A known in-plane rotation (0.02 rad) and translation of random points are recovered
    exactly, and removing them restores the rest x, y positions while keeping the axial shift."""
    rng = np.random.default_rng(3)
    rest = rng.uniform(-0.03, 0.03, (50, 3))
    c = rest[:, :2].mean(axis=0)
    moved = _rotate(rest, 0.02, np.array([3e-4, -1e-3]), c)
    moved[:, 2] += 1e-3                        # the axial part is not in-plane: kept
    t, theta, centre = T.rigid_inplane(rest, moved)
    assert theta == pytest.approx(0.02, abs=1e-12)
    assert t == pytest.approx([3e-4, -1e-3], abs=1e-15)
    back = T.remove_rigid_inplane(rest, moved)
    assert np.allclose(back[:, :2], rest[:, :2], atol=1e-15)
    assert np.allclose(back[:, 2], rest[:, 2] + 1e-3, atol=1e-15)


def test_a_symmetric_barrel_has_no_rigid_part():
    """A barrel deformation symmetric about the axis has zero rigid in-plane translation and
    rotation (below 1e-15)."""
    g = np.linspace(-0.03, 0.03, 7)
    rest = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T
    barrel = rest.copy()
    barrel[:, :2] *= 1 + 0.05 * np.cos(np.pi * rest[:, 2:] / 0.07)
    t, theta, _ = T.rigid_inplane(rest, barrel)
    assert np.abs(t).max() < 1e-16 and abs(theta) < 1e-15


def test_quantisation_step_found_on_a_grid_and_not_in_noise(tc):
    """Values on a 0.625 mm grid give that step with full coherence, uniform random values give
    no step, and the data's y coordinates at 18.25 % are quantised in 0.625 mm steps."""
    rng = np.random.default_rng(0)
    q, c = T.quantisation_step(0.625e-3 * rng.integers(-60, 60, 300) + 0.0002)
    assert q == pytest.approx(0.625e-3, rel=2e-3) and c == pytest.approx(1.0)
    assert T.quantisation_step(rng.uniform(-0.03, 0.03, 300))[0] is None
    # the data's y coordinates: steps of 0.625 mm (the README's "about 0.6 mm")
    assert T.quantisation_step(tc.positions[3][:, 1])[0] == pytest.approx(0.625e-3, rel=2e-3)


def test_noise_of_a_smooth_field_plus_scatter_is_the_scatter():
    """The measured noise of a smooth polynomial displacement field is zero, and with Gaussian
    scatter added it is that scatter's standard deviation per component, within 15 %."""
    rng = np.random.default_rng(1)
    rest = rng.uniform(-0.03, 0.03, (343, 3))
    x, y, z = rest.T / 0.04
    smooth = 1e-3 * np.c_[x * z ** 2, 0.3 * y ** 3 - x * y * z, 2 * z + z ** 4]
    assert np.abs(T.noise(rest, smooth)).max() < 1e-15
    sigma = np.array([1e-4, 3e-4, 1e-4])
    measured = T.noise(rest, smooth + sigma * rng.standard_normal((343, 3)))
    assert measured == pytest.approx(sigma, rel=0.15)


def test_bead_errors_against_closed_forms(tc):
    """The bead errors are zero for the measurement itself, 1 mm axial and 0 lateral for a 1 mm
    shift along z, and 0.5 mm lateral for a (0.3, 0.4) mm shift; the excess over the floor is
    sqrt(rms^2 - floor^2), within holds up to sqrt(2) floors, and a non-finite field raises
    ModelError."""
    m = B.Measured(tc)
    u = m.u(3)
    scale = m.scale(3)
    exact = B.errors(u, u, m.u_raw(3), scale)
    assert exact["bead_rms_mm"] == 0 and exact["bead_max_mm"] == 0
    shifted = B.errors(u + [0, 0, 1e-3], u, m.u_raw(3), scale)
    assert shifted["bead_axial_rms_mm"] == pytest.approx(1.0)
    assert shifted["bead_lateral_rms_mm"] == 0
    assert shifted["bead_rms_rel"] == pytest.approx(1.0 / scale["total"])
    side = B.errors(u + [3e-4, 4e-4, 0], u, m.u_raw(3), scale)
    assert side["bead_lateral_rms_mm"] == pytest.approx(0.5)
    assert B.excess(0.5, 0.3) == pytest.approx(0.4) and B.excess(0.2, 0.3) == 0
    assert B.within(0.3 * np.sqrt(2), 0.3) and not B.within(0.3 * np.sqrt(2) * 1.01, 0.3)
    with pytest.raises(ModelError, match="not finite"):
        B.errors(u * np.nan, u, u, scale)


def test_floor_and_layer_profiles_from_the_data(tc):
    """At 18.25 % the y noise lies between 0.2 and 0.4 mm, the axial floor is below the lateral
    one and the total is their norm; the raw lateral bulge of the middle layer exceeds both end
    layers', and layer 7 moves 15.0165 mm axially."""
    m = B.Measured(tc)
    f = m.floor(3)
    # the y quantisation alone (0.625 mm on rest and deformed) gives 0.255 mm
    assert 0.2 < f["noise_xyz"][1] < 0.4 and f["axial"] < f["lateral"]
    assert f["total"] == pytest.approx(np.linalg.norm(f["noise_xyz"]))
    s = m.summary()["states"][2]
    # the data's README: a barrel, 2.98 / 5.45 / 3.93 mm at k = 1, 4, 7 raw (with the shift)
    raw = B.layer_lateral(tc, m.u_raw(3))
    assert raw[3] > raw[0] and raw[3] > raw[6]
    assert s["layer_axial_mm"][6] == pytest.approx(15.0165, abs=1e-3)


def test_located_points_interpolate_affine_fields_exactly(tc):
    """The beads located in the 10 mm mesh get non-negative barycentric weights summing to 1 that
    interpolate an affine field exactly (1e-15), and a point outside the mesh raises MeshError."""
    mesh = P.mesh(10.0)
    X = B.Measured(tc).beads
    loc = mesh.locate(X)
    A = np.array([[0.1, 0.2, 0.3], [0.0, -0.1, 0.05], [0.2, 0.1, -0.3]])
    b = np.array([1e-3, 2e-3, 3e-3])
    assert np.abs(mesh.interpolate(mesh.points @ A.T + b, loc) - (X @ A.T + b)).max() < 1e-15
    assert np.all(loc[1] >= -1e-12) and np.allclose(loc[1].sum(axis=1), 1)
    with pytest.raises(MeshError, match="outside the mesh"):
        mesh.locate([[0.09, 0.04, 0.04]])


def test_load_fractions_and_schedule():
    """load_fractions gives k / n or the given increasing fractions ending at 1 and refuses
    anything else; the schedule reaches the 4, 10 and 14.6 mm travels exactly at steps 4, 10 and
    15, no step above the mesh's step strain."""
    assert load_fractions(4).tolist() == [0.25, 0.5, 0.75, 1.0]
    assert load_fractions([0.3, 1.0]).tolist() == [0.3, 1.0]
    for bad in (0, [0.5, 0.4, 1.0], [0.5, 0.9], [], [0.0, 1.0], "x"):
        with pytest.raises(ModelError, match="load_steps"):
            load_fractions(bad)
    travels = P.nominal_travels()
    assert travels == pytest.approx([0.004, 0.010, 0.0146])
    assert P.step_strain(P.mesh(10.0)) == pytest.approx(0.0125)
    assert P.step_strain(P.mesh(5.0)) == pytest.approx(0.00625)
    fractions, at = P.schedule(travels, 0.0125)
    reached = [fractions[k - 1] * travels[-1] for k in at]
    assert reached == pytest.approx(travels, rel=1e-12)
    steps = np.diff([0.0] + fractions) * travels[-1]
    assert steps.max() <= 0.0125 * T.SIDE * (1 + 1e-12)
    assert at == [4, 10, 15]
    with pytest.raises(ModelError, match="divide"):
        P.mesh(30.0)


def test_frictionless_continuum_is_the_uniaxial_closed_form():
    """Frictionless plates: the neo-Hookean cube compresses homogeneously, every lateral
    stretch the closed form's (reference.hyperelastic.uniaxial)."""
    m = cube(3, T.SIDE, "six")
    E, nu = 15e3, 0.499
    travel = 0.1 * T.SIDE
    sol = hyperelastic.solve(m, Material(E, nu), P.dirichlet(m, "frictionless", travel),
                             element="P2", mixed=True, load_steps=[0.5, 1.0], keep_steps=[1])
    lat, _ = hyperelastic.uniaxial(0.9, Material(E, nu))
    x = m.points
    assert np.allclose(sol.u[:, 0], (lat - 1) * (x[:, 0] - T.SIDE / 2), atol=1e-9)
    assert np.allclose(sol.u[:, 2], travel * (1 - x[:, 2] / T.SIDE), atol=1e-9)
    half, _ = hyperelastic.uniaxial(0.95, Material(E, nu))
    mid = sol.at(x, step=1)
    assert np.allclose(mid[:, 1], (half - 1) * (x[:, 1] - T.SIDE / 2), atol=1e-9)
    assert np.allclose(sol.at(x), sol.u, atol=1e-12)
    with pytest.raises(ModelError, match="not kept"):
        sol.at(x, step=2)


def test_bonded_plates_hold_both_faces_and_frictionless_only_pins_rigid_motion():
    """Bonded plates prescribe all three components of the 50 plate nodes; frictionless plates
    prescribe only u_z there except two fixed-plate nodes that pin the rigid in-plane motion, and
    an unknown plate condition raises ModelError."""
    m = cube(5, T.SIDE, "five")
    bonded = P.dirichlet(m, "bonded", 1e-3)
    assert len(bonded) == 50 and all(None not in v for v in bonded.values())
    fr = P.dirichlet(m, "frictionless", 1e-3)
    pinned = [v for v in fr.values() if v[0] is not None or v[1] is not None]
    assert len(fr) == 50 and sorted(pinned, key=str) == [(0.0, 0.0, 0.0), (None, 0.0, 0.0)]
    with pytest.raises(ModelError, match="unknown plate"):
        P.dirichlet(m, "glued", 1e-3)


def test_static_solve_stops_at_the_given_fractions(mat):
    """A static solve with load fractions 0.25 and 1.0 calls on_step once per fraction and ends
    at the one-step solution, to 1e-9 of the largest displacement."""
    m = cube(3, 0.032, "six")
    pm = build("fem-linear", m, mat)
    bc = P.dirichlet(cube(3, T.SIDE, "six"), "bonded", 1e-3)
    seen = []
    st = pm.solve_static(bc, load_steps=[0.25, 1.0], on_step=lambda k, x: seen.append(k))
    assert seen == [1, 2]
    direct = pm.solve_static(bc, load_steps=1)
    assert np.abs(st.u - direct.u).max() < 1e-9 * np.abs(direct.u).max()


@pytest.mark.parametrize("model", ["pbcm-variational", "msm", "fem-neohookean"])
def test_bead_field_does_not_depend_on_E(tc, model):
    """Displacement control: every force scales with E, so the bead field does not move
    with it (1e-9 relative: the static solve's tolerance, 1e-10 E h^2)."""
    from cases.studies.truthcube.study import TruthCubeSettings, bead_displacements
    mesh = P.mesh(10.0)
    fields = []
    for E in (15e3, 47e3):
        u, failed = bead_displacements(model, mesh, ("bonded", "nominal", 0.499),
                                       P.nominal_travels(), B.Measured(tc).beads,
                                       TruthCubeSettings(E=E, quick=True))
        assert failed is None and len(u) == 3
        fields.append(np.array(u))
    a, b = fields
    assert np.linalg.norm(a - b) <= 1e-9 * np.linalg.norm(a)
    assert np.abs(a).max() > 5e-3                  # the 18.25 % state moved the beads


def test_settings_refuse_a_compressible_silicone(tmp_path):
    """The study's settings refuse nu = 0.3 with a ModelError, and `pbcm run truth-cube --nu 0.3`
    exits 2 without creating its output folder."""
    from cases.studies.truthcube.study import TruthCubeSettings
    with pytest.raises(ModelError, match="nearly incompressible"):
        TruthCubeSettings(nu=0.3)
    from cases.cli import main
    assert main(["run", "truth-cube", "--quick", "--nu", "0.3", "--out",
                 str(tmp_path / "x")]) == 2
    assert not (tmp_path / "x").exists()


def test_the_quick_study_holds_its_gold_and_its_controls(quick_truthcube, capsys):
    """The quick study passes `pbcm check` and holds one row per model and state on the 10 mm
    bonded mesh, each a finite RMS or a stated failure. The neo-Hookean continuum's axial layer
    profile rises toward the moving plate, and linear elasticity's gap to it grows with strain
    from below the floor at 5 %."""
    from cases.cli import main
    status = main(["check", "--metrics", str(quick_truthcube.parent), "--gold",
                   str(ROOT / "gold"), "--allow-new"])
    assert status == 0, capsys.readouterr().out
    doc = json.loads((quick_truthcube / "metrics.json").read_text())
    assert {r["mesh"] for r in doc["rows"]} == {"10mm"}
    assert {r["variant"] for r in doc["rows"]} == {"bonded"}
    # every model at every state, a number or a stated failure
    assert len(doc["rows"]) == 3 * len(doc["parameters"]["models"])
    for r in doc["rows"] + doc["references"]:
        assert r["failed"] or np.isfinite(r["bead_rms_mm"])
    # the continuum's axial profile rises from the fixed plate to the moving one, as measured
    nh = [r for r in doc["references"] if r["model"] == "neo-Hookean P2/P1"]
    assert all(np.all(np.diff(r["layer_axial_mm"]) > 0) for r in nh)
    # linear elasticity's distance from the continuum grows with the strain, from below the
    # measurement's floor at 5 % (its linearisation error)
    lin = sorted((r for r in doc["references"] if r["model"] == "linear P2"),
                 key=lambda r: r["strain"])
    gap = [r["bead_vs_continuum_mm"] for r in lin]
    assert gap == sorted(gap) and gap[0] < doc["data"]["states"][0]["floor_mm"]["total"]
    md = (quick_truthcube / "report.md").read_text()
    assert "Kerdok" in md and "noise" in md
    assert (quick_truthcube / "beads_by_layer.png").is_file()


def test_the_index_answers_and_scores_against_reality(quick_truthcube, tmp_path):
    """The index's scorecard row on the measured body comes from the study's metrics: every
    model's cell, none of it in the overall (continuum) ranking; a quick study (no variants
    of the unmeasured inputs, so no u_input) decides no answer and names the command that
    does."""
    from cases.cli import main
    from cases.registry import CASES
    for name in CASES:
        (tmp_path / name).symlink_to(ROOT / "reports" / name, target_is_directory=True)
    (tmp_path / "truth-cube").symlink_to(quick_truthcube, target_is_directory=True)
    assert main(["index", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "index.md").read_text()
    doc = json.loads((quick_truthcube / "metrics.json").read_text())
    h = doc["headline"]
    assert "**How far from a measured body?** Quick: not decided (`pbcm run truth-cube` " \
        "decides" in md
    row = next(line for line in md.splitlines()
               if line.startswith("| [truth-cube/bonded, 10mm (measured beads)]"))
    for m in doc["parameters"]["models"][:6]:       # the first table's models
        assert f"{h['models'][m]['bead_rms_rel']:.3g} at 18.25 %" in row
    assert md.index("## Scorecard") < md.index("truth-cube/bonded, 10mm")


def test_against_the_continuum_a_model_is_read_against_its_u_val():
    """A model's bead distance from the continuum is within it when at most the model's u_val
    at that state (0.45 against 0.5: yes; 0.55: no), never against the floor alone."""
    from cases.studies.truthcube.report import DEFAULT, against_continuum
    data = {"states": [{"state": 1, "strain": 0.1, "floor_mm": {"total": 0.3}}]}
    rows = [{"mesh": "5mm", "variant": DEFAULT, "model": m, "state": 1,
             "bead_vs_continuum_mm": d} for m, d in (("a", 0.45), ("b", 0.55))]
    said = against_continuum(rows, data, "5mm", {1: {"a": 0.5, "b": 0.5}})
    assert said["a"] == "within u_val at every state"
    assert said["b"].startswith("beyond u_val from")


def test_against_the_continuum_the_beads_noise_is_left_out():
    """Read against the continuum, a model's u_val loses the beads' noise (no measurement
    enters): 0.5 with a noise of 0.3 leaves 0.4, and never below 0."""
    from cases.studies.truthcube.report import without_noise
    data = {"states": [{"state": 1, "floor_mm": {"total": 0.3}}]}
    u = without_noise({1: {"a": 0.5, "b": 0.2}}, data)
    assert u[1]["a"] == pytest.approx(0.4) and u[1]["b"] == 0.0


def test_a_state_is_reproduced_within_the_models_u_val_there():
    """A run reproduces a state when its total bead RMS is at most its u_val at that state
    (1.0 against 1.2: yes; 1.3: no); a model without a u_val falls back to the floor."""
    from cases.studies.truthcube.report import verdicts
    data = {"states": [{"state": 1, "floor_mm": {"total": 0.3, "axial": 0.1, "lateral": 0.3}}]}
    rows = [{"mesh": "5mm", "variant": "bonded", "model": m, "state": 1, "bead_rms_mm": v,
             "bead_axial_rms_mm": 0.1, "bead_lateral_rms_mm": v}
            for m, v in (("a", 1.0), ("b", 1.3), ("c", 1.0))]
    v = verdicts(rows, data, {1: {"a": 1.2, "b": 1.2}})
    assert v[("5mm", "bonded", "a")] == [(1, True)]
    assert v[("5mm", "bonded", "b")] == [(1, False)]
    assert v[("5mm", "bonded", "c")] == [(1, False)]      # 1.0 is beyond one floor of noise
