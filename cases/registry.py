"""The case library: name -> the module that declares it (a ``CASE``, see
``cases.framework.Case``), and the studies: name -> the module that declares a ``STUDY``
(``cases.framework.Study``). Adding a case or a study is one line here."""
import importlib

MODULES = {
    "paper-cube": "cases.library.paper_cube",
    "cantilever": "cases.library.cantilever",
    "torsion": "cases.library.torsion",
    "indentation": "cases.library.indentation",
    "large-compression": "cases.library.large_compression",
    "self-weight": "cases.library.self_weight",
    "modes": "cases.library.modes",
}
STUDY_MODULES = {
    "convergence": "cases.studies.convergence",
    "extensions": "cases.studies.extensions",
    "artefact": "cases.studies.artefact",
    "truth-cube": "cases.studies.truthcube",
}

CASES = {name: importlib.import_module(module).CASE for name, module in MODULES.items()}


def studies():
    """{name: Study}, imported on first use (a study builds on the cases)."""
    return {name: importlib.import_module(module).STUDY for name, module in STUDY_MODULES.items()}
