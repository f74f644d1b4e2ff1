"""The convergence study: every model on every mesh family at falling mesh sizes h, for the
paper cube (clamped and sliding), the cantilever and the torsion bar, against one converged FEM
reference per problem; then the fits, the effective elasticity of every model on every lattice
and the accuracy per cost.
"""
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from model import PRESETS, build
from reference import linear
from ...measuring import metrics as M
from ...running import stop
from ...running.progress import Progress
from ...running.store import OFF, key
from ...framework import MaterialSettings, MESH_FAMILIES
from ...running.runner import FINDINGS, free_components, jsonable
from ...running.workers import dearest_first, one_blas_thread
from .cost import accuracy_per_cost
from .elasticity import table as elasticity_table
from .extrapolation import (EXACT, SAME_ERROR, blind_levels, cancellation, fit, observed_order,
                            ratio_limit)
from .problems import PROBLEMS
from .manufactured import units as manufactured_units
from .patch import units as patch_units
from .steps import units as steps_units

FEM_P1 = "FEM P1"              # the yardstick: scikit-fem P1 on the model's own mesh
MAX_NODES = 10_000             # a level is run where its mesh fits: Newton's sparse LU grows
#                                faster than the nodes (fill-in), so finer levels cost hours
STATIC_RTOL = 1e-12            # the static residual, relative to E h^2: far below the errors
# families whose levels are one lattice at smaller h (an expansion in h holds: extrapolate);
# the unstructured meshes are perturbed at random anew at each h
SELF_SIMILAR = ("five", "six", "bcc")


@dataclass
class ConvergenceSettings(MaterialSettings):
    """What the study runs: material, problems, mesh families, models, the mesh sizes h [mm],
    the load scale (linear regime) and the lattice patch of the effective elasticity."""

    problems: tuple = tuple(PROBLEMS)
    meshes: tuple = MESH_FAMILIES
    models: tuple = tuple(PRESETS)
    h_mm: tuple = (8.0, 4.0, 2.0, 4.0 / 3.0)
    load_scale: float = 1e-3
    patch_n: int = 9
    # the finest spacing of the references' P2 ladders [mm] (None: each problem's own ladder;
    # quick: 2 mm, which leaves the torsion bar's 1.33 mm level, three quarters of the quick
    # references' time, for the full run)
    ref_finest_mm: float = None
    quick: bool = False
    # the verification ladder (manufactured solutions, patch tests, step ladders): the
    # extensions study, which reads the fits and the elasticity alone, runs without it
    verification: bool = True

    def __post_init__(self):
        super().__post_init__()

    def problem(self):
        """What the gate compares: the problem the metrics answer."""
        return {**self.material_record(),
                "h_mm": [round(h, 6) for h in self.h_mm], "load_scale": self.load_scale,
                "ref_ladders_mm": {p: list(self.ladder(p)) for p in self.problems},
                "max_nodes": MAX_NODES, "patch_n": self.patch_n}

    def ladder(self, name):
        """The spacings [mm] of problem ``name``'s reference: its ladder down to
        ``ref_finest_mm``."""
        hs = PROBLEMS[name].ref_ladder_mm
        return hs if self.ref_finest_mm is None else tuple(
            h for h in hs if h >= self.ref_finest_mm * (1 - 1e-9))

    @property
    def units(self):
        """The independent units a worker pool can share out: (problem, bc) pairs."""
        return sum(len(PROBLEMS[p].bcs) for p in self.problems)

    def describe(self):
        return {**self.problem(), "problems": list(self.problems), "meshes": list(self.meshes),
                "bcs": sorted({bc for p in self.problems for bc in PROBLEMS[p].bcs}),
                "models": list(self.models), "quick": self.quick}


def levels(problem, family, s):
    """The mesh sizes run for ``problem`` on ``family``: every h of the settings whose mesh
    has at most MAX_NODES nodes (bcc adds a node per cell)."""
    out = []
    for h in s.h_mm:
        n = np.prod(problem.nodes_per_side(h))
        cells = np.prod([k - 1 for k in problem.nodes_per_side(h)])
        if n + (cells if family == "bcc" else 0) <= MAX_NODES:
            out.append(h)
    return out


# ---------------------------------------------------------------------- the FEM reference
@dataclass
class ProblemReference:
    """The converged FEM of one (problem, bc): P2 on the structured mesh at the spacings of
    the problem's ladder, with its response and its own error estimate; Richardson's
    extrapolation of the field from the two finest levels where that estimate is the
    smaller. ``at(points)`` is its displacement there."""

    problem: str
    bc: str
    ladder: tuple
    levels: list             # LinearResult per spacing of the ladder
    factor: float            # the extrapolation's h_f^p / (h_c^p - h_f^p); 0: the finest level
    response: float
    error_estimate: float
    p2_estimate: float       # the finest P2's own estimate
    increments: list
    order: float

    def at(self, points):
        fine = self.levels[-1].at(points)
        if self.factor == 0.0:
            return fine
        return fine + self.factor * (fine - self.levels[-2].at(points))

    def summary(self):
        return {"case": self.problem, "bc": self.bc, "ladder_mm": list(self.ladder),
                "element": "P2", "dofs": self.levels[-1].info["dofs"],
                "extrapolated": self.factor != 0.0, "response_fem": self.response,
                "error_estimate": self.error_estimate, "p2_error_estimate": self.p2_estimate,
                "increments": self.increments, "order": self.order}


def solve_reference(problem, bc, s):
    """P2 on the 'five' mesh at each spacing of the problem's ladder (8, 4, 2 mm; the
    torsion bar adds 1.33 mm). The relative L2 changes of the displacement at the coarsest
    mesh's nodes between the three finest levels give the observed order p
    (``cases.studies.convergence.extrapolation.observed_order``) and the finest level's error, its last change
    times h_f^p / (h_c^p - h_f^p). Richardson's extrapolation of the field from the two finest
    levels, u_f + (u_f - u_c) h_f^p / (h_c^p - h_f^p), has as error estimate its distance to
    the same extrapolation one level coarser (an upper estimate: what is left when the error
    is not yet a pure C h^p); the reference is whichever of the two has the smaller estimate.
    The finest level's own estimate is ``reference.linear.estimate``'s, as every case's
    reference's (the larger of the displacement's and the energy's Richardson estimates).
    Without an order (a problem P2 solves exactly: the sliding cube) it is the finest level
    with that estimate."""
    hs = s.ladder(problem.case)
    probe = problem.mesh("five", hs[0]).points
    ps = problem.settings(s.E, s.nu)
    levels, meshes = [], []
    for h in hs:
        stop.checkpoint()
        mesh = problem.mesh("five", h)
        loads = problem.loads(mesh, bc, ps, s.load_scale)
        levels.append(linear.solve(mesh, s.material, problem.dirichlet(mesh, bc, ps,
                                                                      s.load_scale),
                                   element="P2", solver=problem.ref_solver(h),
                                   **_fem_loads(loads, mesh)))
        meshes.append(mesh)
    u = [r.at(probe) for r in levels]
    # the finest level's estimate: the one estimator every reference uses
    plain, inc, _, _, _ = linear.estimate([SimpleNamespace(u=x, energy=r.energy)
                                           for x, r in zip(u, levels)], hs)
    responses = [problem.response_value(m, r.u, r.reaction, bc, ps)
                 for m, r in zip(meshes, levels)]
    order = observed_order(hs[-3:], [inc[-2] + inc[-1], inc[-1], 0.0])

    def factor(hc, hf):
        return hf**order / (hc**order - hf**order)
    if order is None or order <= 0.5:
        return ProblemReference(problem.case, bc, hs, levels, 0.0, responses[-1], plain,
                                plain, inc, order)
    k, k1 = factor(hs[-2], hs[-1]), factor(hs[-3], hs[-2])
    fine, coarse = u[-1] + k * (u[-1] - u[-2]), u[-2] + k1 * (u[-2] - u[-3])
    est = float(np.linalg.norm(fine - coarse) / max(np.linalg.norm(fine), 1e-300))
    if est >= plain:
        return ProblemReference(problem.case, bc, hs, levels, 0.0, responses[-1], plain,
                                plain, inc, order)
    response = responses[-1] + k * (responses[-1] - responses[-2])
    return ProblemReference(problem.case, bc, hs, levels, k, float(response), est, plain, inc,
                            order)


# ---------------------------------------------------------------------- one (problem, bc, family)
def family_runs(problem, bc, family, s, ref, hs, store=OFF):
    """The runs of every model and of FEM P1 on ``family`` at each of ``hs``; each row taken
    from ``store`` where it is kept, the mesh and the reference touched only for the rest."""
    rows = []
    ps = problem.settings(s.E, s.nu)
    names = (FEM_P1,) + tuple(s.models)
    for h in hs:
        stop.checkpoint()
        keys = {m: key(kind="convergence-run", **ref.what, mesh=family, level_mm=float(h), model=m)
                for m in names}
        found = {m: store.get(k) for m, k in keys.items()}
        if all(v is not None for v in found.values()):
            rows += [found[m] for m in names]
            continue
        mesh = problem.mesh(family, h)
        dirichlet = problem.dirichlet(mesh, bc, ps, s.load_scale)
        loads = problem.loads(mesh, bc, ps, s.load_scale)
        u_ref = ref.at_mesh(family, h, mesh.points)
        fem = (ref.response if problem.reference_on_reference_mesh()
               else problem.response_value(mesh, u_ref, None, bc, ps))
        base = {"case": problem.case, "mesh": family, "bc": bc, "h_mm": float(h),
                "nodes": mesh.n_nodes, "tets": mesh.n_tets, "response_fem": fem}
        if found[FEM_P1] is None:
            p1 = linear.solve(mesh, s.material, dirichlet, element="P1",
                              solver=problem.spec.fem_solver, **_fem_loads(loads, mesh))
            found[FEM_P1] = store.put(keys[FEM_P1], {**base, "model": FEM_P1, **_metrics(
                problem, mesh, bc, ps, p1.u, p1.reaction, u_ref, fem, dirichlet)})
        f_ext = loads.nodal_forces(mesh)
        for name in s.models:
            if found[name] is not None:
                continue
            stop.checkpoint()
            row = {**base, "model": name, "failed": None}
            try:
                pm = build(name, mesh, s.material)
                st = pm.solve_static(dirichlet, f_ext=f_ext, rtol=STATIC_RTOL)
                row.update(_metrics(problem, mesh, bc, ps, st.u, st.reaction, u_ref, fem,
                                    dirichlet))
            except FINDINGS as exc:     # a model without equilibrium here: a finding
                row.update(failed=str(exc), disp_rel_l2=None, reaction_ratio=None,
                           reaction_rel_err=None, response=None)
            found[name] = store.put(keys[name], row)
        rows += [found[m] for m in names]
    return rows


class StoredReference:
    """The reference of one (problem, bc) as the runs read it: its values at a family mesh's
    nodes (``at_mesh``), its ``response`` and ``summary()``, each taken from ``store`` where
    kept; the P2 ladder is solved only when something asked for is not (its solutions are
    too large to keep: 150 MB for the cantilever)."""

    def __init__(self, problem, bc, s, store=OFF):
        self.problem, self.bc, self.s, self.store = problem, bc, s, store
        self.what = {"problem": problem.case, "bc": bc,
                     **{k: v for k, v in s.problem().items()}}
        self._solved = self._meta = None

    def solved(self):
        if self._solved is None:
            self._solved = solve_reference(self.problem, self.bc, self.s)
        return self._solved

    def _kept(self):
        if self._meta is None:
            k = key(kind="convergence-reference", **self.what)
            self._meta = self.store.get(k) or self.store.put(k, {
                "summary": self.solved().summary(), "response": self.solved().response})
        return self._meta

    @property
    def response(self):
        return self._kept()["response"]

    def summary(self):
        return self._kept()["summary"]

    def at_mesh(self, family, h, points):
        """The reference at the nodes ``points`` of the ``family`` mesh of size ``h``."""
        k = key(kind="convergence-reference-at", **self.what, mesh=family, level_mm=float(h))
        found = self.store.get(k)
        return found if found is not None else self.store.put(k, self.solved().at(points))


def _fem_loads(loads, mesh):
    kw = {"traction": loads.fem_traction(1e-9 * mesh.size),
          "body_force": None if loads.body_force is None else np.asarray(loads.body_force)}
    return {k: v for k, v in kw.items() if v is not None}


def _metrics(problem, mesh, bc, ps, u, reaction, u_ref, fem, dirichlet):
    """The displacement error over the free components and the response's ratio."""
    value = problem.response_value(mesh, u, reaction, bc, ps)
    ratio = problem.ratio(value, fem)
    free = free_components(dirichlet, mesh.n_nodes)
    return {"disp_rel_l2": M.rel_l2(u, u_ref, free), "response": value,
            "reaction_ratio": M.finite("reaction_ratio", ratio) if ratio is not None else None,
            "reaction_rel_err": None if ratio is None else abs(ratio - 1)}


class ReferenceValues:
    """What the runs of one (problem, bc) read of its reference, computed once and handed to
    the (problem, bc, family) units: the values at each family mesh's nodes, the response and
    the summary (a StoredReference's interface, without the P2 ladder)."""

    def __init__(self, what, response, summary, at):
        self.what, self.response, self._summary, self._at = what, response, summary, at

    def summary(self):
        return self._summary

    def at_mesh(self, family, h, points):
        return self._at[(family, float(h))]


def reference_unit(job):
    """The reference of one (problem, bc) as its runs read it (a ReferenceValues): nothing is
    solved where the store keeps every value; the values at the nodes of a family's meshes are
    taken only where some run of that family is not stored."""
    name, bc, s, store = job
    problem = PROBLEMS[name]
    ref = StoredReference(problem, bc, s, store)
    at = {}
    for fam in s.meshes:
        for h in levels(problem, fam, s):
            if not _all_stored(ref, fam, h, s, store):
                at[(fam, float(h))] = ref.at_mesh(fam, h, problem.mesh(fam, h).points)
    return ReferenceValues(ref.what, ref.response, ref.summary(), at)


def _all_stored(ref, family, h, s, store):
    return all(store.get(key(kind="convergence-run", **ref.what, mesh=family, level_mm=float(h),
                             model=m)) is not None for m in (FEM_P1,) + tuple(s.models))


def family_unit(job):
    """The runs of one (problem, bc, family) at its levels against the reference values."""
    name, bc, family, s, store, ref = job
    problem = PROBLEMS[name]
    return family_runs(problem, bc, family, s, ref, levels(problem, family, s), store)


def _verification_unit(job):
    """One row of a verification table (manufactured solutions, patch test, step
    convergence): ``(fn, args)`` from its module's ``units``."""
    fn, args = job
    return fn(*args)


def _weights(name, s):
    """{family: the expected cost of its runs}, for the time left and the order of work."""
    p = PROBLEMS[name]
    return {fam: sum(p.cost(h) * (2 if fam == "bcc" else 1) for h in levels(p, fam, s))
            * (len(s.models) + 1) for fam in s.meshes}


# ---------------------------------------------------------------------- the study
def fits(runs, references=()):
    """A fit per (case, mesh, bc, model) of the displacement error over h, with the limit of
    the stiffness ratio extrapolated alike (never on a family that is not self-similar, never
    a limit at or below zero) and the series flagged where it may cancel rather than
    converge. ``references`` (their summaries) give each error's own uncertainty: its
    problem's reference error estimate. A level that tests nothing (``blind_levels``) is left
    out of its family's fits where three levels remain (recorded in ``left_out_mm``); with
    fewer it stays, and the report says it tests nothing."""
    u_ref = {(r["case"], r["bc"]): r.get("error_estimate") or 0.0 for r in references}
    blind = blind_levels(runs)
    out = []
    keys = dict.fromkeys((r["case"], r["mesh"], r["bc"], r["model"]) for r in runs)
    for case, mesh, bc, model in keys:
        rs = sorted((r for r in runs if (r["case"], r["mesh"], r["bc"], r["model"])
                     == (case, mesh, bc, model) and r.get("disp_rel_l2") is not None),
                    key=lambda r: -r["h_mm"])
        dropped = [r["h_mm"] for r in rs if (case, bc, mesh, r["h_mm"]) in blind]
        if len(rs) - len(dropped) >= 3:     # left out where an order can still be observed
            rs = [r for r in rs if (case, bc, mesh, r["h_mm"]) not in blind]
        else:
            dropped = []
        row = {"case": case, "mesh": mesh, "bc": bc, "model": model, "levels": len(rs),
               "left_out_mm": dropped}
        if len(rs) < 2:
            out.append({**row, "order": None, "e_inf": None, "e_inf_err": None,
                        "verdict": "not enough levels", "why": "fewer than two levels solved",
                        "ratio_inf": None, "ratio_inf_err": None})
            continue
        h = [r["h_mm"] for r in rs]
        nested = mesh in SELF_SIMILAR
        f = fit(h, [r["disp_rel_l2"] for r in rs], nested=nested,
                u=u_ref.get((case, bc), 0.0))
        row.update(order=f.order, e_inf=f.e_inf, e_inf_err=f.e_inf_err, verdict=f.verdict,
                   why=f.why, label=f.label())
        ratios = [r["reaction_ratio"] for r in rs]
        if all(v is not None for v in ratios):
            limit, err = ratio_limit(h, ratios, nested)
            row.update(ratio_inf=limit, ratio_inf_err=err if limit is not None else None,
                       ratio_why=None if limit is not None else err)
        else:
            ratios = None
            row.update(ratio_inf=None, ratio_inf_err=None, ratio_why="a level without ratio")
        row["cancellation"] = cancellation([r["disp_rel_l2"] for r in rs], ratios)
        out.append(row)
    return out


def cancelling(fitted):
    """The (case, mesh, bc, model) of the fits whose series may cancel."""
    return {(f["case"], f["mesh"], f["bc"], f["model"]) for f in fitted
            if f.get("cancellation")}


def run(s, workers=None, log=True, bench=None, store=OFF):
    """Run the study with settings ``s``: the metrics document (runs, fits, references,
    effective elasticity, accuracy per cost from the ``bench`` document). ``workers`` (a
    started cases.running.workers.Workers) runs the units side by side: first the reference of each
    (problem, bc), then the runs of each (problem, bc, family); the results do not depend on
    it (one BLAS thread everywhere). ``store`` gives the runs, reference values and the
    elasticity table it has, and keeps those computed."""
    pairs = [(name, bc) for name in s.problems for bc in PROBLEMS[name].bcs]
    weights = {name: _weights(name, s) for name in s.problems}
    total = sum(sum(weights[name].values()) for name, _ in pairs)
    ref_weight, elastic_weight = 0.05 * total, 0.05 * total
    with Progress("convergence", total + ref_weight + 2 * elastic_weight, log=log,
                  width=36) as track:
        refs = dearest_first(
            reference_unit, [(name, bc, s, store) for name, bc in pairs], workers,
            lambda i: track.advance(ref_weight / len(pairs),
                                    f"{pairs[i][0]} {pairs[i][1]}: reference"),
            [PROBLEMS[name].reference_cost(s.ladder(name)) for name, _ in pairs])
        jobs = [(name, bc, fam, s, store, ref) for (name, bc), ref in zip(pairs, refs)
                for fam in s.meshes]
        rows = dearest_first(
            family_unit, jobs, workers,
            lambda i: track.advance(weights[jobs[i][0]][jobs[i][2]], " ".join(jobs[i][:3])),
            [weights[name][fam] for name, _, fam, *_ in jobs])
        with one_blas_thread():
            eff = elasticity_table(s, store)
        track.advance(elastic_weight, "effective elasticity")
        tables = {} if not s.verification else {
            "manufactured": manufactured_units(s.meshes, s.quick, store),
            "patch": patch_units((FEM_P1,) + tuple(s.models), s.meshes, s.material, store),
            # quick: the first family only (a minute a family for every model)
            "steps": steps_units(s.models, s.meshes[:1] if s.quick else s.meshes, s.E, s.nu,
                                 s.rho, store)}
        work = [(name, unit) for name, us in tables.items() for unit in us]
        checked = dearest_first(
            _verification_unit, [(fn, args) for _, (fn, args, _) in work], workers,
            lambda i: track.advance(elastic_weight / len(work), f"verification: {work[i][0]}"),
            [cost for _, (_, _, cost) in work])
        if not work:
            track.advance(elastic_weight, "no verification asked")
        verification = {name: [r for (n, _), r in zip(work, checked) if n == name]
                        for name in tables}
    runs = [r for rs in rows for r in rs]
    summaries = [ref.summary() for ref in refs]
    fitted = fits(runs, summaries)
    data = {"runs": runs, "fits": fitted, "references": summaries,
            "elasticity": eff, "cost": accuracy_per_cost(
                runs, bench, EXACT, cancelling(fitted),
                {(r["case"], r["bc"]): r.get("error_estimate") or 0.0 for r in summaries}),
            **verification}
    return jsonable(data)


__all__ = ["ConvergenceSettings", "run", "fits", "cancelling", "blind_levels", "SAME_ERROR",
           "levels", "solve_reference", "family_runs",
           "reference_unit", "family_unit", "StoredReference", "ReferenceValues", "FEM_P1"]
