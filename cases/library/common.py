"""What the library's cases share: bars meshed at a spacing, their end faces, and sentences
that rank the models and compare FEM with a closed form, computed from the runs."""
import numpy as np

from model import ModelError
from model.bc import merge
from model.mesh import box
from ..framework import MM

CUBE_BCS = ("clamped", "sliding")    # the compressed cube's bases


def cube_boundary_sets(mesh, bc, size):
    """(driven, lateral, held) of a cube [0, size]^3 [m] pushed down on its top: the top
    nodes, moved in y; what the top holds laterally; and the mapping that holds the rest.

    ``clamped``: bottom fully fixed, top fully prescribed. ``sliding``: only y prescribed at top
    and bottom; the origin pinned and the node at (size, 0, 0) held in z remove rigid
    motions."""
    top, bottom = mesh.nodes_on_plane("y", size), mesh.nodes_on_plane("y", 0.0)
    if bc == "clamped":
        return top, (0.0, None, 0.0), {int(i): (0.0, 0.0, 0.0) for i in bottom}
    if bc != "sliding":
        raise ModelError(f"unknown boundary condition {bc!r}; choose from {', '.join(CUBE_BCS)}")
    held = [(int(i), (None, 0.0, None)) for i in bottom]
    origin = mesh.nodes_where(lambda p: np.all(np.abs(p) < 1e-9, axis=1))[0]
    corner_x = mesh.nodes_where(lambda p: (np.abs(p[:, 0] - size) < 1e-9)
                                & (np.abs(p[:, 1]) < 1e-9) & (np.abs(p[:, 2]) < 1e-9))[0]
    held += [(int(origin), (0.0, 0.0, 0.0)), (int(corner_x), (None, 0.0, 0.0))]
    return top, (None, None, None), merge(held)


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


def _by_model(runs, metric):
    by = {}
    for r in runs:
        if r.get(metric) is not None:
            by.setdefault(r["model"], []).append(r[metric])
    return by


def estimate(runs, key="p2_error_estimate"):
    """The reference's error estimate a ranking of ``runs`` respects: the largest of their
    references' (one per mesh and bc; None where the reference has none); ``key`` the
    reference's (nh_error_estimate for the neo-Hookean one)."""
    est = [r[key] for r in runs if r.get(key) is not None]
    return max(est) if est else None


def ranking(runs, metric, label, estimate_key="p2_error_estimate"):
    """'model: median metric (range)' sentences, best first, over the runs that gave it; a
    model whose median is within the reference's estimate (``estimate_key``) of the one
    above is called tied with it (the reference cannot order them)."""
    by, est = _by_model(runs, metric), estimate(runs, estimate_key)
    med = {m: float(np.median(v)) for m, v in by.items()}
    order = sorted(by, key=med.get)
    out = []
    for k, m in enumerate(order):
        tie = ""
        if k and est is not None and med[m] - med[order[k - 1]] < est:
            tie = f" Tied with {order[k - 1]} (within the reference's estimate {est:.2g})."
        out.append(f"{m}: {label} median {med[m]:.3g} (from {min(by[m]):.3g} to "
                   f"{max(by[m]):.3g} over {len(by[m])} runs).{tie}")
    return out


def best_and_worst(runs, metric, what, exact=False, estimate_key="p2_error_estimate"):
    """One line naming the model closest to FEM and the farthest, by median ``metric``; the
    models within the reference's estimate (``estimate_key``) of the closest are named tied
    with it, and the line says so where that estimate exceeds a fifth of the smallest error
    it ranks (``exact``: the metric is against a closed form, which has no estimate)."""
    by, est = _by_model(runs, metric), None if exact else estimate(runs, estimate_key)
    if not by:
        return f"No model gave {what}."
    med = {m: float(np.median(v)) for m, v in by.items()}
    best, worst = min(med, key=med.get), max(med, key=med.get)
    line = (f"{what}: closest {best} (median error {med[best]:.3g}), farthest {worst} "
            f"({med[worst]:.3g}).")
    if est is None:
        return line
    tied = [m for m in sorted(med, key=med.get) if m != best and med[m] - med[best] < est]
    if tied:
        line += f" Tied with {best} within the reference's estimate {est:.2g}: {', '.join(tied)}."
    smallest = min(min(v) for v in by.values())
    if est > smallest / 5:
        line += (f" The reference's estimate ({est:.2g}) exceeds a fifth of the smallest "
                 f"error ranked ({smallest:.2g}): differences below it are not resolved.")
    return line


def failures(runs, key="static_failed", where="in the linear regime"):
    """One line on the runs whose static solve (``key``) failed, or that none did."""
    bad = [f"{r['model']} on {r['mesh']}/{r['bc']}" for r in runs if r.get(key)]
    return (f"No static equilibrium {where} for " + ", ".join(bad) + "." if bad
            else f"Every model found its static equilibrium {where} on every mesh run.")


def finite_load(runs):
    """{group title: sentences} on the case's load against the neo-Hookean reference, or {}
    where no run has one: the ranking by displacement (and reaction), fem-linear's error
    named its linearisation error, and the failures."""
    if not any(r.get("nh_error_estimate") is not None or r.get("finite_failed")
               for r in runs):
        return {}
    nh = "nh_error_estimate"
    out = [best_and_worst(runs, "disp_rel_l2_nh", "Displacement at the case's load",
                          estimate_key=nh)]
    out += ranking(runs, "disp_rel_l2_nh", "displacement error", nh)
    if any(r.get("reaction_rel_err_nh") is not None for r in runs):
        out += ranking(runs, "reaction_rel_err_nh", "reaction error", nh)
    lin = [r["disp_rel_l2_nh"] for r in runs
           if r["model"] == "fem-linear" and r.get("disp_rel_l2_nh") is not None]
    if lin:
        out.append(f"fem-linear's error at the case's load is its linearisation error: "
                   f"median {np.median(lin):.3g} (from {min(lin):.3g} to {max(lin):.3g}).")
    refs = sorted({f"{r['mesh']}/{r['bc']}" for r in runs if r.get(nh) is None
                   and r.get("finite_failed")})
    if refs:
        out.append("No neo-Hookean reference on " + ", ".join(refs) + ".")
    out.append(failures([r for r in runs if r.get(nh) is not None], "finite_failed",
                        "at the case's load"))
    return {"At the case's load, against the neo-Hookean reference": out}
