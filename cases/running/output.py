"""Where results go: every output path is checked before any computing, and a case folder is
replaced as a whole (built in a sibling temporary folder, then swapped in), so that after an
interrupt it holds exactly the earlier complete set of files or the new one.
"""
import contextlib
import ctypes
import ctypes.util
import errno
import os
import re
import shutil
import socket
import signal
import tempfile
import threading
from pathlib import Path

from model.errors import PbcmError
from . import stop

# a folder the suite may replace: empty, or written by it before (it always holds this file)
OWNED_MARK = "metrics.json"
ROOT_MARK = "index.md"          # the reports root: what `pbcm report` and `pbcm index` write
# a sweep's folder (``pbcm sweep``): its runs/<key>/metrics.json are rows of a table, not
# case metrics, so the gate does not read them
SWEEP_MARK = "sweep.json"
TMP_TAG = ".pbcm-tmp-"
# a staging folder's name: .<target>.pbcm-tmp-<host>.<pid>.<random>[-old]
_STAGED = re.compile(re.escape(TMP_TAG) + r"(?P<host>.+)\.(?P<pid>\d+)\.[^.]*(-old)?$")


def staging_prefix(target):
    """The prefix of ``target``'s staging folders made by this process."""
    return f".{Path(target).name}{TMP_TAG}{socket.gethostname()}.{os.getpid()}."


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def stale_staging(target):
    """The staging folders of ``target`` that a run on this machine left behind when it was
    killed (its process is gone); a folder of a run still going, or of another machine, is
    never among them."""
    target = Path(target)
    out = []
    for p in sorted(target.parent.glob(f".{target.name}{TMP_TAG}*")):
        m = _STAGED.search(p.name)
        if p.is_dir() and m and m["host"] == socket.gethostname() and not _alive(int(m["pid"])):
            out.append(p)
    return out


class OutputError(PbcmError, OSError):
    """An output path cannot be written: it names the path and what to do."""


@contextlib.contextmanager
def no_interrupt():
    """Hold Ctrl-C (SIGINT) and SIGTERM back until the block is done: for the few system calls
    that must not be separated (a swap of folders, a rename)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def writable_folder(path, flag="--out"):
    """Create ``path`` (and its parents) if needed and prove it takes files; else OutputError
    naming ``flag``."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"{flag} {path} is a file, not a folder; give a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise OutputError(f"{flag} {path} cannot be written ({exc.strerror or exc}); "
                          "give a folder you can write to") from None
    return path


def writer(path, mark=OWNED_MARK):
    """The case or study whose output ``path`` holds (its ``mark``'s 'case' entry), or None
    where it holds none or the mark does not say."""
    import json
    try:
        data = json.loads((Path(path) / mark).read_text())
    except (OSError, ValueError):
        return None
    return data.get("case") if isinstance(data, dict) and isinstance(data.get("case"), str) \
        else None


def owned(path, mark=OWNED_MARK):
    """True when the suite may replace ``path``: missing, empty, or a folder pbcm wrote (it
    holds ``mark``: a case's metrics.json, the benchmark's bench.json)."""
    path = Path(path)
    return not path.exists() or (path.is_dir() and (
        (path / mark).is_file() or not any(path.iterdir())))


class StagedFolder:
    """A case folder written atomically.

    ``StagedFolder(target)`` checks at once that ``target`` may be replaced and that its parent
    takes files, and creates the staging folder ``path`` beside it; write everything there,
    then ``commit()`` swaps it in and removes the earlier contents (files the run did not
    produce do not survive). ``discard()`` (also on leaving a ``with`` block by an exception)
    removes the staging folder and leaves ``target`` as it was.
    """

    def __init__(self, target, flag="--out", mark=OWNED_MARK, owner=None):
        self.target = Path(target)
        if self.target.exists() and not self.target.is_dir():
            raise OutputError(f"{flag} {self.target} is a file, not a folder; give a folder")
        if (self.target / ROOT_MARK).is_file() and not (self.target / mark).is_file():
            raise OutputError(f"{flag} {self.target} is the root of pbcm's reports (it holds "
                              f"{ROOT_MARK}): each case and study writes its own folder in it; "
                              f"give {self.target / (owner or 'NAME')}")
        if not owned(self.target, mark):
            raise OutputError(f"{flag} {self.target} holds files that pbcm did not write (no "
                              f"{mark}); pbcm replaces the whole folder it writes, so "
                              "give a new or empty folder")
        wrote = writer(self.target, mark)
        if owner and wrote and wrote != owner:
            raise OutputError(f"{flag} {self.target} holds the output of {wrote}, not of "
                              f"{owner}; writing {owner} there would replace it: give "
                              f"another folder (e.g. {self.target.parent / owner})")
        if os.path.ismount(self.target):
            raise OutputError(f"{flag} {self.target} is a mount point: pbcm swaps in the "
                              "folder it writes by a rename, which a mount point cannot take; "
                              f"give a folder inside it (e.g. {self.target / (owner or 'out')})")
        parent = writable_folder(self.target.parent, flag=f"{flag} {self.target}: the folder")
        for left in stale_staging(self.target):    # a killed run's: never its own output
            shutil.rmtree(left, ignore_errors=True)
        self.path = Path(tempfile.mkdtemp(prefix=staging_prefix(self.target), dir=parent))
        os.chmod(self.path, 0o777 & ~_umask())

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is not None:
            self.discard()

    def discard(self):
        """Remove the staging folder (nothing once committed)."""
        if self.path is not None:
            shutil.rmtree(self.path, ignore_errors=True)
            self.path = None

    def commit(self):
        stop.checkpoint()   # never swap in the output of a run that was told to stop
        with no_interrupt():
            if self.target.exists():
                if not _exchange(self.path, self.target):   # no atomic swap on this system
                    old = self.path.with_name(self.path.name + "-old")
                    os.rename(self.target, old)
                    os.rename(self.path, self.target)
                    self.path = old
            else:
                os.rename(self.path, self.target)
                self.path = None
        self.discard()   # the staging path now holds the earlier contents, if any
        return self.target


def write_atomic(path, data):
    """Write ``data`` (str or bytes) to ``path`` through a temporary file in the same folder
    (created if need be) and a rename: a reader sees the old file or the new one, never a
    part; a run killed while writing leaves only a hidden temporary file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}{TMP_TAG}", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode() if isinstance(data, str) else data)
        os.chmod(tmp, 0o666 & ~_umask())
        with no_interrupt():
            os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a, b):
    """Swap two paths in one system call (Linux renameat2); False where unsupported."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError, TypeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                   ctypes.c_uint]
    if fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP):  # e.g. a file system without it
        return False
    raise OSError(err, os.strerror(err), str(b))
