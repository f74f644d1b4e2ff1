"""The conformance gate: every force term, built-in, from an entry point or from a ``--term``
file, is checked against its contract (``model.terms.Term``) when it is first made with a given
set of options, before any model, case or study uses it. A term that fails is refused, with the
name of the check and the numbers.

The checks, on a small irregular mesh (the 3 x 3 x 3 six-split cube, its nodes moved by 5 % of
an edge) at a deformed state (moved again by 5 %):

- zero force at rest;
- the numba kernel equal to the term's numpy formula (``forces_numpy``);
- forces unchanged under a translation, and turned with a rigid rotation (where the term
  claims ``rotation_invariant``);
- zero net force (where it claims ``momentum``) and zero net torque (``angular_momentum``);
- for a conservative term, forces equal to the negative central-difference gradient of its
  energy.

A claim a term does not make is declared on it (``Term.momentum``, ``angular_momentum``,
``rotation_invariant``, ``conservative``), never silently skipped.
"""
import numpy as np

from .errors import ModelError
from .material import Material
from .mesh import TetMesh, cube

# the bounds: rounding where the check is exact, the central difference's truncation (the
# step 1e-6 of an edge) where it is not
EXACT = 1e-10
GRADIENT = 1e-6
FD_STEP = 1e-6
PROBE_C = 0.5              # a term whose constant is fitted ("auto") is checked at this c
_passed = set()


def probe():
    """(mesh, material, x): the irregular probe mesh at rest and a deformed state of it."""
    base = cube(3, 0.02, "six")
    h = 0.01
    rng = np.random.default_rng(20261125)
    rest = base.points + 0.05 * h * rng.standard_normal(base.points.shape)
    mesh = TetMesh(rest, base.tets)
    x = rest + 0.05 * h * rng.standard_normal(rest.shape)
    return mesh, Material(E=10e3, nu=0.3, rho=1000.0), x


def _rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _fd_gradient(energy, x, h):
    g = np.zeros_like(x)
    for i in range(x.shape[0]):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += h
            xm[i, k] -= h
            g[i, k] = (energy(xp) - energy(xm)) / (2 * h)
    return g


def checks(term, mesh, x):
    """[(check, value, bound)] of ``term`` (made on ``mesh``) at ``x``: each value a relative
    deviation that passes when at most its bound."""
    f = term.forces(x)
    bad = int(np.count_nonzero(~np.isfinite(f)))
    if bad:
        return [("finite forces at a deformed state", float("nan"),
                 f"finite ({bad} of {f.size} components are not)")]
    size = np.abs(f).max()
    if not size > 0:
        return [("forces at a deformed state", 0.0, "> 0")]
    out = [("zero force at rest", float(np.abs(term.forces(mesh.points)).max() / size),
            EXACT)]
    try:
        numpy_f = term.forces_numpy(x)
    except (AttributeError, NotImplementedError):
        out.append(("kernel equals forces_numpy", float("inf"), EXACT))
    else:
        out.append(("kernel equals forces_numpy", float(np.abs(f - numpy_f).max() / size),
                    EXACT))
    shift = np.array([0.03, -0.05, 0.02])
    out.append(("invariance under translation",
                float(np.abs(term.forces(x + shift) - f).max() / size), EXACT))
    if getattr(term, "rotation_invariant", True):
        R = _rotation([0.2, -1.0, 0.5], 1.1)
        out.append(("invariance under rotation",
                    float(np.abs(term.forces(x @ R.T + shift) - f @ R.T).max() / size), EXACT))
    if getattr(term, "momentum", True):
        out.append(("zero net force",
                    float(np.linalg.norm(f.sum(axis=0)) / np.abs(f).sum()), EXACT))
    if getattr(term, "angular_momentum", True):
        r = x - x.mean(axis=0)
        out.append(("zero net torque", float(
            np.linalg.norm(np.cross(r, f).sum(axis=0))
            / (np.linalg.norm(r, axis=1) * np.linalg.norm(f, axis=1)).sum()), EXACT))
    if term.conservative:
        h = FD_STEP * mesh.mean_edge
        g = _fd_gradient(term.energy, x, h)
        out.append(("forces equal minus the energy gradient",
                    float(np.abs(f + g).max() / size), GRADIENT))
    return out


def _show(v):
    """A check's value as text: a number, or what it is when it is not one."""
    return f"{v:.3g}" if np.isfinite(v) else f"not finite ({v})"


def _probe_params(cls, params):
    p = {**cls.params, **params}
    if p.get("c") == "auto":
        p["c"] = PROBE_C
    return p


def conform(cls, params=None):
    """Check term class ``cls`` with ``params`` (once per class and options in a process);
    raise ModelError naming every failed check with its value and bound."""
    params = dict(params or {})
    options = tuple(sorted((k, repr(v)) for k, v in params.items() if k not in ("c", "scale")))
    if (cls, options) in _passed:
        return
    mesh, material, x = probe()
    p = _probe_params(cls, {k: v for k, v in params.items() if k != "scale"})
    try:
        term = cls(mesh, material, **p)
        found = checks(term, mesh, x)
    except ModelError as exc:
        raise ModelError(f"force term {cls.name!r} failed its conformance checks: {exc}") \
            from exc
    except Exception as exc:      # a user term's own error, in its constructor or kernel
        raise ModelError(f"force term {cls.name!r} raised {type(exc).__name__} in its "
                         f"conformance checks: {exc}; fix the term") from exc
    failed = [(c, v, b) for c, v, b in found
              if isinstance(b, str) or not (np.isfinite(v) and v <= b)]
    if failed:
        given = ", ".join(f"{k}={v}" for k, v in p.items()) or "no parameters"
        raise ModelError(
            f"force term {cls.name!r} ({given}) is refused: it fails the conformance check(s) "
            + "; ".join(f"'{c}': {_show(v)} > {b:g}" if not isinstance(b, str)
                        else f"'{c}': {_show(v)}, expected {b}" for c, v, b in failed)
            + " (relative). Fix the term, or declare a claim it does not make "
            "(momentum, angular_momentum, rotation_invariant, conservative = False).")
    _passed.add((cls, options))


__all__ = ["conform", "checks", "probe"]
