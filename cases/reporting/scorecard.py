"""The scorecard's populations on the error model (``cases.measuring.error_model``): per case and
boundary condition, every model's model-form error against FEM P1 on the same tetrahedra, the
discretisation error those tetrahedra share, the total against the continuum, and the
uncertainties a comparison of them is read against; then the rankings across populations, with
failed runs counted against their model."""
import math
from dataclasses import dataclass, field, replace

import numpy as np

from .document import rel, rel_range
from ..measuring import error_model as E
from ..framework import LINEAR_STRAIN

# an identity check passes where a law that coincides with P1's in the linear regime stays
# within ten times the regime's strain of it (its geometric nonlinearity there is of the order
# of the strain); the tolerance is set apart from the distances it checks
IDENTITY_TOL = 10 * LINEAR_STRAIN

# in the linear regime (strain 1e-4) these laws are P1's own law: their distance to P1 is the
# numerical floor of a model-form comparison, not a model's error
SAME_LAW = {E.P1_LINEAR: ("fem-corotated", "fem-neohookean")}


@dataclass
class Population:
    """One case under one boundary condition: ``parts`` {model: [Parts or None per run]},
    ``quantity`` the case's decomposed quantity, ``u_model_form`` the uncertainty of a
    model-form comparison, ``u_continuum`` the reference's (its estimate or, larger, its spread
    over the meshes) with ``spread_defect`` where the spread exceeds the estimate, ``patch_test``
    whether it is one, ``quick`` whether its runs are a quick preview."""

    case: str
    bc: str
    quantity: object
    parts: dict
    u_model_form: float
    u_continuum: float
    spread_defect: bool
    patch_test: bool
    quick: bool
    meshes: dict = field(default_factory=dict)     # {model: [mesh per run]}
    lost: dict = field(default_factory=dict)       # {model: [unpaired modes per run]}
    lost_total: dict = field(default_factory=dict)  # the same against the continuum
    where: str = ""        # ' at the load' for a case's second population on one bc
    # each mesh poses its own continuum problem (the case's ``per_mesh_continuum``): the
    # values' spread over the meshes is no uncertainty, u_num is the estimate alone
    per_mesh: bool = False
    # FEM P1, the twin, locks here (the case's ``locking_prone``): shown, never pooled
    locking: bool = False
    # at finite load, the linear law within NEARLY_LINEAR of P1 with the reference's law:
    # the linear regime's observation again, shown and never pooled a second time
    nearly_linear: bool = False

    @property
    def ranked(self):
        """Whether the overall ranking pools this population: neither a patch test (pass or
        fail, the consistency limit's subject) nor locking-prone (its model-form error ranks
        closeness to a locked mesh) nor, at finite load, a load the linear law meets within
        NEARLY_LINEAR (the linear regime's observation counted twice)."""
        return not self.patch_test and not self.locking and not self.nearly_linear

    @property
    def unpaired(self):
        """{model: failed parts (unpaired modes) over its runs}, where the quantity has them."""
        return {m: sum(v) for m, v in self.lost.items()}

    @property
    def unpaired_total(self):
        """{model: failed parts against the continuum (its unpaired modes) over its runs}."""
        return {m: sum(v) for m, v in self.lost_total.items()}

    def without(self, mesh):
        """The population without its runs on ``mesh`` (the unit of analysis left out)."""
        keep = {m: [k for k, x in enumerate(self.meshes[m]) if x != mesh] for m in self.parts}
        return replace(self, parts={m: [self.parts[m][k] for k in ks] for m, ks in keep.items()},
                       meshes={m: [self.meshes[m][k] for k in ks] for m, ks in keep.items()},
                       lost={m: [self.lost[m][k] for k in keep[m]] for m in self.lost},
                       lost_total={m: [self.lost_total[m][k] for k in keep[m]]
                                   for m in self.lost_total})

    @property
    def label(self):
        return f"{self.case}/{self.bc}{self.where}"

    @property
    def finite(self):
        """Whether this population is judged at finite load (P1 with the reference's law)."""
        return self.quantity.p1 != E.P1_LINEAR

    @property
    def identity(self):
        """The models this population's model-form comparison cannot judge: FEM P1 itself and
        the laws that coincide with its law here (in the linear regime every FEM law is P1's):
        identity checks, never ranked."""
        return {self.quantity.p1, *SAME_LAW.get(self.quantity.p1, ())}

    def errors(self, model, part):
        """[|part| or None per run] of ``model`` (None: the run, or that part, failed)."""
        return [None if p is None or getattr(p, part) is None else abs(getattr(p, part))
                for p in self.parts[model]]

    def standings(self, part="model_form"):
        """``error_model.standings`` of the models other than the identity checks (P1 itself
    and the laws that coincide with it)."""
        u = self.u_model_form if part == "model_form" else self.u_continuum
        return E.standings({m: self.errors(m, part) for m in self.parts
                            if part != "model_form" or m not in self.identity}, u,
                           self.unpaired if part == "model_form" else self.unpaired_total)

    def discretisation(self):
        """FEM P1's |discretisation error| on each mesh (the same for every model there)."""
        runs = self.parts.get(self.quantity.p1, [])
        return [abs(p.discretisation) for p in runs
                if p is not None and p.discretisation is not None]


def populations(runs_by_case, declared, quick, patch_tests, estimate_keys):
    """The Populations of every case with a decomposed quantity (``Case.decompositions``: the
    linear regime's, the load's): ``runs_by_case`` {case: runs}, ``declared`` {case: Case},
    ``quick`` {case: bool}, ``patch_tests`` {case: bcs}, ``estimate_keys`` {case: the run key
    of its reference's error estimate}."""
    out = []
    for case, all_runs in runs_by_case.items():
        quantities = declared[case].decompositions()
        for q in quantities:
            # a run is of the population where its comparison is posed (a reference there)
            runs = [r for r in all_runs if not q.posed or r.get(q.posed) is not None]
            if not any(_key(q) in r for r in runs):
                continue                 # metrics written before the case declared it
            at_load = q.p1 != E.P1_LINEAR and len(quantities) > 1
            for bc in dict.fromkeys(r["bc"] for r in runs):
                out.append(_population(case, bc, q, [r for r in runs if r["bc"] == bc],
                                       quick[case], bc in patch_tests[case],
                                       # the reference that poses it gives its estimate
                                       q.posed or estimate_keys[case],
                                       " at the load" if at_load else "",
                                       bc in getattr(declared[case], "per_mesh_continuum",
                                                     ()),
                                       bc in getattr(declared[case], "locking_prone", ())))
    return [replace(p, nearly_linear=True) if p.finite and
            (lin := linearisation(p)) is not None and lin <= NEARLY_LINEAR else p
            for p in out]


def linearisation(p):
    """The linear law's model-form error at a finite-load population (its median over the
    meshes against P1 with the reference's law: the linearisation error at the load), or None
    where it has no finite one."""
    st = next((s for _, s, _ in p.standings() if s.model == E.P1_LINEAR), None)
    return st.score if st is not None and math.isfinite(st.score) else None


# a finite load the linear law meets within this (its linearisation error, model-form against
# P1 with the reference's law) tests a nearly linear response
NEARLY_LINEAR = 0.05


def _population(case, bc, q, rs, quick, patch_test, estimate_key, where, per_mesh=False,
                locking=False):
    dec = E.decomposed(rs, q)
    failed_modes = getattr(q, "unpaired", None)
    failed_total = getattr(q, "unpaired_total", None)
    parts, meshes, lost, lost_total = {}, {}, {}, {}
    for r in rs:
        parts.setdefault(r["model"], []).append(dec[(r["mesh"], r["bc"], r["model"])])
        meshes.setdefault(r["model"], []).append(r["mesh"])
        if failed_modes:
            lost.setdefault(r["model"], []).append(r.get(failed_modes) or 0)
        if failed_total:
            lost_total.setdefault(r["model"], []).append(r.get(failed_total) or 0)
    twins = [abs(p.model_form) for m in SAME_LAW.get(q.p1, ()) if m in parts
             for p in parts[m] if p is not None]
    # P1's own model run against the twin a Norm is measured on (the reference's P1): how
    # closely two solvers of one discrete problem agree, below which nothing is resolved
    if isinstance(q, E.Norm):
        twins += [abs(r[q.model_form]) for r in rs
                  if r["model"] == q.p1 and r.get(q.model_form) is not None]
    u_mf = max([E.ROUND_OFF] + twins)
    est = [r[estimate_key] for r in rs if r.get(estimate_key) is not None]
    cont = {r["mesh"]: r.get(q.continuum) for r in rs} if hasattr(q, "continuum") else {}
    cont = [] if per_mesh else [_first(v) for v in cont.values() if v is not None]
    u_c, defect = E.u_num(max(est) if est else None, cont)
    return Population(case, bc, q, parts, u_mf, u_c, defect, patch_test, quick, meshes, lost,
                      lost_total=lost_total, where=where, per_mesh=per_mesh, locking=locking)


def _key(q):
    """The run key whose presence shows the runs were measured for ``q``."""
    return getattr(q, "key", None) or q.model_form


def _first(v):
    """A scalar quantity, or the last load step of a sequence (the largest load)."""
    return float(v[-1]) if isinstance(v, (list, tuple)) else float(v)


def cell(standing, tied_with=None):
    """'median [min-max] n/N' of a standing's runs, with its failed runs and tie named."""
    s = standing
    if not s.values:
        text = f"failed, 0 of {s.runs}"
    elif math.isinf(s.score):
        text = (f"failed at the median: {len(s.values)} of {s.runs} runs gave "
                f"{', '.join(f'{rel(v)}' for v in s.values)}")
    else:     # the median over every run, a failed one counted as infinitely wrong
        text = (f"{rel(s.score)} [{rel_range(min(s.values), max(s.values))}] "
                f"{len(s.values)}/{s.runs}" + (f", {s.failed} failed" if s.failed else ""))
    return text + unordered_text(tied_with)


def unordered_text(others):
    """'; tied with A; not resolved from B (...)' of an ``error_model.Unordered`` (a plain
    tuple: every name tied)."""
    if not others:
        return ""
    tied = getattr(others, "tied", tuple(others))
    loose = getattr(others, "unresolved", ())
    return ((f"; tied with {', '.join(tied)}" if tied else "")
            + (f"; not resolved from {', '.join(loose)} (beyond u_val, within both medians' "
               "spread over the meshes)" if loose else ""))


def unresolved(pops, models, finite=False):
    """{(upper, lower): what was left out} for each pair of neighbours of
    ``ranked(overall(...))`` whose order reverses when one mesh family is left out of every
    population (the mesh, not the run, is the unit of analysis), or one case is left out: the
    first such mesh, else case."""
    order = [m for _, m, _, _ in ranked(overall(pops, models, finite))]
    out = {}
    for left_out, subset in _subsets(pops, finite):
        alt = overall(subset, models, finite)
        for a, b in zip(order, order[1:]):
            # reversed, or level: an order one subset cannot keep is not resolved
            if (a, b) not in out and a in alt and b in alt and \
                    _order(alt[a], a)[:1] >= _order(alt[b], b)[:1]:
                out[(a, b)] = left_out
    # a pair the direct comparison orders the same way under every leave-out is resolved
    return {k: v for k, v in out.items() if not paired_ahead(pops, *k, finite)}


def unresolved_pairs(pops, models, finite=False):
    """{(upper, lower)} over every pair of ``ranked(overall(...))``, not its neighbours alone,
    whose order reverses or levels when one mesh family or one case is left out, or whose
    mean ranks are equal: what no group boundary may separate."""
    base = ranked(overall(pops, models, finite))
    order = [m for _, m, _, _ in base]
    out = {(m, t) for _, m, _, t in base if t}
    for _, subset in _subsets(pops, finite):
        alt = overall(subset, models, finite)
        for i, a in enumerate(order):
            for b in order[i + 1:]:
                if a in alt and b in alt and _order(alt[a], a)[:1] >= _order(alt[b], b)[:1]:
                    out.add((a, b))
    return {(a, b) for a, b in out if not paired_ahead(pops, a, b, finite)}


def _paired_ratio(subset, a, b, finite):
    """The geometric mean over the cases (a case's boundary conditions averaged first) of
    a's population score over b's, on the populations of one regime both ran in; None where
    either failed in one (a failed run has no ratio) or none is shared."""
    by_case = {}
    for p in subset:
        if p.finite != finite or not p.ranked:
            continue
        score = {st.model: st.score for _, st, _ in p.standings()}
        if a not in score or b not in score:
            continue
        if not (math.isfinite(score[a]) and math.isfinite(score[b])) or \
                score[a] <= 0 or score[b] <= 0:
            return None
        by_case.setdefault(p.case, []).append(math.log(score[a] / score[b]))
    if not by_case:
        return None
    return math.exp(float(np.mean([np.mean(v) for v in by_case.values()])))


def paired_ahead(pops, a, b, finite=False):
    """Whether a's model-form error is below b's paired, population by population: the
    geometric mean of their ratios below 1 on every population and whatever mesh family or
    case is left out (the two compared directly, not through their ranks among the others),
    and a resolved ahead of b in at least one population as its case's report orders them
    (neither tied with the other nor within both medians' spread over the meshes): a
    difference no population resolves is not resolved by pooling them."""
    ratios = [_paired_ratio(pops, a, b, finite)] + [
        _paired_ratio(subset, a, b, finite) for _, subset in _subsets(pops, finite)]
    return all(r is not None and r < 1.0 for r in ratios) and any(
        _resolved_before(p, a, b) for p in pops if p.finite == finite and p.ranked)


def _resolved_before(p, a, b):
    """Whether population ``p`` orders a before b beyond their uncertainty (not tied, not
    within both medians' spread over the meshes)."""
    st = {s.model: (s.score, tie) for _, s, tie in p.standings()}
    if a not in st or b not in st:
        return False
    (sa, ta), (sb, tb) = st[a], st[b]
    apart = b not in ta and a not in tb
    return apart and sa < sb


def not_resolved_from(pops, models, first, finite=False):
    """{model: what was left out}: the models ranked after ``first`` that come level with it
    or before it when one mesh family or one case is left out, pair by pair with ``first``
    (never chained through a neighbour): ``first`` is not resolved from them."""
    order = [m for _, m, _, _ in ranked(overall(pops, models, finite))]
    after = order[order.index(first) + 1:] if first in order else []
    out = {}
    for left_out, subset in _subsets(pops, finite):
        alt = overall(subset, models, finite)
        if first not in alt:
            continue
        for m in after:
            if m in alt and m not in out and \
                    _order(alt[m], m)[:1] <= _order(alt[first], first)[:1]:
                out[m] = left_out
    return {m: v for m, v in out.items() if not paired_ahead(pops, first, m, finite)}


def _subsets(pops, finite):
    """[(what was left out, the populations without it)]: each mesh family, then each case
    where the regime has more than one (the case is a unit too: an order one case decides is
    not resolved)."""
    cases = sorted({p.case for p in pops if p.finite == finite
                    and (p.ranked or counts_failures(p))})
    out = [(mesh, [p.without(mesh) for p in pops]) for mesh in _meshes(pops, finite)]
    if len(cases) > 1:
        out += [(case, [p for p in pops if p.case != case]) for case in cases]
    return out


def _meshes(pops, finite):
    return sorted({x for p in pops if p.finite == finite for ms in p.meshes.values()
                   for x in ms})


def spread(pops, models, finite=False):
    """{model: (smallest, largest) geometric mean} over the rankings that leave one mesh
    family out of every population: how much the unit of analysis moves the figure."""
    out = {}
    for mesh in _meshes(pops, finite):
        for m, e in overall([p.without(mesh) for p in pops], models, finite).items():
            if e[1] is not None and math.isfinite(e[1]):
                lo, hi = out.get(m, (e[1], e[1]))
                out[m] = (min(lo, e[1]), max(hi, e[1]))
    return out


def counts_failures(p):
    """Whether population ``p``, which the ranking leaves out for its numbers, still counts in
    it for its failures: not a patch test (the consistency limit's subject), and a ranked
    model failed there as a ranked population would read it, at the median (half its runs or
    more without a number) or with an unpaired mode (a failure is a result wherever it
    happened)."""
    return not p.ranked and not p.patch_test and any(
        _failure_key(p, st) != (0, 0) for _, st, _ in p.standings())


def _failure_key(p, standing):
    """What orders a model in a failure-only ranking, as a ranked population's standings
    would: its unpaired modes first, then its failed runs where they fail its median (a
    failed run counted as infinitely wrong); fewer failures leave a median its numbers would
    decide, so they order nothing here."""
    lost = p.unpaired.get(standing.model, 0)
    return lost, standing.failed if math.isinf(standing.score) else 0


def failure_rank(p, model):
    """``model``'s rank in a population counted for its failures alone (``counts_failures``):
    after every model whose failures there weigh less (``_failure_key``), so the models that
    did not fail at the median share the first rank (its numbers order nothing)."""
    keys = {st.model: _failure_key(p, st) for _, st, _ in p.standings()}
    return 1 + sum(k < keys[model] for k in keys.values())


def overall(pops, models, finite=False):
    """{model: (mean rank, geometric mean of its finite population scores, failed runs,
    failed populations, populations, failed runs where the numbers are left out, those of
    them that rank (``failure_ranks``))} over the
    populations of one regime (``finite``): every population counts for every model, a failed
    run (no number, or at the load no converged solve) against its model; each case weighs one
    (its boundary conditions are averaged first: two bcs of one case are not two independent
    observations); each score floored at its population's model-form uncertainty; P1 itself
    left out (an identity check). The populations ``Population.ranked`` leaves out for their
    numbers (patch tests, locking-prone problems, nearly linear finite loads) give no score;
    those where a model failed at the median (``counts_failures``, not patch tests) still
    give each model a rank by its failures (``failure_rank``), so a failure counts wherever
    it happened, as it would in a ranked population;
    a failed run counts once, as infinitely wrong in its population's rank (``_order``)."""
    used = [p for p in pops if p.finite == finite and p.ranked]
    checked = [p for p in pops if p.finite == finite and counts_failures(p)]
    out = {}
    for m in models:
        mine = [p for p in used if m in p.parts and m not in p.identity]
        if not mine:
            continue
        by_case, ranks_by_case = {}, {}
        for p in mine:
            rank, st = next((r, s) for r, s, _ in p.standings() if s.model == m)
            by_case.setdefault(p.case, []).append((st.score, p.u_model_form))
            ranks_by_case.setdefault(p.case, []).append(rank)
        outside = [p for p in checked if m in p.parts and m not in p.identity]
        for p in outside:
            ranks_by_case.setdefault(p.case, []).append(failure_rank(p, m))
        ranks = [float(np.mean(c)) for c in ranks_by_case.values()]
        scores = [E.geometric_mean([s for s, _ in c if math.isfinite(s)],
                                   [f for s, f in c if math.isfinite(s)])
                  for c in by_case.values()]
        scores = [s for s in scores if s is not None]
        failed = sum(sum(v is None for v in p.parts[m]) for p in mine)
        lost = sum(not math.isfinite(s) for c in by_case.values() for s, _ in c)
        # every failed run where the numbers are left out, whether or not it moved the rank,
        # and those of them that ranked (where they fail the model's median: ``_failure_key``)
        left = [p for p in pops if p.finite == finite and not p.ranked and not p.patch_test
                and m in p.parts and m not in p.identity]
        failed_outside = sum(sum(v is None for v in p.parts[m]) for p in left)
        ranked_outside = sum(sum(v is None for v in p.parts[m]) for p in left
                             if failure_ranks(p, m))
        out[m] = (E.mean_rank(ranks), E.geometric_mean(scores, [0.0] * len(scores)), failed,
                  lost, len(mine), failed_outside, ranked_outside)
    return out


def failure_ranks(p, model):
    """Whether ``model``'s failed runs in population ``p``, which the ranking leaves out for
    its numbers, rank it there: where they fail its median (half its runs or more without a
    number), as in a ranked population; fewer are counted against it and rank nothing."""
    return any(st.model == model and st.failed and math.isinf(st.score)
               for _, st, _ in p.standings())


def largest(pops, model, finite=False):
    """A model's largest population score (the median over the meshes, a failed run counted
    as infinitely wrong) over the ranked populations of one regime, or None where it ran in
    none."""
    scores = [s.score for p in pops if p.finite == finite and p.ranked
              for _, s, _ in p.standings() if s.model == model]
    return max(scores) if scores else None


def _order(entry, model):
    """The ranking's order of one model: by mean rank (a failed run already ranked where it
    fell in its population, counted once), then by geometric mean."""
    return (entry[0], entry[1] or 0.0, model)


def failed(entry):
    """Whether an ``overall`` entry has a failed run, where its numbers are ranked or not."""
    return bool(entry[2] or entry[5])


def failed_text(entry):
    """'3 failed runs (2 where the numbers are left out)' of an ``overall`` entry ('1 failed
    run', '2 failed runs where the numbers are left out'); '' for none. Where some of those
    left out fail no median, and so rank nothing (``failure_ranks``), it says how many ranked
    and how many are counted only: '3 failed runs where the numbers are left out: 2 ranked,
    1 counted only'."""
    n = entry[2] + entry[5]
    if not n:
        return ""
    text = f"{n} failed run{'s' if n != 1 else ''}"
    counted = entry[5] - entry[6]
    split = ("" if not counted else f"{entry[6]} ranked, {counted} counted only" if entry[6]
             else "counted only")
    if entry[5] and entry[2]:
        return text + f" ({entry[5]} where the numbers are left out" + (
            f": {split})" if split else ")")
    return text + (" where the numbers are left out" + (f": {split}" if split else "")
                   if entry[5] else "")


def ranked(means):
    """[(rank, model, overall's entry, tied_with)], best first (``_order``); equal mean ranks
    share a rank (tied)."""
    order = sorted(means, key=lambda m: _order(means[m], m))
    out, head, rank = [], None, 0
    for k, m in enumerate(order):
        if head is not None and _order(means[m], m)[:1] == _order(means[head], head)[:1]:
            out.append((rank, m, means[m], head))
            continue
        head, rank = m, k + 1
        out.append((rank, m, means[m], None))
    return out


def describe(entry, rng=None):
    """'mean rank r, geometric mean g [range leaving one mesh family out]' with the failed
    runs and populations of ``overall``."""
    r, g, _, lost, n, *_ = entry
    text = f"mean rank {r:.3g}"
    if lost:    # a failed population scores infinitely wrong: no finite mean exists
        text += (f", geometric mean failed ({lost} of {n} populations failed at the median"
                 + (f"; {rel(g)} over the other {n - lost}" if g is not None else "") + ")")
    elif g is not None:
        text += f", geometric mean {rel(g)}"
        if rng:
            text += f" [{rel(rng[0])}-{rel(rng[1])} leaving one mesh family out]"
    if failed(entry):
        text += f", {failed_text(entry)}"
    return text


def case_findings(name, quantities, runs, patch_tests=(), estimate_key="p2_error_estimate",
                  per_mesh_continuum=(), locking_prone=()):
    """(opening lines, tables) of one case's report on the error model, for each of its
    decomposed ``quantities`` (``Case.decompositions``): per boundary condition, the closest
    and farthest model by model-form error with the discretisation error the meshes share,
    and the models whose total is below P1's only by cancellation; a Table per boundary
    condition with every model's standing."""
    from .document import Table

    class Declared:
        @staticmethod
        def decompositions():
            return tuple(quantities)
    Declared.per_mesh_continuum = tuple(per_mesh_continuum)
    Declared.locking_prone = tuple(locking_prone)
    pops = populations({name: runs}, {name: Declared}, {name: False},
                       {name: set(patch_tests)}, {name: estimate_key})
    lines, tables = [], []
    for p in pops:
        st = p.standings()
        if not st:
            continue
        where = f"[{p.bc}{p.where}] " if len(pops) > 1 else ""
        disc = p.discretisation()
        twins = [m for m in sorted(p.identity - {p.quantity.p1}) if m in p.parts]
        # the check's tolerance is set apart from what it checks: the geometric
        # nonlinearity a law may show at the linear regime's strain
        same = [m for m in twins if all(v is not None and v <= IDENTITY_TOL
                                        for v in p.errors(m, "model_form"))]
        ok = [(r, s, t) for r, s, t in st if math.isfinite(s.score)]
        line = (f"{where}What replacing FEM P1 costs ({p.quantity.label}, model-form error, "
                "median over the meshes" + ("; locking-prone: FEM P1 locks here, so the order "
                                            "below is closeness to a locked mesh, not a "
                                            "ranking of the models" if p.locking else "")
                + "): ")
        if twins:
            line += (f"identity checks, P1's own law here, not ranked: {', '.join(twins)}"
                     + " (largest distance to FEM P1: " + ", ".join(
                         f"{m} {rel(max(p.errors(m, 'model_form')), 2)}" for m in twins
                         if all(v is not None for v in p.errors(m, "model_form")))
                     + (f"; equal to it within the linear regime's nonlinearity "
                        f"{IDENTITY_TOL:g}: {', '.join(same)}" if same else
                        f"; none within the linear regime's nonlinearity {IDENTITY_TOL:g}")
                     + ")" + ("; " if ok else ""))
        lin = linearisation(p) if p.finite else None
        nearly = lin is not None and lin < NEARLY_LINEAR
        if nearly:
            # one observation is not counted twice: the linear regime's population ranks it
            line += (f"nearly linear at this load (fem-linear {rel(lin)} from neo-Hookean P1 "
                     f"on this quantity, below {NEARLY_LINEAR:g}): the linear regime's "
                     "observation again, shown in the table, not ranked a second time")
        elif ok:
            first = "first (fewest unpaired modes, then the error)" if p.lost and any(
                p.unpaired.values()) else "nearest the locked twin" if p.locking else "closest"
            # the farthest is the last of every model, a failed one included
            line += f"{first} {ok[0][1].model} ({cell(ok[0][1])}), farthest {st[-1][1].model} " \
                    f"({cell(st[-1][1])})"
            tied = list(ok[0][2])
            if ok[0][2].tied:
                line += f"; tied with {ok[0][1].model} (within u_val {rel(p.u_model_form, 2)}" \
                        f"): {', '.join(ok[0][2].tied)}"
            if ok[0][2].unresolved:
                line += f"; {ok[0][1].model} not resolved from " \
                        f"{', '.join(ok[0][2].unresolved)} (beyond u_val, within both " \
                        "medians' spread over the meshes)"
            first = [f"{m} ({how})"
                     for m, how in population_contenders(p).items() if m not in tied]
            if first:
                line += f"; {ok[0][1].model} is not resolved from " + ", ".join(first)
        elif not same:
            line += "no model gave it on every mesh"
        failed = [f"{s.model} ({s.failed} of {s.runs} failed)" for _, s, _ in st if s.failed]
        if failed:
            line += "; failed runs, counted against their model: " + ", ".join(failed)
        if disc and p.patch_test:
            # a patch test's continuum is P1's own field: an identity check, not a resolution
            line += (f". FEM P1 reproduces this patch test's continuum to {rel(max(disc))} "
                     + ("(exact to round-off: no discretisation error here)"
                        if max(disc) <= E.ROUND_OFF else
                        f"(beyond round-off, {rel(E.ROUND_OFF)}: P1 fails its own patch test)"))
        elif disc and nearly:
            line += (f". FEM P1 itself is {rel(np.median(disc))} "
                     f"[{rel_range(min(disc), max(disc))}] from the continuum on these meshes "
                     "(discretisation error)")
        elif disc and p.u_continuum > np.median(disc) / E.JUDGES:
            # the continuum's u_num exceeds a fifth of P1's own error: nothing is judged closer
            line += (f". FEM P1 itself is {rel(np.median(disc))} "
                     f"[{rel_range(min(disc), max(disc))}] from the continuum on these meshes "
                     f"(discretisation error); the continuum's own u_num, "
                     f"{rel(p.u_continuum, 2)}, exceeds a fifth of it, so no model is judged "
                     "closer to the continuum than P1 or as far")
        elif disc:
            line += (f". FEM P1 itself is {rel(np.median(disc))} "
                     f"[{rel_range(min(disc), max(disc))}] from the continuum on these meshes "
                     "(discretisation error)")
            # |total| < |P1's| with a model-form error: its error opposes P1's; a model that
            # leaves more continuum modes unpaired than P1 is not closer, whatever its rest
            lost = p.unpaired_total
            p1_lost = lost.get(p.quantity.p1, 0)
            closer = [s.model for _, s, _ in ok
                      if _median(p.errors(s.model, "total")) is not None
                      and np.median(disc) - _median(p.errors(s.model, "total"))
                      > p.u_continuum]
            cancel = [m for m in closer if lost.get(m, 0) <= p1_lost]
            lossy = [m for m in closer if m not in cancel]
            level = [s.model for _, s, _ in ok if s.model not in closer
                     and lost.get(s.model, 0) <= p1_lost
                     and _median(p.errors(s.model, "total")) is not None
                     and abs(np.median(disc) - _median(p.errors(s.model, "total")))
                     <= p.u_continuum]
            if lossy:
                line += ("; closer to the continuum than P1 on the modes it pairs, yet not "
                         f"closer: it leaves more continuum modes unpaired than P1 ({p1_lost}): "
                         + ", ".join(f"{m} ({lost[m]})" for m in lossy))
            if cancel:
                line += ("; closer to the continuum than P1 only by cancelling its error: "
                         + ", ".join(cancel))
            if level:
                line += ("; as far from the continuum as P1 within u_val "
                         f"{rel(p.u_continuum, 2)}: " + ", ".join(level))
        lines.append(line + ".")
        rows = [[p.bc, rank, s.model, cell(s, tie), cell_of(p.errors(s.model, "total"))
                 + (f"; {p.unpaired_total[s.model]} of {p.quantity.count * s.runs} modes "
                    "unpaired" if p.unpaired_total.get(s.model) else "")]
                + ([f"{p.unpaired.get(s.model, 0)} of {p.quantity.count * s.runs}"]
                   if p.lost else [])
                for rank, s, tie in st]
        rows.append([p.bc, "-", f"{p.quantity.p1} (FEM P1)", "0 by construction",
                     cell_of(disc)] + (["0"] if p.lost else []))
        rows += [[p.bc, "-", f"{m} (identity check: P1's law here)",
                  cell_of(p.errors(m, "model_form")), cell_of(p.errors(m, "total"))]
                 + ([f"{p.unpaired.get(m, 0)} of {p.quantity.count * len(p.parts[m])}"]
                    if p.lost else []) for m in twins]
        tables.append(Table(f"Model-form error ({p.quantity.label}) per model, against FEM P1 "
                            "on the same tetrahedra, beside the total against the continuum "
                            f"(u_val: model-form {rel(p.u_model_form, 2)}, total "
                            f"{rel(p.u_continuum, 2)}"
                            + (", its estimate widened to the reference's spread over the "
                               "meshes, which exceeds it" if p.spread_defect else "")
                            + (", the reference's estimate alone: each mesh poses its own "
                               "continuum problem" if p.per_mesh else "") + "; the rank "
                            "orders the medians, a model sharing its group's rank where "
                            "not ordered from its first, its cell naming every model it is "
                            "not ordered from, whatever that one's rank):",
                            ["bc", "rank" if p.ranked else
                             "order (the overall ranking counts its failures alone)"
                             if counts_failures(p) else "order (not in the overall ranking)",
                             "model", "model-form", "total"]
                            + (["unpaired P1 modes (failed, ranked first)"] if p.lost else []),
                            rows))
    return lines, tables


def population_contenders(p):
    """{model: 'first without MESH' or 'level with it without MESH'}: the models other than
    the closest that come first, or share the first rank (within the uncertainty), when one
    mesh is left out: the closest is not resolved from them."""
    st = p.standings()
    if not st:
        return {}
    top = st[0][1].model
    meshes = sorted({x for ms in p.meshes.values() for x in ms})
    out = {}
    for mesh in meshes if len(meshes) > 1 else ():     # one mesh left out leaves none
        alt = p.without(mesh).standings()
        for k, (r, s, _) in enumerate(alt):
            if r == 1 and s.model != top and s.model not in out:
                out[s.model] = (f"first without {mesh}" if k == 0
                                else f"level with it without {mesh}")
    return out


def _median(values):
    """The median over every run, a run without a value counted as infinitely wrong."""
    if not values or all(x is None for x in values):
        return None
    return float(np.median([math.inf if x is None else x for x in values]))


def cell_of(values):
    """'median [min-max] n/N' over every run (a failed one counted as infinitely wrong)."""
    v = [x for x in values if x is not None]
    if not v:
        return "n/a"
    med = _median(values)
    return ("failed at the median" if math.isinf(med) else rel(med)) + \
        f" [{rel_range(min(v), max(v))}] {len(v)}/{len(values)}"
