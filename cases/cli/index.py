"""`pbcm index`: reports/index.md and index.html from the folders already written."""
from pathlib import Path

from .common import UsageError

def add(sub):
    """The command's parser."""
    ix = sub.add_parser("index", help="rewrite reports/index.md from the folders written",
                        description="Rewrite index.md and index.html from the case and study "
                                    "folders under --out, without running anything.")
    ix.add_argument("--out", default="reports", help="the reports folder (default reports)")
    ix.set_defaults(func=run)


def run(args):
    """reports/index.md and index.html from the case and study folders already written (after
    a `pbcm run` of one case or study, without running the others again)."""
    from ..registry import CASES, STUDY_MODULES
    from ..reporting.index import write_index
    root = Path(args.out)
    present = [name for name in CASES if (root / name / "metrics.json").is_file()]
    if not present:
        raise UsageError(f"{root} holds no case folder (a CASE/metrics.json): run `pbcm "
                         "report` (or `pbcm run CASE`) first, or give the reports folder")
    missing = [name for name in CASES if name not in present]
    path = write_index(root, present, list(STUDY_MODULES), missing)
    if missing:
        print(f"note: no folder of {', '.join(missing)} under {root}: the index answers over "
              "the cases it found, and says so")
    print(f"index written to {path}, with index.html and the glossary")
    return 0

