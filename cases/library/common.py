"""What the library's cases share: bars meshed at a spacing, their end faces, and sentences
that rank the models and compare FEM with a closed form, computed from the runs."""
import numpy as np

from model.mesh import box
from ..framework import MM


def bar(family, length_mm, height_mm, width_mm, spacing_mm):
    """A box [0, L] x [0, H] x [0, W] (mm in, metres out) with nodes every ``spacing_mm``."""
    n = [int(round(d / spacing_mm)) + 1 for d in (length_mm, height_mm, width_mm)]
    return box(*n, length_mm * MM, height_mm * MM, width_mm * MM, scheme=family)


def face(mesh, x):
    """The nodes of the end face at x [m]."""
    return mesh.nodes_on_plane("x", x)


def vs_closed_form(name, runs, key, closed, unit):
    """'FEM P2 gives ... against the closed form ...' for the first run of each mesh."""
    out = []
    for mesh in dict.fromkeys(r["mesh"] for r in runs):
        r = next(r for r in runs if r["mesh"] == mesh)
        fem = r[key]
        out.append(f"{mesh}: FEM P2 {name} {fem:.4g} {unit}, closed form {closed:.4g} {unit} "
                   f"(FEM / closed form {fem / closed:.3f}; P2 error estimate "
                   f"{r['p2_error_estimate']:.2g}).")
    return out


def ranking(runs, metric, label):
    """'model: median metric (range)' sentences, best first, over the runs that gave it."""
    by = {}
    for r in runs:
        if r.get(metric) is not None:
            by.setdefault(r["model"], []).append(r[metric])
    order = sorted(by, key=lambda m: np.median(by[m]))
    return [f"{m}: {label} median {np.median(by[m]):.3g} (from {min(by[m]):.3g} to "
            f"{max(by[m]):.3g} over {len(by[m])} runs)." for m in order]


def best_and_worst(runs, metric, what):
    """One line naming the model closest to FEM and the farthest, by median ``metric``."""
    by = {}
    for r in runs:
        if r.get(metric) is not None:
            by.setdefault(r["model"], []).append(r[metric])
    if not by:
        return f"No model gave {what}."
    med = {m: float(np.median(v)) for m, v in by.items()}
    best, worst = min(med, key=med.get), max(med, key=med.get)
    return (f"{what}: closest {best} (median error {med[best]:.3g}), farthest {worst} "
            f"({med[worst]:.3g}).")


def failures(runs):
    """One line on the runs whose static solve failed, or that none did."""
    bad = [f"{r['model']} on {r['mesh']}/{r['bc']}" for r in runs if r.get("static_failed")]
    return ("No static equilibrium for " + ", ".join(bad) + "." if bad
            else "Every model found its static equilibrium on every mesh run.")
