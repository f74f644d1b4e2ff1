"""The main job, written once: every case of the library, then every study, each into its
folder, on one worker pool. ``pbcm report`` writes them to reports/, ``pbcm bless`` to a
temporary folder whose metrics it blesses."""
from ..registry import CASES, studies
from .common import (case_configs, run_case_into, run_store, run_study_into, study_config,
                     worker_pool)


def configs(args):
    """The settings of every case and study from the command line, built (and so checked)
    before anything runs: ``{name: settings}``, cases first."""
    cases = case_configs(CASES, args)
    return {**cases, **{name: study_config(st, args) for name, st in studies().items()}}


def run_everything(args, cfgs, folder_of, done=lambda name, runs: None):
    """Run every case and study of ``cfgs`` (from ``configs``) into ``folder_of(name)``, in
    order; ``done(name, runs)`` after each (runs: the case's runs, None for a study)."""
    declared = studies()
    store = run_store(args)
    with worker_pool(args, cfgs) as workers:
        for name, cfg in cfgs.items():
            if name in CASES:
                done(name, run_case_into(name, cfg, folder_of(name), workers, store))
            else:
                run_study_into(declared[name], cfg, folder_of(name), workers, store)
                done(name, None)
