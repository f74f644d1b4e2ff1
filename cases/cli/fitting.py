"""Parameter identification: fit a model's constants to the FEM references of chosen cases.

Each term that declares a ``fit_constant`` (shear c, normal c_n, spring stiffness scale) gets
a factor ``scale_j = exp(theta_j)`` on its calibrated (or given) constant; the residual is the
displacement of every (mesh, bc) of the training cases in the linear regime (the case's loads
scaled to strains of 1e-4, the answer scaled back) against its linear FEM reference at the
nodes, divided by the reference's norm, so that the cost is the sum of the squared
displacement errors of the runs. The reference is FEM P1 on the same tetrahedra by default
(``against="p1"``: the model-form error, what replacing FEM costs; a fit against the
continuum on a coarse mesh would learn to cancel the mesh's own discretisation error, which
does not carry to another mesh), or the converged continuum (``against="continuum"``). scipy's ``least_squares`` (trust region reflective) minimises
it from theta = 0 (the model as built); the Jacobian at the optimum gives the conditioning
(its singular values) and the standard errors and correlations of the constants. The cases
left out are solved before and after: the cross-validation.

This identifies constants from displacements of whole problems, in the spirit of B. Lloyd,
G. Szekely and M. Harders, "Identification of spring parameters for deformable object
simulation", IEEE TVCG 13(5), 2007, who fit spring stiffnesses to a FEM stiffness matrix;
the springs' own rule is A. van Gelder's (J. Graphics Tools 3(2), 1998; model/terms/springs.py).
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from model import build
from model.compose import label, parse
from model.errors import PbcmError
from model.terms import registered
from model.terms.shear import Shear
from ..measuring import metrics as M
from ..running import stop
from ..running.runner import FINDINGS, linear_regime, reaction_along, reference
from ..running.workers import one_blas_thread


class FitError(PbcmError):
    """A fit that cannot be set up (no constant to fit, a case without a displacement)."""


AGAINST = {"p1": "FEM P1 (linear, on the same tetrahedra: the model-form error)",
           "continuum": "the converged continuum (linear P2)"}


@dataclass
class Problem:
    """One (case, mesh, bc) with its references."""

    case: object
    family: str
    bc: str
    settings: object
    mesh: object
    ref: object
    _targets: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def name(self):
        return f"{self.case.name}/{self.family}/{self.bc}"

    def target(self, against):
        """(displacement [m], reaction along the driven axis [N] or None, quantities) of
        the reference ``against`` names (AGAINST), derived once (every evaluation of the fit
        reads it)."""
        if against == "continuum":
            return self.ref.p2.u, self.ref.reaction, self.ref.quantities
        if against not in self._targets:
            p1 = self.ref.p1
            driven = self.case.driven(self.mesh, self.bc, self.settings)
            reaction = None if driven is None else float(reaction_along(p1.reaction, driven))
            q = (self.case.quantities(self.mesh, p1.u, p1.reaction, self.settings, self.bc)
                 if self.case.qoi_errors else {})
            self._targets[against] = (p1.u, reaction, q)
        return self._targets[against]


def fitted_terms(spec):
    """[(term, constant name)] of the terms of ``spec`` that have a constant to fit."""
    classes = registered()
    out = [(t, classes[t].fit_constant) for t, _ in parse(spec)
           if classes[t].fit_constant is not None]
    if not out:
        raise FitError(f"model {label(spec)!r} has no term with a constant to fit (shear, "
                       "normal_*, springs): nothing for pbcm fit to do")
    return out


def check_cases(train, validate):
    """FitError unless the cases can be fitted: static, at least one to train on, none in
    both lists."""
    if not train:
        raise FitError("give at least one case to fit on (--cases)")
    for c in [*train, *validate]:
        if not c.static:
            raise FitError(f"case {c.name} has no static displacement to fit; choose cases "
                           "with a static problem")
    both = sorted({c.name for c in train} & {c.name for c in validate})
    if both:
        raise FitError(f"case(s) {', '.join(both)} both fitted on and left out: a "
                       "cross-validation case must be left out of the fit")


def problems(case, s):
    """The (mesh, bc) problems of ``case`` with settings ``s``, references solved."""
    out = []
    for family in s.meshes:
        mesh = case.mesh(family, s)
        probe = Shear(mesh, s.material, reading="corner")
        for bc in s.bcs:
            stop.checkpoint()
            # the static reference only: a fit reads no transient or modes
            ref = case.solve_reference(mesh, bc, s, probe) or reference(case, mesh, bc, s,
                                                                        probe, extra=False)
            if ref.p2 is None or not case.static:
                raise FitError(f"case {case.name} has no static displacement to fit; choose "
                               "cases with a static problem")
            out.append(Problem(case, family, bc, s, mesh, ref))
    return out


def errors(spec, scales, probs, against="p1"):
    """The residual (concatenated over the problems: the displacement at the nodes divided by
    the reference's norm; for a displacement-driven problem the reaction's relative error,
    without which a stiffness scale would not show in the displacements; the relative errors
    of the case's quantities of interest), each against the reference ``against`` names
    (AGAINST), and each problem's error, the norm of its residual; a problem the model cannot
    solve raises."""
    res, errs = [], []
    for p in probs:
        stop.checkpoint()
        pm = build(spec, p.mesh, p.settings.material, **{t: {"scale": float(k)}
                                                         for t, k in scales.items()})
        st = linear_regime(p.case, pm, p.mesh, p.bc, p.settings, p.ref)
        u_ref, reaction, quantities = p.target(against)
        r = [(st.u - u_ref).ravel() / np.linalg.norm(u_ref)]
        driven = p.case.driven(p.mesh, p.bc, p.settings)
        if driven is not None and reaction:
            r.append([reaction_along(st.reaction, driven) / reaction - 1.0])
        if p.case.qoi_errors:       # the case's quantities of interest (a torque, a tip)
            q = p.case.quantities(p.mesh, st.u, st.reaction, p.settings, p.bc)
            r.append([q[k] / quantities[k] - 1.0 for k in p.case.qoi_errors])
        r = np.concatenate(r)
        res.append(r)
        errs.append(M.finite("fit error", float(np.linalg.norm(r))))
    return np.concatenate(res) / np.sqrt(len(probs)), errs


def constants(spec, scales, mesh, material):
    """The constants the scales stand for: scale x the calibrated c of an auto term, the
    scale itself for a term without one (the spring stiffness scale)."""
    pm = build(spec, mesh, material)
    out = {}
    for (t, const), term in zip(fitted_terms(spec), [x for x in pm.terms
                                                     if x.fit_constant is not None]):
        coef = getattr(term, "coef", None)
        out[f"{t}.{const}"] = float(scales[t] * (coef if coef is not None else 1.0))
    return out


def fit(spec, train, validate, quick=True, overrides=None, progress=print, against="p1"):
    """Fit ``spec``'s constants on the cases ``train`` (Case objects) against the reference
    ``against`` names (AGAINST), cross-validate on ``validate``; return the fit document
    (plain data)."""
    if against not in AGAINST:
        raise FitError(f"--against {against!r}: choose one of {', '.join(AGAINST)}")
    overrides = overrides or {}
    name = label(spec)
    terms = [t for t, _ in fitted_terms(spec)]
    check_cases(train, validate)
    with one_blas_thread():
        train_p = [p for c in train for p in problems(c, c.settings(quick=quick, models=(name,),
                                                                      **overrides))]
        valid_p = [p for c in validate for p in problems(c, c.settings(
            quick=quick, models=(name,), **overrides))]
        evals = []

        def residual(theta):
            scales = dict(zip(terms, np.exp(theta)))
            try:
                r, e = errors(name, scales, train_p, against)
            except FINDINGS as exc:   # no equilibrium at these constants: steer away
                progress(f"fit: {', '.join(f'{t}={v:.4g}' for t, v in scales.items())} "
                         f"failed ({exc}); penalised")
                return np.full(n_res, 1e3)
            evals.append(float(np.sqrt(np.mean(np.square(e)))))
            progress(f"fit: evaluation {len(evals)}: "
                     + ", ".join(f"{t} x{v:.4g}" for t, v in scales.items())
                     + f", rms error {evals[-1]:.4g}")
            return r

        theta0 = np.zeros(len(terms))
        r0, before_train = errors(name, dict(zip(terms, np.ones(len(terms)))), train_p,
                                  against)
        n_res = len(r0)
        sol = least_squares(residual, theta0, method="trf", diff_step=1e-4, x_scale=1.0,
                            bounds=(np.full(len(terms), np.log(1e-3)),
                                    np.full(len(terms), np.log(1e3))))
        scales = dict(zip(terms, np.exp(sol.x)))
        J = sol.jac
        sv = np.linalg.svd(J, compute_uv=False)
        dof = max(J.shape[0] - J.shape[1], 1)
        sigma2 = 2 * sol.cost / dof
        cov = np.linalg.pinv(J.T @ J) * sigma2
        se = np.sqrt(np.diag(cov))
        corr = cov / np.outer(se, se) if np.all(se > 0) else np.full_like(cov, np.nan)
        after_train = errors(name, scales, train_p, against)[1]
        rows_v = []
        for p in valid_p:
            twin = next((t.name for t in train_p if same_problem(p, t)), None)
            if twin is not None:     # the linear regime of one problem again: not left out
                rows_v.append({"problem": p.name, "before": f"the training problem {twin}",
                               "after": f"the training problem {twin}", "twin": twin})
                continue
            try:
                b = errors(name, dict(zip(terms, np.ones(len(terms)))), [p], against)[1][0]
            except FINDINGS as exc:
                b = f"failed: {exc}"
            try:
                a = errors(name, scales, [p], against)[1][0]
            except FINDINGS as exc:
                a = f"failed: {exc}"
            rows_v.append({"problem": p.name, "before": b, "after": a})
    mesh0, mat0 = train_p[0].mesh, train_p[0].settings.material
    return {
        "model": name, "terms": terms, "quick": quick, "against": against,
        "train": [c.name for c in train], "validate": [c.name for c in validate],
        "scales": {t: float(v) for t, v in scales.items()},
        "scale_rel_se": {t: float(s) for t, s in zip(terms, se)},   # d ln(scale) = rel. error
        "constants_on": f"{train_p[0].name} mesh",
        "constants_auto": constants(name, dict.fromkeys(terms, 1.0), mesh0, mat0),
        "constants_fitted": constants(name, scales, mesh0, mat0),
        "correlation": corr.tolist(), "singular_values": sv.tolist(),
        "condition_number": float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf"),
        # a constant whose relative standard error exceeds 1 is not identified by these cases
        "identified": {t: bool(s < 1.0) for t, s in zip(terms, se)},
        "evaluations": len(evals), "optimizer": sol.message, "status": int(sol.status),
        "train_rows": [{"problem": p.name, "before": b, "after": a}
                       for p, b, a in zip(train_p, before_train, after_train)],
        "validate_rows": rows_v,
    }


def same_problem(a, b):
    """True where two problems are one in the linear regime: the same nodes and the same
    reference displacement up to a factor (a case that scales another's load)."""
    if a.mesh.points.shape != b.mesh.points.shape or not np.allclose(a.mesh.points,
                                                                     b.mesh.points):
        return False
    ua, ub = a.ref.p1.u.ravel(), b.ref.p1.u.ravel()
    na, nb = np.linalg.norm(ua), np.linalg.norm(ub)
    return bool(na > 0 and nb > 0 and np.allclose(ua / na, ub / nb, atol=1e-9))


def worst_change(rows):
    """The left-out problem whose error the fit multiplied most (after / before), with that
    factor; a problem that failed after the fit is the worst; None without any."""
    scored = []
    for r in rows:
        if r.get("twin"):
            continue
        b, a = r["before"], r["after"]
        if isinstance(a, str):
            return {**r, "factor": float("inf")}
        if isinstance(b, (int, float)) and b > 0:
            scored.append({**r, "factor": a / b})
    return max(scored, key=lambda r: r["factor"]) if scored else None


def report(doc):
    """A report (cases.reporting.document.Document) of a fit document: the constants, their
    conditioning, and the errors before and after on the training and left-out cases."""
    from ..reporting.document import Document, fmt
    d = Document(f"pbcm fit: {doc['model']}")
    rms = {k: _rms([r[k] for r in doc["train_rows"]]) for k in ("before", "after")}
    left = [r for r in doc["validate_rows"] if not r.get("twin")]
    vrms = {k: _rms([r[k] for r in left]) for k in ("before", "after")}
    twins = [f"{r['problem']} (= {r['twin']})" for r in doc["validate_rows"] if r.get("twin")]
    factors = [r["after"] / r["before"] for r in left if not isinstance(r["after"], str)
               and not isinstance(r["before"], str) and r["before"] > 0]
    failed = sum(isinstance(r["after"], str) for r in left)
    better = sum(f < 1 for f in factors)
    # the fit carries where every left-out problem improves, and does not where most worsen
    # (a failed one counts as worse): read on the problems one by one, never on the rms alone
    carries = (None if not factors and not failed else "carries" if better == len(left)
               else "does not carry" if 2 * (len(left) - better) > len(left) else "not decided")
    d.p(f"Fitted on {', '.join(doc['train'])} ({'quick' if doc['quick'] else 'full'} "
        f"settings): the rms error of the training problems goes from "
        f"{fmt(rms['before'])} to {fmt(rms['after'])}"
        + (f"; on the cases left out ({', '.join(doc['validate'])}) from "
           f"{fmt(vrms['before'])} to {fmt(vrms['after'])}" if left else "")
        + (f" (each left-out problem's error after over before: median "
           f"{fmt(float(np.median(factors)), 2)} [{fmt(min(factors), 2)}-"
           f"{fmt(max(factors), 2)}], better in {better}, worse in {len(left) - better} of "
           f"{len(left)}" + (f", {failed} failed after the fit" if failed else "")
           + f": the fit {carries} to the cases left out)" if carries else "")
        + (f"; left out but the same problem as a training one in the linear regime (one "
           f"observation, not counted as left out): {', '.join(twins)}" if twins else "")
        + "." + (" Quick settings: a preview; the same `pbcm fit` without --quick decides."
                 if doc["quick"] else ""))
    worst = worst_change(doc["validate_rows"])
    if worst:
        d.p(f"Worst change on a case left out: {worst['problem']}, from {fmt(worst['before'])} "
            f"to {fmt(worst['after'])} ({fmt(worst['factor'])} times): an rms can hide one "
            "problem the fit made worse." + (
                " Fit where the reference problem is converged: a fit trained where the "
                "reference itself is far off learns the reference's error."
                if doc.get("against", "continuum") == "continuum" else ""))
    against = doc.get("against", "continuum")
    d.p("Error of a problem: sqrt(disp_rel^2 + reaction_rel_err^2 + the squared relative "
        "errors of the case's quantities of interest) in the linear regime against "
        f"{AGAINST[against]} (the reaction where the problem is driven by a displacement); "
        "the fit minimises the sum of their squares over the training problems"
        + ("; against the model-form error a fit does not learn to cancel the mesh's own "
           "discretisation error, which would not carry to another mesh."
           if against == "p1" else "; on a coarse mesh such a fit also learns to cancel the "
           "mesh's own discretisation error, which does not carry to another mesh."))
    d.p(f"Generated by `pbcm fit`: every number was computed by the fit that wrote this file "
        f"({doc['evaluations']} evaluations; optimizer: {doc['optimizer']}).")
    d.h(2, "Constants")
    d.table(["term", "auto (as built)", "fitted", "factor", "relative std. error",
             "identified"],
            [[k, fmt(doc["constants_auto"][k]), fmt(doc["constants_fitted"][k]),
              fmt(doc["scales"][k.split(".")[0]]), fmt(doc["scale_rel_se"][k.split(".")[0]]),
              "yes" if doc["identified"][k.split(".")[0]] else "no"]
             for k in doc["constants_fitted"]])
    d.p(f"Constants as calibrated on the {doc['constants_on']} (c = auto is fitted per mesh; "
        "the factor carries over). Conditioning of the Jacobian (log-constants): singular "
        "values " + ", ".join(fmt(v) for v in doc["singular_values"])
        + f", condition number {fmt(doc['condition_number'])}"
        + ("; correlation of the log-constants: "
           + "; ".join(f"{a}-{b} {fmt(doc['correlation'][i][j])}"
                       for i, a in enumerate(doc["terms"]) for j, b in enumerate(doc["terms"])
                       if j > i) if len(doc["terms"]) > 1 else "") + ".")
    for title, rows in (("Training problems", doc["train_rows"]),
                        ("Cross-validation: cases left out", doc["validate_rows"])):
        if rows:
            d.h(2, title)
            d.table(["problem", "error before", "after"],
                    [[r["problem"], fmt(r["before"]) if not isinstance(r["before"], str)
                      else r["before"], fmt(r["after"]) if not isinstance(r["after"], str)
                      else r["after"]] for r in rows])
    return d


def _rms(values):
    v = [x for x in values if not isinstance(x, str)]
    return float(np.sqrt(np.mean(np.square(v)))) if v else None
