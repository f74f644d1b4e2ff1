"""The named models: each a list of (term, parameters) of the term registry
(``model.terms``); ``model.compose`` reads a preset name, ``model.build`` builds one."""

# name -> list of (term, parameters); docs/model.md "Shear force" and "Mass-spring baseline"
PRESETS = {
    "pbcm-corner": [("shear", {"reading": "corner"}), ("volume", {})],
    "pbcm-balanced": [("shear", {"reading": "balanced"}), ("volume", {})],
    "pbcm-variational": [("shear", {"reading": "variational", "c": "auto"}), ("volume", {})],
    "pbcm-variational+normal": [("shear", {"reading": "variational", "c": "auto"}),
                                ("normal", {"c": "auto"}), ("volume", {})],
    "msm": [("springs", {})],
    "msm+volume": [("springs", {}), ("volume", {})],
    # docs/model.md "Explicit FEM baselines": what a user would pick instead of a particle model
    "fem-linear": [("fem_linear", {})],
    "fem-corotated": [("fem_corotated", {})],
    "fem-neohookean": [("fem_neohookean", {})],
}

__all__ = ["PRESETS"]
