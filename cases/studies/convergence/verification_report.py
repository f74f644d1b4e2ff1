"""The convergence report's verification section: the references' manufactured-solution
ladders and every model's patch test, each sentence computed from the rows it shows."""
from model.units import MM
from ...measuring import catalogue
from ...reporting.document import fmt
from .steps import DIVISORS, REFERENCE, ROUNDOFF
from .verification import spec


def gate_rows(data):
    """The verification's rows as the gate reads them: (family, 'manufactured', ladder) with
    the finest pair's order and the finest error; (family, 'patch', model) with the patch
    error."""
    rows = [{"mesh": r["mesh"], "bc": "manufactured", "model": r["ladder"],
             "mms_order": r["mms_order"], "mms_rel_l2": r["mms_rel_l2"]}
            for r in data.get("manufactured", ())]
    rows += [{"mesh": r["mesh"], "bc": "patch", "model": r["model"],
              "patch_error": r["patch_error"]} for r in data.get("patch", ())]
    rows += [{"mesh": r["mesh"], "bc": "paper-cube/steps", "model": r["model"],
              "dt_error": r["dt_error"], "dt_order": r["dt_order"]}
             for r in data.get("steps", ())]
    return rows


def manufactured_section(doc, data):
    rows = data.get("manufactured") or []
    if not rows:
        return
    s = spec()
    doc.h(3, "Manufactured solutions: the references' observed orders")
    ok = [r for r in rows if r["passed"]]
    fast = [r for r in ok if r["mms_order"] > r["formal_order"] + r["tolerance"]]
    doc.p(f"{len(ok)} of {len(rows)} ladders pass: the observed L2 order of the finest pair "
          f"within {s['tolerance']:g} of the element's formal order and the finest error under "
          "its bound"
          + (f"; {len(fast)} of them only from below, declared faster: "
             + "; ".join(f"{r['ladder']} on {r['mesh']} at {r['mms_order']:.3f} (pairs "
                         + " then ".join(f"{o:.3f}" for o in r["mms_orders"]) + ")"
                         for r in fast)
             + ": faster than the formal order at these levels, outside its band above"
             if fast else "") + ". " + " ".join(
              f"{r['ladder']} on {r['mesh']} does not: order {r['mms_order']:.3f} against "
              f"{r['formal_order']:g}"
              + (" (faster than its formal order at these levels; the orders of the pairs "
                 + " then ".join(f"{o:.3f}" for o in r["mms_orders"]) + ")"
                 if r["mms_order"] > r["formal_order"] + r["tolerance"] else "")
              + f", finest error {r['mms_rel_l2']:.3g} (bound {r['finest_bound']:g})."
              for r in rows if not r["passed"]))
    entries = {e.name: e for e in s["manufactured"]}
    doc.p("The field is a sum of three plane waves with phases (no component a polynomial) on "
          f"the cube of side {s['size'] / MM:g} mm, E = {s['E']:g} Pa; prescribed on the faces "
          "listed (x: the face x = 0, X: x = side), its traction on the others, its body force "
          "inside (reference.manufactured, the divergence checked against finite differences). "
          + " ".join(f"{e.name}: nu = {e.nu:g}, amplitude {e.amplitude:g} x side, faces "
                     f"{e.faces}." for e in entries.values()))
    label = {n: catalogue.metric(n).label for n in ("mms_errors", "mms_orders", "mms_order",
                                                    "mms_rel_l2")}
    doc.table(["ladder", "mesh", "cells per side", label["mms_errors"], label["mms_orders"],
               label["mms_order"], "formal", "finest bound", "verdict"],
              [[r["ladder"], r["mesh"], ", ".join(str(c) for c in r["cells"]),
                ", ".join(fmt(e, 3) for e in r["mms_errors"]),
                ", ".join(f"{o:.3f}" for o in r["mms_orders"]), f"{r['mms_order']:.3f}",
                f"{r['formal_order']:g} +- {r['tolerance']:g}", fmt(r["finest_bound"]),
                ("FAIL" if not r["passed"] else "pass, faster"
                 if r["mms_order"] > r["formal_order"] + r["tolerance"] else "pass")]
               for r in rows])


def patch_section(doc, data, models):
    rows = data.get("patch") or []
    if not rows:
        return
    p = spec()["patch"]
    fams = list(dict.fromkeys(r["mesh"] for r in rows))
    by = {(r["mesh"], r["model"]): r for r in rows}
    doc.h(3, "Patch test with every boundary node prescribed: each model's strain error")
    doc.p(f"A cube of {p['nodes']} nodes per side; each of the six unit strains times "
          f"{p['strain']:g} prescribed on its boundary nodes (about its centre), the interior "
          "relaxed (static residual below "
          f"{p['rtol']:g} E h^2); the error is the strain the solution misses, the RMS over the "
          "tetrahedra of |eps_h - eps| / |eps|, worst of the six. The perturbed lattices move "
          f"each interior node by up to {p['perturbation']:g} of its shortest edge (seed "
          f"{p['seed']}). A consistent model passes below {p['exact_below']:g} on every family.")
    exact = [m for m in models if all(by.get((f, m), {}).get("patch_error") is not None
                                      and by[(f, m)]["patch_error"] < p["exact_below"]
                                      for f in fams)]
    sentences = [f"Passing on every family: {', '.join(exact) or 'none'}."]
    for m in models:
        if m in exact:
            continue
        mine = [by[(f, m)] for f in fams if (f, m) in by]
        failed = [r for r in mine if r.get("failed")]
        done = [r for r in mine if r.get("patch_error") is not None]
        passed = [r["mesh"] for r in done if r["patch_error"] < p["exact_below"]]
        worst = max(done, key=lambda r: r["patch_error"]) if done else None
        text = f"{m}: "
        if passed:
            text += f"passes on {', '.join(passed)}; "
        if worst is not None:
            text += (f"fails on {', '.join(r['mesh'] for r in done if r['mesh'] not in passed)}"
                     f", worst {worst['patch_error']:.3g} on {worst['mesh']}")
        if failed:
            text += ("; no equilibrium on " + ", ".join(r["mesh"] for r in failed))
        sentences.append(text + ".")
    sliding = _sliding(data, models)
    if sliding:
        sentences.append(sliding)
    doc.ul(sentences)
    doc.table(["model"] + fams,
              [[m] + [("no equilibrium" if by[(f, m)].get("failed")
                       else fmt(by[(f, m)]["patch_error"], 3)) if (f, m) in by else "-"
                      for f in fams] for m in models])


def _sliding(data, models):
    """The sliding paper cube is the same test with traction-free sides (homogeneous uniaxial
    stress): each model's largest displacement error there, over the families, at the finest
    h run."""
    runs = [r for r in data.get("runs", ()) if (r["case"], r["bc"]) == ("paper-cube", "sliding")
            and r.get("disp_rel_l2") is not None]
    if not runs:
        return None
    h = min(r["h_mm"] for r in runs)
    worst = {}
    for r in runs:
        if r["h_mm"] == h and (r["model"] not in worst
                               or r["disp_rel_l2"] > worst[r["model"]]["disp_rel_l2"]):
            worst[r["model"]] = r
    return ("The sliding paper cube (the convergence runs below and the paper-cube report) is "
            "not this test: a homogeneous uniaxial stress with traction-free sides, none of "
            "their nodes prescribed, whose error a fit extrapolates to the consistency limit "
            "of the sliding cube (its table below); its "
            f"largest displacement error over the families at h = {h:.3g} mm: " + ", ".join(
                f"{m} {worst[m]['disp_rel_l2']:.2g} ({worst[m]['mesh']})" for m in models
                if m in worst) + ".")


def steps_section(doc, data):
    rows = data.get("steps") or []
    if not rows:
        return
    doc.h(3, "Time step: RK4 on the paper cube")
    ok = [r for r in rows if r.get("dt_error") is not None]
    failed = [r for r in rows if r.get("failed")]
    orders = [r["dt_order"] for r in ok if r["dt_order"] is not None]
    at_roundoff = sorted({f"{r['model']} ({r['mesh']})" for r in ok if r["dt_order"] is None})
    text = (f"Each model's push of the paper cube (clamped, {len(rows)} runs) at the case's RK4 "
            f"step ({DIVISORS[0]}x), at its half, and at 1/{REFERENCE} as the "
            "reference: the end-of-push displacement error.")
    if ok:
        worst = max(ok, key=lambda r: r["dt_error"])
        text += (f" At the case's step it is at most {worst['dt_error']:.2g} "
                 f"({worst['model']} on {worst['mesh']}, {worst['steps']} steps of "
                 f"{worst['dt_s'] * 1e3:.3g} ms).")
    if orders:
        text += (f" Halving the step divides it by 2^p with p from {min(orders):.2f} to "
                 f"{max(orders):.2f} (RK4's order is 4).")
    if at_roundoff:
        text += (f" At round-off (below {ROUNDOFF:g}) already at the half step: "
                 + ", ".join(at_roundoff) + ".")
    if failed:
        text += " Blown up: " + "; ".join(
            f"{r['model']} on {r['mesh']} at 1/{r['failed_divisor']} of the case's step "
            f"({r['failed']})" for r in failed) + "."
    doc.p(text)
    label = {n: catalogue.metric(n).label for n in ("dt_errors", "dt_order")}
    doc.table(["mesh", "model", "steps", "dt [ms]", label["dt_errors"], label["dt_order"]],
              [[r["mesh"], r["model"], r["steps"], fmt(r["dt_s"] * 1e3),
                "failed" if r.get("failed") else ", ".join(fmt(e, 3) for e in r["dt_errors"]),
                fmt(r.get("dt_order"), 3)] for r in rows])
