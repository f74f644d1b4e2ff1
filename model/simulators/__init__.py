"""Simulators pbcm does not integrate itself, as models: a registry by name
(:class:`model.plugins.Registry`) of :class:`Simulator` classes.

The registry holds, on first use, every module of this package (the Newton engine's solvers:
``newton-xpbd``, ``newton-vbd``, ``newton-semi-implicit``), every module an installed package
names in the entry-point group ``pbcm.models`` and every file in ``PBCM_MODELS``, which
``pbcm --model-file FILE`` sets. A model file defines a :class:`Simulator` subclass with a
``name`` and decorates it with :func:`register`; ``model.build("name(key=value)", mesh,
material)`` then builds it, and every case and study runs it by that name.
"""
from pathlib import Path

from ..errors import ModelError
from ..plugins import Registry
from .base import Simulator, run_to_rest, slowest_frequency

ENTRY_POINT_GROUP = "pbcm.models"
REGISTRY = Registry("model", ENTRY_POINT_GROUP, "PBCM_MODELS", __package__, Path(__file__).parent,
                    "registers a Simulator subclass with @model.simulators.register",
                    skip=("base",))
SIMULATORS = REGISTRY.items
register = REGISTRY.register
load_file = REGISTRY.load_file
user_files = REGISTRY.user_files
add_user_file = REGISTRY.add_user_file
registered = REGISTRY.registered


def make_simulator(kind, mesh, material, label=None, **params):
    """The registered simulator ``kind`` on ``mesh`` with ``params``, named ``label`` (its
    canonical label with the settings given; ``kind`` by default)."""
    sims = registered()
    if kind not in sims:
        raise ModelError(f"unknown model {kind!r}; simulators: {', '.join(sorted(sims))}")
    return sims[kind](mesh, material, label, **params)


__all__ = ["Simulator", "run_to_rest", "slowest_frequency", "ENTRY_POINT_GROUP", "SIMULATORS",
           "register", "load_file", "user_files", "add_user_file", "registered",
           "make_simulator"]
