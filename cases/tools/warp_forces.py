"""The internal forces of pbcm's presets as NVIDIA Warp kernels, in float32 and float64, on any
Warp device: what `pbcm bench --device` times, so that the suite can state GPU costs.

Each term is one kernel over its elements (tetrahedra, or edges for the springs) that adds its
forces into the nodes with ``atomic_add``; a preset's evaluation is its terms' kernels launched
one after the other into one force array. The laws are pbcm's own (model/terms/):

* ``fem_linear``: small-strain constant-strain tetrahedra (``fem.linear_forces``);
* ``volume``: p = -K (V - V0) / V, f_i = p dV/dx_i (``volume.volume_forces``);
* ``springs``: van Gelder's edge springs of msm (``springs.spring_forces``);
* ``normal_edge``: the per-corner edge-strain deviation (``normal_edge.normal_block``);
* ``shear``: the three readings, written from the per-tetrahedron maths that
  ``model/terms/_shear_codegen.py`` writes for numba, translated line by line into a Warp
  kernel, so the two cannot drift apart.

Run as a script it times every covered preset on one device and checks its forces against
pbcm's numba kernels on that device:

    python -m cases.tools.warp_forces --device cuda --sizes 1e4 1e5 1e6 --out DIR
"""
import argparse
import functools
import hashlib
import importlib.util
import json
import os
import re
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import warp as wp
from numba import njit

from model.integrate import total_forces
from model.terms.volume import FLAT

from ..framework import DEFAULT_MATERIAL
from ..library.common import bench_mesh

wp.config.quiet = True
if hasattr(wp.config, "log_level"):      # newer Warp logs its start-up and module loads at INFO
    wp.config.log_level = getattr(wp, "LOG_WARNING", 30)

DTYPES = ("float32", "float64")
# the terms written as Warp kernels; a model of these terms alone is covered
TERMS = ("fem_linear", "volume", "springs", "shear", "normal_edge")
COVERED = ("fem-linear", "msm", "msm+volume", "pbcm-corner", "pbcm-balanced",
           "pbcm-variational", "pbcm-variational+normal")
NOT_COVERED = ("fem-corotated", "fem-neohookean")
NO_ELEMENT = np.iinfo(np.int32).max      # a kernel's flattened-element flag when none is


def _types(dtype):
    if dtype not in DTYPES:
        raise ValueError(f"dtype must be one of {', '.join(DTYPES)}, got {dtype!r}")
    if dtype == "float32":
        return np.float32, wp.float32, wp.vec3f, wp.mat33f
    return np.float64, wp.float64, wp.vec3d, wp.mat33d


@functools.lru_cache(maxsize=None)
def kernels(dtype):
    """The hand-written kernels of one precision (Warp closures over the scalar type)."""
    _, scalar, vec, mat = _types(dtype)
    flat = float(FLAT)

    @wp.kernel
    def fem_linear(x: wp.array(dtype=vec), tets: wp.array2d(dtype=wp.int32),
                   Dinv: wp.array(dtype=mat), vol0: wp.array(dtype=scalar), lam: scalar,
                   mu: scalar, out: wp.array(dtype=vec), bad: wp.array(dtype=wp.int32)):
        """P = 2 mu eps + lam tr(eps) I, eps = sym(F) - I; H = -V0 P Dm^-T: its columns are
        the forces on corners 1..3, corner 0 takes minus their sum."""
        t = wp.tid()
        i, j, k, l = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]
        x0 = x[i]
        F = wp.matrix_from_cols(x[j] - x0, x[k] - x0, x[l] - x0) * Dinv[t]
        if wp.determinant(F) <= scalar(flat):
            wp.atomic_min(bad, 0, t)
            return
        eye = wp.identity(n=3, dtype=scalar)
        eps = scalar(0.5) * (F + wp.transpose(F)) - eye
        P = scalar(2.0) * mu * eps + lam * wp.trace(eps) * eye
        H = -vol0[t] * P * wp.transpose(Dinv[t])
        f1 = vec(H[0, 0], H[1, 0], H[2, 0])
        f2 = vec(H[0, 1], H[1, 1], H[2, 1])
        f3 = vec(H[0, 2], H[1, 2], H[2, 2])
        wp.atomic_add(out, i, -(f1 + f2 + f3))
        wp.atomic_add(out, j, f1)
        wp.atomic_add(out, k, f2)
        wp.atomic_add(out, l, f3)

    @wp.kernel
    def volume(x: wp.array(dtype=vec), tets: wp.array2d(dtype=wp.int32),
               vol0: wp.array(dtype=scalar), K: scalar, out: wp.array(dtype=vec),
               bad: wp.array(dtype=wp.int32)):
        """f_i = p dV/dx_i, p = -K (V - V0) / V; c_j = d(6V)/dx_j."""
        t = wp.tid()
        n0, n1, n2, n3 = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]
        x0 = x[n0]
        d01, d02, d03 = x[n1] - x0, x[n2] - x0, x[n3] - x0
        c1, c2, c3 = wp.cross(d02, d03), wp.cross(d03, d01), wp.cross(d01, d02)
        V6 = wp.dot(d01, c1)
        if V6 <= scalar(flat) * scalar(6.0) * vol0[t]:
            wp.atomic_min(bad, 0, t)
            return
        p6 = -K * (V6 - scalar(6.0) * vol0[t]) / (scalar(6.0) * V6)
        wp.atomic_add(out, n0, -p6 * (c1 + c2 + c3))
        wp.atomic_add(out, n1, p6 * c1)
        wp.atomic_add(out, n2, p6 * c2)
        wp.atomic_add(out, n3, p6 * c3)

    @wp.kernel
    def springs(x: wp.array(dtype=vec), edge: wp.array2d(dtype=wp.int32),
                rest: wp.array(dtype=scalar), k: wp.array(dtype=scalar),
                out: wp.array(dtype=vec), bad: wp.array(dtype=wp.int32)):
        """f = k (l - l0) along every edge; tension pulls j towards i."""
        s = wp.tid()
        i, j = edge[s, 0], edge[s, 1]
        d = x[j] - x[i]
        ln = wp.length(d)
        if ln <= scalar(0.0):
            wp.atomic_min(bad, 0, s)
            return
        f = (k[s] * (ln - rest[s]) / ln) * d
        wp.atomic_add(out, i, f)
        wp.atomic_sub(out, j, f)

    @wp.kernel
    def normal(x: wp.array(dtype=vec), tets: wp.array2d(dtype=wp.int32),
               vol0: wp.array(dtype=scalar), inv_rest: wp.array2d(dtype=scalar),
               coef_G: scalar, out: wp.array(dtype=vec), bad: wp.array(dtype=wp.int32)):
        """Edge pq carries f_p += S_pq d_pq, f_q -= S_pq d_pq with S_pq = 2 c_n G V0
        (2 eps_pq - mean_p - mean_q) / (R_pq L_pq), mean_a the mean strain at corner a."""
        t = wp.tid()
        n0, n1, n2, n3 = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]
        x0, x1, x2, x3 = x[n0], x[n1], x[n2], x[n3]
        d01, d02, d03 = x1 - x0, x2 - x0, x3 - x0
        d12, d13, d23 = x2 - x1, x3 - x1, x3 - x2
        l01, l02, l03 = wp.dot(d01, d01), wp.dot(d02, d02), wp.dot(d03, d03)
        l12, l13, l23 = wp.dot(d12, d12), wp.dot(d13, d13), wp.dot(d23, d23)
        if wp.min(wp.min(wp.min(l01, l02), wp.min(l03, l12)), wp.min(l13, l23)) <= scalar(0.0):
            wp.atomic_min(bad, 0, t)
            return
        one = scalar(1.0)
        iL01, iL02, iL03 = one / wp.sqrt(l01), one / wp.sqrt(l02), one / wp.sqrt(l03)
        iL12, iL13, iL23 = one / wp.sqrt(l12), one / wp.sqrt(l13), one / wp.sqrt(l23)
        r01, r02, r03 = inv_rest[t, 0], inv_rest[t, 1], inv_rest[t, 2]
        r12, r13, r23 = inv_rest[t, 3], inv_rest[t, 4], inv_rest[t, 5]
        e01, e02, e03 = l01 * iL01 * r01 - one, l02 * iL02 * r02 - one, l03 * iL03 * r03 - one
        e12, e13, e23 = l12 * iL12 * r12 - one, l13 * iL13 * r13 - one, l23 * iL23 * r23 - one
        third = scalar(3.0)
        m0 = (e01 + e02 + e03) / third
        m1 = (e01 + e12 + e13) / third
        m2 = (e02 + e12 + e23) / third
        m3 = (e03 + e13 + e23) / third
        k = scalar(2.0) * coef_G * vol0[t]
        two = scalar(2.0)
        S01 = k * (two * e01 - m0 - m1) * r01 * iL01
        S02 = k * (two * e02 - m0 - m2) * r02 * iL02
        S03 = k * (two * e03 - m0 - m3) * r03 * iL03
        S12 = k * (two * e12 - m1 - m2) * r12 * iL12
        S13 = k * (two * e13 - m1 - m3) * r13 * iL13
        S23 = k * (two * e23 - m2 - m3) * r23 * iL23
        wp.atomic_add(out, n0, S01 * d01 + S02 * d02 + S03 * d03)
        wp.atomic_add(out, n1, -S01 * d01 + S12 * d12 + S13 * d13)
        wp.atomic_add(out, n2, -S02 * d02 - S12 * d12 + S23 * d23)
        wp.atomic_add(out, n3, -S03 * d03 - S13 * d13 - S23 * d23)

    return SimpleNamespace(fem_linear=fem_linear, volume=volume, springs=springs,
                           normal=normal, shear=_shear_module(dtype))


# --- the shear readings, from model/terms/_shear_codegen.py ----------------------------------

_SHEAR_HEAD = '''"""Written by cases/tools/warp_forces.py from model/terms/_shear_codegen.py: the shear
readings' per-tetrahedron maths as Warp kernels ({dtype})."""
import warp as wp

SCALAR = wp.{dtype}
VEC = wp.vec3{suffix}


# named apart from Warp's builtins (sub, dot, cross), which a same-named function would shadow
@wp.func
def vsub(a: VEC, b: VEC):
    return a - b


@wp.func
def vaxpy(k: SCALAR, a: VEC, y: VEC):
    return y + k * a


@wp.func
def vlin(p: SCALAR, a: VEC, q: SCALAR, b: VEC):
    return p * a + q * b
'''

_CALLS = {"sub": "vsub", "dot": "wp.dot", "cross": "wp.cross", "axpy": "vaxpy", "lin": "vlin"}
_LITERAL = re.compile(r"(?<![\w.\]])(\d+\.\d*(?:[eE][-+]?\d+)?)")


def _top_level_commas(text):
    depth, count = 0, 0
    for ch in text:
        depth += (ch in "([") - (ch in ")]")
        count += ch == "," and depth == 0
    return count


def _warp_line(line):
    """One line of the numba per-tetrahedron maths as Warp reads it: typed float literals,
    3-tuples as vectors, Warp's square root."""
    indent, body = line[:len(line) - len(line.lstrip())], line.strip()
    body = body.replace("(0.0, 0.0, 0.0)", "VEC()").replace("np.sqrt(", "wp.sqrt(")
    for numba_name, warp_name in _CALLS.items():
        body = re.sub(rf"\b{numba_name}\(", f"{warp_name}(", body)
    m = re.fullmatch(r"(\w+) = \((.*)\)", body)
    if m and _top_level_commas(m.group(2)) == 2:
        body = f"{m.group(1)} = VEC({m.group(2)})"
    body = _LITERAL.sub(r"SCALAR(\1)", body)
    body = re.sub(r"\bFLAT\b", f"SCALAR({float(FLAT)!r})", body)
    return indent + body


def shear_source(dtype):
    """The text of the Warp module holding ``shear_corner``, ``shear_balanced`` and
    ``shear_variational`` in ``dtype``."""
    from model.terms import _shear_codegen as cg
    variant = {**cg.SERIAL,
               "n0, n1, n2, n3 = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]":
               [f"n{c} = tets[t, {c}]" for c in range(4)],
               "x0, x1, x2, x3 = vec(x, n0), vec(x, n1), vec(x, n2), vec(x, n3)":
               [f"x{c} = x[n{c}]" for c in range(4)],
               cg.FLATTENED_ACTION: ["    wp.atomic_min(bad, 0, t)", "    return"],
               cg.SCATTER: [f"wp.atomic_add(out, n{c}, f{c})" for c in range(4)]}
    parts = [_SHEAR_HEAD.format(dtype=dtype, suffix=dtype[-2:] == "64" and "d" or "f")]
    for name, args, doc, before, per_tet in (cg.corner(), cg.balanced(), cg.variational()):
        factor = args.split(", ")[-2]        # G or cG
        parts.append("\n".join(
            ["", "", "@wp.kernel",
             f"def {name}(x: wp.array(dtype=VEC), tets: wp.array2d(dtype=wp.int32), "
             "vol0: wp.array(dtype=SCALAR), gamma0: wp.array2d(dtype=SCALAR), "
             f"{factor}: SCALAR, out: wp.array(dtype=VEC), bad: wp.array(dtype=wp.int32)):",
             f'    """{doc}"""', "    t = wp.tid()"]
            + ["    " + _warp_line(x) for x in before]
            + ["    " + _warp_line(x) for x in cg.expand(per_tet, variant)]))
    return "\n".join(parts) + "\n"


def _shear_module(dtype):
    """The shear kernels' module, written to a file (Warp reads a kernel's source) named by
    its text's hash, so that a changed codegen never meets a stale file."""
    text = shear_source(dtype)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    name = f"pbcm_warp_shear_{dtype}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    folder = Path(tempfile.gettempdir()) / "pbcm-warp"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.py"
    if not path.is_file() or path.read_text() != text:
        # written beside and renamed: a concurrent process never reads half a file
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


# --- one evaluation of a built model ---------------------------------------------------------

def covered(pm):
    """Whether every term of the built model ``pm`` has a Warp kernel here."""
    return all(t.name in TERMS for t in pm.terms)


class WarpForces:
    """One evaluation of a built model's internal forces (the sum of its terms) at positions
    ``x`` by Warp kernels on ``device`` in ``dtype`` (``"float32"`` or ``"float64"``).

    ``launch()`` enqueues one evaluation (what a timing repeats); calling the object launches
    and waits; ``forces()`` returns them as float64 numpy (n, 3) [N], an error where an element
    is flattened or collapsed."""

    def __init__(self, pm, x, device="cpu", dtype="float64"):
        if not covered(pm):
            missing = sorted({t.name for t in pm.terms} - set(TERMS))
            raise ValueError(f"model {pm.name!r} has terms without a Warp kernel: "
                             f"{', '.join(missing)}")
        self.device = wp.get_device(device)
        self.np_dtype, scalar, vec, mat = _types(dtype)
        self.dtype, self.pm, self.n_tets = dtype, pm, pm.mesh.n_tets
        k = kernels(dtype)
        tets = self._array(pm.mesh.tets.astype(np.int32), wp.int32)
        self.x = self._array(np.asarray(x, dtype=self.np_dtype), vec)
        self.f = wp.zeros(pm.mesh.n_nodes, dtype=vec, device=self.device)
        self.launches = []
        for term in pm.terms:
            if term.name == "fem_linear":
                self._add(k.fem_linear, term, tets, self._array(term.Dinv, mat),
                          self._array(term.vol0, scalar), scalar(term.lam), scalar(term.mu))
            elif term.name == "volume":
                self._add(k.volume, term, tets, self._array(term.vol0, scalar), scalar(term.K))
            elif term.name == "springs":
                self._add(k.springs, term, self._array(term.edge.astype(np.int32), wp.int32),
                          self._array(term.rest, scalar), self._array(term.k, scalar))
            elif term.name == "shear":
                _, vol0, gamma0, factor = term.reference_kernel()[1]
                fn = getattr(k.shear, f"shear_{term.p['reading']}")
                self._add(fn, term, tets, self._array(vol0, scalar),
                          self._array(gamma0, scalar), scalar(factor))
            else:       # normal_edge
                coef_G = term.kernel()[1][-1]
                p = pm.mesh.points[pm.mesh.tets]
                pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                inv_rest = 1.0 / np.stack([np.linalg.norm(p[:, b] - p[:, a], axis=1)
                                           for a, b in pairs], axis=1)
                self._add(k.normal, term, tets, self._array(term.vol0, scalar),
                          self._array(inv_rest, scalar), scalar(coef_G))

    def _array(self, a, dtype):
        a = np.ascontiguousarray(a, dtype=np.int32 if dtype is wp.int32 else self.np_dtype)
        return wp.array(a, dtype=dtype, device=self.device)

    def _add(self, kernel, term, elements, *args):
        dim = elements.shape[0]
        bad = wp.full(1, NO_ELEMENT, dtype=wp.int32, device=self.device)
        self.launches.append((kernel, dim, [elements, *args], bad, term))

    def set_positions(self, x):
        self.x.assign(np.asarray(x, dtype=self.np_dtype))

    def launch(self):
        """Enqueue one evaluation into ``self.f`` (no wait)."""
        self.f.zero_()
        for kernel, dim, args, bad, _ in self.launches:
            wp.launch(kernel, dim=dim, inputs=[self.x, *args, self.f, bad], device=self.device)

    def __call__(self):
        self.launch()
        wp.synchronize_device(self.device)
        return self.f

    def forces(self):
        """The forces as float64 numpy (n, 3); a DegenerateTetError where a term's kernel
        flagged an element."""
        for *_, bad, _ in self.launches:
            bad.fill_(NO_ELEMENT)
        f = self().numpy().astype(np.float64)
        for *_, bad, term in self.launches:
            first = int(bad.numpy()[0])
            if first != NO_ELEMENT:
                raise term.degenerate(first)
        return f


def deformed(mesh, seed=0, amplitude=0.03):
    """Positions of ``mesh`` stretched, sheared and randomly perturbed by ``amplitude`` of
    its tetrahedra's length scale (the side of a cube of six times their mean volume; a fixed
    seed): a general state at which every term has forces."""
    rng = np.random.default_rng(seed)
    h = np.cbrt(6.0 * mesh.volumes.mean())
    A = np.array([[1.03, 0.02, 0.0], [0.0, 0.98, 0.015], [0.01, 0.0, 1.01]])
    return mesh.points @ A.T + amplitude * h * rng.uniform(-1.0, 1.0, mesh.points.shape)


def check_device(device):
    """The Warp device ``device`` (a name such as ``cpu``, ``cuda``, ``cuda:0``); a ValueError
    naming the devices there are where it does not exist."""
    try:
        return wp.get_device(device)
    except Exception as exc:
        there = ", ".join(d.alias for d in wp.get_devices())
        raise ValueError(f"Warp has no device {device!r} here ({exc}); devices: {there}") \
            from None


def device_name(device):
    d = wp.get_device(device)
    return f"{d.alias} ({d.name})"


def seconds_per_evaluation(wf, min_s=0.2, max_reps=10000):
    """Wall-clock seconds per force evaluation of ``wf`` (a :class:`WarpForces`), after a
    warm-up launch (which loads the kernels), the device synchronised around the timed
    launches."""
    wf()
    wp.synchronize_device(wf.device)
    t0 = time.perf_counter()
    wf()
    one = max(time.perf_counter() - t0, 1e-7)
    reps = int(min(max_reps, max(3, min_s / one)))
    wp.synchronize_device(wf.device)
    t0 = time.perf_counter()
    for _ in range(reps):
        wf.launch()
    wp.synchronize_device(wf.device)
    return (time.perf_counter() - t0) / reps


@njit   # not cached: it takes the kernels (as cases.tools.bench's loop)
def _force_loop(kernels, x, out, reps):
    for _ in range(reps):
        total_forces(kernels, x, out)


def numba_seconds_per_evaluation(pm, x, min_s=0.2):
    """Wall-clock seconds per force evaluation of pbcm's serial numba kernels on the CPU."""
    kern, out = pm.kernels(), np.zeros_like(x)
    _force_loop(kern, x, out, 1)
    t0 = time.perf_counter()
    _force_loop(kern, x, out, 1)
    reps = int(max(3, min_s / max(time.perf_counter() - t0, 1e-7)))
    t0 = time.perf_counter()
    _force_loop(kern, x, out, reps)
    return (time.perf_counter() - t0) / reps


def time_model(pm, device, dtypes=DTYPES, seed=0, min_s=0.2):
    """Rows of one built, covered model on ``device``: ns per tetrahedron per force evaluation
    in each dtype, and each dtype's max relative difference from pbcm's numba forces at a
    perturbed state."""
    x = deformed(pm.mesh, seed)
    ours = pm.forces(x)
    rows = []
    for dtype in dtypes:
        wf = WarpForces(pm, x, device, dtype)
        diff = float(np.abs(wf.forces() - ours).max() / np.abs(ours).max())
        s = seconds_per_evaluation(wf, min_s)
        rows.append({"model": pm.name, "tets": pm.mesh.n_tets, "nodes": pm.mesh.n_nodes,
                     "device": str(wf.device.alias), "device_name": device_name(device),
                     "dtype": dtype, "ns_per_tet": s / pm.mesh.n_tets * 1e9,
                     "max_rel_diff_vs_numba": diff})
        del wf
    return rows


# --- the script --------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="python -m cases.tools.warp_forces",
        description="Time the Warp kernels of pbcm's covered presets on one device (ns per "
                    "tetrahedron per force evaluation, float32 and float64) and check their "
                    "forces against pbcm's numba kernels.")
    ap.add_argument("--device", default="cpu", help="Warp device: cpu, cuda, cuda:0 ...")
    ap.add_argument("--sizes", nargs="+", type=float, default=[1e4, 1e5],
                    help="approximate tetrahedron counts (the bench's 'five' cubes)")
    ap.add_argument("--models", nargs="+", default=list(COVERED), help="covered presets")
    ap.add_argument("--dtypes", nargs="+", default=list(DTYPES), choices=DTYPES)
    ap.add_argument("--min-seconds", type=float, default=0.2,
                    help="each timing runs at least this long (default 0.2)")
    ap.add_argument("--no-numba", action="store_true",
                    help="skip timing pbcm's numba kernels on the CPU for comparison")
    ap.add_argument("--out", help="folder for warp_forces.json and warp_forces.md")
    args = ap.parse_args(argv)
    try:
        check_device(args.device)
    except ValueError as exc:
        print(f"warp_forces: error: {exc}", file=sys.stderr)
        return 2
    unknown = [m for m in args.models if m not in COVERED]
    if unknown:
        print(f"warp_forces: error: not covered: {', '.join(unknown)}; covered: "
              f"{', '.join(COVERED)}", file=sys.stderr)
        return 2
    from model import build
    mat = DEFAULT_MATERIAL
    rows = []
    head = f"{'model':26s} {'tets':>9s} {'dtype':8s} {'ns/tet':>9s} {'numba ns/tet':>13s} " \
           f"{'max rel diff':>13s}"
    print(f"Warp {wp.config.version} on {device_name(args.device)}")
    print(head)
    for size in args.sizes:
        mesh = bench_mesh(size)
        for name in args.models:
            pm = build(name, mesh, mat)
            numba_ns = None if args.no_numba else \
                numba_seconds_per_evaluation(pm, deformed(mesh), args.min_seconds) \
                / mesh.n_tets * 1e9
            for r in time_model(pm, args.device, args.dtypes, min_s=args.min_seconds):
                r["numba_cpu_ns_per_tet"] = numba_ns
                rows.append(r)
                print(f"{r['model']:26s} {r['tets']:9d} {r['dtype']:8s} "
                      f"{r['ns_per_tet']:9.3g} "
                      f"{'-' if numba_ns is None else format(numba_ns, '13.3g'):>13s} "
                      f"{r['max_rel_diff_vs_numba']:13.2e}", flush=True)
            del pm
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        import platform
        data = {"device": device_name(args.device), "warp": wp.config.version,
                "machine": {"cpu": platform.processor() or platform.machine(),
                            "cores": os.cpu_count(), "python": platform.python_version()}, "not_covered": list(NOT_COVERED),
                "timing": "wall clock per force evaluation after a warm-up launch, device "
                          "synchronised around the timed launches; numba: pbcm's serial "
                          "kernels on the CPU, wall clock",
                "rows": rows}
        (out / "warp_forces.json").write_text(json.dumps(data, indent=1) + "\n")
        (out / "warp_forces.md").write_text("\n".join(
            [f"# Warp force kernels on {data['device']}", "", data["timing"], "", head]
            + [f"{r['model']:26s} {r['tets']:9d} {r['dtype']:8s} {r['ns_per_tet']:9.3g} "
               f"{'-' if r['numba_cpu_ns_per_tet'] is None else format(r['numba_cpu_ns_per_tet'], '13.3g'):>13s} "
               f"{r['max_rel_diff_vs_numba']:13.2e}" for r in rows]) + "\n")
        print(f"written {out / 'warp_forces.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
