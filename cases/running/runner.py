"""The shared runner: for a declared Case, every (mesh, bc) gets its FEM references and every
model its run with the standard metrics, the case's quantities of interest and its extra
metrics. A failure (a mesh that cannot be built, a reference that does not converge, a model
without equilibrium) is recorded in the runs it touches and the case goes on.
"""
import dataclasses
import sys
from dataclasses import dataclass

import numpy as np

from model.bc import bc_arrays
from model.terms.shear import Shear
from reference import hyperelastic, linear
from ..measuring import metrics as M
from . import stop
from ..measuring.catalogue import FINITE, STATIC, err_name, load_name, ref_name
from ..measuring.error_model import at_load
from ..framework import FINDINGS, Reference, linear_scale
from .progress import Progress
from .store import OFF, key
from .workers import one_blas_thread, tick

# a reference field that varies by less than this fraction of its size is uniform: its
# variation is the iterative solver's (relative residual 1e-10 gives about 1e-9 here), and a
# correlation with it would correlate with solver noise (the sliding cube's pressure)
UNIFORM_TOL = 1e-6


def uniform(field):
    """True when a reference field is constant to the solver's accuracy (UNIFORM_TOL)."""
    return np.ptp(field) <= UNIFORM_TOL * max(np.abs(field).max(), 1e-300)


def reaction_along(reaction, driven):
    """The force along the driven axis the supports exert on the driven nodes [N]."""
    nodes, axis = driven
    return -reaction[nodes, axis].sum()


def reference(case, mesh, bc, s, probe, extra=True, nonlinear=None):
    """The default references of one (mesh, bc): the linear regime's (P1 on the mesh and
    converged linear P2) with the case's loads and quantities, the case load's (converged
    neo-Hookean; ``nonlinear``, default ``extra``: not for a static-only run) and
    (``extra``) the case's extra reference work."""
    mat = s.material
    dirichlet = case.dirichlet(mesh, bc, s)
    dirichlet_lin = case.dirichlet_linear(mesh, bc, s)
    loads = case.loads(mesh, bc, s)
    kw = {"traction": loads.fem_traction(1e-9 * mesh.size),
          "body_force": None if loads.body_force is None else np.asarray(loads.body_force)}
    kw = {k: v for k, v in kw.items() if v is not None}
    kw["dirichlet_fn"] = case.dirichlet_fn(mesh, bc, s)
    lin = dict(kw, solver=case.fem_solver)
    p1 = linear.solve(mesh, mat, dirichlet_lin, element="P1", **lin)
    conv = linear.converged(mesh, mat, dirichlet_lin, levels=s.p2_levels, **lin)
    p2 = conv.result
    driven = case.driven(mesh, bc, s)
    ref = Reference(dirichlet=dirichlet, f_ext=loads.nodal_forces(mesh), p1=p1, conv=conv,
                    p2=p2, tau=probe.max_tau(mesh.points + p2.u),
                    reaction=None if driven is None else float(reaction_along(p2.reaction,
                                                                              driven)),
                    quantities=case.quantities(mesh, p2.u, p2.reaction, s, bc),
                    error_estimate=conv.error_estimate, dirichlet_linear=dirichlet_lin,
                    scale=linear_scale(p2, mat))
    if extra if nonlinear is None else nonlinear:     # not for the linear regime alone
        try:
            ref.nonlinear = hyperelastic.converged(mesh, mat, dirichlet,
                                                   levels=s.nh_levels, mixed="auto",
                                                   load_steps=case.finite_steps(s), **kw)
            if driven is not None:
                ref.nonlinear_reaction = float(reaction_along(
                    ref.nonlinear.result.reaction, driven))
            # the model-form error's twin at the load: P1 with the same law on the mesh (no
            # comparison at the load where it has no equilibrium, as where the continuum has none)
            ref.nonlinear_p1 = hyperelastic.solve(mesh, mat, dirichlet, element="P1",
                                                  load_steps=case.finite_steps(s), **kw)
            nh = ref.nonlinear.result
            ref.quantities_at_load = at_load_quantities(case, mesh, bc, s, nh.u, nh.reaction)
        except FINDINGS as exc:     # recorded: the linear regime still stands
            ref.nonlinear, ref.nonlinear_reaction = None, None
            ref.nonlinear_failed = str(exc)
    ref.extra = case.reference_extra(mesh, bc, s, ref) if extra else {}
    return ref


@dataclass
class LinearRegime:
    """A model's solution in the linear regime, brought back to the case's load (divided by
    the scale): what the linear references' answers at the case's load are compared with."""

    u: np.ndarray
    reaction: np.ndarray
    residual: float
    stress: dict

    @classmethod
    def of(cls, st, pm, scale):
        stress = {**pm.tet_stress(st.x), "virial": pm.tet_virial(st.x)}
        return cls(u=st.u / scale, reaction=st.reaction / scale, residual=st.residual / scale,
                   stress={k: None if v is None else v / scale for k, v in stress.items()})


def linear_regime(case, pm, mesh, bc, s, ref):
    """The model's answer in the linear regime brought back to the case's load (the case's
    own solve where the reference has no linear regime; None without a static problem)."""
    if ref.scale is None:
        st = case.solve_static(pm, mesh, bc, s, ref)
        return None if st is None else LinearRegime.of(st, pm, 1.0)
    return LinearRegime.of(case.solve_linear(pm, mesh, bc, s, ref), pm, ref.scale)


def static_metrics(case, lr, mesh, bc, s, ref):
    """The standard metrics of a static solution ``lr`` (its u, reaction, residual and
    per-tetrahedron stress) against the linear references (docs/model.md "What is
    compared"), then the case's quantities of interest and their errors."""
    stress = lr.stress
    free = free_components(ref.dirichlet, mesh.n_nodes)
    out = {"disp_rel_l2_p1": M.rel_l2(lr.u, ref.p1.u, free),
           "disp_max_rel_p1": M.max_rel(lr.u, ref.p1.u, free),
           "disp_rel_l2_p2": M.rel_l2(lr.u, ref.p2.u, free),
           "disp_max_rel_p2": M.max_rel(lr.u, ref.p2.u, free),
           "disp_energy_rel_p2": M.energy_rel(lr.u, ref.p2.u,
                                              linear.p1_stiffness(mesh, s.material))}
    driven = case.driven(mesh, bc, s)
    if driven is None or not np.isfinite(lr.reaction).all():    # none, or a model without forces
        out.update(reaction_n=None, reaction_ratio=None, reaction_rel_err=None)
    else:
        reaction = M.finite("reaction", reaction_along(lr.reaction, driven))
        out.update(reaction_n=reaction,
                   reaction_ratio=M.finite("reaction_ratio", reaction / ref.reaction),
                   reaction_rel_err=M.finite("reaction_rel_err",
                                             abs(reaction / ref.reaction - 1)))
    out.update({
        "stress_corr": None if uniform(ref.tau) else M.correlation(stress["max_tau"], ref.tau),
        "stress_rel_err": M.rel_l2(stress["max_tau"], ref.tau),
        "pressure_corr": (None if uniform(ref.p2.pressure)
                          else M.correlation(stress["pressure"], ref.p2.pressure)),
        "pressure_rel_err": M.rel_l2(stress["pressure"], ref.p2.pressure)})
    if stress["virial"] is None:          # a model that gives no forces
        out.update(stress_force_rel_err=None, stress_force_corr=None)
    else:
        nodal = M.node_patch_average(mesh, stress["virial"])
        out.update({"stress_force_rel_err": M.tensor_rel_l2(nodal, ref.p2.stress_nodes),
                    "stress_force_corr": (None if uniform(M.von_mises(ref.p2.stress_nodes))
                                          else M.correlation(M.von_mises(nodal),
                                                             M.von_mises(ref.p2.stress_nodes)))})
    q = case.quantities(mesh, lr.u, lr.reaction, s, bc)
    out.update(q)
    out.update(case.quantity_metrics(q, ref.quantities, bc))
    for name in case.qoi_errors:
        out[err_name(name)] = M.finite(err_name(name),
                                       abs(q[name] / _nonzero(name, ref.quantities[name]) - 1))
    out["static_residual_n"] = lr.residual
    return out


def free_components(dirichlet, n):
    """(n, 3) bool: the components no Dirichlet condition prescribes (where errors count)."""
    mask, _ = bc_arrays(dirichlet, n)
    return ~mask


def finite_metrics(case, st, mesh, bc, s, ref):
    """The metrics of the model at the case's load against the neo-Hookean reference."""
    nh = ref.nonlinear.result
    free = free_components(ref.dirichlet, mesh.n_nodes)
    out = {"disp_rel_l2_nh": M.rel_l2(st.u, nh.u, free),
           # a case with its own reference at the load (large compression) has no P1 twin
           "disp_rel_l2_nh_p1": None if ref.nonlinear_p1 is None
           else M.rel_l2(st.u, ref.nonlinear_p1.u, free),
           "disp_max_rel_nh": M.max_rel(st.u, nh.u, free),
           "reaction_rel_err_nh": None}
    driven = case.driven(mesh, bc, s)
    if driven is not None:
        reaction = reaction_along(st.reaction, driven)
        out["reaction_rel_err_nh"] = M.finite(
            "reaction_rel_err_nh", abs(reaction / _nonzero("reaction", ref.nonlinear_reaction)
                                       - 1))
    out.update(at_load_quantities(case, mesh, bc, s, st.u, st.reaction))
    return out


def at_load_quantities(case, mesh, bc, s, u, reaction):
    """{run key: value} of the case's decomposed quantity at its load (``error_model.
    at_load``) from a solution (u, reaction) there: the reaction on the driven nodes or one
    of the case's quantities of interest; {} where the case decomposes none at the load."""
    q = case.decomposed
    if at_load(q) not in case.decompositions():     # None (no quantity at the load) never is
        return {}
    if q.key == "reaction_n":
        driven = case.driven(mesh, bc, s)
        value = None if driven is None else float(reaction_along(reaction, driven))
    else:
        value = case.quantities(mesh, u, reaction, s, bc)[q.key]
    return {load_name(q.key): value}


def _nonzero(name, value):
    if value == 0:
        raise M.MetricError(f"quantity {name!r} of the FEM reference is zero: its relative "
                            "error is undefined")
    return value


def model_run(case, mesh_name, mesh, bc, model_name, s, ref):
    """One (mesh, bc, model): its metrics in the linear regime and at the case's load, and
    its fields for figures (the linear regime's; None when that solve failed). A failure of a
    phase is recorded in that phase's ``*_failed`` entry, its metrics are None, and the other
    phases still run."""
    r = {"mesh": mesh_name, "bc": bc, "model": model_name, "nodes": mesh.n_nodes,
         "tets": mesh.n_tets, "failed": None}
    if ref.reaction is not None:
        r["reaction_fem_p2_n"] = ref.reaction
    r.update({ref_name(k): v for k, v in ref.quantities.items()})
    r["p2_error_estimate"] = ref.error_estimate
    r["linear_scale"] = ref.scale
    if ref.nonlinear is not None and not s.static_only:
        r["nh_error_estimate"] = ref.nonlinear.error_estimate
        if ref.nonlinear_reaction is not None:
            r["reaction_fem_nh_n"] = ref.nonlinear_reaction
        r.update({ref_name(k): v for k, v in (ref.quantities_at_load or {}).items()})
    if not s.static_only:
        r.update(case.reference_entries(ref))
    pm = case.build_model(model_name, mesh, s)
    fields = None
    st, finite_failed = None, None
    try:                     # the case's load (not in a static-only run, but where it is all)
        if not s.static_only or ref.scale is None:
            st = case.solve_static(pm, mesh, bc, s, ref)
    except FINDINGS as exc:  # no equilibrium found: a finding
        finite_failed = str(exc)
    blank = {k: None for k in STATIC + tuple(ref.quantities)
             + tuple(err_name(q) for q in case.qoi_errors) + case.quantity_compared}
    try:                     # the linear regime (the case's own solve where it has none)
        if ref.scale is None:    # the case's own solve, done above
            if finite_failed:
                raise M.MetricError(finite_failed)
            lr = None if st is None else LinearRegime.of(st, pm, 1.0)
        else:
            lr = linear_regime(case, pm, mesh, bc, s, ref)
        if lr is None:       # a case without a static problem (modes)
            r.update(blank, static_failed=None)
        else:
            r.update(static_metrics(case, lr, mesh, bc, s, ref), static_failed=None)
            fields = {"mesh": mesh, "u": lr.u, "max_tau": lr.stress["max_tau"],
                      "pressure": lr.stress["pressure"]}
    except FINDINGS as exc:   # no equilibrium found, or a metric undefined: a finding
        r.update(blank, static_failed=str(exc))
    r.update(dict.fromkeys(FINITE))
    if not s.static_only:    # a static-only run has no load phase, whatever its reference has
        r.update(dict.fromkeys(ref.quantities_at_load or ()))
    if (ref.nonlinear is not None or ref.nonlinear_failed) and not s.static_only:
        r["finite_failed"] = finite_failed or ref.nonlinear_failed
        if st is not None and ref.nonlinear is not None:
            try:
                r.update(finite_metrics(case, st, mesh, bc, s, ref))
            except FINDINGS as exc:
                r["finite_failed"] = str(exc)
    nft = None if ref.p2 is None else pm.net_force_torque(mesh.points + ref.p2.u)
    if nft is not None:
        r.update(net_force_rel=M.finite("net_force", nft["force_rel"]),
                 net_torque_rel=M.finite("net_torque", nft["torque_rel"]))
    else:
        r.update(net_force_rel=None, net_torque_rel=None)
    if not s.static_only:
        r.update(case.run_extra(pm, mesh, bc, s, ref, st))
    r["model_info"] = jsonable(pm.info)
    return r, fields


class FailedRun(dict):
    """The row of a run that could not start: a metric it lacks reads None, and a phase's
    ``*_failed`` entry the reason it could not start (so that every phase reads as failed)."""

    def __missing__(self, key):
        return self["failed"] if key.endswith("_failed") else None


def failed_runs(mesh_name, bc, models, phase, exc, mesh=None):
    """The rows of runs that could not start: the reason in ``failed``, the mesh's size where
    it was built, every metric absent."""
    size = {} if mesh is None else {"nodes": mesh.n_nodes, "tets": mesh.n_tets}
    return [FailedRun(mesh=mesh_name, bc=bc, model=m, **size, failed=f"{phase}: {exc}")
            for m in models]


def what(case, s, mesh_name, bc, static_only=None):
    """What determines the results of one (mesh, bc) of ``case`` beside the model: the case,
    mesh, bc and every setting but the selection (the run store's key, ``cases.running.store``)."""
    d = {k: v for k, v in s.describe().items() if k not in ("meshes", "bcs", "models")}
    return {"case": case.name, "mesh": mesh_name, "bc": bc, **d,
            "static_only": s.static_only if static_only is None else static_only}


def _stored(store, kind, case, s, mesh_name, bc, reuse_full, **more):
    """A stored entry of this (mesh, bc), or None; ``reuse_full``: a static-only request
    accepts the entry of a full run (a superset of it)."""
    found = store.get(key(kind=kind, **what(case, s, mesh_name, bc), **more))
    if found is None and reuse_full and s.static_only:
        found = store.get(key(kind=kind, **what(case, s, mesh_name, bc, False), **more))
    return found


def unit(case, s, mesh_name, bc, mesh_of=None, step=None, store=OFF, reuse_full=False):
    """The runs and figure fields of one (mesh, bc): its references, then every model.
    ``mesh_of(name)`` builds (or recalls) the mesh; ``step(text, done)`` reports progress
    (``done`` items of the case's total finished since the last call). The references and
    each model's run are taken from ``store`` (a ``cases.running.store.RunStore``) where it has them,
    and kept there when computed."""
    step = step or (lambda text, done: None)
    mesh_of = mesh_of or (lambda name: case.mesh(name, s))
    base = what(case, s, mesh_name, bc)
    stored = {m: _stored(store, "run", case, s, mesh_name, bc, reuse_full, model=m)
              for m in s.models}
    ref_fields = _stored(store, "reference-fields", case, s, mesh_name, bc, reuse_full)
    if ref_fields is not None and all(v is not None for v in stored.values()):
        step(f"{case.name} {mesh_name}/{bc}: stored", len(s.models) + 1)
        return _assemble(mesh_name, bc, s.models, stored, ref_fields)
    computed = _compute(case, s, mesh_name, bc, mesh_of, step,
                        [m for m in s.models if stored[m] is None],
                        _ReferenceStore(store, case, s, mesh_name, bc, reuse_full))
    for m, value in computed["runs"].items():
        stored[m] = store.put(key(kind="run", **base, model=m), value)
    ref_fields = store.put(key(kind="reference-fields", **base), computed["ref_fields"])
    return _assemble(mesh_name, bc, s.models, stored, ref_fields)


def _assemble(mesh_name, bc, models, stored, ref_fields):
    runs, fields = [], {}
    if ref_fields:
        fields[(mesh_name, bc, "fem-p2")] = ref_fields
    for m in models:
        r, f = stored[m]
        runs.append(r)
        if f is not None:
            fields[(mesh_name, bc, m)] = f
    return runs, fields


class _ReferenceStore:
    """The FEM references of one (mesh, bc) in the run store, so that a run of more models
    (the extensions study's candidates) does not solve them again: kept without the bases
    (``at()`` is the convergence study's, never a case's), taken from a full run's entry
    when only the static problem is asked."""

    def __init__(self, store, case, s, mesh_name, bc, reuse_full):
        self.args = (store, "reference", case, s, mesh_name, bc, reuse_full)
        self.key = key(kind="reference", **what(case, s, mesh_name, bc))

    def get(self):
        return _stored(*self.args)

    def put(self, ref):
        lean = [_without_basis(r) for r in (ref.p1, ref.p2)]
        conv = None if ref.conv is None else dataclasses.replace(ref.conv, result=lean[1])
        self.args[0].put(self.key, dataclasses.replace(ref, p1=lean[0], p2=lean[1], conv=conv))
        return ref


def _without_basis(result):
    """A FEM result without its basis and dof vector (the refined P2 basis is most of its
    size and only ``at()`` reads it)."""
    if not dataclasses.is_dataclass(result):
        return result
    heavy = {f.name for f in dataclasses.fields(result)} & {"basis", "dofs"}
    return dataclasses.replace(result, **dict.fromkeys(heavy))


def _compute(case, s, mesh_name, bc, mesh_of, step, models, refs=None):
    """The references of one (mesh, bc) and the runs of ``models`` on it: {"runs": {model:
    (run, fields or None)}, "ref_fields": the FEM P2 fields or {}}. ``refs`` (a
    ``_ReferenceStore``) gives the references where kept and keeps those solved."""
    out = {"runs": {}, "ref_fields": {}}
    try:
        mesh = mesh_of(mesh_name)
    except FINDINGS as exc:
        step(f"{case.name} {mesh_name}/{bc}: mesh failed", len(s.models) + 1)
        out["runs"] = {r["model"]: (r, None)
                       for r in failed_runs(mesh_name, bc, models, "mesh", exc)}
        return out
    probe = Shear(mesh, s.material, reading="corner")  # the paper's max |tau| measure
    step(f"{case.name} {mesh_name}/{bc}: FEM references", 0)
    try:
        ref = refs.get() if refs is not None else None
        if ref is None:
            ref = (case.solve_reference(mesh, bc, s, probe)
                   or reference(case, mesh, bc, s, probe, extra=not s.static_only))
            if refs is not None:
                refs.put(ref)
    except FINDINGS as exc:
        step(f"{case.name} {mesh_name}/{bc}: references failed", len(s.models) + 1)
        out["runs"] = {r["model"]: (r, None)
                       for r in failed_runs(mesh_name, bc, models, "reference", exc, mesh)}
        return out
    if ref.p2 is not None:
        out["ref_fields"] = {"mesh": mesh, "u": ref.p2.u, "max_tau": ref.tau,
                             "pressure": ref.p2.pressure, **ref.extra}
    step(f"{case.name} {mesh_name}/{bc}", 1 + len(s.models) - len(models))
    for model_name in models:
        stop.checkpoint()
        step(f"{case.name} {mesh_name}/{bc}/{model_name}", 0)
        try:
            r, f = model_run(case, mesh_name, mesh, bc, model_name, s, ref)
        except FINDINGS as exc:   # the model cannot be built on this mesh (calibration)
            [r], f = failed_runs(mesh_name, bc, [model_name], "model", exc, mesh), None
        out["runs"][model_name] = (r, f)
        step(f"{case.name} {mesh_name}/{bc}/{model_name}", 1)
    return out


def _mesh_in_worker(job):
    """Every bc of one mesh, in one worker: the bcs share the mesh and the FEM stiffness
    matrices (reference.assembly keeps the last ones assembled), which a (mesh, bc) per worker
    would assemble twice."""
    case, s, mesh_name, store, reuse_full = job
    mesh_of = _built_once(case, s, warn=False)      # the parent said them
    with one_blas_thread():
        return mesh_name, [unit(case, s, mesh_name, bc, mesh_of,
                                lambda text, done: tick(mesh_name, text, done), store=store,
                                reuse_full=reuse_full) for bc in s.bcs]


def _built_once(case, s, warn=True):
    """``mesh_of(name)``: the case's mesh ``name``, built on first use and then recalled, so
    that its bcs share one mesh; ``warn``: print its quality warnings (once, in the process
    that gives the units out, before any is computed)."""
    meshes = {}

    def mesh_of(name):
        if name not in meshes:
            meshes[name] = case.mesh(name, s)
            for line in meshes[name].warnings() if warn else ():
                print(f"pbcm: warning: {case.name} mesh {name}: {line}", file=sys.stderr)
        return meshes[name]
    return mesh_of


def run(case, s, log=True, workers=None, store=OFF, reuse_full=False):
    """Run every (mesh, bc, model) of ``case`` with settings ``s``; return the runs (metrics)
    and the fields for the figures ({(mesh, bc, model or 'fem-p2'): arrays}). The (mesh, bc)
    units run in this process, or on ``workers`` (a started ``cases.running.workers.Workers``), one
    mesh with all its bcs per task; the results are the same either way and come in the
    declared order. ``store`` (a ``cases.running.store.RunStore``) gives what it has and keeps what
    is computed; ``reuse_full``: a static-only run takes a full run's stored rows."""
    units = [(mesh_name, bc) for mesh_name in s.meshes for bc in s.bcs]
    per_unit = len(s.models) + 1
    results = [None] * len(units)
    with Progress(case.name, len(units) * per_unit, log=log, width=56) as bar:
        if workers is None or len(s.meshes) < 2:
            mesh_of = _built_once(case, s)
            with one_blas_thread():
                for i, (mesh_name, bc) in enumerate(units):
                    stop.checkpoint()
                    results[i] = unit(case, s, mesh_name, bc, mesh_of,
                                      lambda text, done: bar.advance(done, text), store,
                                      reuse_full)
        else:
            bar.advance(0, f"{case.name}: {len(s.meshes)} meshes on {workers.n} workers")
            # the largest mesh first, so that it does not start last and run alone
            mesh_of = _built_once(case, s)
            order = sorted(s.meshes, key=lambda name: -mesh_of(name).n_tets)
            jobs = [(case, s, mesh_name, store, reuse_full) for mesh_name in order]
            ticked, finished = {}, set()

            def running(mesh_name, text, done):   # a model run finished inside a unit
                if mesh_name not in finished:      # a late report is counted at the end
                    ticked[mesh_name] = ticked.get(mesh_name, 0) + done
                    bar.advance(done, text)
            for mesh_name, done in workers.unordered(_mesh_in_worker, jobs, running):
                stop.checkpoint()
                finished.add(mesh_name)
                for bc, result in zip(s.bcs, done):
                    results[units.index((mesh_name, bc))] = result
                bar.advance(per_unit * len(s.bcs) - ticked.get(mesh_name, 0),
                            f"{case.name} {mesh_name}: done")
        bar.advance(0, f"{case.name}: done")
    runs, fields = [], {}
    for r, f in results:
        runs += r
        fields.update(f)
    return runs, fields


def jsonable(d):
    """Plain Python numbers and lists for json (numpy scalars and arrays converted)."""
    if isinstance(d, dict):
        return {k: jsonable(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [jsonable(v) for v in d]
    if isinstance(d, np.ndarray):
        return jsonable(d.tolist())
    if isinstance(d, (np.floating, np.integer, np.bool_)):
        return d.item()
    return d


__all__ = ["run", "unit", "reference", "model_run", "uniform", "jsonable"]
