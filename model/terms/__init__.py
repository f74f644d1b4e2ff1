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

    What a term provides:

    ``name``, ``params``
        its registry name and the parameters a user may pass, with their defaults;
    ``conservative``
        whether an energy exists whose negative gradient the forces are;
    ``kernel()``
        ``(fn, args)``: a numba function called as ``fn(x, *args, out)`` that adds the term's
        forces at positions ``x`` (n, 3) into ``out`` (n, 3) and returns -1, or the index of
        the first element it found flattened or inverted (``degenerate_tets`` turns that index
        into tetrahedra). The compiled integrator calls it directly, with no Python between;
    ``threaded_kernel()``
        optional: the same contract run on several threads with a result equal bit for bit
        to ``kernel()`` (model.terms._threads); None, the default, runs the serial kernel;
    ``forces_numpy(x)``
        the same forces in plain numpy, written from the formula, for the tests;
    ``energy(x)``
        for a conservative term;
    ``calibrate``, ``coef``, ``unit_energy(x)`` and ``calibration_residuals(x, rows)``
        for a term whose constant is fitted (``"auto"``): ``unit_energy`` is the energy with
        ``coef`` = 1, written as ``sum_t w_t sum_k r_tk^2``, and ``calibration_residuals``
        gives ``(r, w)`` for the tetrahedra ``rows``; ``model.calibrate`` sets ``coef``.

    ``scale`` multiplies the whole term (a testing and sensitivity knob, 1 by default).
    """

    name = ""
    conservative = False
    # whether the kernel reports every tetrahedron flattened below FLAT V0 (else the
    # integrator checks the volumes itself)
    checks_inversion = False
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
        fn, args = self.kernel()
        bad = fn(np.ascontiguousarray(x, dtype=np.float64), *args, out)
        if bad >= 0:
            raise self.degenerate(bad)
        return out

    def kernel(self):
        raise NotImplementedError(f"term {self.name!r} provides no kernel")

    def threaded_kernel(self):
        return None

    def degenerate_tets(self, bad):
        """The tetrahedra behind the index a kernel returned (its own element)."""
        return [int(bad)]

    def degenerate(self, bad):
        """The error for a kernel that stopped at element ``bad``."""
        tets = self.degenerate_tets(bad)
        return DegenerateTetError(
            f"tetrahedron {tets[0]} (nodes {self.mesh.tets[tets[0]].tolist()}) is inverted or "
            f"flattened in term {self.name!r}; reduce the load step or time step", tets)

    def energy(self, x):
        raise ModelError(f"term {self.name!r} ({self.describe()}) has no energy: "
                         "it is not conservative")

    def describe(self):
        return self.name

    def info(self):
        """Parameters actually used (for reports)."""
        return {"scale": self.scale, **self.p}
