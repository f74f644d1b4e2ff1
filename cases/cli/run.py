"""`pbcm run CASE`: one case or study, written to its folder."""
from pathlib import Path

from ..output import StagedFolder
from .common import (UsageError, add_selection, case_configs, run_case_into, run_store,
                     run_study_into, study_config, worker_pool)

def add(sub):
    """The command's parser."""
    r = sub.add_parser("run", help="run one case and write its report folder")
    r.add_argument("case", help="a case or study name (see pbcm list)")
    r.add_argument("--out", help="output folder (default reports/CASE)")
    r.add_argument("--rewrite", action="store_true",
                   help="a study only: draw its report again from the runs recorded in the "
                        "metrics.json of --out, without computing (after a change of the "
                        "report's code)")
    add_selection(r)
    r.set_defaults(func=run)


def run(args):
    from ..registry import STUDY_MODULES, studies
    if args.case in STUDY_MODULES and args.rewrite:
        return _rewrite_study(studies()[args.case], Path(args.out) if args.out
                              else Path("reports") / args.case)
    if args.rewrite:
        raise UsageError(f"--rewrite applies to a study ({', '.join(STUDY_MODULES)}), not to "
                         f"the case {args.case}: rerun the case")
    if args.case in STUDY_MODULES:
        study = studies()[args.case]
        for option in ("models", "meshes"):
            if getattr(args, option, None) and option not in study.selections:
                takes = ("it fixes its own" if not study.selections else
                         f"it takes only --{', --'.join(study.selections)}; not")
                raise UsageError(f"--{option} does not apply to the {study.name} study: "
                                 f"{takes} {option}; leave --{option} out")
        cfg = study_config(study, args)
        with StagedFolder(Path(args.out) if args.out else Path("reports") / args.case,
                          owner=args.case) as out, \
                worker_pool(args, {args.case: cfg}) as workers:
            run_study_into(study, cfg, out.path, workers, run_store(args))
            path = out.commit()
        print(f"{args.case}: written to {path}")
        return 0
    cfgs = case_configs([args.case], args)
    with StagedFolder(Path(args.out) if args.out else Path("reports") / args.case,
                          owner=args.case) as out, \
            worker_pool(args, cfgs) as workers:
        runs = run_case_into(args.case, cfgs[args.case], out.path, workers, run_store(args))
        path = out.commit()
    print(f"{args.case}: {len(runs)} runs written to {path}")
    return 0


def _rewrite_study(study, folder):
    """Draw a study's report again from the runs its metrics.json recorded."""
    import json
    path = folder / "metrics.json"
    try:
        metrics = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise UsageError(f"--rewrite reads the {study.name} study's {path}: {exc}; run the "
                         "study first") from None
    got = study.recorded(metrics)
    if got is None:
        raise UsageError(f"the {study.name} study cannot be rewritten from its metrics; rerun it")
    try:
        cfg, data = got
    except (KeyError, TypeError) as exc:
        raise UsageError(f"{path} lacks {exc}: it was written by another version; rerun the "
                         "study") from None
    if cfg.problem() != metrics.get("problem"):
        raise UsageError(f"the {study.name} study's problem parameters have changed since "
                         f"{path} was written; rerun the study")
    with StagedFolder(folder, owner=study.name) as out:
        study.write(out.path, cfg, data)
        written = out.commit()
    print(f"{study.name}: rewritten from its recorded runs in {written}")
    return 0

