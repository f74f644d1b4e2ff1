"""Worker processes for the independent meshes of a case.

Each mesh (with its bcs: their FEM references and every model's runs) depends on nothing
else, so a case runs its meshes on a pool of processes (``multiprocessing``'s spawn pool: no
state is inherited from the parent, whose numba and BLAS threads are not fork-safe). A worker
uses one BLAS thread, and so does a serial run (``one_blas_thread``): the dense eigensolvers'
last bits then do not depend on how many workers ran, and metrics are the same for every
``--workers``.

Ctrl-C reaches the whole process group: workers ignore it and the parent, which owns the
output folders, stops them (``Pool.terminate``) on its way out.
"""
import multiprocessing
import os
import signal

from threadpoolctl import threadpool_limits


def available_cores():
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:       # not on Linux
        return os.cpu_count() or 1


def one_blas_thread():
    """A context in which BLAS runs one thread (numba's own threads are left alone)."""
    return threadpool_limits(limits=1, user_api="blas")


def _ignore_interrupt():
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class Workers:
    """A pool of ``n`` worker processes, started on entering the block and stopped on leaving
    it (at once when the block ends with an exception: a signal, an error)."""

    def __init__(self, n):
        if not (isinstance(n, int) and n >= 1):
            raise ValueError(f"the number of workers must be an integer >= 1, got {n!r}")
        self.n = n
        self._pool = None

    def __enter__(self):
        self._pool = multiprocessing.get_context("spawn").Pool(
            self.n, initializer=_ignore_interrupt)
        return self

    def __exit__(self, kind, value, tb):
        if kind is None:
            self._pool.close()
        else:
            self._pool.terminate()
        self._pool.join()
        self._pool = None

    def unordered(self, fn, items):
        """``fn(item)`` for every item, as the workers finish them (each item is sent to the
        next free worker)."""
        return self._pool.imap_unordered(fn, items, chunksize=1)


__all__ = ["Workers", "available_cores", "one_blas_thread"]
