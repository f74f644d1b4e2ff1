"""The run store: every model run and every FEM reference, kept once under a key of what
determines it, so that a second `pbcm report`, a study and a sweep find what was computed.

A key is the hash of what determines a result: its kind (a case's reference or model run, a
study's unit), the case, mesh, bc and model, the settings that define the problem (material,
geometry, loads, mode, what the run skips), and the fingerprint of the source a run executes
(every file of ``model``, ``reference`` and ``cases``, every term file given with ``--term`` and
every package of the ``pbcm.terms`` entry points) and of the numerical libraries' versions. A
change to any of these files therefore misses every entry: nothing stale is ever served.

The entries live in a diskcache (SQLite and files) in ``$PBCM_CACHE``, by default the user's
cache directory; an entry is committed in one transaction after its value is written, so a run
killed while writing leaves no entry that a later run would trust. ``--no-cache`` (or
``PBCM_NO_CACHE=1``) bypasses the store. Each entry is tagged with the source fingerprint it
was computed under (a different one makes it stale: no key of today's source finds it) and
expires ``KEEP_DAYS`` days after it was last stored or found, so stale entries leave on their
own; the store is capped at ``PBCM_CACHE_SIZE_GB`` (default ``SIZE_GB``), the least recently
used entries evicted beyond it (diskcache's eviction). ``pbcm cache info`` shows it and
``pbcm cache clear [--stale]`` empties it. ``PBCM_CACHE_KINDS`` (a comma-separated list of
kinds, e.g. the FEM references: ``reference,convergence-reference``) keeps and finds only
entries of those kinds: every model run is computed, the references solved once (the test
suite runs so).
"""
import hashlib
import json
import os
import sqlite3
import sys
from functools import lru_cache
from pathlib import Path

from model.errors import PbcmError

ENV = "PBCM_CACHE"
ENV_OFF = "PBCM_NO_CACHE"
ENV_KINDS = "PBCM_CACHE_KINDS"
ENV_SIZE = "PBCM_CACHE_SIZE_GB"
SIZE_GB = 4.0          # the default cap in GiB: a day's work of the library, with room
KEEP_DAYS = 14         # an entry neither stored nor found for this long expires
# the kinds that hold FEM references only: what no model, and no patch of a model, changes
REFERENCE_KINDS = ("reference", "convergence-reference", "convergence-reference-at",
                   "artefact-reference", "truthcube-reference", "truthcube-fit",
                   "manufactured")
PACKAGES = ("model", "reference", "cases")
ROOT = Path(__file__).resolve().parents[2]
SKIP = {"__pycache__"}


_WARNED = set()


def _warn(text):
    """One line on stderr, once per process and text."""
    if text not in _WARNED:
        _WARNED.add(text)
        print(f"pbcm: warning: {text}", file=sys.stderr)


def default_folder():
    """``$PBCM_CACHE``, else the user's cache directory for pbcm."""
    if os.environ.get(ENV):
        return Path(os.environ[ENV]).expanduser()
    import platformdirs
    return Path(platformdirs.user_cache_dir("pbcm"))


def fingerprint():
    """The fingerprint of the source this process runs: pbcm's own and every term file and
    entry-point term package it loads (``PBCM_TERMS``, group ``pbcm.terms``); taken once per
    set of term files (a process runs the code it loaded, whatever happens to the files
    later)."""
    from model import simulators, terms
    return _fingerprint(tuple(terms.user_files()) + tuple(simulators.user_files()))


@lru_cache(maxsize=None)
def _fingerprint(term_files):
    h = hashlib.sha256(source_hash(ROOT).encode())
    for f in term_sources(term_files):
        h.update(str(f).encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()


def term_sources(term_files=()):
    """The files of the terms and simulators pbcm loads from outside its package:
    ``term_files`` and every Python file of the packages named in the ``pbcm.terms`` and
    ``pbcm.models`` entry-point groups, sorted."""
    import importlib.metadata
    import importlib.util
    from model.simulators import ENTRY_POINT_GROUP as MODELS
    from model.terms import ENTRY_POINT_GROUP as TERMS
    out = {Path(f).resolve() for f in term_files if Path(f).is_file()}
    eps = [*importlib.metadata.entry_points(group=TERMS),
           *importlib.metadata.entry_points(group=MODELS)]
    for ep in eps:
        top = ep.value.split(":")[0].split(".")[0]
        try:
            spec = importlib.util.find_spec(top)
        except (ImportError, ValueError):
            spec = None
        if spec is None:
            continue                 # its import fails with its own message when it is used
        if spec.submodule_search_locations:
            for folder in spec.submodule_search_locations:
                out.update(p.resolve() for p in Path(folder).rglob("*.py")
                           if not SKIP & set(p.parts))
        elif spec.origin and Path(spec.origin).is_file():
            out.add(Path(spec.origin).resolve())
    return sorted(out)


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
                         getattr(skfem, "__version__", "?"), *engine_versions()]).encode())
    return h.hexdigest()


def engine_versions():
    """The optional engines' versions (the Newton models' numbers come from them), where
    installed."""
    import importlib.metadata
    out = []
    for dist in ("warp-lang", "newton"):
        try:
            out.append(f"{dist} {importlib.metadata.version(dist)}")
        except importlib.metadata.PackageNotFoundError:
            pass
    return out


def key(**what):
    """The key of a result determined by ``what`` (plain values) and the source: its kind, a
    colon, and the hash of the rest (the kind readable, for ``PBCM_CACHE_KINDS``)."""
    text = json.dumps({**what, "source": fingerprint()}, sort_keys=True, default=repr)
    return f"{what.get('kind', '')}:{hashlib.sha256(text.encode()).hexdigest()}"


def kind_of(k):
    """The kind a key was made with ('' for a key made without one)."""
    return k.split(":", 1)[0] if ":" in k else ""


class RunStore:
    """The store in ``folder`` (default ``default_folder()``); ``enabled=False`` finds nothing
    and keeps nothing. Picklable: a worker process opens the same folder. ``found`` and
    ``kept`` count this process's hits and writes. ``kinds`` (default ``$PBCM_CACHE_KINDS``,
    else every kind): the kinds of entry kept and found; any other key finds nothing and
    keeps nothing."""

    def __init__(self, folder=None, enabled=True, kinds=None):
        self.folder = Path(folder) if folder else default_folder()
        self.enabled = enabled and not os.environ.get(ENV_OFF)
        if kinds is None and os.environ.get(ENV_KINDS):
            kinds = [k.strip() for k in os.environ[ENV_KINDS].split(",") if k.strip()]
        self.kinds = None if kinds is None else frozenset(kinds)
        self._cache = None
        self.found = self.kept = 0

    def __getstate__(self):
        return {"folder": self.folder, "enabled": self.enabled,
                "kinds": None if self.kinds is None else sorted(self.kinds)}

    def __setstate__(self, state):
        self.__init__(state["folder"], state["enabled"], state.get("kinds"))

    def _keeps(self, k):
        return self.enabled and (self.kinds is None or kind_of(k) in self.kinds)

    def _open(self):
        if self._cache is None:
            import diskcache
            self.folder.mkdir(parents=True, exist_ok=True)
            db = self.folder / "cache.db"
            if db.is_file() and db.stat().st_size == 0 and len(list(self.folder.iterdir())) > 1:
                self._set_aside("its index cache.db is empty")
            try:
                self._cache = diskcache.Cache(str(self.folder), **settings())
                len(self._cache)          # reads the index: a corrupt one raises here
            except sqlite3.DatabaseError as exc:
                self._set_aside(f"its index is corrupt ({exc})")
                self._cache = diskcache.Cache(str(self.folder), **settings())
        return self._cache

    def _set_aside(self, why):
        """Move a broken store aside (kept, never rebuilt over its files) and say so once."""
        if self._cache is not None:
            self._cache.close()
            self._cache = None
        aside = self.folder.with_name(f"{self.folder.name}.broken-{os.getpid()}")
        os.rename(self.folder, aside)
        self.folder.mkdir(parents=True)
        _warn(f"the run store {self.folder}: {why}; moved aside to {aside} (delete it when "
              "you like) and started empty")

    def _failed(self, what, exc):
        """The optional store failed: warn once, go on without it (a run never stops for
        it)."""
        self.enabled = False
        _warn(f"the run store {self.folder} could not {what} ({type(exc).__name__}: {exc}); "
              "going on without it (--no-cache skips it; a corrupt store is moved aside on "
              "the next run)")

    def get(self, k):
        """The value stored under key ``k``, or None (also when the store fails: it warns
        once and is off for the rest of the process)."""
        if not self._keeps(k):
            return None
        try:
            cache = self._open()
            value = cache.get(k)
            if value is not None:
                cache.touch(k, expire=KEEP_DAYS * 86400)    # found: kept another while
        except (OSError, sqlite3.Error) as exc:
            self._failed("be read", exc)
            return None
        if value is not None:
            self.found += 1
        return value

    def put(self, k, value):
        """Keep ``value`` under key ``k`` (committed whole, or not at all); a store that cannot
        keep it warns once and is off for the rest of the process."""
        if self._keeps(k):
            try:
                self._open().set(k, value, expire=KEEP_DAYS * 86400, tag=fingerprint())
            except (OSError, sqlite3.Error) as exc:
                self._failed("keep a result", exc)
                return value
            self.kept += 1
        return value

    def _tags(self):
        """{key: the source fingerprint its entry was computed under (None: untagged)}."""
        cache, out = self._open(), {}
        for k in list(cache.iterkeys()):
            got = cache.get(k, read=True, tag=True)
            if got is None or got[0] is None:
                continue                     # gone meanwhile (expired, evicted)
            if hasattr(got[0], "close"):
                got[0].close()
            out[k] = got[1]
        return out

    def info(self):
        """{'folder', 'bytes', 'entries': {kind: n}, 'stale': n, 'cap_bytes'}: what the store
        holds, a stale entry being one computed under another source than this process's."""
        cache, now = self._open(), fingerprint()
        cache.expire()
        tags = self._tags()
        kinds = {}
        for k in tags:
            kinds[kind_of(k)] = kinds.get(kind_of(k), 0) + 1
        return {"folder": self.folder, "bytes": cache.volume(), "entries": kinds,
                "stale": sum(t != now for t in tags.values()),
                "cap_bytes": settings()["size_limit"]}

    def clear(self, stale_only=False):
        """Remove every entry, or only those computed under another source; the number
        removed."""
        cache = self._open()
        if not stale_only:
            return cache.clear()
        now = fingerprint()
        return sum(bool(cache.delete(k)) for k, t in self._tags().items() if t != now)

    def close(self):
        if self._cache is not None:
            self._cache.close()
            self._cache = None


def settings():
    """The diskcache settings of the store: capped at ``$PBCM_CACHE_SIZE_GB`` (default
    SIZE_GB), the least recently used entries evicted beyond it."""
    raw = os.environ.get(ENV_SIZE)
    try:
        gb = float(raw) if raw else SIZE_GB
        if not gb > 0:
            raise ValueError
    except ValueError:
        raise StoreError(f"{ENV_SIZE}={raw!r}: the run store's cap in GB is a number > 0; "
                         "set it to one, or unset it for the default") from None
    return {"size_limit": int(gb * 2 ** 30), "eviction_policy": "least-recently-used"}


class StoreError(PbcmError, ValueError):
    """A setting of the run store that cannot be used."""


OFF = RunStore(enabled=False)

__all__ = ["RunStore", "OFF", "key", "kind_of", "fingerprint", "source_hash", "default_folder",
           "term_sources", "ENV", "ENV_OFF", "ENV_KINDS", "REFERENCE_KINDS"]
