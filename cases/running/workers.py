"""The one engine for parallel work: cases, studies and sweeps hand it their units.

A unit (a mesh of a case with all its bcs, a problem and bc of the convergence study, a point
of a sweep) depends on nothing else, so it runs on an executor:

- ``Workers(n)``: ``n`` local worker processes (the default; spawned, so that no state is
  inherited from the parent, whose numba and BLAS threads are not fork-safe);
- ``Cluster(address)``: the workers of a Dask scheduler (``--scheduler ADDRESS``), or
  ``Cluster(None, n)`` a LocalCluster of ``n`` processes.

Both give ``outcomes(fn, items)``: ``(index, error, result)`` per item as the units finish,
and ``unordered(fn, items)``: the results, raising the first error. A worker that dies (killed,
out of memory) does not lose its unit: the local pool is started again and the unfinished
units are given out again (at most ``RETRIES`` times); Dask's scheduler does the same
(``distributed.scheduler.allowed-failures``). A worker uses one BLAS thread, and so does a
serial run (``one_blas_thread``): the dense eigensolvers' last bits then do not depend on how
many workers ran, and metrics are the same for every executor.

Ctrl-C reaches the whole process group: local workers ignore it and the parent, which owns
the output folders, stops them on its way out.
"""
import logging
import multiprocessing
import os
import signal
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from threadpoolctl import threadpool_limits

from model import PbcmError

RETRIES = 2                  # how many times a unit whose worker died is given out again
CONNECT_TIMEOUT_S = 10       # how long a scheduler has to answer


class WorkerLost(RuntimeError):
    """A unit whose worker died on every try."""


class SchedulerError(PbcmError):
    """No Dask scheduler answers at the address given."""


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


_TICKS = None      # in a local worker: the queue its progress goes to (None elsewhere)


def _init_worker(ticks):
    global _TICKS
    _ignore_interrupt()
    _TICKS = ticks


def tick(*news):
    """Report progress within a unit from the process running it: ``news`` reaches the
    ``on_tick`` of the ``outcomes`` call that gave the unit out (a local pool's; nothing on
    a Dask cluster, where a unit's progress shows when it ends)."""
    if _TICKS is not None:
        _TICKS.put(news)


def _indexed(item):
    fn, i, job = item
    with one_blas_thread():
        return i, fn(job)


def dearest_first(fn, jobs, workers, done=lambda i: None, cost=None):
    """``fn(job)`` for every job, in this process or on ``workers`` (a started executor), the
    dearest first (``cost``: one expected cost per job, so that the longest unit does not
    start last and run alone); ``done(i)`` as each finishes; the results in the jobs'
    order. A stop (cases.running.stop) is honoured between units."""
    from . import stop
    results = [None] * len(jobs)
    order = sorted(range(len(jobs)), key=lambda i: -(cost[i] if cost is not None else 0))
    if workers is None:
        with one_blas_thread():
            for i in order:
                stop.checkpoint()
                results[i] = fn(jobs[i])
                done(i)
    else:
        for i, result in workers.unordered(_indexed, [(fn, i, jobs[i]) for i in order]):
            stop.checkpoint()
            results[i] = result
            done(i)
    return results


def _call(fn, item):
    with one_blas_thread():
        return fn(item)


class _Executor:
    """What both executors share: ``unordered`` on top of ``outcomes``."""

    n = 1
    dashboard = None

    def unordered(self, fn, items, on_tick=None):
        """``fn(item)`` for every item, as the workers finish them; the first error raised;
        ``on_tick(*news)`` for what the units report while they run (``tick``)."""
        for _, error, result in self.outcomes(fn, items, on_tick):
            if error is not None:
                raise error
            yield result


class Workers(_Executor):
    """A pool of ``n`` local worker processes, started on entering the block and stopped on
    leaving it (at once when the block ends with an exception: a signal, an error)."""

    def __init__(self, n):
        if not (isinstance(n, int) and n >= 1):
            raise ValueError(f"the number of workers must be an integer >= 1, got {n!r}")
        self.n = n
        self._pool = self._ticks = None

    def _start(self):
        context = multiprocessing.get_context("spawn")
        self._ticks = context.SimpleQueue()
        self._pool = ProcessPoolExecutor(self.n, mp_context=context, initializer=_init_worker,
                                         initargs=(self._ticks,))

    def __enter__(self):
        self._start()
        return self

    def _stop(self, now):
        if self._pool is None:
            return
        if now:   # a signal or an error: take the workers down, do not wait for them
            for p in list((self._pool._processes or {}).values()):
                p.terminate()
        self._pool.shutdown(wait=True, cancel_futures=now)
        self._pool = None

    def __exit__(self, kind, value, tb):
        self._stop(now=kind is not None)

    def _drain(self, on_tick):
        while on_tick is not None and self._ticks is not None and not self._ticks.empty():
            on_tick(*self._ticks.get())

    def outcomes(self, fn, items, on_tick=None):
        """``(index, error, result)`` of ``fn(items[index])`` as each finishes; a unit whose
        worker died is given out again on a new pool, at most RETRIES times; ``on_tick(*news)``
        for each report of a running unit (``tick``), in this process."""
        items = list(items)
        tries = [0] * len(items)
        left = set(range(len(items)))
        while left:
            futures = {self._pool.submit(_call, fn, items[i]): i for i in sorted(left)}
            broken = False
            pending = set(futures)
            while pending:
                done, pending = wait(pending, timeout=0.25 if on_tick else None,
                                     return_when=FIRST_COMPLETED)
                self._drain(on_tick)
                for fut in done:
                    i = futures[fut]
                    try:
                        result = fut.result()
                    except BrokenProcessPool:
                        broken = True
                        continue
                    except Exception as exc:            # the unit's own error
                        left.discard(i)
                        yield i, exc, None
                        continue
                    left.discard(i)
                    yield i, None, result
            if broken:
                self._stop(now=True)
                self._start()
                for i in sorted(left):
                    tries[i] += 1
                    if tries[i] > RETRIES:
                        left.discard(i)
                        yield i, WorkerLost(f"the worker running unit {i} died {tries[i]} "
                                            "times; rerun to try it again"), None


class Cluster(_Executor):
    """The workers of the Dask scheduler at ``address``, or (``address`` None) a LocalCluster
    of ``n`` processes, one thread each; connected on entering the block."""

    def __init__(self, address=None, n=None):
        self.address, self.n = address, n or available_cores()
        self.client = self.cluster = None

    def __enter__(self):
        from distributed import Client, LocalCluster
        if self.address:
            try:
                self.client = Client(self.address, timeout=f"{CONNECT_TIMEOUT_S}s")
            except (OSError, TimeoutError) as exc:
                raise SchedulerError(
                    f"--scheduler {self.address}: no Dask scheduler answers there ({exc}); "
                    "start one with `dask scheduler` and workers with `dask worker "
                    f"{self.address}` (README, 'Running on a cluster')") from None
            self.n = max(1, len(self.client.scheduler_info().get("workers", {})))
        else:
            self.cluster = LocalCluster(n_workers=self.n, threads_per_worker=1, processes=True,
                                        silence_logs=logging.ERROR)
            self.client = Client(self.cluster)
        self.dashboard = self.client.dashboard_link
        return self

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def outcomes(self, fn, items, on_tick=None):
        """``(index, error, result)`` as each task finishes; a task whose worker died is
        given to another by the scheduler (allowed-failures), and only then is an error
        (``on_tick`` is not called: a unit's progress shows when it ends)."""
        from distributed import as_completed
        futures = {self.client.submit(_call, fn, item, pure=False): i
                   for i, item in enumerate(items)}
        try:
            for fut in as_completed(futures):
                try:
                    result = fut.result()
                except Exception as exc:   # the unit's error, or KilledWorker
                    yield futures[fut], exc, None
                    continue
                yield futures[fut], None, result
        finally:
            for fut in futures:
                fut.cancel()


def executor(scheduler=None, workers=None, units=None):
    """The executor of a command: a Dask cluster at ``scheduler``, else ``workers`` local
    processes (default the cores available, at most ``units``); None for one process."""
    if scheduler:
        return Cluster(scheduler)
    n = workers or available_cores()
    if units is not None:
        n = min(n, units)
    return Workers(n) if n > 1 else None


__all__ = ["Workers", "Cluster", "executor", "available_cores", "one_blas_thread", "tick",
           "WorkerLost", "SchedulerError", "RETRIES"]
