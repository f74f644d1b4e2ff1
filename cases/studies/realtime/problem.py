"""The real-time study on a user's problem (`pbcm run realtime --problem FILE.toml`): the
problem's mesh refined uniformly up to at least 1e5 tetrahedra
(``cases.library.problem.family``), each model timed there as the bench times the cube's
family (``cases.tools.realtime_bench``: wall clock per simulated second, the prescribed
displacements ramped over RAMP_S, the tractions and gravity constant), and its static
equilibrium under the whole load against FEM P1 on the same tetrahedra and against the
converged continuum (neo-Hookean P2 on the problem's mesh, refined).

The timings are measured by the command (``cases.cli.run``), which keeps them in the run
store under the problem's digests and this machine's name, so that a rerun draws the same
report from the same timings (``--no-cache`` times again)."""
from dataclasses import dataclass

import numpy as np

from model.presets import PRESETS
from reference import hyperelastic
from ...library.problem.case import BC
from ...library.problem.family import MIN_TETS, family
from ...reporting import costs as bench_costs
from .study import P1, QUICK_REF_LEVELS, RealtimeSettings, force_along

RAMP_S = 1.0            # the prescribed displacements reach their values over this time [s]


class ProblemLoading:
    """A problem's loading over its refinement family, with the methods of the cube's
    (``study.CubePush``); the family is built once, on first use."""

    bc = BC
    # the levels step by eight: a size above every reach would cost the most to solve and
    # decide nothing
    above_reach = False

    def __init__(self, spec, quick=False):
        self.spec, self.quick = spec, quick
        self._family = None
        force = next((m for m in spec.measures if m.kind == "reaction"), None)
        where = next((n for n, sel in spec.selections.items() if force is not None
                      and np.array_equal(sel.nodes, force.nodes)), "its nodes")
        sums = (f"the reaction along {'xyz'[force.axis]} on {where}" if force
                else "no reaction measured")
        loads = [w for w, on in (("its tractions", spec.surfaces), ("gravity", spec.gravity))
                 if on]
        held = f"its prescribed displacements ramped over {RAMP_S:g} s"
        self.words = {
            "loading": f"the loads of {spec.path.name} on {spec.mesh_file.name} refined",
            "load": "the problem's loading", "field": "the displacement field",
            "loads_detail": (f"the loads of {spec.path.name} ({held}"
                             + (f", {' and '.join(loads)} constant" if loads else "")
                             + f") on {spec.mesh_file.name} refined uniformly, each "
                             "tetrahedron into eight; every model judged at the whole load "
                             "against the neo-Hookean continuum, as every verdict at a finite "
                             "load is (the problem's own case report judges its linear "
                             "regime)"),
            "question": f"The question a simulator builder asks of the problem {spec.name}",
            "inputs": "not measured here",
            "timer": "this run", "timing": "the timing", "glossary": "glossary.md",
            "stopped": "at a smaller level, or failed there",
            "solved": "; a law is solved up to the largest level at which a model with it "
                      "was real time in some round (the smallest timed where none was)",
            "stops": "its first level over real time (the next has eight times its "
                     "tetrahedra: its cost cannot come back under real time)",
            "blowup": "one is recorded as the model's failure at that size, and the model is "
                      "not timed further up",
            "quick": f"the full run refines the mesh up to at least {MIN_TETS:_} "
                     "tetrahedra".replace("_", " "),
            "family": f"the refinement family of {spec.mesh_file.name}",
            "force": force.name if force else "force",
            "force_detail": f"{force.name if force else 'force'} ({sums})", "force_is": sums,
            "force_why": "where displacements are prescribed, a law's stiffness shows in the "
                         "force more than in the field",
            "figure": spec.name}

    @property
    def levels(self):
        if self._family is None:
            self._family = family(self.spec, quick=self.quick)
        return self._family

    def _level(self, tets):
        return next(lv for lv in self.levels if lv.mesh.n_tets == tets)

    def sizes(self, quick):
        return [lv.mesh.n_tets for lv in self.levels]

    def mesh(self, tets):
        return self._level(tets).mesh

    def label(self, tets):
        lv = self._level(tets)
        return f"{self.spec.mesh_file.stem}-L{lv.level}"

    def dirichlet(self, mesh):
        return self._level(mesh.n_tets).dirichlet

    def f_ext(self, mesh):
        return self._level(mesh.n_tets).f_ext

    def force_where(self, mesh):
        return self._level(mesh.n_tets).reaction

    def reference(self, s):
        """The continuum (neo-Hookean P2 on the problem's mesh refined ``s.ref_levels``
        times, mixed above the suite's Poisson threshold) under the whole load."""
        base = self.levels[0]
        loads = base.loads
        kw = {"traction": loads.fem_traction(1e-9 * base.mesh.size),
              "body_force": None if loads.body_force is None else np.asarray(loads.body_force)}
        kw = {k: v for k, v in kw.items() if v is not None}
        return hyperelastic.converged(base.mesh, s.material, base.dirichlet,
                                      levels=s.ref_levels, mixed="auto", **kw)

    def reference_force(self, result):
        return force_along(result.reaction, self.levels[0].reaction)

    def __getstate__(self):
        """Pickled without its family (a worker is given its meshes with its jobs)."""
        return {**self.__dict__, "_family": None}


@dataclass
class ProblemRealtimeSettings(RealtimeSettings):
    """The real-time study of one problem: its material, models and references from the
    TOML (``spec``, a checked Spec), and the mode."""

    spec: object = None
    models: tuple = ()

    def __post_init__(self):
        super().__post_init__()
        self.loading = ProblemLoading(self.spec, self.quick)

    @classmethod
    def of(cls, spec, quick=False, models=None):
        """The settings of ``spec``; ``models`` default the TOML's (where it names none, the
        bench's real-time family: every preset and Newton's solvers where installed), FEM P1
        with the continuum's law always among them (the yardstick every bound is made of)."""
        models = models or spec.models
        if set(models) == set(PRESETS):
            models = bench_costs.family_models(quick)
        models = tuple(dict.fromkeys(tuple(models) + (P1,)))     # the yardstick, ranked too
        m = spec.material
        return cls(E=m.E, nu=m.nu, rho=m.rho, quick=quick, spec=spec, models=tuple(models))

    @property
    def case_name(self):
        """The name its metrics.json records (the owner of its folder): NAME.realtime."""
        return f"{self.spec.name}.realtime"

    @property
    def ref_levels(self):
        return QUICK_REF_LEVELS if self.quick else self.spec.nh_levels

    @property
    def units(self):
        return len(self.loading.sizes(self.quick)) * len(self.models)

    def problem(self):
        spec = self.spec
        return {**self.material_record(), **spec.digests, "problem": spec.name,
                "ramp_s": RAMP_S, "bc": BC,
                "reference": {"element": "P2", "mesh": spec.mesh_file.name,
                              "refinements": self.ref_levels}}

    def describe(self):
        return {**self.problem(), "quick": self.quick, "models": list(self.models),
                "meshes": {self.loading.label(t): t for t in self.loading.sizes(self.quick)}}
