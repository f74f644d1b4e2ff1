"""Floating-point operations per tetrahedron of a model's force evaluation, counted, not
estimated: its kernels run uncompiled (numba's jit disabled, in a process of its own) on numbers
that count every addition, subtraction, multiplication, division, negation and elementary
function (square root, logarithm) applied to them. A fused multiply-add counts as two, the
convention of peak rates; comparisons and index arithmetic are not floating-point work and are
not counted. The count is taken at a slightly deformed state, so that a kernel's branches are
those of a push; the counted forces are returned too, to check that the counted run is the
compiled one's arithmetic."""
import json
import math
import os
import subprocess
import sys

import numpy as np

# the bench's 'five' cube of 4^3 cells, a few seconds uncompiled: its 320 tetrahedra fill
# whole blocks (model/terms/_blocks.py), so no padded lane is counted as a tetrahedron's work
COUNT_TETS = 320
JIT_OFF = "NUMBA_DISABLE_JIT"


class Counted:
    """A float that counts the operations applied to it in ``Counted.ops``."""

    ops = 0
    __slots__ = ("v",)

    def __init__(self, v):
        self.v = float(v)

    @staticmethod
    def _f(o):
        return o.v if isinstance(o, Counted) else o

    def _op(self, v):
        Counted.ops += 1
        return Counted(v)

    def __add__(self, o):
        return self._op(self.v + Counted._f(o))

    def __radd__(self, o):
        return self._op(Counted._f(o) + self.v)

    def __sub__(self, o):
        return self._op(self.v - Counted._f(o))

    def __rsub__(self, o):
        return self._op(Counted._f(o) - self.v)

    def __mul__(self, o):
        return self._op(self.v * Counted._f(o))

    def __rmul__(self, o):
        return self._op(Counted._f(o) * self.v)

    def __truediv__(self, o):
        return self._op(self.v / Counted._f(o))

    def __rtruediv__(self, o):
        return self._op(Counted._f(o) / self.v)

    def __pow__(self, o):
        return self._op(self.v ** Counted._f(o))

    def __neg__(self):
        return self._op(-self.v)

    def __abs__(self):
        return Counted(abs(self.v))

    def sqrt(self):                  # np.sqrt on an object array element
        return self._op(math.sqrt(self.v))

    def log(self):
        return self._op(math.log(self.v))

    def __float__(self):
        return self.v

    def __lt__(self, o):
        return self.v < Counted._f(o)

    def __le__(self, o):
        return self.v <= Counted._f(o)

    def __gt__(self, o):
        return self.v > Counted._f(o)

    def __ge__(self, o):
        return self.v >= Counted._f(o)

    def __eq__(self, o):
        return self.v == Counted._f(o)

    def __hash__(self):
        return hash(self.v)


def counted(a):
    """A float array (or float) as Counted numbers; anything else as it is."""
    if isinstance(a, np.ndarray) and a.dtype == np.float64:
        out = np.empty(a.shape, dtype=object)
        for i, v in np.ndenumerate(a):
            out[i] = Counted(v)
        return out
    if isinstance(a, float):
        return Counted(a)
    if isinstance(a, tuple):
        return tuple(counted(v) for v in a)
    return a


class _CountingNumpy:
    """numpy, except that the float scratch arrays a kernel allocates hold Counted numbers, so
    that the work done on them is counted as well."""

    def __getattr__(self, name):
        return getattr(np, name)

    @staticmethod
    def empty(shape, dtype=np.float64):
        if np.dtype(dtype) != np.float64:
            return np.empty(shape, dtype)
        return counted(np.zeros(shape))

    zeros = empty

    @staticmethod
    def empty_like(a, dtype=None):
        return _CountingNumpy.empty(np.shape(a), a.dtype if dtype is None else dtype)

    zeros_like = empty_like


def count_here(name, x=None):
    """(floating-point operations per tetrahedron of ``name``'s force evaluation on the bench
    cube of COUNT_TETS, its forces (n, 3)), in this process, whose numba jit must be off."""
    from numba import config
    if not config.DISABLE_JIT:
        raise RuntimeError(f"counting needs {JIT_OFF}=1 set before numba is imported (run "
                           "`counts`, which starts a process of its own)")
    from model import build
    from ..framework import DEFAULT_MATERIAL
    from ..library.common import bench_mesh
    mesh = bench_mesh(COUNT_TETS)
    pm = build(name, mesh, DEFAULT_MATERIAL)
    if x is None:
        x = pushed(mesh.points)
    kernels = pm.kernels()
    # the kernels' modules allocate their scratch through this numpy while counting
    patched = [m for m in list(sys.modules.values())
               if getattr(m, "__name__", "").startswith("model.terms")
               and getattr(m, "np", None) is np]
    out = counted(np.zeros_like(x))
    Counted.ops = 0
    try:
        for m in patched:
            m.np = _CountingNumpy()
        for fn, args in kernels:
            fn(counted(x), *(counted(a) for a in args), out)
    finally:
        for m in patched:
            m.np = np
    forces = np.array([[Counted._f(v) for v in row] for row in out], dtype=float)
    return Counted.ops / mesh.n_tets, forces


def pushed(points):
    """The state at which operations are counted: the cube pressed 1 % and perturbed."""
    wobble = 1e-5 * np.sin(np.arange(points.size)).reshape(points.shape)
    return points * np.array([1.0, 0.99, 1.0]) + wobble * points.max()


_COUNTED = {}     # model: its count, once per process (the kernels do not change within one)


def counts(models):
    """{model: floating-point operations per tetrahedron, or None where it could not be
    counted}, counted in a process of its own with numba's jit off."""
    todo = [m for m in dict.fromkeys(models) if m not in _COUNTED]
    if todo:
        env = {**os.environ, JIT_OFF: "1"}
        got = subprocess.run([sys.executable, "-m", __name__, *todo], env=env,
                             capture_output=True, text=True, check=False)
        try:
            _COUNTED.update(json.loads(got.stdout.strip().splitlines()[-1]))
        except (ValueError, IndexError):
            _COUNTED.update({m: None for m in todo})
    return {m: _COUNTED.get(m) for m in models}


def main(models):
    out = {}
    for m in models:
        try:
            out[m] = count_here(m)[0]
        except Exception:       # a kernel that cannot run uncompiled is reported uncounted
            out[m] = None
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv[1:])
