"""`pbcm report`: every case and study, written with the index."""
from contextlib import ExitStack

from ..running.output import StagedFolder, writable_folder
from .common import add_selection
from .pipeline import configs, run_everything, timing_line

def add(sub):
    """The command's parser."""
    rep = sub.add_parser("report", help="run every case and write reports/ with its index")
    rep.add_argument("--out", help="output folder (default reports)")
    add_selection(rep)
    rep.set_defaults(func=run)


def run(args):
    from ..reporting.index import write_index
    from ..registry import CASES
    cfgs = configs(args)
    root = writable_folder(args.out or "reports")
    with ExitStack() as stack:   # every case folder checked and staged before any computing
        staged = {name: stack.enter_context(StagedFolder(root / name, owner=name))
                  for name in cfgs}

        def done(name, runs, seconds):
            what = "" if runs is None else f"{len(runs)} runs "
            print(f"{name}: {what}written to {staged[name].commit()} in {seconds:.0f} s")
        spent = run_everything(args, cfgs, lambda name: staged[name].path, done)
    path = write_index(root, list(CASES), [n for n in cfgs if n not in CASES])
    print(f"index written to {path}, with index.html and the glossary")
    print(timing_line(spent))
    return 0
