"""Blocks of tetrahedra: the layout the force kernels vectorise over.

A kernel that loops tetrahedron by tetrahedron, reading its corners through the index array
and adding into the nodes as it goes, runs one tetrahedron at a time: the compiler cannot
prove that the stores into ``out`` leave the next tetrahedron's inputs alone, and it will not
gather. Here each block of ``B`` tetrahedra takes three passes:

1. :func:`gather`: the corners' positions into a scratch array ``s`` (12 rows of ``B``: row
   ``3 c + k`` is coordinate k of corner c), a plain scalar copy; the driver first asks the
   caches for the index and data rows of the block ``AHEAD`` blocks on (:func:`ahead`);
2. the term's block function: the same straight-line maths for lane ``i`` of the block,
   reading ``s`` and the term's per-tetrahedron data in the blocked layout of
   :func:`blocked`, writing the four corner forces into rows ``OUT ...`` of ``s``. Every
   address is a constant offset of a few base pointers and the trip count is the constant
   ``B``, so LLVM turns the loop into SIMD code over the lanes (no remainder loop: every
   tetrahedron goes through the same instructions);
3. :func:`scatter`: the forces added into ``out`` in increasing tetrahedron order, corner by
   corner, as the serial kernels always did; or, in the threaded mode, :func:`scatter_routed`
   for one thread's share of the blocks (``model.terms._threads.SplitBlocks``).

A kernel whose maths per element is a few dozen operations (the volume term alone, the
springs) loses more to the scratch array's round trip than the lanes win, and stays a scalar
loop; its threaded twin takes its elements ``B`` at a time all the same (the routes of
``model.terms._threads.SplitBlocks``).

The last block is padded with copies of the last tetrahedron (its index and its data), so
its lanes compute a real element; only the first ``m`` lanes are ever added or stored.
A flattened element is flagged in row ``FLAG`` of ``s`` (its margin: <= 0 when flattened)
and counted; the driver then reports the first one (:func:`first_flat`).

Numba's cache keys a compiled kernel on its own file only: after editing this one, run
``python model/terms/_shear_codegen.py`` (the generated file records this file's hash) and
clear ``model/terms/__pycache__`` for the other kernels that use it (``fem``, ``normal_edge``).
"""
import numpy as np
from llvmlite import ir
from numba import njit
from numba.core import cgutils, types
from numba.extending import intrinsic, overload

B = 32             # tetrahedra per block: a multiple of the SIMD width, small enough for L1
OUT = 12 * B       # where the block's corner forces start in the scratch array
FLAG = 24 * B      # the flattening margins of the block's lanes
SCRATCH = 25 * B   # the scratch array's length

# fast maths without reassociation (as the shear kernels): each lane rounds as the scalar
# code would, whichever SIMD width the compiler picks
FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}
# division by zero gives inf rather than a Python exception: no branch in the lanes
OPTIONS = dict(cache=True, fastmath=FAST, error_model="numpy", boundscheck=False)
# a block function small enough for LLVM to inline is inlined by numba into each driver
# instead: LLVM inlines a callee compiled in the same process but not one loaded from numba's
# cache, and its fused multiply-adds differ between the two, so a driver's bits would hang on
# which process compiled what (the shear blocks are too large for LLVM to inline)
INLINED = dict(OPTIONS, inline="always")
# blocks a driver asks the caches for ahead of the one it computes: the per-tetrahedron data of
# a block lie in several rows, which the hardware's prefetchers do not follow while the gather
# and the scatter jump about the nodes (on the bench's 1e6 cube the kernels ran 1.2-1.5 times
# faster with it, the same at 2 and at 4 blocks ahead)
AHEAD = 4
LINE = 64          # bytes per cache line


@intrinsic
def _prefetch(typingctx, a, i):
    """A read prefetch of a[i] into every cache level (llvm.prefetch): a hint, which never
    faults and changes no value."""
    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, signature.args[0], array, [args[1]],
                                       wraparound=False, boundscheck=False)
        i8p, i32 = ir.IntType(8).as_pointer(), ir.IntType(32)
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]),
            "llvm.prefetch.p0i8")
        # read, locality 3 (keep in every level), data cache
        builder.call(fn, [builder.bitcast(ptr, i8p), i32(0), i32(3), i32(1)])
        return context.get_dummy_value()
    return types.void(a, i), codegen


def prefetch(a, i):
    """Ask the caches for a[i]; run as Python (numba's jit disabled), nothing."""


@overload(prefetch)
def _prefetch_compiled(a, i):
    return lambda a, i: _prefetch(a, i)


@njit(**INLINED)
def ahead(a, blk, nb):
    """Ask the caches for block blk + AHEAD (the last block at most) of ``a``, an array in the
    blocked layout of :func:`blocked` or :func:`blocked_tets` cut into ``nb`` blocks."""
    per = a.size // nb
    start = min(blk + AHEAD, nb - 1) * per
    for k in range(0, per, LINE // a.itemsize):
        prefetch(a, start + k)


@njit(inline="always", fastmath=FAST, error_model="numpy")
def rsqrt(a):
    """1 / sqrt(a) to within two units in the last place, for a lane: the single-precision root
    refined by two Newton steps in double (single precision's root and division are several
    times faster in the SIMD units than double's). For 1e-37 < a < 1e38 (squared lengths and
    areas of any mesh in SI units); a = 0 gives inf."""
    y = np.float64(np.float32(1.0) / np.sqrt(np.float32(a)))
    y = y * (1.5 - 0.5 * a * y * y)
    return y * (1.5 - 0.5 * a * y * y)


def n_blocks(m):
    return -(-m // B)


def blocked(a, dtype=np.float64):
    """Per-tetrahedron data a (m,) or (m, k) as the flat array of (n_blocks, k, B): entry
    (t, j) at ``((t // B) * k + j) * B + t % B``, the last block padded with row m - 1."""
    a = np.asarray(a)
    a2 = a.reshape(len(a), -1)
    m, k = a2.shape
    nb = n_blocks(m)
    pad = np.concatenate([a2, np.repeat(a2[-1:], nb * B - m, axis=0)])
    return np.ascontiguousarray(pad.reshape(nb, B, k).transpose(0, 2, 1), dtype=dtype).ravel()


def blocked_tets(tets):
    """The corner indices (n_blocks * k * B,) int32 in the blocked layout, of tetrahedra
    (m, 4) or of any elements (m, k) (the threaded mode's routes of edges)."""
    if tets.max(initial=0) >= 2**31:
        raise ValueError("more than 2**31 nodes")
    return blocked(tets, np.int32)


@njit(**OPTIONS)
def gather(x, tb, blk, s):
    """The positions of block blk's corners into rows 0..11 of s. A lane's twelve values are
    loaded before any is stored: the compiler cannot tell s from x, and would otherwise
    order every load after the previous store."""
    base = blk * 4 * B
    for i in range(B):
        n0, n1, n2, n3 = tb[base + i], tb[base + B + i], tb[base + 2 * B + i], \
            tb[base + 3 * B + i]
        a0, a1, a2 = x[n0, 0], x[n0, 1], x[n0, 2]
        b0, b1, b2 = x[n1, 0], x[n1, 1], x[n1, 2]
        c0, c1, c2 = x[n2, 0], x[n2, 1], x[n2, 2]
        d0, d1, d2 = x[n3, 0], x[n3, 1], x[n3, 2]
        s[i], s[B + i], s[2 * B + i] = a0, a1, a2
        s[3 * B + i], s[4 * B + i], s[5 * B + i] = b0, b1, b2
        s[6 * B + i], s[7 * B + i], s[8 * B + i] = c0, c1, c2
        s[9 * B + i], s[10 * B + i], s[11 * B + i] = d0, d1, d2


@njit(**OPTIONS)
def scatter(out, tb, blk, m, s):
    """out += the block's corner forces, tetrahedron by tetrahedron, corners in order (a
    lane's forces loaded before any addition, as in :func:`gather`)."""
    base = blk * 4 * B
    for i in range(min(B, m - blk * B)):
        n0, n1, n2, n3 = tb[base + i], tb[base + B + i], tb[base + 2 * B + i], \
            tb[base + 3 * B + i]
        a0, a1, a2 = s[OUT + i], s[OUT + B + i], s[OUT + 2 * B + i]
        b0, b1, b2 = s[OUT + 3 * B + i], s[OUT + 4 * B + i], s[OUT + 5 * B + i]
        c0, c1, c2 = s[OUT + 6 * B + i], s[OUT + 7 * B + i], s[OUT + 8 * B + i]
        d0, d1, d2 = s[OUT + 9 * B + i], s[OUT + 10 * B + i], s[OUT + 11 * B + i]
        out[n0, 0] += a0
        out[n0, 1] += a1
        out[n0, 2] += a2
        out[n1, 0] += b0
        out[n1, 1] += b1
        out[n1, 2] += b2
        out[n2, 0] += c0
        out[n2, 1] += c1
        out[n2, 2] += c2
        out[n3, 0] += d0
        out[n3, 1] += d1
        out[n3, 2] += d2


@njit(**OPTIONS)
def scatter_routed(out, tb, blk, m, s, route, buf):
    """scatter for one thread's share of the blocks: a corner whose slot has a route r >= 0
    (its node is also touched by an earlier share) is stored into buf[r], to be added after
    the earlier shares in the serial order; the others are added into out."""
    base = blk * 4 * B
    for i in range(min(B, m - blk * B)):
        for c in range(4):
            slot = base + c * B + i
            n, r = tb[slot], route[slot]
            f0, f1, f2 = s[OUT + (3 * c) * B + i], s[OUT + (3 * c + 1) * B + i], \
                s[OUT + (3 * c + 2) * B + i]
            if r < 0:
                out[n, 0] += f0
                out[n, 1] += f1
                out[n, 2] += f2
            else:
                buf[r, 0], buf[r, 1], buf[r, 2] = f0, f1, f2


@njit(**OPTIONS)
def first_flat(s, blk, m):
    """The first flattened tetrahedron of block blk (its margin <= 0), or -1."""
    for i in range(min(B, m - blk * B)):
        if s[FLAG + i] <= 0.0:
            return blk * B + i
    return -1

