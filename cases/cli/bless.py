"""`pbcm bless`: the gold values rewritten from measured metrics."""
import sys
from pathlib import Path

from ..running.output import StagedFolder, writable_folder, write_atomic
from .common import add_selection, number
from .pipeline import configs, run_everything

def add(sub):
    """The command's parser."""
    b = sub.add_parser(
        "bless", help="rewrite the gold values from measured metrics and print what changed",
        description="Set the gold values from measured metrics: quick mode into the compact "
                    "files gold/CASE.quick.jsonl (6 significant digits; a value that agrees "
                    "to that precision is kept as it is), full mode by installing the case "
                    "folder as the committed reports/CASE. Without --metrics it first runs "
                    "every case and study, and only when --run asks for it: in full mode "
                    "(the whole main job, as `pbcm report` runs it) unless --quick is "
                    "given. It keeps the gold rows of "
                    "runs it did not see (other modes, meshes, models) unless --prune is "
                    "given; --margin sets the policy's rtol. It prints every value it adds, "
                    "changes or removes.")
    b.add_argument("--margin", type=number("--margin", "a relative tolerance, a number > 0",
                                            low=0), default=None,
                   help="relative tolerance rtol of the policy (default: keep the policy's, "
                        "0.1 for a new gold folder)")
    b.add_argument("--prune", action="store_true",
                   help="remove (and list) gold rows of runs not in the metrics blessed")
    b.add_argument("--gold", default="gold",
                   help="the gold folder to rewrite (default gold)")
    b.add_argument("--metrics", help="bless the metrics.json files under this folder instead "
                                     "of a fresh run")
    b.add_argument("--run", action="store_true",
                   help="without --metrics: run every case and study first (the quick or "
                        "the full main job), then bless")
    add_selection(b)
    b.set_defaults(func=run)


def run(args):
    """Gold from a folder of metrics (``--metrics``) or from a fresh run of every case: the
    compact files of quick mode, and for full mode the case folders installed where the
    policy keeps the full-mode gold. What it keeps: gold rows of runs it did not see (other
    modes, meshes, models...) unless ``--prune``."""
    import tempfile
    from ..running.gate import (COMPACT_MODES, POLICY, CheckError, Gold, Policy, bless, load,
                                measured)
    folder = Path(args.gold)
    if not args.metrics and not args.run:
        print("pbcm bless: error: nothing to bless: give --metrics DIR (metrics already "
              "measured, e.g. by `pbcm report --quick --out DIR`), or --run to run every case "
              "and study first" + (" (quick mode)" if args.quick else " (full mode: the whole "
                                   "main job, as `pbcm report` runs it)"), file=sys.stderr)
        return 2
    if args.metrics and args.run:
        print("pbcm bless: error: --run and --metrics exclude each other: bless what was "
              "measured, or run first", file=sys.stderr)
        return 2
    try:   # every check before the run: the old gold must load and the folder be writable
        writable_folder(folder, flag="--gold")
        old = load(folder) if (folder / POLICY).is_file() and any(
            folder.glob("*.jsonl")) else Gold(Policy(atol_of=dict(ATOL_OF)), {}, {}, folder)
        if args.metrics:
            values = measured(args.metrics)
            new, changes = bless(values, old, rtol=args.margin, prune=args.prune)
            _write_gold(folder, old, new, values, changes, Path(args.metrics))
        else:
            cfgs = configs(args)
            with tempfile.TemporaryDirectory(prefix="pbcm-bless-") as tmp:
                def folder_of(name):
                    (Path(tmp) / name).mkdir()
                    return Path(tmp) / name
                run_everything(args, cfgs, folder_of)
                values = measured(tmp)
                new, changes = bless(values, old, rtol=args.margin, prune=args.prune)
                _write_gold(folder, old, new, values, changes, Path(tmp))
    except CheckError as exc:
        print(f"pbcm bless: error: {exc}", file=sys.stderr)
        return 2
    for line in changes or ["no change"]:
        print(line)
    n = sum(len(r) for k, r in new.rows.items() if k[1] in COMPACT_MODES)
    print(f"{n} gold values of {', '.join(COMPACT_MODES)} mode in {folder}")
    return 0


# absolute floors of a new gold folder: static displacements are solved to a residual of
# 1e-9 (model.static), so their differences below 1e-8 are the solver's
ATOL_OF = {"disp_rel_l2_p1": 1e-8, "disp_rel_l2_p2": 1e-8, "disp_max_rel_p2": 1e-8}


def _write_gold(folder, old, new, values, changes, root):
    """Write the compact gold files (atomically, each), the policy when it changed, and
    install the case folders of full-mode metrics where the full-mode gold lives."""
    import shutil
    from ..running.gate import COMPACT_MODES, POLICY, compact_files, policy_text
    files = compact_files(new)
    for name, text in files.items():
        path = folder / name
        if not path.is_file() or path.read_text() != text:
            write_atomic(path, text)
    for path in folder.glob("*.jsonl"):
        if path.name not in files:
            path.unlink()
    if not (folder / POLICY).is_file() or new.policy != old.policy:
        write_atomic(folder / POLICY, policy_text(new.policy))
    full = new.full_root
    for (case, mode), source in sorted((values.sources or {}).items()):
        if mode in COMPACT_MODES:
            continue
        target = full / case
        if source.parent.resolve() == target.resolve():
            changes.append(f"full    {case}: the gold is {target / 'metrics.json'} itself")
            continue
        with StagedFolder(target) as out:
            shutil.copytree(source.parent, out.path, dirs_exist_ok=True)
            out.commit()
        changes.append(f"full    {case}: {source.parent} installed as the gold {target}")

