"""Stopping on Ctrl-C (SIGINT) and SIGTERM, even where a library swallows the exception.

A Python signal handler raises in whatever bytecode the main thread runs next. That may be a
finaliser (``__del__``, llvmlite frees LLVM objects that way while numba compiles) or a
callback from C, where Python prints "Exception ignored" and goes on. The run then finished
and exited 0 after SIGTERM on a CI machine. So the handler also records the signal, and
``checkpoint()`` raises it again at points the suite owns: between runs and before any output
folder is swapped in.
"""
import signal
import sys
import threading


class Terminated(BaseException):
    """SIGTERM. A BaseException, as KeyboardInterrupt is: library code that catches Exception
    must not swallow it."""


_EXCEPTIONS = {signal.SIGINT: KeyboardInterrupt, signal.SIGTERM: Terminated}
_received = []


# the libraries in whose Python frames an exception can leave native objects half-freed
# (llvmlite disposes LLVM objects from finalisers while numba compiles): there the signal is
# only recorded, and ``checkpoint()`` raises it at the next point the suite owns
NATIVE = ("llvmlite", "numba")
NATIVE_DEPTH = 8     # the innermost frames looked at


def _in_native(frame):
    """Whether one of the innermost frames runs code of a NATIVE library."""
    for _ in range(NATIVE_DEPTH):
        if frame is None:
            return False
        if str(frame.f_globals.get("__name__", "")).split(".")[0] in NATIVE:
            return True
        frame = frame.f_back
    return False


def _handler(signum, frame):
    _received.append(signum)
    if _in_native(frame):
        return
    raise _EXCEPTIONS[signum]()


def checkpoint():
    """Raise KeyboardInterrupt or Terminated if such a signal arrived since ``handling``
    began, whether or not its first exception got through."""
    if _received:
        raise _EXCEPTIONS[_received[0]]()


class handling:
    """Within this block SIGINT and SIGTERM raise and are remembered for ``checkpoint``
    (main thread only; elsewhere nothing changes). Python's "Exception ignored" report of
    such an exception dropped in a finaliser or a C callback is silenced: ``checkpoint``
    raises it again, and the run ends with its one-line message."""

    def __enter__(self):
        self._previous, self._hook = {}, None
        if threading.current_thread() is threading.main_thread():
            _received.clear()
            for sig in _EXCEPTIONS:
                self._previous[sig] = signal.signal(sig, _handler)
            self._hook = sys.unraisablehook
            sys.unraisablehook = self._unraisable
        return self

    def _unraisable(self, unraisable):
        if not (_received and (isinstance(unraisable.exc_value, tuple(_EXCEPTIONS.values()))
                               or _in_finaliser(unraisable))):
            self._hook(unraisable)

    def __exit__(self, *exc):
        for sig, previous in self._previous.items():
            signal.signal(sig, previous)
        if self._hook is not None:
            sys.unraisablehook = self._hook
        _received.clear()


def quiet_finalisers():
    """For the rest of this process, no report of an exception raised in a ``__del__``: after a
    stop, a finaliser the signal cut off half-way fails again when its object is collected
    (llvmlite's ObjectRef.__del__, an AttributeError, when Ctrl-C lands while numba compiles in
    the main process), after the command has said in one line that it stopped."""
    hook = sys.unraisablehook

    def quiet(unraisable):
        if not _in_finaliser(unraisable):
            hook(unraisable)
    sys.unraisablehook = quiet


def _in_finaliser(unraisable):
    return getattr(unraisable.object, "__name__", "") == "__del__"
