"""What the cases' narratives share: the harness's ranking sentences
(``cases.reporting.rankings``), named here for the cases' prose, and the comparison of FEM with a
closed form."""
from ...reporting.rankings import (best_and_worst, estimate, failures,  # noqa: F401
                                   finite_load, per_run, ranking)


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
