"""The case contract: what a case declares, and what the shared runner (``cases.running.runner``) does
with it.

A case is a module that declares one :class:`Case` subclass: its geometry and mesh family,
boundary conditions and loads, quantities of interest, closed form, quick and full settings and
any case-specific metric, finding or figure. It does not loop, solve the FEM references, compute
the standard metrics, write files or gate: the runner, ``cases.reporting.report`` and ``cases.running.gate``
do that for every case alike. Millimetres stop at the case module's edge: everything a case
hands the runner is in SI units, except the quantities it names ``*_mm`` for its report.
"""
import abc
import importlib
from dataclasses import dataclass, field, fields
from typing import ClassVar

import numpy as np

from model.units import MM  # noqa: F401 (the cases' millimetre)
from model import PRESETS, Material, PbcmError, build
from model.errors import ConvergenceError, ModelError
from model import static
from model.compose import parse, simulator
from model.mesh import SCHEMES
from model.loads import body_forces, traction_forces
from .measuring import catalogue
from .measuring.error_model import at_load

# ``Case.decomposed_at_load``'s default: the case's ``decomposed`` quantity at its load
AT_LOAD = "the decomposed quantity at the load"

# what a run may fail with and still be a finding: the suite's own errors and numerical ones
FINDINGS = (PbcmError, ArithmeticError, np.linalg.LinAlgError)

MESH_FAMILIES = SCHEMES          # five, six, bcc, unstructured
# the linear regime: the case's loads scaled so that the largest strain of the converged linear
# reference (its tetrahedron averages) is this; every model then answers as its linearisation
LINEAR_STRAIN = 1e-4


def scaled(dirichlet, k):
    """Prescribed displacements ``dirichlet`` ({node: (ux, uy, uz)}, None free) times ``k``."""
    return {i: tuple(None if v is None else v * k for v in u) for i, u in dirichlet.items()}


# the material every case and study runs by default (the paper cube's), and its record in a
# metrics document: one place for both
DEFAULT_E, DEFAULT_NU = 10e3, 0.45
DEFAULT_RHO = next(f.default for f in fields(Material) if f.name == "rho")   # the model's
DEFAULT_MATERIAL = Material(DEFAULT_E, DEFAULT_NU, DEFAULT_RHO)   # the paper cube's


# each material field and its key in a metrics document (SI, the unit in the key)
MATERIAL_KEYS = {"E": "E_Pa", "nu": "nu", "rho": "rho_kg_m3"}


def material_record(E, nu, rho=None):
    """The material as a metrics document records it (SI, units in the keys); without the
    density where it is None (a static problem, where it plays no part)."""
    got = {"E": E, "nu": nu, "rho": rho}
    return {k: got[f] for f, k in MATERIAL_KEYS.items() if got[f] is not None}


@dataclass
class MaterialSettings:
    """The material a case or study runs: E [Pa], nu, rho [kg/m^3] as the command line gives
    them (defaults the paper cube's), and the one ``Material`` made from them, checked there,
    that the models and every reference take."""

    E: float = DEFAULT_E
    nu: float = DEFAULT_NU
    rho: float = DEFAULT_RHO
    material: Material = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        self.material = Material(E=self.E, nu=self.nu, rho=self.rho)

    def material_record(self, static=False):
        """The material as a metrics document records it (``static``: without the density,
        which a static problem does not use)."""
        return material_record(self.E, self.nu, None if static else self.rho)


@dataclass
class Settings(MaterialSettings):
    """What one run of a case does: the material (``MaterialSettings``), the selection
    (meshes, boundary conditions, models) and the resolution of the references. A case
    subclasses it to add its own fields (geometry, load, steps) and names them in
    ``problem()``."""

    meshes: tuple = ()
    bcs: tuple = ()
    models: tuple = ()
    p2_levels: int = 1          # refinements of the converged P2 reference
    nh_levels: int = 1          # refinements of the converged neo-Hookean reference
    quick: bool = False
    shear_scale: float = 1.0    # for tests, in the API only: scales every shear term (1 = the model)
    # True: the linear regime's static metrics and quantities only; the case load's
    # neo-Hookean reference and the case's extra reference work and metrics (reference_extra,
    # reference_entries, run_extra: dynamics, modes) are skipped
    static_only: bool = False

    def problem(self):
        """The parameters that define the problem the metrics answer (what a bound was
        measured at). Subclasses add their geometry and loads."""
        return {**self.material_record(),
                "p2_levels": self.p2_levels, **regimes(self)}

    @property
    def units(self):
        """The independent units a worker pool can share out: the meshes (a worker runs one
        mesh with all its bcs)."""
        return len(self.meshes)

    def describe(self):
        """Everything the run was given: the problem, the selection and the switches."""
        return {**self.problem(), "meshes": list(self.meshes), "bcs": list(self.bcs),
                "models": list(self.models), "quick": self.quick,
                "shear_scale": self.shear_scale}


# Newton from rest may stagnate where a split load converges: a solver's limit, not the
# model's, so a static solve fails only when every split does
LOAD_SPLITS = (1, 2, 4, 8)
# a load step whose residual this many Newton iterations in a row have not halved is split
# more finely (a study passes it as solve_split's stall; a converging Newton step halves it in
# one or two, and on a large mesh each iteration factorises a Newton matrix)
STALL = 10


def solve_split(pm, dirichlet, f_ext=None, splits=LOAD_SPLITS, upright=False, **kw):
    """``(static result, load steps)``: the model's equilibrium under ``dirichlet`` (and
    ``f_ext``), in the fewest of ``splits`` equal steps that converges; the last split's
    error where none does. With ``upright`` an equilibrium with an inverted tetrahedron (a
    spring lattice's folded branch, which a Newton solve in one large step can land on)
    counts as not converged, so that the next split is tried."""
    from model.geometry import signed_volumes
    extra = {} if f_ext is None else {"f_ext": f_ext}
    if not getattr(pm, "splits_load", True):      # a simulator run to rest: more load steps change nothing
        splits = splits[:1]
    for steps in splits:
        try:
            st = pm.solve_static(dirichlet, load_steps=steps, **extra, **kw)
            if upright:
                folded = int(np.sum(signed_volumes(pm.mesh.points + st.u, pm.mesh.tets) <= 0))
                if folded:
                    raise ConvergenceError(
                        f"an equilibrium with {folded} of {pm.mesh.n_tets} tetrahedra "
                        f"inverted in {steps} load steps")
            return st, steps
        except ConvergenceError:
            if steps == splits[-1]:
                raise


def linear_scale(p2, material):
    """The factor that brings the loads of the linear result ``p2`` down to the linear
    regime: its largest tetrahedron-average principal strain to LINEAR_STRAIN (1 where it is
    already below)."""
    E, nu = material.E, material.nu
    sig = p2.stress
    eps = ((1 + nu) * sig - nu * np.trace(sig, axis1=1, axis2=2)[:, None, None] * np.eye(3)) / E
    largest = float(np.abs(np.linalg.eigvalsh(eps)).max())
    if not np.isfinite(largest) or largest == 0:
        raise ModelError("the linear reference has no strain: the case's loads are zero "
                            "or not finite")
    return min(1.0, LINEAR_STRAIN / largest)


def regimes(s):
    """The problem's entries that say how the two regimes are posed (what a gold file's
    bounds were measured at)."""
    return {"linear_strain": LINEAR_STRAIN, "nh_levels": s.nh_levels}


@dataclass(frozen=True)
class Traction:
    """A uniform traction ``value`` [Pa] (3,) on the boundary facets lying in the plane
    x_axis = ``at`` [m]."""

    axis: int
    at: float
    value: tuple


@dataclass(frozen=True)
class Loads:
    """The loads of a case: tractions and a constant body force [N/m^3]. The FEM references
    integrate them exactly; the particle model receives them as consistent nodal forces
    (``nodal_forces``)."""

    tractions: tuple = ()
    body_force: tuple = None

    def nodal_forces(self, mesh):
        """Consistent nodal forces (n, 3) [N] of these loads on ``mesh`` (P1 shape functions),
        or None when there is no load."""
        if not self.tractions and self.body_force is None:
            return None
        f = np.zeros_like(mesh.points)
        for t in self.tractions:
            f += traction_forces(mesh, t.axis, t.at, t.value)
        if self.body_force is not None:
            f += body_forces(mesh, self.body_force)
        return f

    def scaled(self, k):
        """These loads times ``k``."""
        return Loads(tractions=tuple(Traction(t.axis, t.at, tuple(v * k for v in t.value))
                                     for t in self.tractions),
                     body_force=None if self.body_force is None
                     else tuple(v * k for v in self.body_force))

    def fem_traction(self, tol):
        """The tractions as the callable ``(points, normals) -> (..., 3)`` that
        ``reference.linear.solve`` takes (None without tractions)."""
        if not self.tractions:
            return None
        tractions = self.tractions

        def traction(points, normals):
            out = np.zeros_like(points)
            for t in tractions:
                on = np.abs(points[..., t.axis] - t.at) <= tol
                out += np.where(on[..., None], np.asarray(t.value, float), 0.0)
            return out
        return traction


@dataclass(frozen=True)
class Knob:
    """A case setting a sweep may turn for a generic axis (``resolution``, ``load``): the
    Settings field ``field`` and the label of its values (with their unit)."""

    field: str
    label: str


@dataclass
class Reference:
    """The FEM side of one (mesh, bc), as the runner computes it by default.

    The linear regime: linear P1 on the mesh and converged linear P2 (``conv``, its finest
    solution ``p2``) under ``dirichlet_linear`` and the loads at the case's size (linear, so
    any size gives the same relative errors), the paper's max |tau| of the P2 displacement
    (``tau``), the reaction on the driven nodes, the case's quantities of interest of the P2
    solution; ``scale`` the factor that brings the loads down to LINEAR_STRAIN, at which
    each model is solved (None: the case has no linear regime, its metrics come from its
    own solve). The case's load: the converged neo-Hookean reference under ``dirichlet``
    (``nonlinear``, its reaction ``nonlinear_reaction``; None with ``nonlinear_failed`` the
    reason when it has none). Anything the case adds is in ``extra``."""

    dirichlet: dict
    f_ext: np.ndarray
    p1: object
    conv: object
    p2: object
    tau: np.ndarray
    reaction: float
    quantities: dict
    error_estimate: float
    extra: dict = field(default_factory=dict)
    dirichlet_linear: dict = None
    scale: float = None
    nonlinear: object = None
    nonlinear_reaction: float = None
    nonlinear_failed: str = None
    quantities_at_load: dict = None   # the quantities of interest of ``nonlinear`` at the load
    nonlinear_p1: object = None       # FEM P1 with the neo-Hookean law on the mesh: the twin


class Case(abc.ABC):
    """A case, declared. Subclasses set the class attributes and implement ``mesh`` and
    ``dirichlet``; every other hook has a default that fits a static linear problem.

    Attributes
    ----------
    name : the name on the command line and the folder under reports/.
    title : one line for the report and ``pbcm list``.
    settings_class : the Settings subclass with the case's own fields.
    meshes, quick_meshes : mesh families run in full and in quick mode.
    bcs, quick_bcs : boundary-condition names (quick_bcs None: all of them in quick mode).
    models : model presets (default every preset).
    quick : settings that ``--quick`` changes (e.g. ``{"p2_levels": 1}``).
    headline : the metric (a catalogue name) that sums the case up in the scorecard: an
        error, smaller is better, per run.
    headline_pair : the metric shown beside it, so that a scalar cannot hide a wrong field
        nor a field a wrong stiffness: the reaction error of a displacement-driven case, the
        displacement error of a force-driven one (None: nothing to pair).
    headline_estimate : the run key of the error estimate of the headline's reference (the
        floor of its entries in the index's geometric mean).
    patch_tests : the boundary conditions whose problem is a patch test (a field every
        consistent discretisation reproduces exactly): reported pass or fail, never pooled.
    per_mesh_continuum : the boundary conditions where each mesh poses its own continuum
        problem (a closed form read at the mesh's nodes, a load on the mesh's own nodes): the
        continuum values' spread over the meshes is then no numerical uncertainty, and u_num
        is the reference's estimate alone.
    locking_prone : the boundary conditions where FEM P1, the model-form twin, locks (constant-
        strain tetrahedra near incompressibility): its model-form error ranks closeness to a
        locked mesh, so the population is shown and said, never pooled in the overall ranking.
    decomposed : what the error model (``cases.measuring.error_model``) splits into model-form error
        (against FEM P1 with the same law on the same tetrahedra) and discretisation error
        (FEM P1 against the continuum): a ``Scalar`` quantity or a ``Norm``; None: the case
        has no continuum reference to decompose against.
    decomposed_at_load : the same at the case's load, against FEM P1 with the reference's
        neo-Hookean law (default ``AT_LOAD``: the quantity ``decomposed`` itself, measured on
        the finite-strain solve, ``error_model.at_load``, so that both regimes rank one
        quantity; None where ``decomposed`` is already at the load or the case has none).
    gated : case metrics the CI gate bounds beside the standard ones (catalogue names; the
        catalogue gives their direction).
    columns : case metrics shown in the per-(mesh, bc) table after the standard ones
        (catalogue names: the catalogue gives header, unit and digits; ``cell`` the text).
    qoi_errors : scalar quantities of interest that get ``<name>_rel_err`` = |model / FEM - 1|.
    quantity_compared : the metrics ``quantity_metrics`` computes from the model's and the
        reference's quantities (None where the linear regime failed).
    narrative : the case's report prose, a :class:`Narrative` subclass or its "module:Class"
        (imported on first use, so that the prose may import the case's constants); None:
        the default narrative, which says what every case's report says.
    fem_solver : the linear FEM solver ("auto", "direct", "amg").
    static : whether the case has a static displacement problem (what ``pbcm fit`` fits).
    resolution, load : the Settings fields a sweep's ``resolution`` and ``load`` axes turn
        (a Knob each), or None where the case has none.
    """

    name: ClassVar[str]
    title: ClassVar[str]
    settings_class: ClassVar[type] = Settings
    meshes: ClassVar[tuple] = MESH_FAMILIES
    quick_meshes: ClassVar[tuple] = ("five",)
    bcs: ClassVar[tuple] = ("clamped",)
    quick_bcs: ClassVar[tuple] = None
    models: ClassVar[tuple] = tuple(PRESETS)
    quick: ClassVar[dict] = {}
    headline: ClassVar[str] = "disp_rel_l2_p2"
    headline_pair: ClassVar[str] = None
    headline_estimate: ClassVar[str] = "p2_error_estimate"
    patch_tests: ClassVar[tuple] = ()
    per_mesh_continuum: ClassVar[tuple] = ()
    locking_prone: ClassVar[tuple] = ()
    decomposed: ClassVar[object] = None
    decomposed_at_load: ClassVar[object] = AT_LOAD
    gated: ClassVar[tuple] = ()
    columns: ClassVar[tuple] = ()
    qoi_errors: ClassVar[tuple] = ()
    quantity_compared: ClassVar[tuple] = ()   # the names quantity_metrics returns
    narrative: ClassVar[object] = None   # its Narrative subclass, or "module:Class"
    fem_solver: ClassVar[str] = "auto"    # the linear FEM solver (reference.solvers.linear_solve)
    static: ClassVar[bool] = True          # False: no static displacement (modes)
    resolution: ClassVar[Knob] = None      # what a sweep's resolution axis turns
    load: ClassVar[Knob] = None            # what a sweep's load axis turns

    def __init_subclass__(cls, **kw):
        """A declaration error shows when the case is imported, not in its report."""
        super().__init_subclass__(**kw)
        for attr in ("gated", "columns", "qoi_errors", "quantity_compared", "patch_tests"):
            if not isinstance(getattr(cls, attr), tuple):
                raise TypeError(f"{cls.__name__}.{attr} must be a tuple (a one-element tuple "
                                "needs its trailing comma)")
        for name in (cls.headline, *cls.gated, *cls.columns, *cls.quantity_compared,
                     *([cls.headline_pair] if cls.headline_pair else [])):
            catalogue.metric(name)      # a KeyError naming where to declare it
        catalogue.gated(*cls.gated)     # a gated metric needs a direction, before any run

    @classmethod
    def decompositions(cls):
        """The quantities the error model decomposes for this case (linear regime, load)."""
        at = cls.decomposed_at_load
        if at == AT_LOAD:
            at = at_load(cls.decomposed)
        return tuple(q for q in (cls.decomposed, at) if q is not None)

    # ------------------------------------------------------------------ settings
    def settings(self, quick=False, **kw):
        """The case's Settings: full by default, with ``quick`` overrides, then ``kw``
        (None values ignored: what the user did not give)."""
        kw = {k: v for k, v in kw.items() if v is not None}
        base = {"meshes": self.quick_meshes if quick else self.meshes,
                "bcs": (self.quick_bcs or self.bcs) if quick else self.bcs,
                "models": self.models, **(self.quick if quick else {}), "quick": quick}
        names = {f.name for f in fields(self.settings_class) if f.init}
        return self.settings_class(**{k: v for k, v in {**base, **kw}.items() if k in names})

    # ------------------------------------------------------------------ declaration
    @abc.abstractmethod
    def mesh(self, family, s):
        """The TetMesh of mesh family ``family`` (SI units)."""

    @abc.abstractmethod
    def dirichlet(self, mesh, bc, s):
        """The prescribed displacements of boundary condition ``bc``: {node: (ux, uy, uz)}."""

    def dirichlet_linear(self, mesh, bc, s):
        """The prescribed displacements the linear regime scales down (loads small enough
        that strains stay below 1e-4): the case's own by default; a case that prescribes a
        finite rotation gives its linearisation (a scaled finite rotation is not a small
        rotation: it keeps the radial contraction 1 - cos(angle) in proportion)."""
        return self.dirichlet(mesh, bc, s)

    def dirichlet_fn(self, mesh, bc, s):
        """The prescribed displacement at new boundary points of refined and P2 meshes,
        ``points (k, 3) -> (k, 3)`` (see ``reference.linear.solve``); None: linear
        interpolation of the nodal values."""
        return None

    def loads(self, mesh, bc, s):
        """The case's loads (default none)."""
        return Loads()

    def finite_steps(self, s):
        """Load steps of the neo-Hookean reference at the case's load (default 1)."""
        return 1

    def driven(self, mesh, bc, s):
        """(nodes, axis) whose summed reaction along ``axis`` is the case's force (the
        ``reaction_*`` metrics), or None for a load-controlled case."""
        return None

    def quantities(self, mesh, u, reaction, s, bc):
        """Quantities of interest of a displacement ``u`` (n, 3) and reaction (n, 3), computed
        alike for the model and the FEM reference; names ending in _mm are in millimetres."""
        return {}

    def quantity_metrics(self, q, ref_q, bc):
        """The metrics ``quantity_compared`` of the model's quantities ``q`` against the
        reference's ``ref_q``, beyond the relative errors of ``qoi_errors`` (a profile's
        shape, say)."""
        return {}

    def closed_form(self, s, bc):
        """Closed-form values of quantities of interest (same names), where one exists."""
        return {}

    def params(self, s):
        """The case's parameters for metrics.json ``params`` (default: the problem)."""
        return s.problem()

    # ------------------------------------------------------------------ phases
    def build_model(self, name, mesh, s):
        """The particle model ``name`` (a preset or a composed spec, ``model.compose``), with
        the test-only shear scale."""
        has_shear = not simulator(name) and any(t == "shear" for t, _ in parse(name))
        extra = {"shear": {"scale": s.shear_scale}} if has_shear and s.shear_scale != 1 else {}
        return build(name, mesh, s.material, **extra)

    def solve_reference(self, mesh, bc, s, probe):
        """A Reference of the case's own making (e.g. neo-Hookean), or None for the default:
        linear P1 on the mesh and converged P2 with the case's loads. ``probe`` is the
        paper's max |tau| measure on this mesh (a corner-reading Shear term)."""
        return None

    def reference_extra(self, mesh, bc, s, ref):
        """Case-specific reference work (a transient, modes), stored in ``ref.extra``."""
        return {}

    def reference_entries(self, ref):
        """Entries of the reference copied into every run of its (mesh, bc)."""
        return {}

    def solve_static(self, pm, mesh, bc, s, ref):
        """The model's static solution at the case's load (default Newton with the loads, in
        the fewest of LOAD_SPLITS equal steps that converges); None for a case without a
        static problem."""
        return solve_split(pm, ref.dirichlet, f_ext=ref.f_ext)[0]

    def solve_linear(self, pm, mesh, bc, s, ref):
        """The model's static solution in the linear regime: ``dirichlet_linear`` and the
        loads times ``ref.scale``, the solver's force tolerance scaled alike (so that the
        regime's relative accuracy is the case load's)."""
        k = ref.scale
        return pm.solve_static(scaled(ref.dirichlet_linear, k),
                               f_ext=None if ref.f_ext is None else k * ref.f_ext,
                               rtol=static.RTOL * k)

    def run_extra(self, pm, mesh, bc, s, ref, st):
        """Case-specific metrics of one run; ``st`` is None when the static solve failed."""
        return {}

    def story(self):
        """The case's :class:`Narrative` (``narrative``, or the default one)."""
        told = self.narrative or Narrative
        if isinstance(told, str):
            module, _, name = told.partition(":")
            told = getattr(importlib.import_module(module), name)
        return told(self)

class Narrative:
    """A case's report prose, apart from its physics: the setup notes, what was run, the
    opening lines, the findings, a table cell's text and the case's own sections, each
    computed from the runs. Every hook has a default, so a new case needs no narrative; a
    case that says more names a subclass in ``Case.narrative``. ``self.case`` is the case
    told (its physics: closed form, quantities, declarations).

    Attributes
    ----------
    notes : report lines on how the case is set up; the metrics' definitions come from the
        catalogue.
    draws_stress, magnify : whether the narrative draws its own stress panels; the
        displacement magnification of the standard ones.
    up : the vertical axis ("x", "y" or "z") the report's figures stand on.
    glossary : the glossary's path from the case's report.
    material_from : where the report says the material comes from (the options that change
        it).
    """

    notes: ClassVar[tuple] = ()
    draws_stress: ClassVar[bool] = False
    magnify: ClassVar[float] = 5.0
    up: ClassVar[str] = "y"
    glossary: ClassVar[str] = "../glossary.md"
    material_from: ClassVar[str] = "override with --E, --nu, --rho"

    def __init__(self, case):
        self.case = case

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        if not isinstance(cls.notes, tuple):
            raise TypeError(f"{cls.__name__}.notes must be a tuple (a one-element tuple needs "
                            "its trailing comma)")

    def command(self):
        """The command that runs the case, as its report tells its reader."""
        return f"pbcm run {self.case.name}"

    def notes_for(self, s):
        """The report's notes for settings ``s``: ``notes`` unless the setup notes depend on
        the settings."""
        return self.notes

    def what_was_run(self, s, runs):
        """Report lines saying what the case ran (geometry, loads, references)."""
        return []

    def references_line(self, s):
        """The report's sentence on what the references are (the runner's default ones)."""
        return (f"References: linear FEM P1 on the same mesh, and P2 on {s.p2_levels} uniform "
                "refinement(s) (the continuum's reference, evaluated at the particle nodes) "
                "with its own error estimate, which the reports read it against.")

    def conclusion(self, s, runs):
        """Three lines that open the report, computed from the runs."""
        return []

    def findings(self, s, runs):
        """{group title: [sentences]} computed from the runs."""
        return {}

    def cell(self, metric, run):
        """The table text of ``metric`` (a catalogue Metric) in ``run``; a case overrides it
        where a cell says more than the number (a run that blew up)."""
        return metric.cell(run.get(metric.name))

    def sections(self, doc, s, runs, fields, out):
        """Case-specific sections and figures, written into ``out`` and added to ``doc``."""


class Study(abc.ABC):
    """A study: runs of its own shape (several cases, mesh sizes, derived fits) rather than
    the (mesh, bc, model) runs of a Case; it runs, writes its folder and declares what the
    gate reads. ``pbcm run NAME`` and ``pbcm report`` treat it as they treat a case.

    Attributes
    ----------
    name, title : as for a Case.
    """

    name: ClassVar[str]
    title: ClassVar[str]
    # what the index's mode column says of a run without --quick (a study whose full run is
    # on coarse meshes says so there)
    full_mode: ClassVar[str] = "full"
    # the command line's selections the study honours; `pbcm run NAME` refuses the others
    # (`pbcm report` passes them to the studies that take them)
    selections: ClassVar[tuple] = ("models", "meshes")
    # the keys of its metrics.json that hold its runs (dicts with 'model', 'mesh' and, for a
    # run that gave no number, 'failed'): what the index reads so that no failure is unread
    runs_recorded: ClassVar[tuple] = ()
    # its settings dataclass (``problem()``: what the gate compares; ``describe()``: the
    # parameters metrics.json records), the settings --quick changes, the settings fields a
    # caller may give (None: every one; the material and ``selections`` otherwise), and the
    # metrics.json keys that hold the data its report is drawn from (none: no --rewrite)
    settings_class: ClassVar[type] = None
    quick: ClassVar[dict] = {}
    takes: ClassVar[tuple] = None
    recorded_keys: ClassVar[tuple] = ()
    # lists of records kept beside metrics.json, each as KEY.json (too large to sit in it)
    record_files: ClassVar[tuple] = ()

    def settings(self, quick=False, **kw):
        """The study's settings: full by default, the ``quick`` overrides, then ``kw`` (None
        values ignored, and the fields the study does not take: a selection it fixes)."""
        names = {f.name for f in fields(self.settings_class) if f.init}
        if self.takes is not None:
            names &= {"E", "nu", "rho", *self.takes, *self.selections}
        given = {k: tuple(v) if isinstance(v, list) else v for k, v in kw.items()
                 if v is not None and k in names}
        return self.settings_class(**{**(self.quick if quick else {}), **given,
                                      "quick": quick})

    @abc.abstractmethod
    def run(self, s, workers=None, log=True, bench=None, store=None):
        """Compute everything; return the data its ``write`` takes. ``bench`` is the
        `pbcm bench` document (cost), or None; ``store`` a ``cases.running.store.RunStore`` to take
        stored results from and keep computed ones in (None: none)."""

    @abc.abstractmethod
    def write(self, out, s, data):
        """Write metrics.json (with ``gate_runs``: rows keyed by mesh, bc and model, and
        ``gated``), the report and the figures into the folder ``out``."""

    def definitions(self):
        """'term: definition' lines of the study's own terms, for the glossary."""
        return []

    def scorecard(self, metrics):
        """Rows the index's scorecard adds for this study, from its ``metrics``
        (metrics.json): ``[(label, metric, {model: (text, band)})]`` with band 0 (good), 1 or
        2 (bad), each optionally with a fourth item (FEM P1 vs continuum, u_val) for the
        row's shared columns; none by default (the scorecard's rows are the cases')."""
        return []

    def recorded(self, metrics):
        """``(settings, data)`` as a run recorded them in ``metrics`` (its metrics.json), for
        ``pbcm run NAME --rewrite``: the report drawn again from the recorded runs after a
        change of the report's code, without computing; the settings from the recorded
        parameters (``recorded_settings``), the data from ``recorded_keys`` with what the
        report derives drawn again (``redrawn``). None: the study records no data."""
        if not self.recorded_keys:
            return None
        p = metrics["parameters"]
        s = self.settings(quick=p["quick"], **self.recorded_settings(p))
        return s, self.redrawn(s, {k: metrics[k] for k in self.recorded_keys}, metrics)

    def recorded_settings(self, parameters):
        """The settings fields a run recorded in its ``parameters``: each under its own name or,
        for the material, its record's (``material_record``)."""
        out = {}
        for f in fields(self.settings_class):
            key = f.name if f.name in parameters else MATERIAL_KEYS.get(f.name)
            if f.init and f.name != "quick" and key in parameters:
                v = parameters[key]
                out[f.name] = tuple(v) if isinstance(v, list) else v
        return out

    def redrawn(self, s, data, metrics):
        """The recorded ``data`` with what the report derives from it drawn again by the
        current rules (a fit, a judgement; never a run); as recorded by default."""
        return data


__all__ = ["Case", "Narrative", "Study", "Settings", "Loads", "Traction", "Knob", "Reference",
           "MM", "MESH_FAMILIES"]
