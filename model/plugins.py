"""Plug-ins registered by name, as meshio registers formats: the force terms (``model.terms``)
and the simulators pbcm does not integrate itself (``model.simulators``).

A :class:`Registry` holds, on first use:

* every module of its own package (a new built-in is one new file there);
* every module an installed package names in its entry-point group
  (``[project.entry-points."pbcm.terms"] myterm = "mypackage.myterm"``);
* every file named in its environment variable (paths separated by ``os.pathsep``), which the
  command line's ``--term FILE`` and ``--model-file FILE`` set, so that worker processes load
  the same files.
"""
import importlib
import importlib.metadata
import importlib.util
import os
import pkgutil
from pathlib import Path

from .errors import ModelError


class Registry:
    """Classes by ``cls.name``: ``noun`` names them in messages ("force term"), ``group`` is the
    entry-point group, ``env`` the environment variable of user files, ``package`` and
    ``folder`` the built-in modules' package and folder (its modules not starting with ``_``
    and not in ``skip``), ``how`` says how a file registers one."""

    def __init__(self, noun, group, env, package, folder, how, skip=()):
        self.noun, self.group, self.env = noun, group, env
        self.package, self.folder, self.how, self.skip = package, Path(folder), how, set(skip)
        self.items = {}
        self._files = {}
        self._loaded = False

    def register(self, cls):
        """Class decorator: make ``cls`` available under ``cls.name``."""
        if cls.name in self.items and self.items[cls.name] is not cls:
            raise ModelError(f"{self.noun} {cls.name!r} is registered twice")
        self.items[cls.name] = cls
        return cls

    def load_file(self, path):
        """Import the user file ``path`` (a module that registers); return the names it
        registered. A file is imported once per process."""
        path = Path(path).resolve()
        if path in self._files:
            return self._files[path]
        if not path.is_file() or path.suffix != ".py":
            raise ModelError(f"{self.noun} file {path} does not exist or is not a .py file: "
                             f"give the path of a Python file that {self.how}")
        before = set(self.items)
        spec = importlib.util.spec_from_file_location(
            f"pbcm_user_{self.noun.split()[-1]}s.{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        try:
            spec.loader.exec_module(module)
        except ModelError:
            raise
        except Exception as exc:
            raise ModelError(f"{self.noun} file {path} failed to import: "
                             f"{type(exc).__name__}: {exc}") from exc
        new = sorted(set(self.items) - before)
        if not new:
            raise ModelError(f"{self.noun} file {path} registers no {self.noun.split()[-1]}: "
                             f"a file {self.how}")
        self._files[path] = new
        return new

    def user_files(self):
        """The files named in the environment variable."""
        return [p for p in os.environ.get(self.env, "").split(os.pathsep) if p]

    def add_user_file(self, path):
        """Load ``path`` now and name it in the environment variable (inherited by worker
        processes)."""
        names = self.load_file(path)
        files = self.user_files()
        if str(Path(path).resolve()) not in files:
            os.environ[self.env] = os.pathsep.join([*files, str(Path(path).resolve())])
        return names

    def load_all(self):
        if not self._loaded:
            for mod in pkgutil.iter_modules([str(self.folder)]):
                if not mod.name.startswith("_") and mod.name not in self.skip:
                    importlib.import_module(f"{self.package}.{mod.name}")
            for ep in importlib.metadata.entry_points(group=self.group):
                try:
                    ep.load()
                except Exception as exc:
                    raise ModelError(f"the {self.noun} package {ep.value!r} (entry point "
                                     f"{ep.name!r} of group {self.group}) failed to import: "
                                     f"{exc}") from exc
            self._loaded = True
        for f in self.user_files():
            self.load_file(f)

    def registered(self):
        """Every registered class by name (built-in, entry points and user files)."""
        self.load_all()
        return dict(self.items)
