"""Accuracy at a real-time budget: on this machine, the largest mesh each model runs in real
time (from `pbcm bench`) and how far from the continuum it is there, on the paper's push."""
from ...framework import Study
from ...running.store import OFF
from . import report
from .study import RealtimeSettings, run


class Realtime(Study):
    name = "realtime"
    selections = ()            # its models and meshes are the bench's
    title = "accuracy at a real-time budget: the largest mesh each model runs in real time"
    settings_class = RealtimeSettings
    recorded_keys = ("runs", "error_estimate", "top_force_n", "machine")

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)


STUDY = Realtime()
