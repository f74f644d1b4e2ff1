"""The two-thread mode of a force kernel, equal bit for bit to the serial kernel.

A serial kernel adds each tetrahedron's four forces into ``out`` in increasing tetrahedron
order. Here the tetrahedra are computed in parallel into ft (m, 4, 3) by the kernel's
``_tets`` twin (the same generated lines), then every node sums its contributions in the same
increasing order (parallel over nodes): the same additions in the same order, so the same
bits, whatever the number of threads. Off by default; ``model.build(..., threads=2)``.
"""
import numpy as np
from numba import njit, prange


def node_slots(tets, n_nodes):
    """CSR of node -> its slots t * 4 + i (corner i of tetrahedron t), in increasing t."""
    slot = np.argsort(tets.ravel(), kind="stable")
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(tets.ravel(), minlength=n_nodes), out=ptr[1:])
    return ptr, slot.astype(np.int64)


@njit(cache=True, parallel=True)
def gather(ft, ptr, slot, out):
    """out[n] += the stored forces of node n, in increasing tetrahedron order."""
    f = ft.reshape(-1, 3)
    for n in prange(out.shape[0]):
        for k in range(ptr[n], ptr[n + 1]):
            s = slot[k]
            out[n, 0] += f[s, 0]
            out[n, 1] += f[s, 1]
            out[n, 2] += f[s, 2]


CHUNKS = 64   # ranges of tetrahedra handed to the threads (any count gives the same bits)


@njit(parallel=True)  # not cached: it takes a kernel (see model.integrate)
def per_tet(x, kernel_tets, args, ft, flat):
    m = ft.shape[0]
    n_flat = 0
    for c in prange(CHUNKS):
        n_flat += kernel_tets(x, *args, ft, flat, c * m // CHUNKS, (c + 1) * m // CHUNKS)
    return n_flat


@njit  # not cached: it takes a kernel
def per_tet_then_gather(x, kernel_tets, args, ft, flat, ptr, slot, out):
    """A force kernel's contract (add into out, return the first flattened element or -1)
    from its per-tetrahedron twin and :func:`gather`."""
    flat[:] = 0
    if per_tet(x, kernel_tets, args, ft, flat) > 0:
        return np.argmax(flat)
    gather(ft, ptr, slot, out)
    return -1


class TwoThreads:
    """The buffers of the two-thread mode for one term: ft, the flags and the node CSR, over
    its elements (tetrahedra, or a spring term's edges)."""

    def __init__(self, tets, n_nodes):
        self.ft = np.empty((len(tets), tets.shape[1], 3))    # a tetrahedron's 4, an edge's 2
        self.flat = np.zeros(len(tets), dtype=np.int8)
        self.ptr, self.slot = node_slots(tets, n_nodes)

    def kernel(self, kernel_tets, args):
        return per_tet_then_gather, (kernel_tets, args, self.ft, self.flat, self.ptr, self.slot)
