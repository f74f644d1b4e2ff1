"""The force terms' registry by name: built-in modules of this package, installed packages in
the entry-point group ``pbcm.terms`` and user term files (``PBCM_TERMS``, ``pbcm --term``),
each loaded on first use."""
import importlib
import importlib.metadata
import importlib.util
import os
import pkgutil
from pathlib import Path

from ..errors import ModelError

TERMS = {}


def register(cls):
    """Class decorator: make ``cls`` available under ``cls.name``."""
    if cls.name in TERMS and TERMS[cls.name] is not cls:
        raise ModelError(f"force term {cls.name!r} is registered twice")
    TERMS[cls.name] = cls
    return cls


ENTRY_POINT_GROUP = "pbcm.terms"
_loaded_files = {}


def load_file(path):
    """Import the user term file ``path`` (a module that registers terms); return the names
    it registered. A file is imported once per process."""
    path = Path(path).resolve()
    if path in _loaded_files:
        return _loaded_files[path]
    if not path.is_file() or path.suffix != ".py":
        raise ModelError(f"term file {path} does not exist or is not a .py file: give the "
                         "path of a Python file that registers a term with @register")
    before = set(TERMS)
    spec = importlib.util.spec_from_file_location(f"pbcm_user_terms.{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except ModelError:
        raise
    except Exception as exc:
        raise ModelError(f"term file {path} failed to import: {type(exc).__name__}: {exc}") \
            from exc
    new = sorted(set(TERMS) - before)
    if not new:
        raise ModelError(f"term file {path} registers no term: decorate a Term subclass "
                         "with @model.terms.register")
    _loaded_files[path] = new
    return new


def user_files():
    """The term files named in ``PBCM_TERMS``."""
    return [p for p in os.environ.get("PBCM_TERMS", "").split(os.pathsep) if p]


def add_user_file(path):
    """Load ``path`` now and name it in ``PBCM_TERMS`` (inherited by worker processes)."""
    names = load_file(path)
    files = user_files()
    if str(Path(path).resolve()) not in files:
        os.environ["PBCM_TERMS"] = os.pathsep.join([*files, str(Path(path).resolve())])
    return names


_packages_loaded = []


def _load_all():
    if not _packages_loaded:
        for mod in pkgutil.iter_modules([str(Path(__file__).parent)]):
            if not mod.name.startswith("_") and mod.name not in ("base", "registry"):
                importlib.import_module(f"{__package__}.{mod.name}")
        for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
            try:
                ep.load()
            except Exception as exc:
                raise ModelError(f"the term package {ep.value!r} (entry point {ep.name!r} of "
                                 f"group {ENTRY_POINT_GROUP}) failed to import: {exc}") from exc
        _packages_loaded.append(True)
    for f in user_files():
        load_file(f)


def registered():
    """Every registered term class by name (built-in, entry points and term files)."""
    _load_all()
    return dict(TERMS)


def make_term(name, mesh, material, **params):
    """Instantiate the registered term ``name`` on ``mesh`` with ``params``, after its
    conformance checks (``model.conformance``: once per term and options in a process)."""
    from ..conformance import conform
    _load_all()
    if name not in TERMS:
        raise ModelError(f"unknown force term {name!r}; registered: {', '.join(sorted(TERMS))}")
    conform(TERMS[name], params)
    try:
        return TERMS[name](mesh, material, **params)
    except ModelError:
        raise
    except Exception as exc:      # a user term's own error on this mesh
        raise ModelError(f"force term {name!r} raised {type(exc).__name__} when made on a mesh "
                         f"of {mesh.n_tets} tetrahedra: {exc}; fix the term") from exc
