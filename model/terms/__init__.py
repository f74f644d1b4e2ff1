"""Force terms: a registry by name, as meshio registers formats.

A term is one module that defines a :class:`Term` subclass decorated with :func:`register`.
The registry holds, on first use:

* every module of this package (a new built-in term is one new file here);
* every module named by an installed package in the entry-point group ``pbcm.terms``
  (``[project.entry-points."pbcm.terms"] myterm = "mypackage.myterm"``);
* every file in the environment variable ``PBCM_TERMS`` (paths separated by ``os.pathsep``),
  which ``pbcm --term FILE`` sets, so that worker processes load the same files.
"""
from .base import CalibratedTerm, Fused, Term, fused_units
from .registry import (ENTRY_POINT_GROUP, TERMS, add_user_file, load_file, make_term, register,
                       registered, user_files)

__all__ = ["CalibratedTerm", "Fused", "Term", "fused_units", "ENTRY_POINT_GROUP", "TERMS", "add_user_file",
           "load_file", "make_term", "register", "registered", "user_files"]
