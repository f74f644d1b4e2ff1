"""Force terms: a registry by name, as meshio registers formats.

A term is one module in this package that defines a :class:`Term` subclass decorated with
:func:`register`; every module here is imported on first use, so a new term is one new file.
"""
import importlib
import pkgutil

import numpy as np

from ..errors import ModelError, DegenerateTetError

TERMS = {}


def register(cls):
    """Class decorator: make ``cls`` available under ``cls.name``."""
    if cls.name in TERMS and TERMS[cls.name] is not cls:
        raise ModelError(f"force term {cls.name!r} is registered twice")
    TERMS[cls.name] = cls
    return cls


def _load_all():
    for mod in pkgutil.iter_modules(__path__):
        if not mod.name.startswith("_"):
            importlib.import_module(f"{__name__}.{mod.name}")


def make_term(name, mesh, material, **params):
    """Instantiate the registered term ``name`` on ``mesh`` with ``params``."""
    _load_all()
    if name not in TERMS:
        raise ModelError(f"unknown force term {name!r}; registered: {', '.join(sorted(TERMS))}")
    return TERMS[name](mesh, material, **params)


class Term:
    """Base class of a force term.

    Subclasses set ``name``, ``conservative`` (an energy exists and forces are its negative
    gradient) and implement ``_kernel_forces(x, out)`` (numba, adds into ``out``, returns the
    first degenerate tetrahedron or -1) and ``forces_numpy(x)`` (plain numpy, for the tests).
    ``scale`` multiplies the whole term (a testing and sensitivity knob, 1 by default).
    """

    name = ""
    conservative = False
    # parameters a user may pass, with defaults
    params = {}

    def __init__(self, mesh, material, scale=1.0, **params):
        unknown = set(params) - set(self.params)
        if unknown:
            raise ModelError(f"term {self.name!r} has no parameter(s) {', '.join(sorted(unknown))}; "
                             f"it takes {', '.join(sorted(self.params)) or 'none'} and scale")
        self.mesh, self.material, self.scale = mesh, material, float(scale)
        self.p = {**self.params, **params}

    def forces(self, x, out=None):
        """Internal forces (n, 3) at positions ``x``; added into ``out`` when given."""
        out = np.zeros_like(x) if out is None else out
        bad = self._kernel_forces(np.ascontiguousarray(x, dtype=np.float64), out)
        if bad >= 0:
            raise DegenerateTetError(
                f"tetrahedron {bad} (nodes {self.mesh.tets[bad].tolist()}) is inverted or "
                f"flattened in term {self.name!r}; reduce the load step or time step", [bad])
        return out

    def energy(self, x):
        raise ModelError(f"term {self.name!r} ({self.describe()}) has no energy: "
                         "it is not conservative")

    def describe(self):
        return self.name

    def info(self):
        """Parameters actually used (for reports)."""
        return {"scale": self.scale, **self.p}
