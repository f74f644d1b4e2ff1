"""The case library: name -> the module that declares it (a ``CASE``, see
``cases.framework.Case``). Adding a case is one line here."""
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

CASES = {name: importlib.import_module(module).CASE for name, module in MODULES.items()}
