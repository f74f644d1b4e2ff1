"""The case library: name -> the module that declares it (a ``CASE``, see
``cases.framework.Case``). Adding a case is one line here."""
import importlib

MODULES = {
    "paper-cube": "cases.library.paper_cube",
}

CASES = {name: importlib.import_module(module).CASE for name, module in MODULES.items()}
