"""`pbcm cache`: what the run store holds, and emptying it."""
from .common import UsageError


def add(sub):
    """The command's parser."""
    c = sub.add_parser("cache", help="show or clear the run store",
                       description="The run store ($PBCM_CACHE, default the user cache "
                                   "directory) keeps every FEM reference and model run under a "
                                   "key of what determines it. `info` prints its folder, size, "
                                   "cap ($PBCM_CACHE_SIZE_GB) and entries by kind, and how many "
                                   "are stale (computed under another source: no run of this "
                                   "one finds them; they expire on their own); `clear` removes "
                                   "every entry, `clear --stale` only the stale ones.")
    what = c.add_subparsers(dest="action", required=True)
    what.add_parser("info", help="folder, size, cap, entries by kind, stale entries")
    clear = what.add_parser("clear", help="remove every entry (or --stale ones)")
    clear.add_argument("--stale", action="store_true",
                       help="remove only the entries computed under another source")
    c.set_defaults(func=run)


def run(args):
    from ..running.store import RunStore
    store = RunStore()
    if not store.enabled:
        raise UsageError("the run store is off (PBCM_NO_CACHE is set): unset it to see it")
    try:
        if args.action == "info":
            i = store.info()
            print(f"run store {i['folder']}: {_size(i['bytes'])} of its {_size(i['cap_bytes'])} "
                  f"cap, {sum(i['entries'].values())} entries, {i['stale']} stale")
            for kind, n in sorted(i["entries"].items()):
                print(f"  {kind or '(no kind)':<28} {n}")
        else:
            n = store.clear(stale_only=args.stale)
            print(f"removed {n} {'stale ' if args.stale else ''}entries from {store.folder}")
    finally:
        store.close()
    return 0


def _size(n):
    """Bytes in binary units (the cap is set in GiB)."""
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n} B" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1024
