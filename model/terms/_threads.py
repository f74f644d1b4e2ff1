"""The threaded mode of a force kernel, equal bit for bit to the serial kernel.

A serial kernel adds each element's forces into ``out`` in increasing element order. Its
threaded mode (:class:`SplitBlocks`) makes the same additions in the same order, whatever the
number of threads: the elements are taken in blocks of ``B`` (``model.terms._blocks``), every
thread runs the kernel's ``_range`` twin over its share of the blocks (a contiguous range) and
adds straight into ``out``, except at the nodes an earlier share also touches: those forces are
stored into a buffer (``scatter_routed``) and added after every share has finished, in the
serial order. Only the nodes where two shares meet (a layer, for a mesh ordered in space)
wait, and only the blocks that hold one (``late``) take the routed scatter.

Off by default; ``model.build(..., threads=2)``.
"""
import numba
import numpy as np
from numba import njit, prange

from ._blocks import B, n_blocks


@njit(parallel=True)  # not cached: it takes a kernel
def split_blocks(x, kernel_range, args, bounds, late, route, buf, dest, firsts, out):
    """A force kernel's contract from its ``_range`` twin run on the shares of blocks
    ``bounds`` in parallel, then the routed forces ``buf`` added at ``dest`` in order."""
    shares = bounds.shape[0] - 1
    for c in prange(shares):
        firsts[c] = kernel_range(x, *args, bounds[c], bounds[c + 1], late, route, buf, out)
    for c in range(shares):
        if firsts[c] >= 0:
            return firsts[c]
    for r in range(dest.shape[0]):
        n = dest[r]
        out[n, 0] += buf[r, 0]
        out[n, 1] += buf[r, 1]
        out[n, 2] += buf[r, 2]
    return -1


class SplitBlocks:
    """The routes of the threaded mode of one blocked kernel (the module docstring): the
    blocks cut into ``shares`` ranges (default: numba's thread count, at least 2); for every
    corner slot of the blocked index array ``tb`` (m elements) ``route``, -1 where its
    node's force is added at once, else its place in the buffer of delayed additions; and
    ``late``, the blocks that hold a delayed slot (only they take ``scatter_routed``)."""

    def __init__(self, tb, m, n_nodes, shares=None):
        shares = max(2, numba.get_num_threads()) if shares is None else shares
        nb = n_blocks(m)
        corners = len(tb) // (nb * B)         # a tetrahedron's 4, an edge's 2
        self.bounds = np.linspace(0, nb, shares + 1).round().astype(np.int64)
        # every slot in the serial kernel's order of additions: block, lane, corner
        blk, lane, corner = np.meshgrid(np.arange(nb), np.arange(B), np.arange(corners),
                                        indexing="ij")
        slot = (blk * corners * B + corner * B + lane).ravel()
        real = (blk * B + lane).ravel() < m
        slot, share = slot[real], np.searchsorted(self.bounds, blk.ravel()[real], "right") - 1
        node = tb[slot]
        first = np.full(n_nodes, shares, dtype=np.int64)
        np.minimum.at(first, node, share)
        late = share > first[node]
        self.route = np.full(len(tb), -1, dtype=np.int32)
        self.route[slot[late]] = np.arange(late.sum())
        # the blocks with a delayed corner (the others take the plain scatter)
        self.late = np.zeros(nb, dtype=np.bool_)
        self.late[slot[late] // (corners * B)] = True
        self.dest = node[late].astype(np.int64)
        self.buf = np.empty((len(self.dest), 3))
        self.firsts = np.empty(shares, dtype=np.int64)

    def kernel(self, kernel_range, args):
        return split_blocks, (kernel_range, args, self.bounds, self.late, self.route,
                              self.buf, self.dest, self.firsts)


def split_of(owner, tb, m, n_nodes):
    """The :class:`SplitBlocks` of a term's blocked index array ``tb``, built once (kept on
    the term)."""
    if getattr(owner, "_split_blocks", None) is None:
        owner._split_blocks = SplitBlocks(tb, m, n_nodes)
    return owner._split_blocks
