"""The run store: every model run and every FEM reference, kept once under a key of what
determines it, so that a second `pbcm report`, a study and a sweep find what was computed.

A key is the hash of what determines a result: its kind (a case's reference or model run, a
study's unit), the case, mesh, bc and model, the settings that define the problem (material,
geometry, loads, mode, what the run skips), and the fingerprint of the package's source (every
file of ``model``, ``reference`` and ``cases``) and of the numerical libraries' versions. A change
to any source file therefore misses every entry: nothing stale is ever served.

The entries live in a diskcache (SQLite and files) in ``$PBCM_CACHE``, by default the user's
cache directory; an entry is committed in one transaction after its value is written, so a run
killed while writing leaves no entry that a later run would trust. ``--no-cache`` (or
``PBCM_NO_CACHE=1``) bypasses the store.
"""
import hashlib
import json
import os
from functools import lru_cache
from pathlib import Path

ENV = "PBCM_CACHE"
ENV_OFF = "PBCM_NO_CACHE"
PACKAGES = ("model", "reference", "cases")
ROOT = Path(__file__).resolve().parents[1]
SKIP = {"__pycache__"}


def default_folder():
    """``$PBCM_CACHE``, else the user's cache directory for pbcm."""
    if os.environ.get(ENV):
        return Path(os.environ[ENV]).expanduser()
    import platformdirs
    return Path(platformdirs.user_cache_dir("pbcm"))


@lru_cache(maxsize=None)
def fingerprint():
    """The fingerprint of the source this process runs: taken once (a process runs the code
    it loaded, whatever happens to the files later)."""
    return source_hash(ROOT)


def source_hash(root):
    """The hash of every file of the package's source under ``root`` (path and bytes) and of
    the versions of the libraries the numbers come from."""
    import numba
    import numpy
    import scipy
    import skfem
    h = hashlib.sha256()
    for package in PACKAGES:
        for f in sorted((Path(root) / package).rglob("*")):
            if f.is_file() and not SKIP & set(f.parts) and f.suffix not in (".pyc",):
                h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
    h.update(json.dumps([numpy.__version__, scipy.__version__, numba.__version__,
                         getattr(skfem, "__version__", "?")]).encode())
    return h.hexdigest()


def key(**what):
    """The key of a result determined by ``what`` (plain values) and the source."""
    text = json.dumps({**what, "source": fingerprint()}, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()


class RunStore:
    """The store in ``folder`` (default ``default_folder()``); ``enabled=False`` finds nothing
    and keeps nothing. Picklable: a worker process opens the same folder. ``found`` and
    ``kept`` count this process's hits and writes."""

    def __init__(self, folder=None, enabled=True):
        self.folder = Path(folder) if folder else default_folder()
        self.enabled = enabled and not os.environ.get(ENV_OFF)
        self._cache = None
        self.found = self.kept = 0

    def __getstate__(self):
        return {"folder": self.folder, "enabled": self.enabled}

    def __setstate__(self, state):
        self.__init__(state["folder"], state["enabled"])

    def _open(self):
        if self._cache is None:
            import diskcache
            self.folder.mkdir(parents=True, exist_ok=True)
            # no size limit: results are evicted by a change of source, not by age
            self._cache = diskcache.Cache(str(self.folder), size_limit=2 ** 62,
                                          eviction_policy="none")
        return self._cache

    def get(self, k):
        """The value stored under key ``k``, or None."""
        if not self.enabled:
            return None
        value = self._open().get(k)
        if value is not None:
            self.found += 1
        return value

    def put(self, k, value):
        """Keep ``value`` under key ``k`` (committed whole, or not at all)."""
        if self.enabled:
            self._open().set(k, value)
            self.kept += 1
        return value

    def close(self):
        if self._cache is not None:
            self._cache.close()
            self._cache = None


OFF = RunStore(enabled=False)

__all__ = ["RunStore", "OFF", "key", "fingerprint", "source_hash", "default_folder", "ENV", "ENV_OFF"]
