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
    from ..index import write_index
    root = Path(args.out)
    missing = [name for name in CASES if not (root / name / "metrics.json").is_file()]
    if missing:
        raise UsageError(f"{root} lacks the metrics.json of {', '.join(missing)}: run "
                         "`pbcm report` (or `pbcm run CASE` for each) first")
    path = write_index(root, list(CASES), list(STUDY_MODULES))
    print(f"index written to {path}, with index.html and the glossary")
    return 0

