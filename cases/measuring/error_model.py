"""The error model every verdict reads, written once.

A model run on a mesh is three numbers apart from the continuum, each relative to the
continuum's value |Q_c| so that they add:

- **model-form error** (Q_model - Q_P1) / |Q_c|: what replacing FEM P1 (the same law on the same
  tetrahedra, under the same constraints and load) by the model costs;
- **discretisation error** (Q_P1 - Q_c) / |Q_c|: how far FEM P1 on that mesh is from the
  converged continuum, shared by every model on the mesh;
- **total error** (Q_model - Q_c) / |Q_c| = model-form + discretisation.

A case declares what it decomposes (:class:`Scalar` for a quantity of interest, :class:`Norm`
for an error that is already a norm against P1, where the parts bound the total by the triangle
inequality instead of summing to it). Every comparison is read against its validation
uncertainty u_val = sqrt(u_num^2 + u_input^2 + u_D^2) (ASME V&V 20): two errors closer than
u_val are tied. A run that gave no number counts against its model (:func:`standings`)."""
import math
from dataclasses import dataclass

import numpy as np

from model.static import RTOL
from .names import load_name, ref_name

# a relative value within ten times the solvers' tolerance is round-off (a solve stops there,
# and where it stops differs from one processor to the next): printed as such, and never the
# difference that decides a tie or a rank
ROUND_OFF = 10 * RTOL
# a reference judges an error only where its own estimate is at most a fifth of it
JUDGES = 5
P1_LINEAR = "fem-linear"          # FEM P1 with the linear law: the twin in the linear regime
P1_FINITE = "fem-neohookean"      # FEM P1 with the reference's law: the twin at finite load


class ErrorModelError(ValueError):
    """Inputs the error model cannot decompose (a zero or non-finite continuum value, shapes
    that differ, a negative uncertainty)."""


@dataclass(frozen=True)
class Parts:
    """One run's errors, signed, relative to the continuum (``total`` = ``model_form`` +
    ``discretisation`` for a scalar; bounded by their magnitudes' sum for a norm); None for
    a part that failed (a mode unpaired against the continuum)."""

    model_form: float
    discretisation: float
    total: float


def _array(name, q):
    a = np.asarray(q, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ErrorModelError(f"{name} is not finite ({q!r}): a failed solve has no error")
    return a


def _largest(e):
    """The signed component of largest magnitude of a sequence's errors (a scalar as is)."""
    e = np.atleast_1d(e)
    return float(e[np.argmax(np.abs(e))])


def decompose(q_model, q_p1, q_continuum):
    """:class:`Parts` of a scalar quantity (or of a sequence: load steps, each part its
    largest-magnitude component) from the model's, FEM P1's and the continuum's values."""
    qm, qp, qc = (_array(n, q) for n, q in (("the model's value", q_model),
                                            ("FEM P1's value", q_p1),
                                            ("the continuum's value", q_continuum)))
    if not qm.shape == qp.shape == qc.shape:
        raise ErrorModelError(f"the model's, P1's and the continuum's values differ in shape "
                              f"({qm.shape}, {qp.shape}, {qc.shape}): compare the same steps")
    if np.any(qc == 0):
        raise ErrorModelError("the continuum's value is zero: a relative error is undefined; "
                              "decompose a quantity the load makes non-zero")
    scale = np.abs(qc)
    return Parts(_largest((qm - qp) / scale), _largest((qp - qc) / scale),
                 _largest((qm - qc) / scale))


def u_val(u_num, u_input=0.0, u_d=0.0):
    """The validation uncertainty sqrt(u_num^2 + u_input^2 + u_D^2) (ASME V&V 20): the
    numerical solution's, the unmeasured inputs' and the measurement's, in the error's unit."""
    for name, u in (("u_num", u_num), ("u_input", u_input), ("u_D", u_d)):
        if not (math.isfinite(u) and u >= 0):
            raise ErrorModelError(f"{name} = {u!r}: an uncertainty is finite and non-negative")
    return math.sqrt(u_num ** 2 + u_input ** 2 + u_d ** 2)


def u_num(estimate, continuum_values):
    """The reference's numerical uncertainty for one continuum problem posed on several meshes:
    its stated estimate and the relative spread (max - min) / |median| of its values across
    the meshes, combined in quadrature as independent parts of u_num, and whether the spread
    exceeds the estimate (a defect of the reference, to fix by refining)."""
    vals = np.array([v for v in continuum_values if v is not None], dtype=float)
    est = 0.0 if estimate is None else float(estimate)
    if vals.size < 2:
        return est, False
    spread = float((vals.max() - vals.min()) / abs(np.median(vals)))
    return float(np.hypot(est, spread)), spread > est


def input_spread(values, variants, base="bonded"):
    """u_input of one output: ``values`` {variant: output}, ``variants`` {variant: its inputs
    (a tuple)}, each variant other than ``base`` changing inputs of the base's; per input
    changed (the variants that change the same inputs), half the range of the output over
    them and the base, combined in quadrature (independent inputs, V&V 20)."""
    if base not in values or base not in variants:
        vals = list(values.values())
        return (max(vals) - min(vals)) / 2 if len(vals) > 1 else 0.0
    groups = {}
    for name, inputs in variants.items():
        if name != base and name in values:
            changed = tuple(k for k, (a, b) in enumerate(zip(inputs, variants[base])) if a != b)
            groups.setdefault(changed, [values[base]]).append(values[name])
    return math.sqrt(sum(((max(v) - min(v)) / 2) ** 2 for v in groups.values()))


@dataclass(frozen=True)
class Scalar:
    """A case's decomposed quantity: ``key`` the run key of the model's value (a number or a
    sequence over load steps), ``continuum`` the run key of the converged continuum's, ``p1``
    the model whose run on the same mesh is FEM P1 with the same law (``P1_FINITE`` at finite
    load), ``label`` what it is."""

    key: str
    continuum: str
    label: str
    p1: str = P1_LINEAR
    posed: str = None         # as :class:`Norm`'s

    def parts(self, run, p1_run):
        """The run's :class:`Parts`, or None where the run or its P1 twin has no value."""
        vals = run.get(self.key), (p1_run or {}).get(self.key), run.get(self.continuum)
        if any(v is None for v in vals):
            return None
        return decompose(*vals)


@dataclass(frozen=True)
class Norm:
    """A case's decomposed error that is a norm (a field, a set of paired frequencies):
    ``model_form`` the run key of the model's error against P1 on the same mesh, ``total`` that
    against the continuum; the discretisation error is P1's own ``total``; ``unpaired`` the run
    key of how many of its parts failed against P1 (a run with one is a failed run: its
    largest error is undefined). The parts are
    magnitudes and bound the total (triangle inequality)."""

    model_form: str
    total: str
    label: str
    p1: str = P1_LINEAR
    unpaired: str = None      # run key counting the parts that failed (unpaired modes)
    unpaired_total: str = None   # the same against the continuum (the total's failed parts)
    count: int = 1            # the parts a run compares (the modes it pairs)
    # the run key that is None where the comparison does not exist on a run's mesh (no
    # reference there): such a run is no run of the population, never a model's failure
    posed: str = None

    def parts(self, run, p1_run):
        """The run's :class:`Parts`, or None where it or its P1 twin has no value, or where a
        part failed against P1 (an unpaired mode: the largest error over the parts is then
        undefined, so the run is a failed run)."""
        mf, tot = run.get(self.model_form), run.get(self.total)
        disc = (p1_run or {}).get(self.total)
        if any(v is None for v in (mf, tot, disc)):
            return None
        if run["model"] == self.p1:
            mf = 0.0           # P1 against itself, whatever its own run key says
        elif self.unpaired and run.get(self.unpaired):
            return None
        # a continuum mode unpaired fails the comparison against the continuum alone
        lost = self.unpaired_total and run.get(self.unpaired_total)
        lost_p1 = self.unpaired_total and (p1_run or {}).get(self.unpaired_total)
        return Parts(float(_array("model-form error", mf)),
                     None if lost_p1 else float(_array("discretisation error", disc)),
                     None if lost or lost_p1 else float(_array("total error", tot)))


def at_load(q):
    """The quantity ``q`` of the linear regime at the case's load: the same :class:`Scalar`
    (the same quantity of interest, so that both regimes rank one quantity) measured on the
    finite-strain solve, against FEM P1 with the reference's neo-Hookean law on the same
    tetrahedra and the converged neo-Hookean continuum; None for a quantity that is not a
    linear-regime :class:`Scalar` (a set of frequencies, a quantity already at the load)."""
    if not isinstance(q, Scalar) or q.p1 != P1_LINEAR:
        return None
    key = load_name(q.key)
    return Scalar(key, ref_name(key), f"{q.label} at the load", p1=P1_FINITE,
                  posed="nh_error_estimate")


def decomposed(runs, quantity):
    """{(mesh, bc, model): Parts or None} over ``runs``, each run paired with the run of
    ``quantity.p1`` on the same mesh and boundary condition (None: no value, or no P1 twin)."""
    twins = {(r["mesh"], r["bc"]): r for r in runs if r["model"] == quantity.p1}
    return {(r["mesh"], r["bc"], r["model"]):
            quantity.parts(r, twins.get((r["mesh"], r["bc"]))) for r in runs}


@dataclass(frozen=True)
class Standing:
    """One model in one population: its errors (magnitudes) over the runs that gave one and
    how many runs it had."""

    model: str
    values: tuple
    runs: int

    @property
    def failed(self):
        return self.runs - len(self.values)

    @property
    def score(self):
        """The median over every run, a failed run counting as infinitely wrong (a failure
        scores against its model, never removes the population)."""
        if not self.runs:
            return math.inf
        return float(np.median(list(self.values) + [math.inf] * self.failed))

    @property
    def spread(self):
        """How much the median moves with the meshes (each run is one mesh, the unit of
        analysis): half the range of the medians with one run left out (a jackknife), those
        that stay finite; 0 with fewer than three runs (nothing left to take a median of)."""
        every = list(self.values) + [math.inf] * self.failed
        if len(every) < 3 or math.isinf(self.score):
            return 0.0
        meds = [float(np.median(every[:k] + every[k + 1:])) for k in range(len(every))]
        meds = [m for m in meds if math.isfinite(m)]
        return (max(meds) - min(meds)) / 2 if meds else 0.0


class Unordered(tuple):
    """The models a standing is not ordered from (every one of them, as a tuple): ``tied``
    those within the comparison's u_val alone (V&V 20: a difference below u_val is a tie);
    ``unresolved`` the rest, beyond u_val but within both medians' spread over the meshes
    (leaving one mesh out could reverse or level the order: not resolved, never called a
    tie)."""

    def __new__(cls, names, tied=()):
        out = super().__new__(cls, names)
        out.tied = tuple(n for n in names if n in tied)
        return out

    @property
    def unresolved(self):
        return tuple(n for n in self if n not in self.tied)


def standings(by_model, u, lost=None):
    """Rank a population: ``by_model`` {model: [error magnitude or None per run]}, ``u`` the
    validation uncertainty of a difference, ``lost`` {model: failed parts of runs that gave a
    number (unpaired modes)}, ranked on before the error. Returns [(rank, Standing,
    Unordered)], best first: a model whose score is within ``u`` (tied) or within ``u`` and
    the two medians' ``Standing.spread`` over the meshes in quadrature (not resolved) of the
    first of the last group (and that lost as many parts) shares that group's rank, so no
    model ranks above one with a smaller median; the :class:`Unordered` names every other
    model it is not ordered from, and which of them it is tied with (pair by pair, never
    chained, so two neighbours across a rank boundary are still named); failed runs count
    against their model, and models that all failed their median share the last rank."""
    lost = lost or {}
    u = max(u, ROUND_OFF)       # round-off never orders two models
    # models that all failed their median are ordered by how many runs failed
    st = sorted((Standing(m, tuple(abs(v) for v in vs if v is not None), len(vs))
                 for m, vs in by_model.items()),
                key=lambda s: (lost.get(s.model, 0), s.score, s.failed, s.model))

    def same(a, b):
        return lost.get(a.model, 0) == lost.get(b.model, 0)

    def tied(a, b):     # within the comparison's u_val
        return same(a, b) and (a.score == b.score or abs(a.score - b.score) < u)

    def unordered(a, b):    # or within both medians' spread over the meshes beside it
        return same(a, b) and (tied(a, b) or abs(a.score - b.score) < math.sqrt(
            u ** 2 + a.spread ** 2 + b.spread ** 2))

    out, head = [], None
    for k, s in enumerate(st):
        # the last group's rank where it is not ordered from that group's first: a model never
        # shares an earlier group's rank past one with a smaller median ranked apart
        if head is not None and unordered(s, head[1]):
            rank = head[0]
        else:
            rank = k + 1
            head = (rank, s)
        others = [o for o in st if o is not s]
        out.append((rank, s, Unordered(tuple(o.model for o in others if unordered(s, o)),
                                       {o.model for o in others if tied(s, o)})))
    return out


def mean_rank(ranks):
    """A model's overall standing over populations: the mean of its rank in each (a failure
    ranked where it fell), so that every population stays in every model's comparison."""
    return float(np.mean(ranks)) if ranks else None


def geometric_mean(scores, floors):
    """The geometric mean of a model's population scores, each floored at its population's
    uncertainty (an error below what the comparison resolves counts as that uncertainty);
    infinite where any population failed."""
    vals = [max(s, f, 1e-300) for s, f in zip(scores, floors)]
    if not vals:
        return None
    if any(math.isinf(v) for v in vals):
        return math.inf
    return float(np.exp(np.mean(np.log(vals))))
