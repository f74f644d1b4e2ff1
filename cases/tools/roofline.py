"""The bench's roofline: what one core of this machine can do, measured in the bench's own run,
and how close a kernel comes to it.

Two peaks: a STREAM-like copy (b[i] = a[i] over arrays far larger than the caches: 16 bytes per
element moved, the STREAM convention) and a fused multiply-add loop (64 independent
accumulators, which the compiler lays out in SIMD registers: two operations per element per
iteration). A kernel's attainable rate at its arithmetic intensity I (floating-point
operations per byte) is min(FMA peak, copy bandwidth x I); its fraction is its own rate (its
counted operations per tetrahedron over its measured time per tetrahedron) over that. The bytes
are the compulsory traffic: every array the kernels read once (the per-tetrahedron data and the
nodes' positions), the forces read and written once; gathers that miss the cache move more."""
import time

import numpy as np
from numba import njit

COPY_DOUBLES = 1 << 24        # 128 MiB per array: far beyond any cache
FMA_LANES = 64                # independent accumulators: latency hidden, SIMD filled (fewer stay scalar)
FMA_ITERATIONS = 1 << 21
REPEATS = 5                   # the best of these: a peak is what the machine can do


@njit(cache=True)
def _copy(a, b):
    for i in range(a.size):
        b[i] = a[i]


@njit(cache=True, fastmath=True)
def _fma(n, a, b):
    acc = np.zeros(FMA_LANES)
    for k in range(FMA_LANES):
        acc[k] = k
    for _ in range(n):
        for k in range(FMA_LANES):
            acc[k] = acc[k] * a + b
    return acc.sum()


def _best(call):
    _ = call()                            # compiled and warmed outside the timings
    times = []
    for _ in range(REPEATS):
        t0 = time.thread_time_ns()
        call()
        times.append((time.thread_time_ns() - t0) * 1e-9)
    return min(times)


def peaks():
    """{"copy_gb_s": the copy's bandwidth, "fma_gflop_s": the FMA loop's rate} on one core,
    in thread CPU time like the kernels'."""
    a = np.arange(COPY_DOUBLES, dtype=np.float64)
    b = np.empty_like(a)
    copy = _best(lambda: _copy(a, b))
    # a and b keep every accumulator bounded: acc -> b / (1 - a)
    fma = _best(lambda: _fma(FMA_ITERATIONS, 0.5, 1.0))
    return {"copy_gb_s": 16.0 * COPY_DOUBLES / copy / 1e9,
            "fma_gflop_s": 2.0 * FMA_LANES * FMA_ITERATIONS / fma / 1e9}


def bytes_per_tet(pm):
    """The compulsory bytes per tetrahedron of ``pm``'s force evaluation: every array its
    kernels take, once (an array two kernels share, once), the positions read and the forces
    read and written."""
    seen, total = set(), 0
    for _, args in pm.kernels():
        for a in args:
            if isinstance(a, np.ndarray) and id(a) not in seen:
                seen.add(id(a))
                total += a.nbytes
    node = pm.mesh.points.nbytes
    return (total + 3 * node) / pm.mesh.n_tets


def fraction(flops, bytes_, ns_per_tet, peak):
    """(the kernel's rate in GFLOP/s, the attainable rate at its intensity, its fraction of
    that); None where the operations were not counted."""
    if flops is None or not ns_per_tet:
        return None, None, None
    rate = flops / ns_per_tet
    attainable = min(peak["fma_gflop_s"], peak["copy_gb_s"] * flops / bytes_)
    return rate, attainable, rate / attainable
