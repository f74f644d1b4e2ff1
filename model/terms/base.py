"""The contracts of a force term: :class:`Term` and, for a term with a fitted constant,
:class:`CalibratedTerm`."""
import numpy as np

from ..errors import DegenerateTetError, ModelError


class Term:
    """Base class of a force term.

    What a term provides:

    ``name``, ``params``
        its registry name and the parameters a user may pass, with their defaults;
    ``conservative``
        whether an energy exists whose negative gradient the forces are;
    ``momentum``, ``angular_momentum``, ``rotation_invariant``
        the claims the conformance gate (``model.conformance``) checks: zero net force, zero
        net torque, forces turned with a rigid rotation (True by default: a term that does
        not make one says so);
    ``kernel()``
        ``(fn, args)``: a numba function called as ``fn(x, *args, out)`` that adds the term's
        forces at positions ``x`` (n, 3) into ``out`` (n, 3) and returns -1, or the index of
        the first element it found flattened or inverted (``degenerate_tets`` turns that index
        into tetrahedra). The compiled integrator calls it directly, with no Python between;
    ``reference_kernel()``
        optional: ``(fn, args)`` of a plainer kernel with the same contract whose forces the
        kernel's equal to round-off (a built-in term's former, tetrahedron-by-tetrahedron
        kernel, kept for the tests); None, the default, where there is none;
    ``threaded_kernel()``
        optional: the same contract run on several threads with a result equal bit for bit
        to ``kernel()`` (model.terms._threads); None, the default, runs the serial kernel;
    ``fuse(other)``
        optional: a :class:`Fused` unit whose one kernel adds this term's forces and those of
        ``other``, a later term of the same model, in one pass over the tetrahedra (equal to
        the two kernels to round-off); None, the default, where it cannot;
    ``forces_numpy(x)``
        the same forces in plain numpy, written from the formula, for the tests;
    ``tangent(x)``
        optional: d forces / d x (sparse, 3n x 3n) in closed form; where every term of a
        model has one, its Newton solves and implicit steps use them instead of a coloured
        finite difference;
    ``energy(x)``
        for a conservative term;
    ``calibrate``, ``coef``, ``unit_energy(x)`` and ``calibration_residuals(x, rows)``
        the calibration hooks, for a term whose constant ``c="auto"`` is fitted when the
        model is built (:class:`CalibratedTerm` provides all but the residuals):
        ``calibrate`` is true while ``coef`` awaits the fit; ``unit_energy`` is the energy with
        ``coef`` = 1, written as ``sum_t w_t sum_k r_tk^2``; ``calibration_residuals`` gives
        ``(r, w)`` for the tetrahedra ``rows``. ``model.calibrate`` then sets every ``coef``
        at once by non-negative least squares on the quadratic forms of the unit energies
        under homogeneous deviatoric strain, against the isotropic ``G |dev eps|^2 V``;
    ``fit_constant``
        the name under which ``pbcm fit`` reports the term's fitted constant (``"c"``,
        ``"c_n"``, ``"k_scale"``), or None for a term with nothing to fit (the volume term:
        its constant is the material's K). The fit varies ``scale``, so the constant
        reported is ``scale * coef`` for a calibrated term and ``scale`` otherwise.

    ``scale`` multiplies the whole term (a testing and sensitivity knob, 1 by default).
    """

    name = ""
    conservative = False
    momentum = True
    angular_momentum = True
    rotation_invariant = True
    # whether the kernel reports every tetrahedron flattened below FLAT V0 (else the
    # integrator checks the volumes itself)
    checks_inversion = False
    # parameters a user may pass, with defaults
    params = {}
    # what `pbcm fit` calls the constant it fits (None: nothing to fit)
    fit_constant = None
    # true while the constant ``c = "auto"`` awaits model.calibrate (which sets ``coef``)
    calibrate = False

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

    def reference_kernel(self):
        return None

    def fuse(self, other):
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


class CalibratedTerm(Term):
    """A term ``W = scale * coef * unit_energy`` whose ``c`` is ``"auto"`` (fitted by
    ``model.calibrate`` when the model is built, on ``unit_energy``) or a positive number. A
    subclass provides ``kernel_args(k)`` (the kernel and its arguments for the factor ``k =
    scale * coef``), ``calibration_residuals(x, rows)`` and ``forces_numpy``; ``unit_energy``
    follows. Conservative unless the subclass says not (a shear reading whose forces are not
    W's gradient: then W is only what the calibration fits, and ``energy`` is refused)."""

    conservative = True
    params = {"c": "auto"}
    fit_constant = "c_n"

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        c = self.p["c"]
        if c != "auto" and not (isinstance(c, (int, float)) and not isinstance(c, bool)
                                and np.isfinite(c) and c > 0):
            raise ModelError(f"{self.name} c must be 'auto' or a positive number, got {c!r}")
        self.coef = None if c == "auto" else float(c)
        self.calibrate = c == "auto"
        self.G = material.G        # scale multiplies forces and energy after calibration
        self.vol0 = mesh.volumes

    def info(self):
        return {**super().info(), "c": self.coef}

    def kernel(self):
        if self.coef is None:
            raise ModelError(f"{self.name} term with c='auto' is not calibrated yet: build the "
                             "model with model.build, or pass a number for c")
        return self.kernel_args(self.scale * self.coef)

    def kernel_args(self, k):
        raise NotImplementedError

    def calibration_residuals(self, x, rows):
        raise NotImplementedError

    def unit_energy(self, x):
        r, w = self.calibration_residuals(np.ascontiguousarray(x, dtype=np.float64),
                                          slice(None))
        return float(np.sum(w * np.sum(r.reshape(len(w), -1) ** 2, axis=1)))

    def energy(self, x):
        return self.scale * self.coef * self.unit_energy(x)


class Fused:
    """Two terms of a model whose forces one kernel computes in one pass (``Term.fuse``): what
    a model runs in their place, with a term's kernel contract. A flattened tetrahedron is
    reported as the first term's (the fused terms test flattening alike)."""

    def __init__(self, first, second, kernel, threaded_kernel):
        self.terms = (first, second)
        self.name = f"{first.name} + {second.name}"
        self.checks_inversion = first.checks_inversion or second.checks_inversion
        self._kernel, self._threaded = kernel, threaded_kernel

    def kernel(self):
        return self._kernel()

    def threaded_kernel(self):
        return self._threaded(self)

    def degenerate_tets(self, bad):
        return self.terms[0].degenerate_tets(bad)

    def degenerate(self, bad):
        return self.terms[0].degenerate(bad)


def fused_units(terms):
    """The kernel units of a model's ``terms``, in order: a term, or a :class:`Fused` unit
    where a term fuses with a later one (which is then not run on its own)."""
    units, taken = [], set()
    for i, term in enumerate(terms):
        if i in taken:
            continue
        unit = term
        for j in range(i + 1, len(terms)):
            if j not in taken and (fused := term.fuse(terms[j])) is not None:
                taken.add(j)
                unit = fused
                break
        units.append(unit)
    return units
