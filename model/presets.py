"""The named models: each a list of (term, parameters) of the term registry
(``model.terms``); ``model.compose`` reads a preset name, ``model.build`` builds one.

``PRESETS`` are what the cases and studies run by default: every shear reading calibrated alike
(``c = "auto"``, :mod:`model.calibrate`). ``LITERAL`` are the same readings at the paper's
literal constant c = 1, by name, run where asked for (``--models pbcm-corner-literal``)."""

# name -> list of (term, parameters); docs/model.md "Shear force" and "Mass-spring baseline"
PRESETS = {
    "pbcm-corner": [("shear", {"reading": "corner", "c": "auto"}), ("volume", {})],
    "pbcm-balanced": [("shear", {"reading": "balanced", "c": "auto"}), ("volume", {})],
    "pbcm-variational": [("shear", {"reading": "variational", "c": "auto"}), ("volume", {})],
    "pbcm-variational+normal": [("shear", {"reading": "variational", "c": "auto"}),
                                ("normal_edge", {"c": "auto"}), ("volume", {})],
    "msm": [("springs", {})],
    "msm+volume": [("springs", {}), ("volume", {})],
    # docs/model.md "Explicit FEM baselines": what a user would pick instead of a particle model
    "fem-linear": [("fem_linear", {})],
    "fem-corotated": [("fem_corotated", {})],
    "fem-neohookean": [("fem_neohookean", {})],
}

LITERAL = {f"pbcm-{reading}-literal": [("shear", {"reading": reading, "c": 1.0}), ("volume", {})]
           for reading in ("corner", "balanced", "variational")}

# corotated FEM integrated by backward Euler (model.implicit) at a fixed step, as surgical
# simulators run it: a rendered frame's (1/60 s) and a haptic loop's (1 ms); run where asked for
FRAME_S, HAPTIC_S = 1.0 / 60.0, 1e-3
IMPLICIT_STEP = {"fem-corotated-implicit-frame": FRAME_S,
                 "fem-corotated-implicit-haptic": HAPTIC_S}
IMPLICIT = {name: PRESETS["fem-corotated"] for name in IMPLICIT_STEP}

# every name a model spec may use
NAMED = {**PRESETS, **LITERAL, **IMPLICIT}

__all__ = ["PRESETS", "LITERAL", "IMPLICIT", "IMPLICIT_STEP", "NAMED"]
