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
    "realtime": "cases.studies.realtime",
    "engines": "cases.studies.engines",
}

CASES = {name: importlib.import_module(module).CASE for name, module in MODULES.items()}


def studies():
    """{name: Study}, imported on first use (a study builds on the cases)."""
    return {name: importlib.import_module(module).STUDY for name, module in STUDY_MODULES.items()}


CASE_GROUP = "pbcm.cases"       # the entry-point group of cases from outside the package


def user_cases(files=()):
    """{name: Case} of the cases from outside the package: those the ``pbcm.cases`` entry
    points name (a Case instance or class each) and those the Python ``files`` declare (a
    module-level ``CASE``); never part of ``CASES`` (the library, which the test suite and
    ``pbcm report`` run). A name that clashes with the library, a study or another user case
    is refused."""
    import importlib.metadata
    out = {}

    def add(obj, where):
        from .framework import Case
        case = obj() if isinstance(obj, type) else obj
        if not isinstance(case, Case):
            raise UserCaseError(f"{where} gives {obj!r}, not a cases.framework.Case: declare "
                                "CASE = YourCase()")
        if case.name in CASES or case.name in STUDY_MODULES or case.name in out:
            raise UserCaseError(f"{where} declares the case {case.name!r}, a name already "
                                "taken (the library, a study or another case): rename it")
        out[case.name] = case
    for ep in importlib.metadata.entry_points(group=CASE_GROUP):
        try:
            obj = ep.load()
        except Exception as exc:
            raise UserCaseError(f"the {CASE_GROUP} entry point {ep.name} ({ep.value}) failed "
                                f"to import: {exc}") from exc
        add(obj, f"the {CASE_GROUP} entry point {ep.name}")
    for f in files:
        add(file_case(f), f"--case {f}")
    return out


def file_case(path):
    """The ``CASE`` a Python file declares, imported once per path; pickled as the path, so a
    worker process imports the file again (it cannot import a module that lives nowhere on
    its path)."""
    import copyreg
    import hashlib
    import importlib.util
    from pathlib import Path
    path = Path(path).resolve()
    if not path.is_file():
        raise UserCaseError(f"--case {path}: no such file; give a Python file that declares "
                            "CASE = YourCase()")
    if path in _FILE_CASES:
        return _FILE_CASES[path]
    name = "pbcm_user_case_" + hashlib.sha256(str(path).encode()).hexdigest()[:12]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        raise UserCaseError(f"--case {path} failed to import: {type(exc).__name__}: {exc}") \
            from exc
    case = getattr(module, "CASE", None)
    if case is None:
        raise UserCaseError(f"--case {path} declares no CASE: add CASE = YourCase()")
    case = case() if isinstance(case, type) else case
    copyreg.pickle(type(case), lambda c, p=str(path): (file_case, (p,)))
    _FILE_CASES[path] = case
    return case


_FILE_CASES = {}


class UserCaseError(ValueError):
    """A case from outside the package that cannot be used."""
