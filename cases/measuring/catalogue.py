"""The metric catalogue: every metric the suite writes, declared once.

A :class:`Metric` says what a run key means: its unit, the gate's direction (``"max"``: the
value is an error, smaller is better, and the gate bounds it; ``"min"``: larger is better;
None: reported, not gated), its short label (table headers) and a one-line definition (the
reports' definition lists). Tables, definition lists, gated sets, charts and the gate read
these declarations; nothing else writes a metric's label, unit or direction.

A quantity of interest declared here brings two derived keys with it: its FEM value
(``ref_name``: ``tip_deflection_mm`` -> ``tip_deflection_fem_mm``) and its relative error
(``err_name``: ``tip_deflection_rel_err``, direction "max"), unless those are declared
themselves. To add a metric: one ``declare(...)`` line below (in the group it belongs to),
then compute it under that name; a case kept outside the package declares its own with
``catalogue.declare`` in its module.

Keys of a run that are not metrics (what identifies a run, a failure message, a run
parameter) are listed in ``DESCRIPTORS``; a test checks that every key of every committed
metrics.json is one or the other.
"""
from dataclasses import dataclass

from .numbers import fmt, rel

from .names import (UNIT_OF_SUFFIX, UNIT_SUFFIXES, err_name, load_name,  # noqa: F401
                    ref_name, unit_suffix)


@dataclass(frozen=True)
class Metric:
    """One metric: ``name`` (its run key), ``unit`` ("1" for a ratio; SI but for names
    ending in _mm), ``label`` (table header), ``definition`` (one line), ``direction``
    ("max": an error, "min": a correlation, "signed": gated but neither side better, or None:
    not gated), and how a table shows it: ``shown`` = (unit text, factor) when
    shown in another unit than stored (e.g. ("mN", 1e3)), ``digits`` significant."""

    name: str
    unit: str
    label: str
    definition: str
    direction: str = None
    shown: tuple = None
    digits: int = 3

    def __post_init__(self):
        if self.direction not in (None, "max", "min", "signed"):
            raise ValueError(f"metric {self.name}: direction {self.direction!r} is not "
                             "'max', 'min', 'signed' or None")
        suffix = unit_suffix(self.name)
        named = UNIT_OF_SUFFIX.get(suffix, "1")
        if named != (self.unit if self.unit != "count" else "1"):
            want = [k for k, v in UNIT_OF_SUFFIX.items() if v == self.unit]
            raise ValueError(
                f"metric {self.name}: its name says unit {named!r} (suffix {suffix!r}) but it "
                f"is declared in {self.unit!r}; name it with "
                + (f"the suffix {want[0]!r}" if want else "no unit suffix"))

    @property
    def header(self):
        """The table header: the label with the unit shown (none for a ratio)."""
        unit = self.shown[0] if self.shown else self.unit
        return self.label if unit == "1" else f"{self.label} [{unit}]"

    def cell(self, value):
        """``value`` as a table shows it (n/a for None)."""
        if value is None or isinstance(value, (list, dict, str, bool)):
            return fmt(value) if not isinstance(value, (list, dict)) else "n/a"
        if isinstance(value, int) and self.unit == "count":
            return str(value)
        if self.unit == "1" and not self.shown:
            return rel(value, self.digits)       # a relative value: round-off said as such
        return fmt(value * (self.shown[1] if self.shown else 1), self.digits)

    def line(self):
        """The definition-list line: ``label (name): definition``."""
        return f"{self.label} ({self.name}): {self.definition}"


CATALOGUE = {}


def declare(name, unit, label, definition, direction=None, shown=None, digits=3):
    """Declare metric ``name`` (see :class:`Metric`); declaring a name again differently is an
    error (the same declaration again, a module imported twice, is not)."""
    m = Metric(name, unit, label, definition, direction, shown, digits)
    if CATALOGUE.get(name, m) != m:
        raise ValueError(f"metric {name} declared twice, differently: {CATALOGUE[name]} and {m}")
    CATALOGUE[name] = m


def _derived(name):
    """The Metric of a FEM twin, a relative error or the value at the load of a declared
    quantity, or None."""
    for q, m in CATALOGUE.items():
        if load_name(q) == name != q:
            return Metric(name, m.unit, f"{m.label} at the load",
                          f"the {m.label} at the case's load (the finite-strain solve).", None,
                          m.shown, m.digits)
        if ref_name(load_name(q)) == name:
            return Metric(name, m.unit, f"NH {m.label} at the load",
                          f"the {m.label} of the converged neo-Hookean reference at the case's "
                          "load.", None, m.shown, m.digits)
        if ref_name(q) == name != q:
            return Metric(name, m.unit, f"FEM {m.label}",
                          f"the {m.label} of the FEM reference's solution.", None, m.shown,
                          m.digits)
        if err_name(q) == name != q:
            return Metric(name, "1", f"{m.label} err",
                          f"|model / FEM - 1| of the {m.label}.", "max")
    return None


def metric(name):
    """The Metric of run key ``name``; a KeyError naming where to declare it otherwise."""
    m = CATALOGUE.get(name) or _derived(name)
    if m is None:
        raise KeyError(f"{name!r} is not a metric of the catalogue: declare it in "
                       "cases/measuring/catalogue.py")
    return m


def known(name):
    """True when ``name`` is a declared metric or derived from one."""
    return name in CATALOGUE or _derived(name) is not None


def gated(*names):
    """{name: direction} of metrics the gate bounds, in the order given; a metric without a
    direction cannot be gated."""
    out = {}
    for n in names:
        d = metric(n).direction
        if d is None:
            raise ValueError(f"metric {n} has no gate direction in the catalogue")
        out[n] = d
    return out


def definitions(names):
    """The definition lines of ``names`` (each once, in order)."""
    return [metric(n).line() for n in dict.fromkeys(names)]


# keys of a run (or a study's row) that are not metrics: what identifies it, why it failed,
# what it was run with
DESCRIPTORS = frozenset({
    "case", "mesh", "bc", "model", "failed", "static_failed", "dyn_failed", "dyn_failed_dt4",
    "dyn_verdict", "cancellation", "ratio_why", "calibration_patch",
    "model_info", "nodes", "tets", "h_mm", "dyn_dt_s", "dyn_steps", "dyn_t_end_s", "label",
    "why", "verdict", "levels", "metric", "dropped", "dyn_reaction_t_s", "homogeneous_failed",
    "finite_failed",
    # the convergence study's levels left out of a fit (each a spacing in mm), with why
    "left_out_mm",
    # the artefact study's factors: the mesh split and size, the model's parts, the load
    "split", "nodes_per_side", "unmatched_faces", "load", "family", "reading",
    "constant", "normal", "flutter",
    # each term's constant as the artefact study built it ({term_c: value}, fitted or given)
    "constants",
    # how the artefact study's static solve was run: the equal load steps that converged
    "load_steps",
    # the truth-cube study's factors: the plate assumption, the measured state
    "variant", "plates", "travel", "nu", "state", "strain",
    # how a study's reference was solved: its element, spacings, size, extrapolation
    "element", "ladder_mm", "dofs", "extrapolated",
    # the verification ladder's declaration: a manufactured ladder's name, levels, formal
    # order, bound and tolerance, its verdict; a patch's interior node count
    "ladder", "cells", "formal_order", "finest_bound", "tolerance", "passed", "interior",
    "one_sided", "dt_s", "steps", "failed_divisor",
    # the real-time study: whether a size's accuracy was computed, the law whose statics a
    # model has, and the bench's timing row of the model and size (its own record)
    "accuracy", "law", "cost",
    # the engines study: the regime and quantity compared, the engine's solver and settings
    "regime", "quantity", "solver", "iterations", "substeps"})

# ---------------------------------------------------------------- the standard static metrics
declare("disp_rel_l2_p1", "1", "disp L2 P1",
         "||u_model - u_ref|| / ||u_ref|| over the free components (the prescribed ones, equal "
         "in both, left out), against linear FEM P1 on the same mesh.", "max")
declare("disp_max_rel_p1", "1", "disp max P1",
         "max_i |u_model,i - u_ref,i| / max_i |u_ref,i| over the free components, against FEM "
         "P1 on the same mesh.")
declare("disp_rel_l2_p2", "1", "disp L2 P2",
         "||u_model - u_ref|| / ||u_ref|| over the free components, against the converged P2 "
         "reference at the particle nodes.", "max")
declare("disp_max_rel_p2", "1", "disp max P2",
         "max_i |u_model,i - u_ref,i| / max_i |u_ref,i| over the free components, against the "
         "converged P2 reference.", "max")
declare("disp_energy_rel_p2", "1", "disp energy P2",
         "||u_model - u_ref||_K / ||u_ref||_K, the error in the energy norm of the linear P1 "
         "stiffness K on the model's mesh (the continuum's energy of the difference's "
         "interpolant), against the converged P2 reference at the nodes.", "max")
declare("reaction_n", "N", "reaction",
         "the force the supports exert on the driven nodes along the driven axis (n/a in a "
         "load-controlled case).", shown=("mN", 1e3), digits=4)
declare("reaction_ratio", "1", "reaction ratio",
         "the reaction of the model over that of FEM P2.")
declare("reaction_rel_err", "1", "reaction err",
         "|reaction ratio - 1|.", "max")
declare("reaction_fem_p2_n", "N", "FEM P2 reaction",
         "the reaction of the converged P2 reference.", shown=("mN", 1e3), digits=4)
declare("stress_corr", "1", "G|gamma| corr",
         "a strain measure, not the model's stress: Pearson correlation of the paper's "
         "max |tau| = G max |gamma| over the 24 corner shear strains of each tetrahedron, "
         "computed alike from the model's and from the FEM P2 displacement (n/a where the "
         "reference field is uniform).", "min")
declare("stress_rel_err", "1", "G|gamma| err",
         "relative L2 error of that strain measure against FEM P2's.", "max")
declare("stress_force_rel_err", "1", "stress err (forces)",
         "the model's own stress, from its forces: the virial -(1/V) sym sum (x - c) (x) f of "
         "the forces its terms put on each tetrahedron, averaged over each node's tetrahedra "
         "(volume-weighted), against FEM P2's stress averaged alike; relative L2 error of the "
         "tensors over the nodes.", "max")
declare("stress_force_corr", "1", "stress corr (forces)",
         "Pearson correlation over the nodes of the von Mises stress of that model stress "
         "with FEM P2's (n/a where the reference is uniform).", "min")
declare("pressure_corr", "1", "pressure corr",
         "Pearson correlation of the model's p = -K (V - V0)/V per tetrahedron with the FEM P2 "
         "pressure -tr(sigma)/3 averaged over it (n/a where the reference is uniform).")
declare("pressure_rel_err", "1", "pressure err",
         "relative L2 error of that pressure against FEM P2's.", "max")
declare("static_residual_n", "N", "residual",
         "the largest free-node force left by the model's static solve.")
declare("net_force_rel", "1", "net F",
         "|sum f| / sum |f| of the model's internal forces at the FEM P2 deformed state (zero "
         "for a momentum-conserving model).", "max", digits=2)
declare("net_torque_rel", "1", "net T",
         "|sum x x f| / sum |x||f| of those forces.", digits=2)
declare("p2_error_estimate", "1", "P2 error estimate",
         "the P2 reference's own error estimate: its change over the last refinement.")

declare("linear_scale", "1", "linear-regime scale",
         "the factor on the case's loads at which the linear-regime metrics were solved: the "
         "largest tetrahedron-average strain of the linear reference is then 1e-4; the "
         "model's answer is divided by it again, so that the linear-regime metrics compare "
         "its linearisation with linear FEM.", digits=3)

# ---------------------------------------------------------------- the case's load
declare("disp_rel_l2_nh_p1", "1", "disp L2 NH vs P1",
        "at the case's load: ||u_model - u_P1|| / ||u_P1|| over the free components, against "
        "FEM P1 with the neo-Hookean law on the same tetrahedra (a field's distance to that "
        "twin, read for fem-linear's linearisation; the model-form error that ranks is the "
        "case's own quantity at the load; fem-neohookean's is an identity check).", "max")
declare("disp_rel_l2_nh", "1", "disp L2 NH",
        "at the case's load: ||u_model - u_ref|| / ||u_ref|| over the free components, "
        "against the converged neo-Hookean P2 reference at the particle nodes (fem-linear's "
        "holds the linear law's departure from the neo-Hookean field and P1's "
        "discretisation error; the first is disp_rel_l2_nh_p1).", "max")
declare("disp_max_rel_nh", "1", "disp max NH",
        "at the case's load: max_i |u_model,i - u_ref,i| / max_i |u_ref,i| over the free "
        "components, against the neo-Hookean reference.", "max")
declare("reaction_rel_err_nh", "1", "reaction err NH",
        "at the case's load: |reaction / neo-Hookean reaction - 1| (n/a in a load-controlled "
        "case).", "max")
declare("reaction_fem_nh_n", "N", "NH reaction",
        "the reaction of the converged neo-Hookean reference at the case's load.",
        shown=("mN", 1e3), digits=4)
declare("nh_error_estimate", "1", "NH error estimate",
        "the neo-Hookean reference's own error estimate: its change over the last "
        "refinement, Richardson-extrapolated where an order can be observed.")

# ---------------------------------------------------------------- paper cube: the artefact
declare("bulge_profile_mm", "mm", "layer profile",
         "for each y-layer (0, 8, 16, 24, 32 mm) the mean outward lateral displacement of the "
         "side-face nodes.")
declare("alternation_mm", "mm", "alternation",
         "the bulge/neck signature: the period-2 (Nyquist) component of the layer profile "
         "over the layers free to move laterally, beta of profile_k = alpha profile_FEM,k + "
         "s_k + beta (-1)^k read by one weighted sum of those layers: blind exactly to the "
         "reference at any scale and to polynomials up to degree 2, reading a pure (-1)^k "
         "pattern as its amplitude, and of all such sums the one least sensitive to a family "
         "of smooth fields (Gaussian bulges two layer spacings wide and more, end layers "
         "decaying over two spacings and more, a half-sine barrel). Zero to round-off for the "
         "continuum against itself, scaled, and for parabolic barrels; any other smooth field "
         "leaks a stated fraction of its height, and an end layer sharper than two spacings "
         "more (the artefact report's metric check); positive puts the layers of even index "
         "from the base out (the ends and the middle of five: the paper's sign). On five "
         "layers it cannot tell a smooth bump from an alternation (the paper's own view); n/a "
         "where the reference and a quadratic span the free layers (the clamped five-layer "
         "cube's three).", digits=2)
declare("alternation_rel", "1", "alternation rel",
         "the signature over the reference profile's mean |lateral displacement|; the "
         "pattern is called clear from 0.01.", "signed")
declare("line_alternation_mm", "mm", "line signatures",
         "the signature of each vertical line of side-face nodes (one per face and node "
         "position across it), read with the layer profile's weights: the node-level pattern "
         "whose mean over the lines is alternation_mm.")
declare("line_alternation_fem_mm", "mm", "continuum line signatures",
         "line_alternation_mm of the continuum at the same nodes: the leak of its smooth "
         "line shapes.")
declare("alternation_max_rel", "1", "largest |alternation|",
         "a model's largest |alternation rel| over its paper-cube runs (extensions study).",
         "max")
declare("paper_pattern", "1", "paper pattern",
         "1 when the middle and end layers bulge relative to their neighbours while the 8 and "
         "24 mm layers neck (second differences +, -, +), as the paper reports, else 0.")
declare("apparent_poisson", "1", "apparent nu",
         "the mean of the layer profile over the half side, divided by the axial compression "
         "push / size (exactly nu for linear FEM on the sliding base).")
declare("growth_rate_1_s", "1/s", "growth",
         "the largest exponential growth rate of the undamped model linearised at rest (max Re "
         "sqrt(eig(M^-1 df/dx))); above zero the force field flutters.")
declare("verdict_changes_dt4", "1", "dt/4 changes verdict",
         "whether the dynamic run repeated at a quarter of the step changes whether it blew "
         "up.")

# ---------------------------------------------------------------- paper cube: dynamics
declare("dyn_vs_static_rel_l2", "1", "dyn vs static",
         "relative L2 distance between the end of the dynamic run and the static "
         "equilibrium.", digits=2)
declare("dyn_at_rest", "1", "at rest",
         "whether the dynamic run came to rest before its end.")
declare("dyn_reaction_n", "N", "reaction(t)",
         "the top reaction over push and hold of the dynamic run.")
declare("reaction_time_rel_l2", "1", "reaction(t) err",
         "relative L2 of the top reaction over push and hold against the FEM transient on the "
         "same boundary motion (all modes superposed, consistent mass, the same damping).",
         "max")
declare("disp_end_push_rel_l2", "1", "disp end push err",
         "relative L2 of the displacement at the end of the push against the FEM transient.",
         "max")
declare("rest_time_s", "s", "rest",
         "when every node is slower than the rest speed (checked every 0.1 s of hold).", "max",
         digits=2)

# ---------------------------------------------------------------- modes
declare("frequencies_hz", "Hz", "frequencies",
         "the first 10 non-rigid frequencies of the model linearised at rest (coloured "
         "finite-difference Jacobian, lumped mass; |Re sqrt(lambda)| / 2 pi).")
declare("modal_rel_err", "1", "modal err",
         "the largest relative frequency error of the first 10 non-rigid FEM P2 modes "
         "(consistent mass), with the case's constraints, each against the model mode paired "
         "with it by shape (unpaired ones left out).", "max")
declare("modal_rel_err_median", "1", "median err",
         "the median of those relative errors.", "max")
declare("modal_rel_err_free", "1", "modal err free",
         "the modal error free-free, after the rigid modes.", "max")
declare("rigid_modes", "count", "rigid modes",
         "zero eigenvalues (below 1e-8 of the largest): 6 free-free, 0 clamped expected.",
         "max")
declare("frequencies_fem_estimate", "1", "FEM frequency estimates",
        "each FEM P2 frequency's relative change over the reference's last refinement (n/a "
        "without one, in quick mode).")
declare("modal_fem_estimate", "1", "FEM modal estimate",
        "the largest relative change of the first 10 FEM P2 frequencies with the case's "
        "constraints over the reference's last refinement (n/a without one).")
declare("modal_free_fem_estimate", "1", "FEM free modal estimate",
        "the same, free-free.")
declare("modes_unpaired", "count", "unpaired",
        "FEM modes among the first 10 (of each set compared) that no model mode matches in "
        "shape (MAC >= 0.8 with the mode, or with the space of a cluster of equal "
        "frequencies): left out of the frequency errors.", "max")
declare("modes_unpaired_held", "count", "unpaired held",
        "the same among the first 10 modes with the case's constraints alone (the paper "
        "cube's clamped base).", "max")
declare("modal_rel_err_p1", "1", "modal err P1",
        "the model-form modal error: the largest relative frequency error of the first 10 "
        "non-rigid modes of FEM P1 on the same tetrahedra (lumped mass, the case's "
        "constraints), each against the model mode paired with it by shape (unpaired ones "
        "counted in modes_unpaired_p1).", "max")
declare("modes_unpaired_p1", "count", "unpaired P1",
        "FEM P1 modes among the first 10 that no model mode matches in shape (the same "
        "pairing as modes_unpaired): failed modes of the model-form comparison.", "max")
declare("rigid_modes_free", "count", "rigid modes free",
         "zero eigenvalues free-free (6 expected).", "max")
declare("rest_time_fem_s", "s", "FEM rest",
         "when the FEM transient comes to rest.", digits=2)

# ---------------------------------------------------------------- case quantities
declare("tip_deflection_mm", "mm", "tip deflection",
         "the mean -u_y over the nodes of the loaded face x = L.", digits=4)
declare("top_settlement_mm", "mm", "settlement",
         "the mean -u_y over the top-face nodes.", digits=4)
declare("top_settlement_cf_mm", "mm", "closed form",
         "the closed-form settlement at this mesh's top nodes (sliding base only).", digits=4)
declare("top_settlement_cf_rel_err", "1", "err vs closed form",
         "|model / closed form - 1| of the top settlement in the linear regime, scaled to "
         "the case's load (the closed form is linear elasticity).", "max")
declare("torque_nm", "N m", "torque",
         "the moment about the bar's axis of the forces the supports exert on the turned end "
         "face, sum (y - y_c) R_z - (z - z_c) R_y with rest positions as arms.",
         shown=("uN m", 1e6), digits=4)
declare("warping_mm", "mm", "warping",
         "the RMS over the end face of the axial displacement u_x about its mean.")
declare("surface_profile_mm", "mm", "surface profile",
         "u_y of the top nodes on the centre line z = 16 mm, by x.")
declare("profile_rel_err", "1", "profile err",
         "relative L2 error of the surface profile against FEM P2.", "max")
declare("edge_shear_pa", "Pa", "edge shear",
         "the peak of the paper's max |tau| over the tetrahedra touching the punch's edge "
         "nodes (singular in the continuum: each model's own value, gated as a regression, "
         "never compared with a reference).", "signed", digits=4)
declare("force_steps_n", "N", "force(steps)",
         "the top force at each compression step.")
declare("force_steps_fem_n", "N", "neo-Hookean force(steps)",
         "the top force of the neo-Hookean P2 reference at each step.")
declare("force_linear_steps_n", "N", "linear FEM force(steps)",
         "the top force of linear FEM P2 at each step.")
declare("lateral_strain_steps", "1", "lateral strain(steps)",
         "the mean outward displacement of the side-face nodes over the half side, per step.")
declare("lateral_strain_fem_steps", "1", "neo-Hookean lateral strain(steps)",
         "the lateral strain of the neo-Hookean P2 reference per step.")
declare("lateral_strain_linear_steps", "1", "linear FEM lateral strain(steps)",
         "the lateral strain of linear FEM P2 per step.")
declare("force_rel_err_max", "1", "force err max",
         "the largest |F_model / F_neo-Hookean - 1| of the top force over the steps.", "max")
declare("lateral_rel_err_max", "1", "lateral err max",
         "the largest relative error of the lateral strain over the steps.", "max")
declare("linear_force_rel_err_max", "1", "linear FEM force err",
         "the force err max of linear FEM P2 against neo-Hookean (the linear reference's own "
         "error at this strain).")
declare("linear_lateral_rel_err_max", "1", "linear FEM lateral err",
         "the lateral err max of linear FEM P2 against neo-Hookean.")
declare("homogeneous_force_steps_n", "N", "homogeneous force(steps)",
         "the top force of the homogeneous (sliding) compression at each step.")
declare("homogeneous_energy_force_steps_n", "N", "energy force(steps)",
         "dW/d(push) of the model's stored energy along the homogeneous compression, by "
         "central differences (conservative models).")
declare("homogeneous_force_law_steps_n", "N", "neo-Hookean law force(steps)",
         "the neo-Hookean law's top force in homogeneous compression, in closed form.")
declare("homogeneous_force_dev_max", "1", "law deviation",
         "the largest |F_model / F_law - 1| of the homogeneous compression over the steps: "
         "how far the model's own law is from neo-Hookean (a constitutive check, not ranked).")

# ---------------------------------------------------------------- the Truth Cube: measured beads
declare("bead_rms_mm", "mm", "bead RMS",
        "RMS over the 343 measured beads of |u_model - u_measured| at one measured state, the "
        "measurement's rigid in-plane motion removed (the model at the rest bead positions: "
        "P1 on its mesh, a FEM reference by its own basis).", "max")
declare("bead_max_mm", "mm", "bead max",
        "the largest |u_model - u_measured| over the beads.", "max")
declare("bead_axial_rms_mm", "mm", "bead axial RMS",
        "RMS over the beads of the axial (z, the compression's) component of the error.",
        "max")
declare("bead_lateral_rms_mm", "mm", "bead lateral RMS",
        "RMS over the beads of the length of the lateral (x, y) part of the error.", "max")
declare("bead_rms_rel", "1", "bead RMS rel",
        "bead RMS over the RMS measured displacement |u_measured|.", "max")
declare("bead_axial_rel", "1", "bead axial rel",
        "bead axial RMS over the RMS measured axial displacement.", "max")
declare("bead_lateral_rel", "1", "bead lateral rel",
        "bead lateral RMS over the RMS measured lateral displacement.", "max")
declare("bead_vs_continuum_mm", "mm", "bead vs continuum",
        "RMS over the beads of |u_model - u_continuum|: the model against the neo-Hookean "
        "continuum under the same plates, travel and nu, at the measured rest bead positions "
        "(below the measurement's floor the measurement cannot tell the two apart).", "max")
declare("bead_raw_rms_mm", "mm", "bead RMS raw",
        "bead RMS against the measurement as scanned (its rigid in-plane motion kept).")
declare("layer_axial_mm", "mm", "layer axial",
        "the mean axial displacement of each bead layer k = 1..7 (1 at the fixed plate).")
declare("layer_lateral_mm", "mm", "layer lateral",
        "the mean outward lateral displacement of each layer's 24 outer beads (the barrel).")
declare("travel_mm", "mm", "travel",
        "the moving plate's travel at the state (nominal strain x 80 mm, or fitted).",
        digits=4)
declare("increments", "1", "increments",
        "a reference's relative changes between its successive refinement levels.")
declare("bead_change_mm", "mm", "bead change",
        "a reference's RMS change of the bead displacement over its last refinement: its "
        "error estimate where it meets the measurement.")
declare("error_estimate", "1", "reference estimate",
        "a reference's own error estimate: its relative change over the last refinement, "
        "Richardson-extrapolated where an order can be observed.")

# ---------------------------------------------------------------- convergence and extensions
declare("response", "1", "response",
         "the problem's scalar response (its reaction or displacement measure) in SI units.")
declare("disp_rel_l2", "1", "disp L2",
         "||u_model - u_ref|| / ||u_ref|| over the free components, against the problem's "
         "finest reference.", "max")
declare("disp_form_rel_l2", "1", "model-form disp L2",
        "||u_model - u_P1|| / ||u_ref|| over the free components: the model-form error, the "
        "model against FEM P1 with the continuum's law on the same tetrahedra, relative to "
        "the converged continuum's field.", "max")
declare("e_inf", "1", "e_inf",
         "the error extrapolated to h -> 0 by the fit of error against mesh size.", "max")
declare("e_inf_err", "1", "e_inf uncertainty", "the fit's uncertainty of e_inf.")
declare("ratio_inf", "1", "ratio_inf",
         "the response ratio model / reference extrapolated to h -> 0.")
declare("ratio_inf_err", "1", "ratio_inf uncertainty", "the fit's uncertainty of ratio_inf.")
declare("order", "1", "order", "the fitted order of convergence of the error in h.")
declare("mms_errors", "1", "MMS L2 per level",
         "||u_h - u|| / ||u|| in L2 against the manufactured field, at each level of a ladder.")
declare("mms_orders", "1", "orders per pair",
         "log(e1 / e2) / log(h1 / h2) of each successive pair of a manufactured ladder.")
declare("mms_order", "1", "observed order",
         "the observed L2 order of a manufactured ladder on its finest pair of levels.",
         "signed")
declare("mms_rel_l2", "1", "finest MMS L2",
         "||u_h - u|| / ||u|| in L2 against the manufactured field on a ladder's finest "
         "level.", "max")
declare("dt_errors", "1", "step error per step size",
         "||x - x_ref|| / ||x_ref - X|| at the end of the paper cube's push, at the case's RK4 "
         "step and its half, x_ref the push at an eighth of the step.")
declare("dt_error", "1", "step error",
         "the paper cube's end-of-push displacement at the case's RK4 step against the push at "
         "an eighth of it, relative to the displacement.", "max")
declare("dt_order", "1", "step order",
         "the observed order of the step error when the step is halved (RK4's is 4); none "
         "where the half step's error is at round-off.", "signed")
declare("patch_errors", "1", "patch error per strain",
         "the RMS over the tetrahedra of |eps_h - eps| / |eps| for each of the six unit "
         "strains of the patch test (Voigt order).")
declare("patch_error", "1", "patch error",
         "the patch test's consistency error: the worst over the six unit strains of the RMS "
         "over the tetrahedra of |eps_h - eps| / |eps|, eps_h the relaxed solution's strain.",
         "max")
declare("C_eff_pa", "Pa", "C_eff",
         "the lattice's effective elasticity tensor (Voigt 6 x 6) from six homogeneous "
         "strains.")
for _n in ("E_x_pa", "E_y_pa", "E_z_pa", "E_110_pa", "E_111_pa", "E_xy_plane_pa"):
    declare(_n, "Pa", _n[:-3], f"the effective Young's modulus {_n[:-3]} of C_eff.")
for _n in ("G_xy_pa", "G_xz_pa", "G_yz_pa"):
    declare(_n, "Pa", _n[:-3], f"the effective shear modulus {_n[:-3]} of C_eff.")
for _n in ("nu_xy", "nu_xz", "nu_yx", "nu_yz", "nu_zx", "nu_zy"):
    declare(_n, "1", _n, f"the effective Poisson ratio {_n[3:]} of C_eff.")
declare("K_eff_pa", "Pa", "K_eff",
         "C_eff's bulk modulus: v.M v / 3 of its Mandel form M, v the unit volumetric "
         "direction.")
declare("deviatoric_moduli_pa", "Pa", "deviatoric moduli",
         "C_eff's five deviatoric Kelvin moduli, ascending (each 2G when isotropic).")
declare("bulk_rel_err", "1", "bulk err",
         "K_eff over the target's K, minus 1.")
declare("deviatoric_rel_err", "1", "deviatoric errs",
         "each deviatoric Kelvin modulus over the target's 2G, minus 1.")
declare("moduli_rel_err", "1", "moduli err",
         "the largest relative error of C_eff's bulk modulus and five deviatoric Kelvin moduli "
         "(eigenvalues of its Mandel form on the deviatoric subspace, symmetric part) against "
         "the isotropic target's K and 2G: isotropy judged modulus by modulus, so that a "
         "stiff bulk block cannot hide a soft shear modulus.", "max")
declare("anisotropy_AU", "1", "A^U",
         "the universal anisotropy index of C_eff (0 for an isotropic material).", "max")
declare("asymmetry", "1", "asymmetry",
         "||C_eff - C_eff^T|| / ||C_eff|| (zero for a model with an energy).")
declare("error", "1", "case error",
         "the model-form error of the case's decomposed quantity for one run, against FEM P1 "
         "with the same law on the same tetrahedra (the extensions study's ranking unit).",
         "max")
declare("engine_error", "1", "engine model-form error",
         "|model-form error| of an engine's run (the engines study): its case's decomposed "
         "quantity against FEM P1 with the same law on the same tetrahedra, relative to the "
         "continuum's.", "max")
declare("value_rel", "1", "Q / |Q_c|",
         "the case's decomposed quantity from one run over the converged continuum's |Q_c| on "
         "the run's mesh (the engines study): 1 is the continuum's answer.")
declare("estimate", "1", "reference's estimate",
         "the continuum reference's own relative error estimate for the run's regime (P2 in the "
         "linear regime, neo-Hookean at the load).")
declare("model_form", "1", "model-form error (signed)",
         "(Q - Q_P1) / |Q_c| of one run: against FEM P1 with the same law on the same "
         "tetrahedra, relative to the continuum's value (the engines study).")
declare("total", "1", "distance from the continuum (signed)",
         "(Q - Q_c) / |Q_c| of one run: model-form plus FEM P1's discretisation error.")
declare("u_num", "1", "u_num",
         "the reference's numerical uncertainty for one case and regime (the engines study): "
         "its largest estimate over the meshes and the relative spread of the continuum's "
         "value over them, in quadrature; u_val, with no unmeasured input or data.")
declare("force_rel", "1", "top force from the continuum (signed)",
         "(f - f_c) / |f_c| for the top force f the paper's push needs (the reaction on the "
         "cube's top along the push; the real-time study).")
declare("force_form_rel", "1", "top force model-form error (signed)",
         "(f - f_P1) / |f_c| for the top force: a law's stiffness against FEM P1's with the "
         "continuum's law on the same tetrahedra, which the displacement field under a "
         "prescribed push hardly sees (the real-time study).")
declare("discretisation", "1", "P1 discretisation",
         "FEM P1's discretisation error of the case's decomposed quantity on the run's mesh, "
         "against the converged continuum (the extensions study's failure criterion).")
del _n

# the standard metrics of a static solution (None when the static solve failed), the ones the
# gate bounds in every case, and the columns of every case's table
STATIC = ("disp_rel_l2_p1", "disp_max_rel_p1", "disp_rel_l2_p2", "disp_max_rel_p2",
          "disp_energy_rel_p2", "reaction_n", "reaction_ratio", "reaction_rel_err",
          "stress_corr", "stress_rel_err", "stress_force_rel_err", "stress_force_corr",
          "pressure_corr", "pressure_rel_err", "static_residual_n")
# the metrics at the case's load, against the neo-Hookean reference (None where it failed)
FINITE = ("disp_rel_l2_nh", "disp_rel_l2_nh_p1", "disp_max_rel_nh", "reaction_rel_err_nh")
STANDARD_GATED = gated(*(n for n in STATIC + FINITE + ("net_force_rel",)
                         if CATALOGUE[n].direction))
TABLE = ("disp_rel_l2_p1", "disp_rel_l2_p2", "disp_max_rel_p2", "disp_energy_rel_p2",
         "reaction_ratio", "stress_force_rel_err", "stress_corr", "pressure_corr",
         "net_force_rel", "net_torque_rel")
