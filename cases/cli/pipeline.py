"""The main job, written once: every case of the library, then every study, each into its
folder, on one worker pool. ``pbcm report`` writes them to reports/, ``pbcm bless`` to a
temporary folder whose metrics it blesses."""
import time

from ..registry import CASES, studies
from .common import (case_configs, run_case_into, run_store, run_study_into, study_config,
                     worker_pool)


def configs(args):
    """The settings of every case and study from the command line, built (and so checked)
    before anything runs: ``{name: settings}``, cases first."""
    cases = case_configs(CASES, args)
    return {**cases, **{name: study_config(st, args) for name, st in studies().items()}}


def run_everything(args, cfgs, folder_of, done=lambda name, runs, seconds: None):
    """Run every case and study of ``cfgs`` (from ``configs``) into ``folder_of(name)``, in
    order; ``done(name, runs, seconds)`` after each (runs: the case's runs, None for a study;
    seconds: its wall time, the pool's start and the store's look-ups included). Returns
    {name: seconds}: what the main job's time is made of, measured."""
    declared = studies()
    store = run_store(args)
    spent = {}
    with worker_pool(args, cfgs) as workers:
        for name, cfg in cfgs.items():
            t0 = time.perf_counter()
            if name in CASES:
                runs = run_case_into(name, cfg, folder_of(name), workers, store)
            else:
                run_study_into(declared[name], cfg, folder_of(name), workers, store)
                runs = None
            spent[name] = time.perf_counter() - t0
            done(name, runs, spent[name])
    return spent


def timing_line(spent):
    """'wall time: cases 1450 s (paper-cube 300, ...), studies 2400 s (...), in all 3850 s'."""
    def part(names):
        return (f"{sum(spent[n] for n in names):.0f} s ("
                + ", ".join(f"{n} {spent[n]:.0f}" for n in names) + ")")
    cases = [n for n in spent if n in CASES]
    rest = [n for n in spent if n not in CASES]
    return ("wall time: " + ", ".join(
        f"{what} {part(names)}" for what, names in (("cases", cases), ("studies", rest))
        if names) + f", in all {sum(spent.values()):.0f} s")
