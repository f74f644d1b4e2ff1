"""The references' manufactured-solution ladder: every entry of ``verification.toml``'s
[[manufactured]] on every mesh family, its relative L2 errors at the declared levels, the
observed order of each pair and the verdict against the element's formal order (the one
tolerance of the spec) and the finest level's bound."""
import numpy as np

from model.mesh import cube
from reference import manufactured as mms
from ...running import stop
from ...running.store import OFF, key
from .verification import spec

def orders(cells, errors):
    """The observed order of each successive pair of levels: log(e1 / e2) / log(h1 / h2)."""
    h = 1.0 / np.asarray(cells, float)
    e = np.asarray(errors, float)
    return list(np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:]))


def run_entry(entry, family, size, E, tolerance, store=OFF):
    """One ladder: the row {ladder, mesh, element, cells, mms_errors, mms_orders, mms_order
    (the finest pair's), mms_rel_l2 (the finest level's), the formal order, the bound and
    ``passed``}."""
    k = key(kind="manufactured", entry=entry.__dict__, mesh=family, size=size, E=E)
    found = store.get(k)
    if found is not None:
        return found
    problem = entry.problem(size, E)
    errors, coarser = [], None
    for c in entry.cells[family]:
        stop.checkpoint()
        # each neo-Hookean level's Newton starts from the level below (nested iteration)
        e, coarser = mms.solve(cube(c + 1, size, family), problem, size, entry.element,
                               entry.mixed, entry.faces, entry.load_steps, start=coarser)
        errors.append(float(e))
    obs = orders(entry.cells[family], errors)
    row = {"ladder": entry.name, "mesh": family, "element": entry.element,
           "cells": list(entry.cells[family]), "mms_errors": errors, "mms_orders": obs,
           "mms_order": obs[-1], "mms_rel_l2": errors[-1], "formal_order": entry.formal_order,
           "finest_bound": entry.finest_bound, "tolerance": tolerance,
           "one_sided": family in entry.faster}
    row["passed"] = judge(row)
    return store.put(k, row)


def judge(row):
    """True when the finest pair's order is within the tolerance of the formal order (at
    least formal - tolerance where the spec declares the family faster: ``one_sided``) and
    the finest error under its bound."""
    low = row["mms_order"] >= row["formal_order"] - row["tolerance"]
    high = row["one_sided"] or row["mms_order"] <= row["formal_order"] + row["tolerance"]
    return bool(low and high and row["mms_rel_l2"] <= row["finest_bound"])


def units(families, quick=False, store=OFF):
    """The table's rows as work units ``(run_entry, args, cost)``: every ladder of the spec
    (those marked for it when ``quick``) on every one of ``families`` that it declares; the
    cost a guess for the order of work (unknowns of the finest level, Newton's five
    iterations, bcc's 2.5 times the tetrahedra)."""
    s = spec()
    return [(run_entry, (e, fam, s["size"], s["E"], s["tolerance"], store),
             e.cells[fam][-1] ** 3 * (8 if e.element == "P2" else 1)
             * (5 if e.material != "linear" else 1) * (2.5 if fam == "bcc" else 1))
            for e in s["manufactured"] if e.quick or not quick
            for fam in families if fam in e.cells]


def table(families, quick=False, store=OFF):
    """The rows of :func:`units`, computed here."""
    return [fn(*args) for fn, args, _ in units(families, quick, store)]


__all__ = ["orders", "run_entry", "judge", "units", "table"]
