"""A user's own problem, declared in one TOML file and run as a case (``pbcm run --problem``):
the mesh file with its unit and up axis, the material, selections of nodes, prescribed
displacements, tractions and gravity, the quantities measured, the models and the references.

``spec`` reads and checks the TOML whole before anything is computed, ``case`` makes the
:class:`~cases.framework.Case` of it, ``template`` is the commented TOML that ``pbcm problem
new`` writes (it runs on the example of examples/cylinder).
"""
from .case import ProblemCase, case_of
from .spec import ProblemError, Spec, load
from .template import EXAMPLE_MESH, template


def problem_case(path):
    """The case of the problem TOML at ``path``, checked whole (a ProblemError otherwise)."""
    return case_of(load(path))


__all__ = ["ProblemCase", "ProblemError", "Spec", "EXAMPLE_MESH", "case_of", "load",
           "problem_case", "template"]
