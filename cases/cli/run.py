"""`pbcm run CASE`: one case or study, written to its folder; `pbcm run --problem FILE`: a
user's problem, declared in a TOML file, run as a case."""
import json
from pathlib import Path

import model
from ..running.output import StagedFolder
from .common import (UsageError, add_selection, case_configs, case_into, case_named,
                     check_executor, chosen_models, run_store, run_study_into, study_config,
                     worker_pool)

def add(sub):
    """The command's parser."""
    r = sub.add_parser("run", help="run one case, study or problem and write its report folder",
                       description="Run a case or study of the library (`pbcm list` names "
                                   "them), or a problem of your own: --problem FILE.toml "
                                   "declares its mesh, material, boundary conditions and "
                                   "measures (`pbcm problem new NAME` writes a commented "
                                   "template).")
    r.add_argument("case", nargs="?", help="a case or study name (see pbcm list)")
    r.add_argument("--case", dest="case_file", action="append", default=[], metavar="FILE",
                   help="a Python file that declares a case of your own (CASE = YourCase(), "
                        "a cases.framework.Case); then run it by its name (repeatable)")
    r.add_argument("--problem", metavar="FILE",
                   help="run the problem this TOML file declares instead of a library case "
                        "(output: reports/problems/NAME, NAME its name); with the study "
                        "realtime, that study on the problem's mesh refined (output: "
                        "reports/problems/NAME.realtime)")
    r.add_argument("--out", help="output folder (default reports/CASE, or "
                                 "reports/problems/NAME for --problem)")
    r.add_argument("--rewrite", action="store_true",
                   help="a study only: draw its report again from the runs recorded in the "
                        "metrics.json of --out, without computing (after a change of the "
                        "report's code)")
    add_selection(r)
    r.set_defaults(func=run)


def run(args):
    from ..registry import STUDY_MODULES, studies
    if args.problem and args.case == "realtime":
        return _run_realtime_problem(args)
    if args.problem or not args.case:
        return _run_problem(args)
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
    case = case_named(args.case, args.case_file)
    with StagedFolder(Path(args.out) if args.out else Path("reports") / args.case,
                          owner=args.case) as out, \
            worker_pool(args, cfgs) as workers:
        runs = case_into(case, cfgs[args.case], out.path, workers, run_store(args))
        path = out.commit()
    print(f"{args.case}: {len(runs)} runs written to {path}")
    return 0


# what a problem's TOML declares, so the command line does not: the option and the key
FROM_THE_TOML = {"meshes": "[mesh] file", "bcs": "the [[displacement]] entries",
                 "E": "[material] E", "nu": "[material] nu", "rho": "[material] rho",
                 "rewrite": None}


def _run_problem(args):
    """`pbcm run --problem FILE`: the problem checked whole, then run as a case into its
    folder, with a verbatim copy of the TOML."""
    from ..library.problem import problem_case
    if not args.problem:
        raise UsageError("give a case or study name (see `pbcm list`), or --problem FILE.toml")
    if args.case:
        raise UsageError(f"give either the case {args.case} or --problem {args.problem}, not "
                         "both (a problem runs as a case, or in the study realtime: `pbcm run "
                         "realtime --problem FILE`)")
    for option, key in FROM_THE_TOML.items():
        if getattr(args, option, None):
            where = f"set {key} in the TOML" if key else "rerun the problem"
            raise UsageError(f"--{option} does not apply to --problem: {where}")
    check_executor(args)
    path = Path(args.problem)
    case = problem_case(path)        # every error of the TOML, before any computing
    cfg = case.settings(quick=args.quick, models=chosen_models(args.models,
                                                                list(model.PRESETS)))
    with StagedFolder(Path(args.out) if args.out else Path("reports") / "problems" / case.name,
                      owner=case.name) as out, \
            worker_pool(args, {case.name: cfg}) as workers:
        runs = case_into(case, cfg, out.path, workers, run_store(args))
        (out.path / path.name).write_bytes(case.spec.source)
        _write_glossary(out.path)
        written = out.commit()
    print(f"{case.name}: {len(runs)} runs written to {written}")
    return 0


def _run_realtime_problem(args):
    """`pbcm run realtime --problem FILE`: the real-time study on the problem's refinement
    family, timed on this machine first (alone: wall clock), then its static solves; with
    ``--rewrite`` drawn again from the runs its folder's metrics.json recorded."""
    from ..library.problem import load
    from ..registry import studies
    from ..reporting.costs import family_models
    from ..studies.realtime.problem import ProblemRealtimeSettings
    for option, key in FROM_THE_TOML.items():
        if key and getattr(args, option, None):
            raise UsageError(f"--{option} does not apply to realtime --problem: set {key} in "
                             "the TOML")
    check_executor(args)
    spec = load(Path(args.problem))          # every error of the TOML, before any computing
    models = chosen_models(args.models, family_models(args.quick) + tuple(model.PRESETS))
    study = studies()["realtime"]
    folder = Path(args.out) if args.out else \
        Path("reports") / "problems" / f"{spec.name}.realtime"
    if args.rewrite:
        cfg, data = _recorded_problem_study(study, spec, folder)
    else:
        cfg = ProblemRealtimeSettings.of(spec, quick=args.quick, models=models)
    with StagedFolder(folder, owner=cfg.case_name) as out:
        if not args.rewrite:
            store = run_store(args)
            bench = timings(cfg, store)
            with worker_pool(args, {cfg.case_name: cfg}) as workers:
                data = study.run(cfg, workers=workers, bench=bench, store=store)
        study.write(out.path, cfg, data)
        (out.path / Path(args.problem).name).write_bytes(spec.source)
        _write_glossary(out.path)
        written = out.commit()
    print(f"realtime on {spec.name}: written to {written}")
    print(json.loads((written / "metrics.json").read_text())["answer"])
    return 0


# what a model's timing on a user's mesh may raise and be recorded as failed there (a
# blow-up, a degenerate or inverted element, a model that does not take the mesh)
TIMING_FAILURES = (model.errors.PbcmError, ArithmeticError, RuntimeError)


def timings(cfg, store, rounds=5):
    """{"realtime_rows": the problem's family timed, "realtime_machine": this machine}: from
    the run store where this machine timed this problem before, else timed now (nothing else
    should run meanwhile: the times are wall clock)."""
    from numpy.linalg import LinAlgError
    from ..running.store import key
    from ..studies.realtime.problem import RAMP_S
    from ..tools import bench, realtime_bench
    here = bench.machine()
    k = key(kind="realtime-problem-timing", **cfg.problem(), quick=cfg.quick,
            models=list(cfg.models), machine=here, rounds=rounds)
    got = store.get(k)
    if got is None:
        family = realtime_bench.problem_family(cfg.loading.levels, cfg.material, RAMP_S)
        rows = realtime_bench.run(list(cfg.models), cfg.quick, rounds, print, family=family,
                                  failures=TIMING_FAILURES + (LinAlgError,),
                                  over_in_a_row=1, label=f"realtime: timing {cfg.spec.name}")
        got = store.put(k, {"realtime_rows": rows, "realtime_machine": here})
    return got


def _recorded_problem_study(study, spec, folder):
    """(settings, data) of the real-time study of ``spec`` recorded in ``folder``'s
    metrics.json, refused where the TOML's problem has changed since."""
    from ..running.runner import jsonable
    from ..studies.realtime.problem import ProblemRealtimeSettings
    path = folder / "metrics.json"
    try:
        metrics = json.loads(path.read_text())
        params = metrics["parameters"]
        cfg = ProblemRealtimeSettings.of(spec, quick=params["quick"],
                                         models=tuple(params["models"]))
        data = {k: metrics[k] for k in study.recorded_keys}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise UsageError(f"--rewrite reads the real-time study of {spec.name} in {folder}: "
                         f"{exc}; run it first (without --rewrite)") from None
    if jsonable(cfg.problem()) != metrics.get("problem"):
        raise UsageError(f"the problem {spec.name} has changed since {path} was written (its "
                         "TOML or mesh): rerun the study")
    return cfg, data


def _write_glossary(folder):
    """The glossary beside a problem's report (its folder may live outside a reports root)."""
    from ..reporting.index import glossary_documents
    from ..running.output import write_atomic
    md, html = glossary_documents()
    write_atomic(folder / "glossary.md", md)
    write_atomic(folder / "glossary.html", html)


def _rewrite_study(study, folder):
    """Draw a study's report again from the runs its metrics.json recorded."""
    from ..reporting.report import read_study
    path = folder / "metrics.json"
    try:
        metrics = read_study(folder, study)
    except (OSError, ValueError) as exc:
        raise UsageError(f"--rewrite reads the {study.name} study's record in {folder}: "
                         f"{exc}; run the study first") from None
    try:
        got = study.recorded(metrics)
        if got is None:
            raise UsageError(f"the {study.name} study cannot be rewritten from its metrics; "
                             "rerun it")
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

