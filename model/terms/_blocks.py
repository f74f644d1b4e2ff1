"""Blocks of tetrahedra: the layout the force kernels vectorise over.

A kernel that loops tetrahedron by tetrahedron, reading its corners through the index array
and adding into the nodes as it goes, runs one tetrahedron at a time: the compiler cannot
prove that the stores into ``out`` leave the next tetrahedron's inputs alone, and it will not
gather. Here each block of ``B`` tetrahedra takes three passes:

1. :func:`gather`: the corners' positions into a scratch array ``s`` (12 rows of ``B``: row
   ``3 c + k`` is coordinate k of corner c), a plain scalar copy;
2. the term's block function: the same straight-line maths for lane ``i`` of the block,
   reading ``s`` and the term's per-tetrahedron data in the blocked layout of
   :func:`blocked`, writing the four corner forces into rows ``OUT ...`` of ``s``. Every
   address is a constant offset of a few base pointers and the trip count is the constant
   ``B``, so LLVM turns the loop into SIMD code over the lanes (no remainder loop: every
   tetrahedron goes through the same instructions);
3. :func:`scatter`: the forces added into ``out`` in increasing tetrahedron order, corner by
   corner, as the serial kernels always did; or, in the two-thread mode, :func:`put` into
   ft (m, 4, 3), which ``model.terms._threads.gather`` sums per node in the same order.

The last block is padded with copies of the last tetrahedron (its index and its data), so
its lanes compute a real element; only the first ``m`` lanes are ever added or stored.
A flattened element is flagged in row ``FLAG`` of ``s`` (its margin: <= 0 when flattened)
and counted; the driver then reports the first one (:func:`first_flat`).

Numba's cache keys a compiled kernel on its own file only: after editing this one, run
``python model/terms/_shear_codegen.py`` (the generated file records this file's hash) and
clear ``model/terms/__pycache__`` for the other kernels that use it (``fem``, ``normal_edge``).
"""
import numpy as np
from numba import njit

B = 32             # tetrahedra per block: a multiple of the SIMD width, small enough for L1
OUT = 12 * B       # where the block's corner forces start in the scratch array
FLAG = 24 * B      # the flattening margins of the block's lanes
SCRATCH = 25 * B   # the scratch array's length

# fast maths without reassociation (as the shear kernels): each lane rounds as the scalar
# code would, whichever SIMD width the compiler picks
FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}
# division by zero gives inf rather than a Python exception: no branch in the lanes
OPTIONS = dict(cache=True, fastmath=FAST, error_model="numpy", boundscheck=False)


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
    """The corner indices (n_blocks * 4 * B,) int32 in the blocked layout."""
    if tets.max(initial=0) >= 2**31:
        raise ValueError("more than 2**31 nodes")
    return blocked(tets, np.int32)


@njit(**OPTIONS)
def gather(x, tb, blk, s):
    """The positions of block blk's corners into rows 0..11 of s."""
    base = blk * 4 * B
    for c in range(4):
        for i in range(B):
            n = tb[base + c * B + i]
            s[(3 * c) * B + i] = x[n, 0]
            s[(3 * c + 1) * B + i] = x[n, 1]
            s[(3 * c + 2) * B + i] = x[n, 2]


@njit(**OPTIONS)
def scatter(out, tb, blk, m, s):
    """out += the block's corner forces, tetrahedron by tetrahedron, corners in order."""
    base = blk * 4 * B
    for i in range(min(B, m - blk * B)):
        for c in range(4):
            n = tb[base + c * B + i]
            out[n, 0] += s[OUT + (3 * c) * B + i]
            out[n, 1] += s[OUT + (3 * c + 1) * B + i]
            out[n, 2] += s[OUT + (3 * c + 2) * B + i]


@njit(**OPTIONS)
def put(ft, flat, blk, first, stop, s):
    """The block's corner forces into ft (m, 4, 3) and its flags into flat, for the
    tetrahedra of the block in [first, stop); returns how many are flattened."""
    n_flat = 0
    for t in range(max(first, blk * B), min(stop, blk * B + B)):
        i = t - blk * B
        for c in range(4):
            for k in range(3):
                ft[t, c, k] = s[OUT + (3 * c + k) * B + i]
        if s[FLAG + i] <= 0.0:
            flat[t] = 1
            n_flat += 1
    return n_flat


@njit(**OPTIONS)
def first_flat(s, blk, m):
    """The first flattened tetrahedron of block blk (its margin <= 0), or -1."""
    for i in range(min(B, m - blk * B)):
        if s[FLAG + i] <= 0.0:
            return blk * B + i
    return -1

