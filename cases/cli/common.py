"""What the commands share: one-line argument errors, numbers checked in the user's units,
the selection of cases, meshes, bcs and models, worker pools, and running one case or study
into a folder."""
import argparse
import math
import re
from pathlib import Path

import model
from ..framework import DEFAULT_E, DEFAULT_NU, DEFAULT_RHO
from ..running.output import StagedFolder  # noqa: F401 (the commands' staging)


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``pbcm: error: ...`` and exit status 2."""

    def error(self, message):
        message = re.sub(r"^argument (\S+): (?=\1 )", "", message)  # the flag is said already
        self.exit(2, f"pbcm: error: {message} (see `{self.prog} --help`)\n")


def number(flag, what, low=None, high=None, integer=False, open_low=True):
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


def poisson(text):
    from model.material import poisson_problem
    v = number("--nu", "Poisson's ratio, a number between -1 and 0.5")(text)
    if poisson_problem(v):
        raise argparse.ArgumentTypeError(f"--nu: {poisson_problem(v)}")
    return v


def choose(kind, given, valid):
    """The names asked for (None when not given: the case's default), or a one-line error
    listing the valid ones (exit status 2)."""
    if given is None:
        return None
    bad = [g for g in given if g not in valid]
    if bad:
        raise UsageError(f"unknown {kind} {', '.join(bad)}; valid: {', '.join(valid)}")
    return tuple(given)


def chosen_models(given, presets):
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


def case_named(name, files=()):
    """The library's case ``name``, else a case from outside the package (``--case FILE``
    files, the ``pbcm.cases`` entry points)."""
    from ..registry import CASES, STUDY_MODULES, UserCaseError, user_cases
    if name in CASES:
        return CASES[name]
    try:
        users = user_cases(files)
    except UserCaseError as exc:
        raise UsageError(str(exc)) from None
    if name not in users:
        raise UsageError(f"unknown case {name}; valid: "
                         f"{', '.join([*CASES, *STUDY_MODULES, *users])} (a case of your own: "
                         "--case FILE.py, or the pbcm.cases entry-point group)")
    return users[name]


def study_config(study, args):
    """A study's settings from the command line, checked before anything runs."""
    from model.mesh import SCHEMES
    check_executor(args)
    if getattr(args, "bcs", None):
        raise UsageError(f"--bcs does not apply to the {study.name} study: it runs each "
                         "problem's own boundary conditions; leave --bcs out")
    return study.settings(quick=args.quick, meshes=choose("mesh", args.meshes, SCHEMES),
                          models=chosen_models(args.models, list(model.PRESETS)),
                          E=args.E, nu=args.nu, rho=args.rho)


def run_study_into(study, cfg, folder, workers=None, store=None):
    """Run ``study`` and write its files into ``folder``; the step costs come from the bench
    beside the folder (reports/bench), or the checkout's."""
    from ..reporting import costs
    from ..running.store import OFF
    data = costs.load(Path(folder).parent)
    study.write(folder, cfg, study.run(cfg, workers=workers, bench=data, store=store or OFF))


def case_config(case, args):
    return case.settings(quick=args.quick,
                         meshes=choose("mesh", args.meshes, case.meshes),
                         bcs=choose("boundary condition", args.bcs, case.bcs),
                         models=chosen_models(args.models, case.models),
                         E=args.E, nu=args.nu, rho=args.rho)


def run_case_into(name, cfg, folder, workers=None, store=None):
    """Run case ``name`` with ``cfg`` (on ``workers``, a started Workers, when given; from
    and into ``store``, a RunStore) and write its files into the existing ``folder``."""
    return case_into(case_named(name), cfg, folder, workers, store)


def case_into(case, cfg, folder, workers=None, store=None):
    """Run ``case`` (a Case, of the library or a user's problem) as ``run_case_into``."""
    from ..reporting.report import write_case
    from ..running.runner import run
    from ..running.store import OFF
    runs, fields = run(case, cfg, workers=workers, store=store or OFF)
    write_case(folder, case, cfg, runs, fields)
    return runs


def worker_pool(args, cfgs):
    """The executor of a command (a context): the Dask cluster at ``--scheduler``, else
    ``--workers`` local processes; nothing to start for one worker or one unit in every case
    (a worker runs one mesh of a case with all its bcs, or one problem and bc of a study)."""
    from contextlib import nullcontext
    from ..running.workers import executor
    units = max(c.units for c in cfgs.values())
    return executor(getattr(args, "scheduler", None), args.workers, units) or nullcontext()


def add_executor(p):
    """--workers and --scheduler: where the units of a command run."""
    p.add_argument("--workers", type=number("--workers", "an integer >= 1", low=0,
                                             integer=True),
                   help="local worker processes running units side by side (default: the "
                        "cores available); the metrics do not depend on it")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the units on the Dask cluster whose scheduler is at ADDRESS, "
                        "e.g. tcp://host:8786, instead of local processes (same metrics)")


def check_executor(args):
    """--scheduler and --workers cannot both be honoured: say so before computing."""
    if getattr(args, "scheduler", None) and (args.workers or getattr(args, "serial", False)):
        raise UsageError("--scheduler runs on that cluster's workers: drop --workers and "
                         "--serial (start more workers with `dask worker ADDRESS`)")


def run_store(args):
    """The run store a command reads and fills (``--no-cache``: none)."""
    from ..running.store import RunStore, settings
    store = RunStore(enabled=not getattr(args, "no_cache", False))
    if store.enabled:
        settings()          # its cap, checked before anything runs
    return store


def add_store(p):
    p.add_argument("--no-cache", action="store_true",
                   help="compute everything, neither reading nor filling the run store "
                        "($PBCM_CACHE, default the user cache directory)")


def case_configs(names, args):
    """Every case's configuration, built (and so checked) before anything runs."""
    check_executor(args)
    return {name: case_config(case_named(name, getattr(args, "case_file", ())), args)
            for name in names}


def add_selection(p):
    p.add_argument("--models", nargs="+",
                   help="model presets, or terms composed with '+', e.g. \"shear(reading="
                        "variational, c=auto) + normal_edge(c=auto) + volume\" (default: "
                        "every preset)")
    add_term_files(p)
    p.add_argument("--meshes", nargs="+", help="meshes (default: all; --quick: the case's quick meshes, five for most, "
                        "five and six for the paper cube)")
    p.add_argument("--bcs", nargs="+", help="boundary conditions (default: all)")
    p.add_argument("--quick", action="store_true",
                   help="each case's quick settings (fewer meshes, coarser references; "
                        "what CI runs)")
    p.add_argument("--E", type=number("--E", "Young's modulus in Pa, a number > 0", low=0),
                   help=f"Young's modulus [Pa] (default {DEFAULT_E:g})")
    p.add_argument("--nu", type=poisson,
                   help=f"Poisson's ratio, -1 < nu < 0.5 (default {DEFAULT_NU:g})")
    p.add_argument("--rho", type=number("--rho", "a density in kg/m^3, a number > 0", low=0),
                   help=f"density [kg/m^3] (default {DEFAULT_RHO:g})")
    add_executor(p)
    add_store(p)


def add_term_files(p):
    p.add_argument("--term", action="append", default=[], metavar="FILE",
                   help="a Python file that registers force terms (repeatable); its terms can "
                        "then be composed in --models")
    p.add_argument("--model-file", action="append", default=[], metavar="FILE",
                   help="a Python file that registers a simulator, a model pbcm does not "
                        "integrate itself (model.simulators; repeatable); its name can then be "
                        "given in --models")

