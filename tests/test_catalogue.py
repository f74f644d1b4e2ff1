"""The metric catalogue: every metric the suite writes is declared once, with a
unit, a gate direction, a label and a definition; what the reports and the gate say about a
metric comes from there."""
import json
from pathlib import Path

import pytest

from cases.measuring import catalogue
from cases.measuring.catalogue import CATALOGUE, DESCRIPTORS, err_name, metric, ref_name
from cases.registry import CASES, studies
from cases.reporting.report import read_study

ROOT = Path(__file__).resolve().parents[1]
# the sections of a metrics.json whose rows carry metrics
ROW_SECTIONS = ("runs", "gate_runs", "case_runs", "fits", "elasticity", "cells", "lines",
                "rows", "references", "manufactured", "patch", "steps")


def _rows(data):
    for section in ROW_SECTIONS:
        rows = data.get(section)
        if isinstance(rows, list):
            yield from (r for r in rows if isinstance(r, dict))


def undeclared(data):
    """The keys of a metrics document's rows and gated set that are neither metrics of the
    catalogue nor descriptors."""
    keys = {k for r in _rows(data) for k in r} | set(data.get("gated", {}))
    return sorted(k for k in keys if k not in DESCRIPTORS and not catalogue.known(k))


@pytest.mark.parametrize("path", sorted(ROOT.glob("reports/*/metrics.json")),
                         ids=lambda p: p.parent.name)
def test_every_committed_metric_is_declared(path):
    """Every key of a committed record's rows (its metrics.json and the files beside it) is a
    declared metric or a descriptor, and each gated metric has its declared direction."""
    study = studies().get(path.parent.name)
    data = read_study(path.parent, study) if study else json.loads(path.read_text())
    assert undeclared(data) == []
    for name, direction in data.get("gated", {}).items():
        assert metric(name).direction == direction, name


def test_an_undeclared_key_is_caught():
    """A row key that is neither a catalogue metric nor a descriptor is reported as undeclared, and
    looking it up as a metric raises a KeyError that says to declare it in the catalogue."""
    data = {"runs": [{"mesh": "five", "model": "x", "disp_rel_l2_p2": 0.1,
                      "wobble_index": 3.0}], "gated": {"disp_rel_l2_p2": "max"}}
    assert undeclared(data) == ["wobble_index"]
    with pytest.raises(KeyError, match="declare it in cases/measuring/catalogue.py"):
        metric("wobble_index")


def test_a_metric_name_carries_the_suffix_of_its_declared_unit():
    """A metric's unit suffix agrees with its declared unit: a suffix naming another unit, a
    unit without its suffix and a ratio with one are refused by name; the longest suffix a
    name ends with is its unit's."""
    with pytest.raises(ValueError, match="name it with the suffix '_pa'"):
        catalogue.Metric("stiffness_Pa", "Pa", "k", "a stiffness")
    with pytest.raises(ValueError, match="name it with the suffix '_n'"):
        catalogue.Metric("force_n_steps", "N", "f", "a force per step")
    with pytest.raises(ValueError, match="name it with no unit suffix"):
        catalogue.Metric("ratio_mm", "1", "r", "a ratio")
    # the longest suffix counts: a rate in 1/s is not a time in s
    assert catalogue.unit_suffix("growth_rate_1_s") == "_1_s"
    assert ref_name("growth_rate_1_s") == "growth_rate_fem_1_s"
    assert catalogue.Metric("growth_rate_1_s", "1/s", "g", "a rate").unit == "1/s"


def test_twins_and_errors_are_derived_from_a_quantity():
    """A quantity's FEM twin name puts _fem before the unit suffix and its error name replaces the
    unit suffix with _rel_err; the twin keeps the unit and has no gate direction, and the error
    is dimensionless and gated from above (max)."""
    assert ref_name("bulge_profile_mm") == "bulge_profile_fem_mm"
    assert ref_name("paper_pattern") == "paper_pattern_fem"
    assert err_name("tip_deflection_mm") == "tip_deflection_rel_err"
    assert err_name("torque_nm") == "torque_rel_err"
    twin = metric("tip_deflection_fem_mm")
    assert twin.unit == "mm" and twin.direction is None
    err = metric("warping_rel_err")
    assert err.unit == "1" and err.direction == "max"


def test_every_declaration_is_complete():
    """Every catalogue entry carries its own name, a unit, a label, a definition ending in a full
    stop and a direction among None, max, min and signed, and is no descriptor; an unknown
    direction, a differing second declaration and gating a metric with no direction are refused."""
    for name, m in CATALOGUE.items():
        assert m.name == name and m.unit and m.label and m.definition.endswith("."), name
        assert m.direction in (None, "max", "min", "signed")
        assert name not in DESCRIPTORS
    with pytest.raises(ValueError, match="direction"):
        catalogue.Metric("x", "1", "x", "x.", direction="up")
    with pytest.raises(ValueError, match="declared twice, differently"):
        catalogue.declare("alternation_rel", "1", "alternation", "another meaning.")
    with pytest.raises(ValueError, match="no gate direction"):
        catalogue.gated("disp_max_rel_p1")


def test_correlations_are_gated_from_below_and_errors_from_above():
    """In the standard gated set exactly the stress correlations (stress_corr, stress_force_corr)
    are gated from below (min), and every other metric is gated from above (max)."""
    # the metrics gated from below: a correlation falls when the model gets worse
    corr = {"stress_corr", "stress_force_corr"}
    assert {n for n, d in catalogue.STANDARD_GATED.items() if d == "min"} == corr
    assert {d for n, d in catalogue.STANDARD_GATED.items() if n not in corr} == {"max"}


def test_headers_show_units_where_they_are_not_ratios():
    """A metric's header shows its display unit unless it is a ratio: a reaction in N is headed and
    printed in mN, a relative L2 error has no unit, a count prints as an integer and a missing
    value as n/a."""
    assert metric("reaction_n").header == "reaction [mN]"
    assert metric("reaction_n").cell(0.0123) == "12.3"
    assert metric("disp_rel_l2_p2").header == "disp L2 P2"
    assert metric("rigid_modes").cell(6) == "6"
    assert metric("alternation_rel").cell(None) == "n/a"


def test_cases_and_studies_gate_declared_metrics():
    """Every headline, gated, column and QoI-error metric of every case is declared; the studies are
    exactly convergence, extensions, artefact, truth-cube, realtime and engines, and each metric a study
    gates has the direction the catalogue declares for it."""
    for case in CASES.values():
        for name in (case.headline, *case.gated, *case.columns, *case.qoi_errors):
            metric(name)
    from cases.studies.convergence.report import GATED as CONVERGENCE
    from cases.studies.extensions.report import GATED as EXTENSIONS
    from cases.studies.artefact.report import GATED as ARTEFACT
    from cases.studies.truthcube.report import GATED as TRUTHCUBE
    from cases.studies.realtime.report import GATED as REALTIME
    from cases.studies.engines.report import GATED as ENGINES
    assert set(studies()) == {"convergence", "extensions", "artefact", "truth-cube", "realtime",
                              "engines"}
    for gated in (CONVERGENCE, EXTENSIONS, ARTEFACT, TRUTHCUBE, REALTIME, ENGINES):
        for name, direction in gated.items():
            assert metric(name).direction == direction
