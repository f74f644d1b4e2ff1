"""The ``pbcm`` command line.

Every argument is checked before any computing starts (names, numbers, output paths); errors
are one line ``pbcm: error: ...`` with exit status 2, Ctrl-C is one line with exit status 130.
"""
import argparse
import math
import os
import re
import sys
import textwrap
from pathlib import Path

import model
import model.terms
from model.errors import PbcmError
from model.mesh import SCHEMES, box, read
from . import stop
from .output import StagedFolder, writable_folder, write_text_atomic

DESCRIPTION = """\
pbcm measures how far the particle soft-body model of Nakagawa et al. is from the continuum:
it runs cases against FEM references, writes reports, and gates CI on gold values."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``pbcm: error: ...`` and exit status 2."""

    def error(self, message):
        message = re.sub(r"^argument (\S+): (?=\1 )", "", message)  # the flag is said already
        self.exit(2, f"pbcm: error: {message} (see `{self.prog} --help`)\n")


def _number(flag, what, low=None, high=None, integer=False, open_low=True):
    """An argparse type: a finite number in (low, high), in the user's units, or an error
    naming the flag."""
    def parse(text):
        try:
            v = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{flag} takes {what}, got {text!r}") from None
        ok = math.isfinite(v) and (low is None or (v > low if open_low else v >= low)) \
            and (high is None or v < high)
        if not ok:
            raise argparse.ArgumentTypeError(f"{flag} takes {what}, got {text}")
        return v
    return parse


def _poisson(text):
    v = _number("--nu", "Poisson's ratio, a number between -1 and 0.5")(text)
    if v >= 0.5:
        raise argparse.ArgumentTypeError(
            f"--nu must be below 0.5, got {text} (0.5 is incompressible, which the volume "
            "term cannot represent: use 0.49 at most)")
    if v <= -1:
        raise argparse.ArgumentTypeError(f"--nu must be above -1, got {text} (at -1 the bulk "
                                         "modulus vanishes)")
    return v


def _mesh_command(args):
    if args.source != "cube" and not Path(args.source).is_file():
        raise UsageError(f"mesh file {args.source} does not exist (or is not a file); give a "
                         "mesh file or 'cube'")
    if args.source == "cube":
        # millimetres at the edge, metres inside
        mesh = box(args.n, args.n, args.n, *(3 * [args.size * 1e-3]), scheme=args.scheme,
                   seed=args.seed)
        title = f"cube n={args.n} size={args.size:g} mm scheme={args.scheme}"
    else:
        mesh = read(args.source)
        title = args.source
    q = mesh.quality()
    print(title)
    print(f"  nodes               {q['nodes']}")
    print(f"  tetrahedra          {q['tets']}")
    print(f"  volume              {q['volume'] * 1e9:.6g} mm^3")
    print(f"  radius ratio        min {q['radius_ratio_min']:.3f}  mean {q['radius_ratio_mean']:.3f}"
          "  (1 = regular, 0 = sliver)")
    print(f"  dihedral angles     min {q['dihedral_min_deg']:.1f} deg  "
          f"max {q['dihedral_max_deg']:.1f} deg")
    if mesh.reoriented:
        print(f"  re-oriented         {mesh.reoriented} negatively ordered tetrahedra")
    return 0


def _choose(kind, given, valid):
    """The names asked for (None when not given: the case's default), or a one-line error
    listing the valid ones (exit status 2)."""
    if given is None:
        return None
    bad = [g for g in given if g not in valid]
    if bad:
        raise UsageError(f"unknown {kind} {', '.join(bad)}; valid: {', '.join(valid)}")
    return tuple(given)


def _models(given, presets):
    """The models asked for as canonical labels (None when not given): presets among
    ``presets``, or composed specs (``model.compose``) checked against the term registry."""
    if given is None:
        return None
    from model.compose import checked
    out = []
    for g in given:
        name = checked(g)      # a ModelError names the unknown term, parameter or value
        if name in model.PRESETS and name not in presets:
            raise UsageError(f"model {name} is not run by this case; valid presets: "
                             f"{', '.join(presets)} (or terms composed with '+')")
        out.append(name)
    return tuple(dict.fromkeys(out))


class UsageError(Exception):
    pass


def _case(name):
    from .registry import CASES, STUDY_MODULES
    if name not in CASES:
        raise UsageError(f"unknown case {name}; valid: {', '.join([*CASES, *STUDY_MODULES])}")
    return CASES[name]


def _study_config(study, args):
    """A study's settings from the command line, checked before anything runs."""
    from model.mesh import SCHEMES
    if getattr(args, "bcs", None):
        raise UsageError(f"--bcs does not apply to the {study.name} study: it runs each "
                         "problem's own boundary conditions; leave --bcs out")
    return study.settings(quick=args.quick, meshes=_choose("mesh", args.meshes, SCHEMES),
                          models=_models(args.models, list(model.PRESETS)),
                          E=args.E, nu=args.nu, rho=args.rho)


def _run_study_into(study, cfg, folder, workers=None):
    """Run ``study`` and write its files into ``folder``; the step costs come from the bench
    beside the folder (reports/bench), or the checkout's."""
    from . import costs
    data = costs.load(Path(folder).parent)
    study.write(folder, cfg, study.run(cfg, workers=workers, bench=data))


def _config(case, args):
    return case.settings(quick=args.quick,
                         meshes=_choose("mesh", args.meshes, case.meshes),
                         bcs=_choose("boundary condition", args.bcs, case.bcs),
                         models=_models(args.models, case.models),
                         E=args.E, nu=args.nu, rho=args.rho, shear_scale=args.shear_scale)


def _run_into(name, cfg, folder, workers=None):
    """Run case ``name`` with ``cfg`` (on ``workers``, a started Workers, when given) and
    write its files into the existing ``folder``."""
    from .report import write_case
    from .runner import run
    case = _case(name)
    runs, fields = run(case, cfg, workers=workers)
    write_case(folder, case, cfg, runs, fields)
    return runs


def _workers(args, cfgs):
    """The worker pool of a command (a context; nothing to start for one worker or one unit
    in every case: a worker runs one mesh of a case with all its bcs, or one problem and bc
    of a study)."""
    from contextlib import nullcontext
    from .workers import Workers, available_cores
    units = max(c.units for c in cfgs.values())
    n = min(args.workers or available_cores(), units)
    return Workers(n) if n > 1 else nullcontext()


def _configs(names, args):
    """Every case's configuration, built (and so checked) before anything runs."""
    return {name: _config(_case(name), args) for name in names}


def _summary(case):
    """The first paragraph of the docstring of the module declaring a case, as whole
    sentences on one line."""
    doc = sys.modules[type(case).__module__].__doc__ or case.title
    return " ".join(doc.strip().split("\n\n")[0].split())


def _list_command(args):
    from .registry import CASES
    from .registry import studies
    for name, case in CASES.items():
        print(textwrap.fill(f"{name}: {_summary(case)}", width=96, subsequent_indent="  "))
        print(f"  meshes: {', '.join(case.meshes)} (quick: {', '.join(case.quick_meshes)})")
        print(f"  bcs:    {', '.join(case.bcs)}")
        print(f"  models: {', '.join(case.models)}")
        knobs = [f"{axis}: {knob.label} ({knob.field})" for axis, knob in
                 (("resolution", case.resolution), ("load", case.load)) if knob is not None]
        if knobs:
            print(f"  sweep axes: {'; '.join(knobs)}")
    for name, study in studies().items():
        print(textwrap.fill(f"{name} (study): {_summary(study)}", width=96,
                            subsequent_indent="  "))
    from .studies.sweeps import SHIPPED
    from .studies.sweeps.spec import load
    from .registry import CASES as cases
    for path in sorted(SHIPPED.glob("*.toml")):
        print(f"{path.stem} (sweep, pbcm sweep {path.stem}): {load(path, cases).title}")
    print("force terms (compose them with '+' in --models):")
    for name, cls in sorted(model.terms.registered().items()):
        params = ", ".join(f"{k}={v}" for k, v in cls.params.items())
        doc = (cls.__doc__ or "").strip().split("\n")[0]
        print(textwrap.fill(f"{name}({params}): {doc}", width=96, initial_indent="  ",
                            subsequent_indent="    "))
    return 0


def _run_command(args):
    from .registry import STUDY_MODULES, studies
    if args.case in STUDY_MODULES and args.rewrite:
        return _rewrite_study(studies()[args.case], Path(args.out) if args.out
                              else Path("reports") / args.case)
    if args.rewrite:
        raise UsageError(f"--rewrite applies to a study ({', '.join(STUDY_MODULES)}), not to "
                         f"the case {args.case}: rerun the case")
    if args.case in STUDY_MODULES:
        study = studies()[args.case]
        cfg = _study_config(study, args)
        with StagedFolder(Path(args.out) if args.out else Path("reports") / args.case) as out, \
                _workers(args, {args.case: cfg}) as workers:
            _run_study_into(study, cfg, out.path, workers)
            path = out.commit()
        print(f"{args.case}: written to {path}")
        return 0
    cfgs = _configs([args.case], args)
    with StagedFolder(Path(args.out) if args.out else Path("reports") / args.case) as out, \
            _workers(args, cfgs) as workers:
        runs = _run_into(args.case, cfgs[args.case], out.path, workers)
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
    with StagedFolder(folder) as out:
        study.write(out.path, cfg, data)
        written = out.commit()
    print(f"{study.name}: rewritten from its recorded runs in {written}")
    return 0


def _bench_command(args):
    from . import costs
    from .tools import bench
    models = _models(args.models, list(model.PRESETS))
    sizes = args.sizes or (bench.QUICK_SIZES if args.quick else bench.SIZES)
    # checked before any timing starts
    old = None
    if args.merge:
        if not models:
            raise UsageError("--merge adds the rows of the --models given to a bench.json: "
                             "name the models to time")
        where = Path(args.out) / costs.FILE
        if not where.is_file():
            raise UsageError(f"--merge needs an existing {where}; run `pbcm bench` first or "
                             "drop --merge")
        old = costs.read(where)
        models = tuple(m for m in models if m not in bench.BASELINES)
    with StagedFolder(Path(args.out), mark=costs.FILE) as out:
        data = bench.run(sizes=sizes, models=models, rounds=3 if args.quick else args.rounds,
                         with_engines=old is None)
        bench.write(bench.merge(old, data) if old else data, out.path)
        path = out.commit()
    print(f"bench written to {path}")
    return 0


def _report_command(args):
    from contextlib import ExitStack
    from .registry import CASES, studies
    from .index import index_documents
    cfgs = _configs(CASES, args)
    study_cfgs = {name: _study_config(st, args) for name, st in studies().items()}
    root = writable_folder(args.out or "reports")
    with ExitStack() as stack:   # every case folder checked and staged before any computing
        staged = {name: stack.enter_context(StagedFolder(root / name))
                  for name in [*CASES, *study_cfgs]}
        workers = stack.enter_context(_workers(args, {**cfgs, **study_cfgs}))
        for name in CASES:
            runs = _run_into(name, cfgs[name], staged[name].path, workers)
            print(f"{name}: {len(runs)} runs written to {staged[name].commit()}")
        for name, cfg in study_cfgs.items():
            _run_study_into(studies()[name], cfg, staged[name].path, workers)
            print(f"{name}: written to {staged[name].commit()}")
    md, html = index_documents(root, list(CASES), list(study_cfgs))
    write_text_atomic(root / "index.md", md)
    write_text_atomic(root / "index.html", html)
    print(f"index written to {root / 'index.md'} and {root / 'index.html'}")
    return 0


def _index_command(args):
    """reports/index.md and index.html from the case and study folders already written (after
    a `pbcm run` of one case or study, without running the others again)."""
    from .registry import CASES, STUDY_MODULES
    from .index import index_documents
    root = Path(args.out)
    missing = [name for name in CASES if not (root / name / "metrics.json").is_file()]
    if missing:
        raise UsageError(f"{root} lacks the metrics.json of {', '.join(missing)}: run "
                         "`pbcm report` (or `pbcm run CASE` for each) first")
    md, html = index_documents(root, list(CASES), list(STUDY_MODULES))
    write_text_atomic(root / "index.md", md)
    write_text_atomic(root / "index.html", html)
    print(f"index written to {root / 'index.md'} and {root / 'index.html'}")
    return 0


def _check_command(args):
    from .gate import NEW, CheckError, check, flip_message, load, measured
    try:
        v = check(load(args.gold, hint="--gold"), measured(args.metrics))
    except CheckError as exc:
        print(f"pbcm check: error: {exc}", file=sys.stderr)
        return 2
    print(f"{'metric':<66} {'measured':>11} {'band':>23} {'margin':>8}  result")
    for b, value, ok in v.rows:
        name = f"{b.case}/{b.mesh}/{b.bc}/{b.model}/{b.metric}"
        low, high = b.band
        print(f"{name:<66} {value:>11.5g} [{low:>10.5g},{high:>10.5g}] "
              f"{b.margin(value):>8.1%}  {'PASS' if ok else 'FAIL'}")
    failed = [r for r in v.rows if not r[2]]
    print(f"{len(v.rows) - len(failed)} passed, {len(failed) + len(v.flips)} failed")
    for b, value, _ in failed:
        low, high = b.band
        print(f"FAIL {b.metric} of {b.case}/{b.mesh}/{b.bc}/{b.model}: {value:.6g} outside "
              f"[{low:.6g}, {high:.6g}] ({b.verdict(value)})")
    for key, gold, now in v.flips:
        print(flip_message(key, gold, now))
    for case, mode, name, n in v.new:
        print(f"NEW  {case} ({mode}) {name}: new, not gated yet ({n} metrics without gold; "
              "`pbcm bless` gates them)")
    if v.new:
        print(f"{len(v.new)} model(s) new, not gated yet")
    return 0 if v.status == NEW and args.allow_new else v.status


def _bless_command(args):
    """Gold from a folder of metrics (``--metrics``) or from a fresh run of every case: the
    compact files of quick mode, and for full mode the case folders installed where the
    policy keeps the full-mode gold. What it keeps: gold rows of runs it did not see (other
    modes, meshes, models...) unless ``--prune``."""
    import tempfile
    from .gate import (COMPACT_MODES, POLICY, CheckError, Gold, Policy, bless, compact_files,
                       load, measured, policy_text)
    from .registry import CASES, studies
    folder = Path(args.gold)
    try:   # every check before the run: the old gold must load and the folder be writable
        writable_folder(folder, flag="--gold")
        old = load(folder) if (folder / POLICY).is_file() and any(
            folder.glob("*.jsonl")) else Gold(Policy(atol_of=dict(ATOL_OF)), {}, {}, folder)
        if args.metrics:
            values = measured(args.metrics)
            new, changes = bless(values, old, rtol=args.margin, prune=args.prune)
            _write_gold(folder, old, new, values, changes, Path(args.metrics))
        else:
            cfgs = _configs(CASES, args)
            study_cfgs = {name: _study_config(st, args) for name, st in studies().items()}
            with tempfile.TemporaryDirectory(prefix="pbcm-bless-") as tmp, \
                    _workers(args, {**cfgs, **study_cfgs}) as workers:
                for name in CASES:
                    (Path(tmp) / name).mkdir()
                    _run_into(name, cfgs[name], Path(tmp) / name, workers)
                for name, cfg in study_cfgs.items():
                    (Path(tmp) / name).mkdir()
                    _run_study_into(studies()[name], cfg, Path(tmp) / name, workers)
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
    from .gate import COMPACT_MODES, POLICY, compact_files, policy_text
    files = compact_files(new)
    for name, text in files.items():
        path = folder / name
        if not path.is_file() or path.read_text() != text:
            write_text_atomic(path, text)
    for path in folder.glob("*.jsonl"):
        if path.name not in files:
            path.unlink()
    if not (folder / POLICY).is_file() or new.policy != old.policy:
        write_text_atomic(folder / POLICY, policy_text(new.policy))
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


def _term_files(p):
    p.add_argument("--term", action="append", default=[], metavar="FILE",
                   help="a Python file that registers force terms (repeatable); its terms can "
                        "then be composed in --models")


def _fit_command(args):
    import json
    from model.compose import label, slug
    from .registry import CASES
    from .studies import fit
    name = label(args.model)
    fit.fitted_terms(name)                       # a model with nothing to fit: refused now
    train = [_case(c) for c in args.cases]
    validate = [_case(c) for c in args.validate] if args.validate is not None else [
        c for n, c in CASES.items() if c.static and n not in args.cases]
    fit.check_cases(train, validate)
    for c in [*train, *validate]:
        _choose("mesh", args.meshes, c.meshes)
        _choose(f"boundary condition of {c.name}", args.bcs, c.bcs)
    overrides = {k: v for k, v in {"E": args.E, "nu": args.nu, "meshes": args.meshes and
                                   tuple(args.meshes), "bcs": args.bcs and tuple(args.bcs)
                                   }.items() if v is not None}
    with StagedFolder(Path(args.out) if args.out else Path("reports") / "fit" / slug(name),
                      mark="fit.json") as out:
        doc = fit.fit(name, train, validate, quick=args.quick, overrides=overrides)
        (out.path / "fit.json").write_text(json.dumps(doc, indent=1) + "\n")
        fit.report(doc).write(out.path)
        path = out.commit()
    for k, v in doc["constants_fitted"].items():
        print(f"{k:<24} auto {doc['constants_auto'][k]:.5g} -> fitted {v:.5g} "
              f"(factor {doc['scales'][k.split('.')[0]]:.4g}, rel. s.e. "
              f"{doc['scale_rel_se'][k.split('.')[0]]:.2g})")
    print(f"condition number {doc['condition_number']:.3g}; report written to {path}")
    return 0


def _sweep_command(args):
    from .studies.sweeps import command
    return command.run(args)


def _selection(p):
    p.add_argument("--models", nargs="+",
                   help="model presets, or terms composed with '+', e.g. \"shear(reading="
                        "variational, c=auto) + normal_edge(c=auto) + volume\" (default: "
                        "every preset)")
    _term_files(p)
    p.add_argument("--meshes", nargs="+", help="meshes (default: all; --quick: five six)")
    p.add_argument("--bcs", nargs="+", help="boundary conditions (default: all)")
    p.add_argument("--quick", action="store_true",
                   help="each case's quick settings (fewer meshes, coarser references; "
                        "what CI runs)")
    p.add_argument("--E", type=_number("--E", "Young's modulus in Pa, a number > 0", low=0),
                   help="Young's modulus [Pa] (default 10e3)")
    p.add_argument("--nu", type=_poisson, help="Poisson's ratio, -1 < nu < 0.5 (default 0.45)")
    p.add_argument("--rho", type=_number("--rho", "a density in kg/m^3, a number > 0", low=0),
                   help="density [kg/m^3] (default 1000)")
    p.add_argument("--workers", type=_number("--workers", "an integer >= 1", low=0,
                                             integer=True),
                   help="processes running a case's meshes side by side (default: the cores "
                        "available); the metrics do not depend on it")
    # test-only: scale the shear term, to prove that the error gate catches a worse model
    p.add_argument("--shear-scale", type=float, default=None, help=argparse.SUPPRESS)


def parser():
    p = Parser(prog="pbcm", description=DESCRIPTION,
               formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"pbcm {model.__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    m = sub.add_parser("mesh", help="print node/tetrahedron counts and quality of a mesh",
                       description="Mesh statistics: 'pbcm mesh FILE' for any meshio-readable "
                                   "file, or 'pbcm mesh cube [--n N --size MM --scheme S]'.")
    m.add_argument("source", help="a mesh file, or 'cube'")
    m.add_argument("--n", type=_number("--n", "an integer >= 2 (nodes per side)", low=2,
                                       integer=True, open_low=False),
                   default=5, help="nodes per side (cube), default 5")
    m.add_argument("--size", type=_number("--size", "a side length in mm, a number > 0", low=0),
                   default=32.0, help="side in mm (cube), default 32")
    m.add_argument("--scheme", choices=SCHEMES, default="five", help="cube tetrahedralisation")
    m.add_argument("--seed", type=int, default=0, help="seed of the 'unstructured' scheme")
    m.set_defaults(func=_mesh_command)
    ls = sub.add_parser("list", help="list the cases, studies and force terms")
    _term_files(ls)
    ls.set_defaults(func=_list_command)
    r = sub.add_parser("run", help="run one case and write its report folder")
    r.add_argument("case", help="a case or study name (see pbcm list)")
    r.add_argument("--out", help="output folder (default reports/CASE)")
    r.add_argument("--rewrite", action="store_true",
                   help="a study only: draw its report again from the runs recorded in the "
                        "metrics.json of --out, without computing (after a change of the "
                        "report's code)")
    _selection(r)
    r.set_defaults(func=_run_command)
    rep = sub.add_parser("report", help="run every case and write reports/ with its index")
    rep.add_argument("--out", help="output folder (default reports)")
    _selection(rep)
    rep.set_defaults(func=_report_command)
    bn = sub.add_parser(
        "bench", help="time every model: force evaluation, RK4 step, calibration, memory",
        description="Time every preset on cubes of about 1e2 to 1e6 tetrahedra (--quick: 1e2 "
                    "and 1e3): ns per tetrahedron per force evaluation, microseconds per RK4 "
                    "step, calibration seconds, memory, and the step ratios to msm and "
                    "fem-linear as medians of per-round ratios (models timed round-robin). "
                    "Writes bench.json, bench.md and step_time.png (the paper's Figure 2).")
    bn.add_argument("--out", default="reports/bench", help="output folder (default reports/bench)")
    bn.add_argument("--quick", action="store_true", help="sizes 1e2 and 1e3, three rounds")
    bn.add_argument("--sizes", nargs="+",
                    type=_number("--sizes", "tetrahedron counts, numbers >= 5", low=4),
                    help="approximate tetrahedron counts (default 1e2 1e3 1e4 1e5 1e6)")
    bn.add_argument("--rounds", type=_number("--rounds", "an integer >= 1", low=0, integer=True),
                    default=7, help="timing rounds (default 7)")
    bn.add_argument("--models", nargs="+", help="model presets or composed models "
                                                "(default: every preset)")
    bn.add_argument("--merge", action="store_true",
                    help="add the rows of --models to the bench.json in --out (timed against "
                         "the baselines in this process) and keep every other row")
    _term_files(bn)
    bn.set_defaults(func=_bench_command)

    ft = sub.add_parser(
        "fit", help="fit a model's constants to the FEM references of chosen cases",
        description="Fit the constants of MODEL's terms (shear c, normal c_n, spring stiffness "
                    "scale) by least squares (scipy) to the FEM displacements of --cases, and "
                    "cross-validate on the cases left out (--validate; default every other "
                    "case with a static problem): error before and after. Writes fit.json and "
                    "report.md/.html to --out (default reports/fit/MODEL).")
    ft.add_argument("model", help="a preset or composed model")
    ft.add_argument("--cases", nargs="+", required=True, help="cases to fit on")
    ft.add_argument("--validate", nargs="*", help="cases left out, to cross-validate on")
    ft.add_argument("--quick", action="store_true", help="each case's quick settings")
    ft.add_argument("--meshes", nargs="+", help="mesh families of every case (default: each "
                                                "case's own)")
    ft.add_argument("--bcs", nargs="+", help="boundary conditions of every case (default: "
                                             "each case's own)")
    ft.add_argument("--out", help="output folder (default reports/fit/MODEL)")
    ft.add_argument("--E", type=_number("--E", "Young's modulus in Pa, a number > 0", low=0))
    ft.add_argument("--nu", type=_poisson)
    _term_files(ft)
    ft.set_defaults(func=_fit_command)

    ix = sub.add_parser("index", help="rewrite reports/index.md from the folders written",
                        description="Rewrite index.md and index.html from the case and study "
                                    "folders under --out, without running anything.")
    ix.add_argument("--out", default="reports", help="the reports folder (default reports)")
    ix.set_defaults(func=_index_command)

    c = sub.add_parser("check", help="compare the latest metrics with the gold values "
                       "(exit 0 pass, 1 fail, 2 missing or malformed, 3 pass with new models)",
                       description="Compare every metrics.json under --metrics with the gold "
                                   "values of --gold (quick mode: gold/CASE.quick.jsonl; full "
                                   "mode: the committed reports/CASE/metrics.json), two-sided, "
                                   "with the tolerance policy of gold/policy.toml. Exit status "
                                   "0: every value holds; 1: some metric left its band, or was "
                                   "n/a in the gold and is a number now (or the reverse); 2: "
                                   "gold without a metric, a metric without gold for a model "
                                   "that has gold, a NaN, a malformed or missing file, or "
                                   "metrics run at other problem parameters than the gold's; "
                                   "3: every value holds, and some model (a new preset or "
                                   "composed model) has no gold at all in that case and mode: "
                                   "listed as 'new, not gated yet' (--allow-new turns 3 into "
                                   "0).")
    c.add_argument("--allow-new", action="store_true",
                   help="exit 0 rather than 3 when the only news is models without gold")
    c.add_argument("--metrics", default="reports", help="a metrics.json or a folder of them "
                   "(default reports)")
    c.add_argument("--gold", default="gold",
                   help="the gold folder (default gold in the current folder: the "
                        "repository's own when run from a checkout)")
    c.set_defaults(func=_check_command)
    sw = sub.add_parser(
        "sweep", help="run a parameter sweep (TOML spec) on Dask: table, runs and report",
        description="Run every point of a sweep spec (cases, fixed settings, axes over E, nu, "
                    "rho, resolution, load, mesh, bc and model; see cases/studies/sweeps/nu.toml) as "
                    "tasks on dask.distributed: a LocalCluster of --workers processes, or the "
                    "cluster at --scheduler. Finished runs are kept (runs/<key>/metrics.json) "
                    "and skipped on a rerun; a failing run is a row with its error. Writes "
                    "table.parquet (table.csv without pyarrow), report.md and its plots. Exit "
                    "status 1 when a task was lost with its workers (rerun to finish).")
    sw.add_argument("spec", help="a sweep spec .toml, or the name of a shipped one (nu)")
    sw.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. "
                                        "tcp://host:8786 (default: a LocalCluster here)")
    sw.add_argument("--workers", type=_number("--workers", "an integer >= 1", low=0,
                                              integer=True),
                    help="LocalCluster worker processes (default: one per core)")
    sw.add_argument("--out", help="output folder (default reports/sweeps/SPEC-NAME)")
    sw.add_argument("--serial", action="store_true",
                    help="run every task in this process, without Dask (same results)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="compute again the runs an earlier sweep recorded as failed")
    sw.add_argument("--plan", action="store_true",
                    help="print the tasks and runs the sweep would compute (and those already "
                         "in --out), then stop: nothing is computed or written")
    _term_files(sw)
    sw.set_defaults(func=_sweep_command)
    b = sub.add_parser(
        "bless", help="rewrite the gold values from measured metrics and print what changed",
        description="Set the gold values from measured metrics: quick mode into the compact "
                    "files gold/CASE.quick.jsonl (6 significant digits; a value that agrees "
                    "to that precision is kept as it is), full mode by installing the case "
                    "folder as the committed reports/CASE. Without --metrics it first runs "
                    "every case and study: in full mode (about 75 minutes on 2 cores) unless "
                    "--quick is given. It keeps the gold rows of runs it did not see (other "
                    "modes, meshes, models) unless --prune is given; --margin sets the "
                    "policy's rtol. It prints every value it adds, changes or removes.")
    b.add_argument("--margin", type=_number("--margin", "a relative tolerance, a number > 0",
                                            low=0), default=None,
                   help="relative tolerance rtol of the policy (default: keep the policy's, "
                        "0.1 for a new gold folder)")
    b.add_argument("--prune", action="store_true",
                   help="remove (and list) gold rows of runs not in the metrics blessed")
    b.add_argument("--gold", default="gold",
                   help="the gold folder to rewrite (default gold)")
    b.add_argument("--metrics", help="bless the metrics.json files under this folder instead "
                                     "of a fresh run")
    _selection(b)
    b.set_defaults(func=_bless_command)
    return p


def main(argv=None):
    """Run the command line on ``argv``; return the exit status (also for --help and for
    argument errors, which argparse would raise as SystemExit)."""
    with stop.handling():   # staging folders are removed on SIGTERM as on Ctrl-C
        return _main(argv)


def _kept(args):
    """What an interrupted command leaves behind, for its last line."""
    if getattr(args, "command", None) == "sweep":
        return ("every run finished is kept in the sweep's runs/ folder: rerun the same "
                "command to resume")
    return "output folders hold what they held before the unfinished one"


def _main(argv):
    args = None
    try:
        try:
            args = parser().parse_args(argv)
        except SystemExit as exc:
            return exc.code if isinstance(exc.code, int) else 2
        for f in getattr(args, "term", []):   # before any model name is checked
            model.terms.add_user_file(f)
        status = args.func(args)
        stop.checkpoint()   # a signal whose exception a library swallowed still stops us
        return status
    except (UsageError, PbcmError) as exc:
        print(f"pbcm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"\npbcm: interrupted; {_kept(args)}", file=sys.stderr)
        return 130
    except stop.Terminated:
        print(f"\npbcm: terminated; {_kept(args)}", file=sys.stderr)
        return 143
    except BrokenPipeError:   # `pbcm check | head`: the reader left; say nothing more
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
