"""What the artefact study's cells say: the paper's question (section 5: do the alternating
bulges and necks come from the mirror symmetry of the tetrahedra or from the missing normal
stress?) answered from the period-2 signature, and which reading of the paper's equations its
own observables point to. Everything here is computed from the cells' rows.

The order of the analysis:

1. The metric's own check (``metric_check``): on each (size, base) the signature's weights are
   applied to smooth test fields (a barrel, Gaussian bulges, end boundary layers down to half a
   layer spacing, at one end or both); a configuration whose worst smooth field leaks a fifth
   of the clear level or more
   decides nothing. Its sensitivity to an alternation confined to the end layers is measured
   too: what a "no clear signature" cannot exclude.
2. The decomposition (``units``): per configuration (size, base) of the mirrored five split each
   model's part (model - FEM P1
   on the same tetrahedra) and FEM P1's own signature, each read against its own uncertainty
   u; the same parts on the conforming splits (the controls), each with its own u, decide
   whether a resolved part is the mirror's.
3. The hypotheses: (a) the mirror, from the decomposition; (b) the normal stress, on pairs
   where a term changes the signature; (c) the model's consistency, a rank correlation, signed
   and unsigned, at two clustering tolerances, with its interval.
4. The reading: the paper's decidable observables on its own lattice, each against its
   threshold and the damping nobody measured.

A class, a cause or a verdict is stated only where the numbers resolve it against their
uncertainty on every configuration it rests on; everything else is 'not resolved' or 'not
decided' with
the reason. The configuration of analysis is a (size, base) of the mirrored mesh; two models whose
signatures agree to SAME are one observation there, and every count is "n of N" over the
distinct ones."""
import numpy as np
from scipy.stats import spearmanr

from model.static import SHORTEST_STEP

from ...reporting.document import fmt
from ...library import paper_cube as P
from ...measuring.metrics import ALTERNATION_CLEAR, nyquist_weights
from .study import (DECISIVE, FIVE_TETS, FIXED_NORMAL_C, HELD, LINEAR_SCALE, LITERAL_NORMAL,
                    SPLITS, SPLITS_TRIED, YARDSTICK as YARDSTICK_MODEL, _free_layers, held, short)

PAPER_COST = 10.0      # the paper (its Figure 2): the time of one step over msm's, more than 10
RUN_S = P.PUSH_MM / P.SPEED_MM_S   # the paper's run: the push, 1.7 mm at 1.7 mm/s
REMOVES = 0.5          # a factor holds as the cause where it removes the pattern this often
TRACKS = 0.7           # a rank correlation from which the signature tracks the patch error
RATIO = 3.0            # one value dominates another (or its uncertainty) from this factor
NEAR = 0.2             # a value within this fraction of a threshold is "at the threshold"
CLEAR = ALTERNATION_CLEAR   # a signature is clear from this fraction of the lateral bulge
LEAK_SHARE = 0.2       # a configuration decides where its worst smooth field leaks below this
#                        share of the clear level (a fifth: as a reference's estimate must be
#                        below a fifth of the error it ranks)
DECIDING_LEAK = LEAK_SHARE * CLEAR
GROWS = 0.0            # a growth rate above this flutters (the glossary's growth: above zero)
ROUND_OFF_FLOOR = 1e-8      # no uncertainty below this (the static solves' own tolerance)
SAME = 1e-3            # two signatures agreeing to this (relative, 3 significant figures): one
COARSE = 1e-2          # the coarser clustering (2 significant figures) (c) is also read at
ACTIVE = 1e-6          # a term changes a signature beyond round-off from this (relative)
WIDTHS = (2, 3, 5)     # the test Gaussians' standard deviations, in layer spacings (2 the
#                        narrowest smooth bulge; 3 and 5 between the weights' design widths)
DECAYS = (2, 5)        # the smooth test boundary layers' decay lengths, in layer spacings
SHARP_DECAYS = (1, 0.5)   # end layers sharper than two spacings: not smooth on these layers
MIN_RESOLVED = 4       # (c) correlates over at least this many resolved signatures
END_LAYERS = 3         # the end-localised alternation: this many free layers at each end
Z95 = 1.96             # the two-sided 95 % normal quantile
MIRRORED, UNMIRRORED = SPLITS["five"], SPLITS["five-unmirrored"]
CONFORMING_CONTROLS = (SPLITS["six"], SPLITS["bcc"])
CONTROL = "fem"


# ---------------------------------------------------------------------------- thresholds

def against(value, threshold):
    """'above', 'below' or 'at' (within NEAR of ``threshold``: at the threshold, not decided)
    for a non-negative ``value``; None where it is None."""
    if value is None:
        return None
    if abs(value - threshold) <= NEAR * threshold:
        return "at"
    return "above" if value > threshold else "below"


def bounded(lo, hi, threshold):
    """A value known only within [lo, hi] against ``threshold``: 'above' where even ``lo`` is
    above it (beyond NEAR), 'below' where even ``hi`` is below it, else 'at' (not decided)."""
    if against(lo, threshold) == "above":
        return "above"
    if hi is not None and against(hi, threshold) == "below":
        return "below"
    return "at"


def clear_call(s, u, own_factor):
    """Whether a signature ``s`` (over the reference's mean, the glossary's alternation rel)
    with uncertainty ``u`` is clear: read on both normalisations, the reference's mean over
    all layers (factor 1) and the model's own mean over its free layers (``own_factor``, the
    reference's mean over the model's own), each as the interval |s| -+ u. 'above' (clear)
    where both are above CLEAR, 'below' where both are below it, 'at' (not decided: at the
    threshold, or the two normalisations disagree) otherwise; with each normalisation's call.
    None where the signature is not defined."""
    if s is None:
        return None, {}
    lo, hi = max(abs(s) - u, 0.0), abs(s) + u
    by = {"reference": bounded(lo, hi, CLEAR)}
    if own_factor is not None:
        by["own"] = bounded(lo * own_factor, hi * own_factor, CLEAR)
    calls = set(by.values())
    return (calls.pop() if len(calls) == 1 else "at"), by


def one_observation(a, b):
    """Whether two models' rows of a configuration are one observation: the same mirrored
    signature to round-off (ACTIVE: a term that changes nothing on that mesh), or the same to
    COARSE (two significant figures, as (c) clusters) on every cell both have there
    (mirrored, controls, unmirrored)."""
    if same(a["five"], b["five"], ACTIVE):
        return True
    pairs = [(a["five"], b["five"]), (a["unmirrored"], b["unmirrored"])] + [
        (a["controls"][x], b["controls"][x]) for x in a["controls"]]
    return all(same(x, y, COARSE) or (x is None and y is None) for x, y in pairs
               if not isinstance(x, str) and not isinstance(y, str))


def same(a, b, tol=SAME):
    """Whether two signatures are one observation (agree to ``tol`` of the larger, or both
    below the round-off floor)."""
    if a is None or b is None:
        return False
    return abs(a - b) <= max(tol * max(abs(a), abs(b)), ROUND_OFF_FLOOR)


# ---------------------------------------------------------------------------- the metric

def test_fields(n, free, decays=DECAYS):
    """{name: [profiles]}: the smooth fields the signature must score (almost) 0 on, over
    ``n`` layers, ``free`` the layers it reads: a half-sine barrel over the cube, Gaussian
    bulges of standard deviation WIDTHS layer spacings centred an eighth of a spacing off each
    free layer and off each half-way point (off the weights' quarter-layer design grid; the
    widths 2 and 3, the decay 2 and the clamped base's barrel are design fields too, 5 and
    the decay 5 are not), and end boundary layers of each decay length ``decays`` (in layer spacings, from
    the first and last free layer) at the base, at the top, and at both with the same and
    with opposite signs."""
    k = np.arange(n, dtype=float)
    layers = np.flatnonzero(free)
    first, last = layers[0], layers[-1]
    centres = np.arange(first, last + 0.25, 0.5) + 0.125
    out = {"barrel": [np.sin(np.pi * k / (n - 1))]} if decays is DECAYS else {}
    for s in (WIDTHS if decays is DECAYS else ()):
        out[f"Gaussian, sd {s} layers"] = [np.exp(-(k - c) ** 2 / (2 * s ** 2))
                                           for c in centres]
    for d in decays:
        base, top = np.exp(-np.abs(k - first) / d), np.exp(-np.abs(last - k) / d)
        out[f"end layer, decay {d:g}"] = [base, top, base + top, base - top]
    return out


def end_alternation(n, free, layers=END_LAYERS):
    """A pure (-1)^k pattern of amplitude 1 confined to ``layers`` free layers at each end
    (0 elsewhere): the paper's end layers bulging, as the metric would see it under
    refinement."""
    k = np.flatnonzero(free)
    e = np.zeros(n)
    e[k[:layers]] = 1.0
    e[k[-layers:]] = 1.0
    return e * (-1.0) ** np.arange(n)


def absorbed_degree(w, m):
    """The highest degree d such that the weights ``w`` on ``m`` consecutive layers are blind
    to every polynomial up to d (what the signature absorbs)."""
    x = np.linspace(-1.0, 1.0, m)
    d = -1
    for deg in range(m):
        p = np.polynomial.legendre.legvander(x, deg)[:, deg]
        if abs(w @ p) > 1e-9 * np.abs(w).sum() * np.abs(p).max():
            break
        d = deg
    return d


def leakage(reference, free):
    """The signature's check on one (size, base): ``reference`` the continuum's layer profile,
    ``free`` the layers read. The number of free layers, the polynomial degree the weights
    absorb, their gain (sum |w|: the most a field of height 1 can score; ||w||_2: what
    uncorrelated noise of 1 per layer reads), what the pure (-1)^k pattern reads (1), per
    smooth test field its largest |score| over its height on the free layers, ``worst`` the
    largest of those and the field, ``sharp`` the same of end layers sharper than two layer
    spacings (SHARP_DECAYS: on these layers half an alternation, so not in the leak) and
    ``ends`` what an alternation of amplitude 1 on END_LAYERS free layers at each end reads
    (the metric's sensitivity to end-localised bulging). None where no signature exists
    (three free layers)."""
    reference = np.asarray(reference, float)
    free = np.asarray(free, bool)
    k = np.flatnonzero(free)
    w = nyquist_weights(reference[free], k)
    if w is None:
        return None

    def score(fields):
        return {name: max(abs(w @ f[free]) / np.abs(f[free]).max() for f in fs)
                for name, fs in fields.items()}
    leaks = score(test_fields(len(reference), free))
    worst = max(leaks, key=leaks.get)
    return {"free": int(free.sum()), "degree": absorbed_degree(w, len(k)),
            "gain": float(np.abs(w).sum()), "noise_gain": float(np.linalg.norm(w)),
            "alternation_reads": float(w @ (-1.0) ** k.astype(float)),
            "leaks": leaks, "worst": leaks[worst], "worst_field": worst,
            "sharp": score(test_fields(len(reference), free, SHARP_DECAYS)),
            "versus_clear": against(leaks[worst], DECIDING_LEAK),
            "ends": float(abs(w @ end_alternation(len(reference), free)[free])),
            "paper_period": paper_period_reads(w, len(reference), free)}


def paper_period_reads(w, n, free):
    """What the weights ``w`` read of the paper's own pattern at its own period (bulges
    16 mm apart, PAPER_BULGES_MM) and amplitude 1, at its worst phase, on ``n`` layers of the
    cube: 1 on five layers (there the period is two layers, the period-2 component itself);
    on more layers the period spans more layers and the signature reads it as smooth."""
    y = np.linspace(0.0, P.SIZE_MM, n)[free]
    period = PAPER_BULGES_MM[1] - PAPER_BULGES_MM[0]
    phase = np.linspace(0.0, np.pi, 37)
    return float(max(abs(w @ np.cos(2 * np.pi * y / period + p)) for p in phase))


def _profile(cells, n, bc, load="paper"):
    """The continuum's layer profile of (n, bc) at ``load`` (the same layers on every split of
    a size)."""
    return next((c["bulge_profile_fem_mm"] for c in cells if c["nodes_per_side"] == n
                 and c["bc"] == bc and c["load"] == load and c.get("bulge_profile_fem_mm")),
                None)


def metric_check(cells):
    """{(n, bc): leakage row + 'decides'}: every configuration (size, base) the cells have; a
    configuration decides where it has DECISIVE or more layers and its worst smooth test field
    leaks below DECIDING_LEAK (a fifth of the clear level; not within NEAR of it)."""
    out = {}
    for n, bc in sorted({(c["nodes_per_side"], c["bc"]) for c in cells}):
        ref = _profile(cells, n, bc)
        row = None if ref is None else leakage(ref, _free_layers(bc, n))
        if row is None:
            out[(n, bc)] = {"n": n, "bc": bc, "free": int(_free_layers(bc, n).sum()),
                            "decides": False, "why": f"{int(_free_layers(bc, n).sum())} free "
                            "layers, no signature (the reference and a quadratic span them)"}
            continue
        reasons = ([f"fewer than {DECISIVE} layers"] if n < DECISIVE else []) + (
            [] if row["versus_clear"] == "below" else
            [f"smooth fields leak {fmt(row['worst'], 2)} of their height, "
             + ("at" if row["versus_clear"] == "at" else "above") + f" {LEAK_SHARE:g} of the "
             f"clear level ({DECIDING_LEAK:g})"])
        why = "; ".join(reasons) or None
        out[(n, bc)] = {"n": n, "bc": bc, **row, "decides": why is None, "why": why}
    return out


def reference_asymmetry(cells, bc="clamped"):
    """{n: the largest |r_k - r_(n-1-k)| over the reference's mean}: the clamped continuum is
    reflection-symmetric about the middle layer, so this is the reference's own mesh error (P2
    on the six split, which is not symmetric)."""
    out = {}
    for n in sorted({c["nodes_per_side"] for c in cells if c["bc"] == bc}):
        r = _arr(_profile(cells, n, bc))
        if r is not None:
            out[n] = float(np.abs(r - r[::-1]).max() / np.abs(r).mean())
    return out


# ---------------------------------------------------------------------------- a cell

def _arr(x):
    return None if x is None else np.asarray(x, float)


def own_mean(c):
    """A cell's own mean outward lateral displacement over its free layers [mm]."""
    p = _arr(c.get("bulge_profile_mm"))
    if p is None:
        return None
    return float(np.abs(p[_free_layers(c["bc"], len(p))]).mean())


def lateral_error(c):
    """The cell's lateral displacement error: its signed mean lateral displacement over the
    free layers over the continuum's, minus 1 (positive: it moves out more, softer laterally;
    negative: less, stiffer; below -1: it moves inward where the continuum moves out)."""
    p, r = _arr(c.get("bulge_profile_mm")), _arr(c.get("bulge_profile_fem_mm"))
    if p is None or r is None:
        return None
    free = _free_layers(c["bc"], len(r))
    ref = float(r[free].mean())
    return float(p[free].mean()) / ref - 1.0 if ref else None


def inward(cells):
    """The models whose mean lateral displacement at the paper's push is negative (inward,
    where the continuum bulges out) on every cell they have a profile on."""
    got = {}
    for c in cells:
        if c["load"] == "paper" and c.get("bulge_profile_mm") and c["family"] != CONTROL:
            got.setdefault(c["model"], []).append((lateral_error(c) or 0.0) < -1.0)
    return [short(m) for m, v in got.items() if all(v)]


def own_factor(c):
    """The reference's mean |lateral displacement| over all layers (alternation rel's
    normaliser) over the cell's own mean over its free layers: alternation rel times this is
    the signature over the model's own mean."""
    m, r = own_mean(c), _arr(c.get("bulge_profile_fem_mm"))
    if not m or r is None:
        return None
    return float(np.abs(r).mean()) / m


def signature_own(c):
    """The signature over the model's own mean lateral displacement on the free layers: what
    a picture of the model's own bulge shows."""
    m = own_mean(c)
    if c.get("failed") or c.get("alternation_mm") is None or not m:
        return None
    return c["alternation_mm"] / m


def _beside_reference(diff, reference, free):
    """(diff - alpha reference) over the free layers, alpha the least-squares scale (to which
    the signature is blind), and the reference's mean |profile| (``alternation_rel``'s
    normaliser)."""
    d, r = np.asarray(diff, float)[free], np.asarray(reference, float)
    rf = r[free]
    alpha = float(d @ rf / (rf @ rf)) if rf @ rf else 0.0
    return d - alpha * rf, float(np.abs(r).mean())


def smooth_amplitude(diff, reference, free):
    """The largest |diff - alpha reference| over the free layers, over the reference's mean
    |profile|: how large a smooth field could leak."""
    e, scale = _beside_reference(diff, reference, free)
    return float(np.abs(e).max() / scale)


def end_step(diff, reference, free):
    """The largest step between the two outermost free layers at either end of
    (diff - alpha reference), over the reference's mean |profile|: how tall an end layer
    sharper than two spacings could be (an alternation's own steps are in it too, so it
    bounds more than it needs to)."""
    e, scale = _beside_reference(diff, reference, free)
    return float(max(abs(e[1] - e[0]), abs(e[-1] - e[-2])) / scale)


def leaks_of(check):
    """(smooth, sharp) of a configuration's check: the worst smooth test field's leak and the
    worst end layer sharper than two spacings'; (0, 0) where it has none."""
    return (check.get("worst") or 0.0, max((check.get("sharp") or {}).values(), default=0.0))


def leak_u(diff, reference, free, leak):
    """What the metric's leak puts into a signature read off ``diff`` (over the reference's
    mean): the smooth leak times the smooth amplitude and the sharp end layers' leak times
    the end step, in quadrature; ``leak`` (smooth, sharp) or one number (smooth only)."""
    smooth, sharp = leak if isinstance(leak, tuple) else (leak, 0.0)
    return float(np.hypot(smooth * smooth_amplitude(diff, reference, free),
                          sharp * end_step(diff, reference, free)))


def signature_u(c, leak, floor=0.0):
    """The uncertainty of a cell's signature (over the reference's mean): ``leak_u`` of
    (model - reference), with ``floor`` (the reference's own period-2 error, bounded by FEM
    P1's on the conforming splits) and round-off, in quadrature; None where the cell has no
    profile."""
    p, r = _arr(c.get("bulge_profile_mm")), _arr(c.get("bulge_profile_fem_mm"))
    if p is None or r is None or c.get("failed"):
        return None
    lu = leak_u(p - r, r, _free_layers(c["bc"], len(r)), leak)
    return float(np.sqrt(lu ** 2 + floor ** 2 + ROUND_OFF_FLOOR ** 2))


def cell_clear(c, leak=0.0, floor=0.0):
    """(call, by normalisation) of a cell's signature against the clear level (``clear_call``
    with ``signature_u``)."""
    if c.get("failed") or c.get("alternation_rel") is None:
        return None, {}
    return clear_call(c["alternation_rel"], signature_u(c, leak, floor), own_factor(c))


def pattern(row, leak=0.0, floor=0.0):
    """'paper' (the paper's sign: the layers of even index from the base out bulge, clear on
    both normalisations against the signature's uncertainty for the configuration's ``leak``),
    'reversed', 'at' (not decided: at the threshold or the normalisations disagree), 'none',
    or None where the signature is not defined or the run failed."""
    v, _ = cell_clear(row, leak, floor)
    if v is None:
        return None
    return "at" if v == "at" else "none" if v == "below" else \
        "paper" if row["alternation_rel"] > 0 else "reversed"


def alternating(row, leak=0.0, floor=0.0):
    """True where the signature is clear, either sign; None where it is not defined."""
    p = pattern(row, leak, floor)
    return None if p is None else p in ("paper", "reversed")


def failure(c):
    """'failed (why)' of a failed cell, the solver's message shortened to its cause."""
    why = str(c.get("failed") or "")
    if "inverted" in why:
        return "failed (inverted element: " + why.split(" is ")[0] + ", " + \
            why.split("in term ")[-1].split(";")[0] + " term)"
    if why.startswith("build: "):      # the model could not be made: its whole cause
        return f"failed ({why.split(';')[0]})"
    return f"failed ({why.split(';')[0][:80]})"


# ---------------------------------------------------------------------------- decomposition

def decisive(cells):
    """The cells at the paper's push with at least DECISIVE layers."""
    return [c for c in cells if c["load"] == "paper" and c["nodes_per_side"] >= DECISIVE]


def _index(cells):
    return {(c["model"], c["split"], c["nodes_per_side"], c["bc"], c["load"]): c
            for c in cells}


def control_model(at, m, n, bc):
    """The model whose cells are ``m``'s controls at (n, bc): its held model (the shear's c of
    the mirrored five split, so that the controls differ from it in the split alone) where that
    ran on any split there, else ``m`` itself."""
    h = held(m)
    return h if any((h, x, n, bc, "paper") in at for x in (UNMIRRORED,) + CONFORMING_CONTROLS) \
        else m


def main_cells(cells):
    """The cells every answer but the mirror's reads: without the held models (the mirror's
    controls only)."""
    return [c for c in cells if c.get("constant") != HELD]


def counted(u):
    """Whether configuration ``u`` counts in the answers: it reads own parts (DECISIVE or more
    layers) and its smooth fields leak below DECIDING_LEAK (as a reference's estimate must be
    below a fifth of what it ranks); one that reads but leaks more is shown apart."""
    return u["reads"] and u["decides"]


def apart(us):
    """'9 clamped (7 free layers; smooth fields leak 0.004 ...)': the configurations that read
    own parts but do not count, with why."""
    return [f"{_where((u['n'], u['bc']))} ({u['check'].get('free')} free layers; "
            f"{u['check'].get('why')})" for u in us if u["reads"] and not u["decides"]]


def _constants_moved(c, controls):
    """'shear_c 0.125 on the mirrored split, 0.0748 on six (Kuhn)': where a model's fitted
    constants on its controls differ from those on the mirrored split (beyond SAME), else ''."""
    mine = c.get("constants") or {}
    out = []
    for y in controls:
        theirs = y.get("constants") or {}
        moved = [k for k in mine if k in theirs and not same(mine[k], theirs[k])]
        if moved:
            out.append(", ".join(f"{k} {fmt(mine[k], 3)} on the mirrored split, "
                                 f"{fmt(theirs[k], 3)} on {y['split']}" for k in moved))
    return "; ".join(out)


def _part(c, fem, ref, free, leak):
    """(part, u) of a model's cell against FEM P1's on the same tetrahedra: the difference of
    their signatures (over the reference's mean) and its uncertainty, the configuration's
    ``leak_u`` of (model - FEM P1), with round-off, in quadrature; (None, None) where either
    is missing."""
    if c is None or fem is None or c.get("alternation_rel") is None \
            or fem.get("alternation_rel") is None:
        return None, None
    d = c["alternation_rel"] - fem["alternation_rel"]
    lu = leak_u(np.asarray(c["bulge_profile_mm"]) - np.asarray(fem["bulge_profile_mm"]), ref,
                free, leak)
    return d, float(np.hypot(lu, ROUND_OFF_FLOOR))


def _mirror_call(d, u, parts):
    """Whether a resolved part ``d`` +- ``u`` on the mirrored split is the mirror's: ``parts``
    the control parts [(part, u)]. The mirror ratio |d| / max |control part| is known within
    [(|d| - u) / max(|c| + u_c), (|d| + u) / max(|c| - u_c)], an unresolved control part's
    lower bound 0 (infinite above where every control part is unresolved); 'above' (the
    mirror's) where the whole interval is RATIO or more, 'below' (on every split) where it is
    all below RATIO, else 'at' (not decided), with the reason."""
    unresolved = [c for c, uc in parts if against(abs(c) / uc, RATIO) != "above"]
    lo = (abs(d) - u) / max([ROUND_OFF_FLOOR] + [abs(c) + uc for c, uc in parts])
    # an unresolved control part cannot be told from 0: its lower bound is 0
    floor_ = max([0.0] + [abs(c) - uc for c, uc in parts if c not in unresolved])
    hi = (abs(d) + u) / floor_ if floor_ > 0 else None
    call = bounded(lo, hi, RATIO)
    why = None if call != "at" else (
        "the ratio at the threshold" if lo >= RATIO * (1 - NEAR) else
        f"the ratio within [{lo:.2g}, {hi:.2g}]: its upper bound within {NEAR:.0%} of "
        f"{RATIO:g}" if hi is not None and hi < RATIO else
        f"the ratio's lower bound {lo:.2g}, below {RATIO:g}"
        + ("" if hi is not None else ", its upper bound unbounded (no control part resolved)"))
    return lo, hi, call, why


def units(cells, models=None):
    """Per (size, base) of the mirrored five split: the metric's check, FEM P1's signature
    there with its uncertainty, and per distinct model its signature with its uncertainty,
    its own part (model - FEM P1 on the same tetrahedra) with its uncertainty, and its parts
    on the conforming controls (six, bcc: those run for every model at that size, the same
    for every model), each with its own uncertainty, and its class.

    The leak of a configuration is its worst smooth test field's score and its worst sharp end
    layer's (``metric_check``). u of a model's part: ``leak_u`` of (model - FEM P1) (FEM P1
    with the continuum's neo-Hookean law) with round-off, in quadrature; a control's part the
    same on its split (the conforming splits the model and FEM P1 ran on at that size). u of
    a signature (FEM P1's or a model's): ``leak_u`` of (cell - reference), with the floor (FEM
    P1's largest signature on any conforming split run at that size: the reference's own
    period-2 error is bounded by it). On the sliding base FEM P1 is exact (a homogeneous
    field), an identity check, not a measured error.

    A configuration reads own parts from DECISIVE layers ('reads': the leak enters every u);
    its clear-level calls decide only where the leak is below DECIDING_LEAK ('decides'). A
    model's class: 'failed (...)' where its mirrored cell or a control failed; 'not decided'
    on a configuration that does not read; 'at the threshold (part / u)' where |part| / u is
    within NEAR of RATIO; 'not resolved' below it (its part cannot be told from 0); else
    'own +' / 'own -' (the paper's sign or reversed) with where it comes from: 'the mirror's'
    where the mirror ratio's interval (``_mirror_call``) is RATIO or more, 'on every split'
    where it is below, else 'mirror not decided' with the reason. Whether it is clear (large
    enough to see) is apart. A model whose cells agree with one counted before it
    (``one_observation``) is one observation with it."""
    check = metric_check(cells)
    at = _index(cells)
    order = list(models or dict.fromkeys(c["model"] for c in cells))
    out = []
    for n, bc in sorted({(c["nodes_per_side"], c["bc"]) for c in cells
                         if c["split"] == MIRRORED}):
        chk = check.get((n, bc), {})
        leak = leaks_of(chk)
        # a configuration reads own parts from DECISIVE layers (the leak is in every u); its
        # clear-level calls decide only where the leak is below DECIDING_LEAK ("decides")
        reads = n >= DECISIVE and chk.get("worst") is not None
        fem = at.get((YARDSTICK_MODEL, MIRRORED, n, bc, "paper"))
        ref = _arr(fem and fem.get("bulge_profile_fem_mm"))
        free = _free_layers(bc, n)
        mirrored = [m for m in order if (m, MIRRORED, n, bc, "paper") in at
                    and at[(m, MIRRORED, n, bc, "paper")]["family"] != CONTROL]
        ctrls = [x for x in CONFORMING_CONTROLS
                 if all((control_model(at, m, n, bc), x, n, bc, "paper") in at
                        for m in mirrored + [YARDSTICK_MODEL])]
        missing = {x: [short(m) for m in mirrored
                       if (control_model(at, m, n, bc), x, n, bc, "paper") not in at]
                   for x in CONFORMING_CONTROLS if x not in ctrls}
        fem_five = None if fem is None else fem.get("alternation_rel")
        fem_all = {x: at[(YARDSTICK_MODEL, x, n, bc, "paper")].get("alternation_rel")
                   for x in CONFORMING_CONTROLS if (YARDSTICK_MODEL, x, n, bc, "paper") in at}
        floor = max([ROUND_OFF_FLOOR] + [abs(v) for v in fem_all.values() if v is not None])
        identity = all(v is not None and abs(v) < ROUND_OFF_FLOOR for v in fem_all.values()) \
            and fem_five is not None and abs(fem_five) < ROUND_OFF_FLOOR
        u_fem = None
        if fem_five is not None and fem is not None:
            u_fem = signature_u(fem, leak, floor)
        fem_vs = None if u_fem is None else against(abs(fem_five) / u_fem, RATIO)
        fem_clear = None if u_fem is None else clear_call(fem_five, u_fem, own_factor(fem))[0]
        rows, seen = [], []
        for m in mirrored:
            c = at[(m, MIRRORED, n, bc, "paper")]
            cm = control_model(at, m, n, bc)
            row = {"model": m, "name": short(m), "family": c["family"],
                   "constant": c["constant"], "five": c.get("alternation_rel"),
                   "five_mm": c.get("alternation_mm"), "own": signature_own(c),
                   "own_factor": own_factor(c), "lateral": lateral_error(c), "controls": {},
                   "control_parts": {}, "controls_held": cm != m,
                   "unmirrored": (at.get((cm, UNMIRRORED, n, bc, "paper")) or {}).get(
                       "alternation_rel"), "same_as": None, "sign": None}
            row["u_sig"] = signature_u(c, leak, floor) if not c.get("failed") else None
            row["clear"], row["clear_by"] = clear_call(row["five"], row["u_sig"] or 0.0,
                                                       row["own_factor"])
            for x in CONFORMING_CONTROLS:
                y = at.get((cm, x, n, bc, "paper"))
                row["controls"][x] = ("not run" if y is None else failure(y)
                                      if y.get("failed") else y.get("alternation_rel"))
            # the model's controls: each conforming split it and FEM P1 ran on at this size
            own_ctrls = [x for x in CONFORMING_CONTROLS if (cm, x, n, bc, "paper") in at
                         and (YARDSTICK_MODEL, x, n, bc, "paper") in at]
            row["ctrls"] = own_ctrls
            # a failed control is a hole in that control, counted against the model, never its
            # whole observation: its part is read against the controls that ran
            row["failed_controls"] = [f"{x}: {v}" for x, v in row["controls"].items()
                                      if x in own_ctrls and isinstance(v, str)]
            own_ctrls = [x for x in own_ctrls if not isinstance(row["controls"][x], str)]
            row["ctrls"] = own_ctrls
            if c.get("failed"):
                row["kind"] = failure(c)
                rows.append(row)
                continue
            if row["five"] is None or fem_five is None or ref is None:
                row["kind"] = "n/a (no signature)"
                rows.append(row)
                continue
            d, u = _part(c, fem, ref, free, leak)
            dup = next((r for r in seen if one_observation(r, row)), None)
            if dup is not None:
                # one observation with a model counted before it; its own part is kept for
                # the pairs that read this model's cell
                row["same_as"] = dup["name"]
                row["kind"] = f"same as {dup['name']}"
                row["own_part"] = (d, u)
                rows.append(row)
                continue
            parts = []
            for x in own_ctrls:
                cp, uc = _part(at[(cm, x, n, bc, "paper")], at[(YARDSTICK_MODEL, x, n, bc,
                                                                "paper")], ref, free, leak)
                row["control_parts"][x] = {"part": cp, "u": uc,
                                           "resolved": against(abs(cp) / uc, RATIO)}
                parts.append((cp, uc))
            row.update({"part": d, "u": u, "part_vs_u": against(abs(d) / u, RATIO),
                        "mirror_ratio": (abs(d) / max([ROUND_OFF_FLOOR]
                                                      + [abs(p) for p, _ in parts])
                                         if parts else None)})
            if parts:
                lo, hi, call, why = _mirror_call(d, u, parts)
                if row["failed_controls"] and call != "at":
                    # a failed control is a failure of the model, not a smaller design: the
                    # mirror read on the controls left is not decided
                    call, why = "at", ("a control failed; the ratio on those that ran is " + (
                        f"{RATIO:g} or more" if call == "above" else f"below {RATIO:g}"))
                moved = _constants_moved(c, [at[(cm, x, n, bc, "paper")] for x in own_ctrls])
                if moved and call != "at":
                    # a control with other fitted constants differs from the model in more than
                    # the split: the mirror read there is not decided (rule 5)
                    call, why = "at", f"its constants are fitted per split ({moved})"
                row.update({"mirror_lo": lo, "mirror_hi": hi, "mirror_vs": call,
                            "mirror_why": why})
            if not reads:
                kind = ("not decided (the paper's 5-layer view)" if n < DECISIVE
                        else f"not decided ({chk.get('why')})")
            elif row["part_vs_u"] == "at":
                kind = "at the threshold (part / u)"
            elif row["part_vs_u"] == "below":
                kind = "not resolved"
            else:
                row["sign"] = "+" if d > 0 else "-"
                kind = f"own {row['sign']}, " + (
                    "mirror not decided (no control ran)" if not parts else
                    "the mirror's" if row["mirror_vs"] == "above" else
                    "on every split" if row["mirror_vs"] == "below" else
                    f"mirror not decided ({row['mirror_why']})") + (
                    " (" + "; ".join(f.split(":")[0] + " failed" for f in
                                     row["failed_controls"]) + ": read on "
                    + (", ".join(x.split(" ")[0] for x in own_ctrls) or "none") + ")"
                    if row["failed_controls"] else "")
            row["kind"] = kind
            seen.append(row)
            rows.append(row)
        distinct = [r for r in rows if r["same_as"] is None]
        out.append({"n": n, "bc": bc, "check": chk, "decides": bool(chk.get("decides")),
                    "reads": reads,
                    "leak": leak[0], "sharp_leak": leak[1], "controls": ctrls,
                    "missing_controls": missing,
                    "fem_five": fem_five, "fem_mm": None if fem is None else
                    fem.get("alternation_mm"), "u_fem": u_fem, "fem_vs": fem_vs,
                    "fem_clear": fem_clear,
                    "fem_controls": fem_all, "floor": floor, "identity": identity,
                    "fem_ratio": None if fem_five is None else abs(fem_five) / floor,
                    "ref_scale_mm": None if ref is None else float(np.abs(ref).mean()),
                    "rows": rows,
                    "distinct": len(distinct), "run": len(rows)})
    return out


def classes(unit):
    """{class: [model names]} over a configuration's distinct models (failed ones under their
    class 'failed')."""
    out = {}
    for r in unit["rows"]:
        if r["same_as"] is None:
            k = "failed" if r["kind"].startswith("failed") else r["kind"]
            out.setdefault(k, []).append(r["name"])
    return out


def two_point_order(coarse, u_coarse, fine, u_fine):
    """(p, u_p) of the slope in h through two sizes, h halved: p = log2(|coarse| / |fine|),
    its uncertainty the parts' u propagated through the slope, u_p = sqrt((u_c / c)^2 +
    (u_f / f)^2) / ln 2. Two points carry no check that the order is asymptotic: u_p is the
    parts' uncertainty only."""
    p = float(np.log2(abs(coarse) / abs(fine)))
    return p, float(np.hypot(u_coarse / coarse, u_fine / fine) / np.log(2.0))


def orders(us):
    """Per base: each distinct model's order in h of its own part [mm] (the relative part times
    its reference's mean, which moves with the size on the clamped base) from the smallest to
    the next size (h halved) where both configurations read and the part is resolved at both
    with one sign: log2 of the ratio, with its uncertainty (``two_point_order``); with how
    many of the models at both sizes it covers."""
    by = {(u["n"], u["bc"]): u for u in us}
    out = {}
    for (n, bc), u in by.items():
        fine = by.get((2 * n - 1, bc))
        if fine is None:
            continue
        if not (u["reads"] and fine["reads"]):
            out[bc] = {"orders": {}, "of": 0, "sizes": (n, fine["n"]),
                       "why": f"the {n}-node {bc} configuration does not read own parts"
                       if not u["reads"] else
                       f"the {fine['n']}-node configuration does not read own parts"}
            continue
        fr = {r["model"]: r for r in fine["rows"] if r["same_as"] is None}
        both = [r for r in u["rows"] if r["same_as"] is None and r["model"] in fr]
        got, u_ = {}, {}
        for r in both:
            f = fr[r["model"]]
            if r.get("part_vs_u") == "above" and f.get("part_vs_u") == "above" \
                    and np.sign(r["part"]) == np.sign(f["part"]):
                sc, sf = u["ref_scale_mm"], fine["ref_scale_mm"]
                got[r["name"]], u_[r["name"]] = two_point_order(
                    r["part"] * sc, r["u"] * sc, f["part"] * sf, f["u"] * sf)
        out[bc] = {"orders": got, "u": u_, "of": len(both), "sizes": (n, fine["n"]),
                   "why": None}
    return out


# ---------------------------------------------------------------------------- hypotheses

def mirror(cells, models=None):
    """Hypothesis (a), the mirror symmetry: the decomposition (``units``), the orders, and the
    configurations that read where FEM P1's own signature or a model's own part is resolved
    and the mirror's."""
    us = units(cells, models)
    dec = [u for u in us if counted(u)]
    mesh = [u for u in dec if u["fem_vs"] == "above" and not u["identity"]]
    own = [u for u in dec if any(r.get("mirror_vs") == "above" and r["sign"]
                                 for r in u["rows"] if r["same_as"] is None)]
    return {"units": us, "orders": orders(us), "deciding": [(u["n"], u["bc"]) for u in dec],
            "holds": bool(mesh or own), "mesh_units": [(u["n"], u["bc"]) for u in mesh],
            "own_units": [(u["n"], u["bc"]) for u in own]}


def normal_stress(cells, us):
    """Hypothesis (b), the missing normal stress: pairs (a configuration of the mirrored
    split that reads own parts, a reading, calibrated or literal, whose own part is resolved
    there, a normal-stress term) where the term changes the signature beyond round-off (ACTIVE); each
    pair's part without and with the term, and whether the term reduces the model's own part
    RATIO-fold (the interval of the ratio from both parts' u). The rest are listed as not
    tested, with why (the term changes nothing; no resolved own part; the configuration does
    not read; failed), and which signs of the own part the tested pairs cover."""
    at = {(c["nodes_per_side"], c["bc"], c["reading"], c["constant"], c["normal"]): c
          for c in cells if c["family"] == "particle"
          and c["constant"] in ("calibrated", "literal")
          and c["split"] == MIRRORED and c["load"] == "paper"}
    rows = {(u["n"], u["bc"]): {r["model"]: r for r in u["rows"]} for u in us}
    dec = {(u["n"], u["bc"]): u for u in us}
    pairs, untested = [], []
    for (n, bc, reading, constant, normal), w in sorted(at.items()):
        if normal == "none":
            continue
        base = at.get((n, bc, reading, constant, "none"))
        name = short(w["model"])
        if base is None:
            continue
        r = rows[(n, bc)].get(base["model"], {})

        def skip(why):
            untested.append({"n": n, "bc": bc, "name": name, "base": short(base["model"]),
                             "sign": r.get("sign"), "why": why})
        if not counted(dec[(n, bc)]):
            skip("the configuration does not count (fewer layers, or its leak too large)")
            continue
        if base.get("failed") or w.get("failed"):
            skip("failed")
            continue
        a, b = base.get("alternation_rel"), w.get("alternation_rel")
        if same(a, b, ACTIVE):
            cn = (w.get("constants") or {}).get(normal.split(" ")[0] + "_c")
            skip("the term changes nothing here (to 1e-6; " + (
                "its constant is not stored" if cn is None else f"its constant c_n = {cn:.2g}")
                + ")")
            continue
        if r.get("part_vs_u") != "above":
            skip(f"{short(base['model'])} has no resolved own part")
            continue
        rw = rows[(n, bc)].get(w["model"], {})
        if rw.get("same_as") and rw["same_as"] != r.get("name"):
            skip(f"one observation with {rw['same_as']}")   # another term's, counted there
            continue
        without, uw = r["part"], r["u"]
        # the model's own cell, also where it agrees with its base to two figures
        with_, uv = rw.get("own_part") or (rw.get("part"), rw.get("u"))
        if with_ is None:
            skip("no part with the term")
            continue
        lo = max(abs(without) - uw, 0.0) / (abs(with_) + uv)
        hi = (abs(without) + uw) / max(abs(with_) - uv, ROUND_OFF_FLOOR)
        reduced = bounded(lo, hi, RATIO)
        cn = (w.get("constants") or {}).get(normal.split(" ")[0] + "_c")
        pairs.append({"n": n, "bc": bc, "term": normal, "model": name, "c_n": cn,
                      "fitted": w.get("constant") == "calibrated" and "(c_n =" not in name,
                      "why": None if reduced != "at" else (
                          "the part with the term is not resolved from 0"
                          if against(abs(with_) / uv, RATIO) != "above" else
                          "the ratio at the threshold"),
                      "sign_change": with_ * without < 0,
                      "shear_c": [(base.get("constants") or {}).get("shear_c"),
                                  (w.get("constants") or {}).get("shear_c")],
                      "base": short(base["model"]), "sign": r["sign"], "without": without,
                      "with": with_, "ratio": abs(with_) / abs(without),
                      "reduced": reduced})
    removed = sum(p["reduced"] == "above" for p in pairs)
    at_ = sum(p["reduced"] == "at" for p in pairs)
    signs = sorted({p["sign"] for p in pairs})
    where = {}
    for x in untested:
        if x["sign"] and x["sign"] not in signs and x["why"].startswith("the term changes "
                                                                          "nothing"):
            where.setdefault(x["base"], set()).add((x["n"], x["bc"]))
    inactive = [f"{b} ({', '.join(f'{n} {bc}' for n, bc in sorted(v))})"
                for b, v in where.items()]
    return {"pairs": pairs, "untested": untested, "tested": len(pairs), "removed": removed,
            "at_threshold": at_, "decided": bool(pairs), "signs": signs,
            "readings": sorted({p["base"] for p in pairs}), "inactive_other_sign": inactive,
            "holds": bool(pairs) and removed >= REMOVES * len(pairs)}


def rank_interval(rho, n):
    """The 95 % interval of a Spearman correlation ``rho`` over ``n`` points by Fisher's z,
    with the variance 1.06 / (n - 3) of Fieller, Hartley and Pearson; None below 4 points."""
    if rho is None or n < 4:
        return None
    z, se = np.arctanh(np.clip(rho, -0.999999, 0.999999)), np.sqrt(1.06 / (n - 3))
    return [float(np.tanh(z - Z95 * se)), float(np.tanh(z + Z95 * se))]


def track_needs(n):
    """(the smallest rho read as 'tracks', the largest read as 'does not track') over ``n``
    independent points: the test's power (``rank_interval``); None below 4 points."""
    if n < 4:
        return None
    w, z = Z95 * np.sqrt(1.06 / (n - 3)), np.arctanh(TRACKS)
    return float(np.tanh(z + w)), float(np.tanh(z - w))


def _track(rho, ci):
    """'tracks' where the whole interval lies at TRACKS or above, 'does not track' where it
    lies below TRACKS, else 'not decided' (one rule, read on the interval both ways)."""
    if ci is None:
        return "not decided (too few models)"
    if ci[0] >= TRACKS:
        return "tracks"
    if ci[1] < TRACKS:
        return "does not track"
    return "not decided (the interval holds 0.7)"


def family(model):
    """The reading a variant belongs to ('pbcm-corner' for 'pbcm-corner +normal_edge', 'msm'
    for 'msm +shear (c = 1)'): variants of one reading share its kernel and its errors, so a
    correlation over them counts each family once in its interval."""
    return short(model).split(" +")[0]


def _cluster(pts, tol):
    """The points (signature, patch error) with those agreeing to ``tol`` in both counted
    once (near-duplicate variants: one observation)."""
    kept = []
    for s, e in pts:
        if not any(same(s, a, tol) and same(e, b, tol) for a, b in kept):
            kept.append((s, e))
    return kept


def consistency(cells):
    """Hypothesis (c), the model's consistency: per conforming mesh with the linear regime
    (the sliding cube at 1e-3 of the push is a patch test) from DECISIVE layers, the rank
    correlation over the distinct approximations (the control left out) between the
    signature at the linear load on the sliding base and the sliding cube's linear-load
    error (one regime), signed
    and on |signature|, with models agreeing to SAME (3 significant figures) and to COARSE (2)
    counted once, each with its 95 % interval; the verdict where all four agree, else 'not
    decided'; not testable on a mesh where fewer than MIN_RESOLVED models' signatures are
    resolved (|signature| at least RATIO times its u, the configuration's leak in it): a
    correlation over signatures that cannot be told from 0 ranks the leak."""
    check = metric_check(cells)
    leak = {k: leaks_of(v) for k, v in check.items()}
    per, size = {}, {}
    for c in cells:
        if (c["nodes_per_side"] < DECISIVE or c["bc"] != "sliding" or c["family"] == CONTROL
                or c["split"] == UNMIRRORED):
            continue
        per.setdefault(c["mesh"], {}).setdefault(c["model"], {})[c["load"]] = c
        size[c["mesh"]] = c["nodes_per_side"]
    rows = []
    for mesh, by_model in per.items():
        pts, clear, at_, failed = [], [], [], []     # clear: resolved; at_: at the threshold
        families = set()
        for model, v in by_model.items():
            if "paper" not in v or "linear" not in v:
                continue
            if v["paper"].get("failed") or v["linear"].get("failed"):
                failed.append(short(model))
                continue
            # one regime: the signature and the patch-test error both at the linear load
            s, e = v["linear"].get("alternation_rel"), v["linear"].get("disp_rel_l2")
            if s is None or e is None:
                continue
            pts.append((s, e))
            families.add(family(model))
            u = signature_u(v["linear"], leak.get((v["linear"]["nodes_per_side"], "sliding"),
                                                  (0.0, 0.0)))
            call = against(abs(s) / u, RATIO)
            (clear if call == "above" else at_ if call == "at" else []).append(short(model))
        if len(pts) < 3:
            continue
        variants = {}
        for tol in (SAME, COARSE):
            kept = _cluster(pts, tol)
            sig, err = np.array(kept).T
            for signed in (True, False):
                x = sig if signed else np.abs(sig)
                rho = (float(spearmanr(x, err).statistic) if np.ptp(x) and np.ptp(err)
                       else None)
                # the interval over the families: variants of one reading are not
                # independent observations
                ci = rank_interval(rho, min(len(kept), len(families)))
                variants[(tol, signed)] = {"n": len(kept), "rho": rho, "interval": ci,
                                           "families": len(families),
                                           "verdict": _track(rho, ci)}
        verdicts = {v["verdict"] for v in variants.values()}
        chk = check.get((size[mesh], "sliding"), {})
        if chk.get("worst") is None:
            verdict = (f"not testable: the configuration ({size[mesh]}, sliding) has no "
                       f"signature ({chk.get('why')})")
        elif len(clear) < MIN_RESOLVED:
            verdict = (f"not testable: {len(clear)} of {len(pts)} signatures resolved, fewer "
                       f"than {MIN_RESOLVED}") + (f" ({', '.join(at_)} at the threshold)" if at_
                                            else "")
        elif len(verdicts) == 1:
            verdict = verdicts.pop()
        else:
            verdict = "not decided (the verdict depends on the sign or the clustering)"
        main = variants[(SAME, True)]
        rows.append({"mesh": mesh, "models": main["n"], "of": len(by_model),
                     "families": len(families),
                     "rho": main["rho"], "interval": main["interval"],
                     "variants": [{"tol": t, "signed": s, **v}
                                  for (t, s), v in variants.items()],
                     "clear": len(clear), "clear_models": clear, "at": at_,
                     "failed": failed, "verdict": verdict})
    return {"rows": rows, "holds": bool(rows) and all(r["verdict"] == "tracks" for r in rows),
            "testable": any(not r["verdict"].startswith("not testable") for r in rows)}


def node_consistency(cells):
    """Hypothesis (c) read at the side nodes: per conforming mesh from DECISIVE layers, on the
    sliding base at the linear load (a patch test: one run, one regime), the rank correlation
    over the distinct models (the control left out; models agreeing to SAME in both counted
    once) between the node-level part (``node_part`` rms against FEM P1 on the same
    tetrahedra) and the patch-test error (disp_rel_l2), with its 95 % interval taken over the
    reading families (``family``: variants of one reading are not independent); 'not
    testable' where fewer than MIN_RESOLVED parts are resolved (RATIO times ``node_u``)."""
    at = _index(cells)
    rows = []
    for mesh, n, split in sorted({(c["mesh"], c["nodes_per_side"], c["split"]) for c in cells
                                  if c["nodes_per_side"] >= DECISIVE and c["split"] != UNMIRRORED
                                  and c["bc"] == "sliding" and c["load"] == "linear"}):
        fem = at.get((YARDSTICK_MODEL, split, n, "sliding", "linear"))
        u = node_u(fem)
        if u is None:
            continue
        pts, resolved, families = [], [], set()
        for c in cells:
            if ((c["mesh"], c["bc"], c["load"]) != (mesh, "sliding", "linear")
                    or c["family"] == CONTROL or c.get("failed")
                    or c.get("disp_rel_l2") is None):
                continue
            rms, _ = node_part(c, fem)
            if rms is None:
                continue
            err = c["disp_rel_l2"]
            if any(same(rms, a, SAME) and same(err, b, SAME) for a, b in pts):
                continue        # one observation with a model counted before it
            pts.append((rms, err))
            families.add(family(c["model"]))
            if against(rms / u, RATIO) == "above":
                resolved.append(short(c["model"]))
        if len(pts) < 3:
            continue
        part, err = np.array(pts).T
        rho = float(spearmanr(part, err).statistic) if np.ptp(part) and np.ptp(err) else None
        ci = rank_interval(rho, min(len(pts), len(families)))
        verdict = (f"not testable: {len(resolved)} of {len(pts)} node-level parts resolved, "
                   f"fewer than {MIN_RESOLVED}" if len(resolved) < MIN_RESOLVED
                   else _track(rho, ci))
        rows.append({"mesh": mesh, "models": len(pts), "families": len(families),
                     "resolved": len(resolved), "u": u,
                     "rho": rho, "interval": ci, "verdict": verdict})
    return {"rows": rows,
            "testable": any(not r["verdict"].startswith("not testable") for r in rows)}


def consistency_across(cells):
    """Hypothesis (c) read within one model across the splits: on the sliding base at the
    linear load (a patch test) from DECISIVE layers, per distinct model (its controls its held
    model's where run) the signature on the mirrored split against each conforming control's,
    each with its u, beside the patch-test error (``disp_rel_l2``) on each. 'split' where the
    mirrored signature is resolved and RATIO times every control's upper bound while some
    control's patch-test error is at least the mirrored split's (within NEAR): the pattern
    follows the split, not the error; 'error' where a control with a resolved signature of the
    same sign has a patch-test error no larger (within NEAR) than the mirrored split's and
    the mirrored signature is not RATIO times that control's upper bound: the pattern goes
    with the error; else 'not decided'."""
    check = metric_check(cells)
    at = _index(cells)
    out = []
    for n in sorted({c["nodes_per_side"] for c in cells if c["split"] == MIRRORED
                     and c["load"] == "linear" and c["nodes_per_side"] >= DECISIVE}):
        leak = leaks_of(check.get((n, "sliding"), {}))
        rows, seen = [], []
        for c in cells:
            if (c["split"] != MIRRORED or c["nodes_per_side"] != n or c["bc"] != "sliding"
                    or c["load"] != "linear" or c["family"] == CONTROL
                    or c.get("constant") == HELD or c.get("failed")
                    or c.get("alternation_rel") is None or c.get("disp_rel_l2") is None):
                continue
            s_, e = c["alternation_rel"], c["disp_rel_l2"]
            if any(same(s_, a) and same(e, b) for a, b in seen):
                continue
            seen.append((s_, e))
            u = signature_u(c, leak)
            cm = control_model(at, c["model"], n, "sliding")
            ctrls = {}
            for x in CONFORMING_CONTROLS:
                y = at.get((cm, x, n, "sliding", "linear"))
                if y is None or y.get("failed") or y.get("alternation_rel") is None:
                    continue
                ctrls[x] = {"sig": y["alternation_rel"], "u": signature_u(y, leak),
                            "error": y["disp_rel_l2"]}
            if not ctrls:
                continue
            resolved = against(abs(s_) / u, RATIO)
            top = max(abs(v["sig"]) + v["u"] for v in ctrls.values())
            worse = [x for x, v in ctrls.items() if v["error"] >= e * (1 - NEAR)]
            if resolved == "above" and abs(s_) - u >= RATIO * top and worse:
                follows = "split"
            elif any(against(abs(v["sig"]) / v["u"], RATIO) == "above"
                     and np.sign(v["sig"]) == np.sign(s_) and v["error"] <= e * (1 + NEAR)
                     and abs(s_) - u < RATIO * (abs(v["sig"]) + v["u"])
                     for v in ctrls.values()):
                follows = "error"
            else:
                follows = "not decided"
            rows.append({"name": short(c["model"]), "sig": s_, "u": u, "error": e,
                         "resolved": resolved, "controls": ctrls, "worse": worse,
                         "follows": follows})
        out.append({"n": n, "rows": rows})
    return out


def across_text(across):
    """(c) across the splits in a sentence per size."""
    got = []
    for x in across:
        rs = x["rows"]
        res = [r for r in rs if r["resolved"] == "above"]
        sp = [r["name"] for r in rs if r["follows"] == "split"]
        er = [r["name"] for r in rs if r["follows"] == "error"]
        ratio = [min(v["error"] for v in r["controls"].values()) / r["error"] for r in rs
                 if r["error"]]
        got.append(
            f"{x['n']} sliding, the linear load: of {len(rs)} distinct models, {len(res)} have "
            f"a resolved signature on the mirrored split; in {len(sp)} it is {RATIO:g} times "
            "every control's upper bound while a control's patch-test error is at least the "
            "mirrored split's: the pattern follows the split, not the error"
            + (f" ({_compress(sp)})" if sp else "")
            + f"; in {len(er)} a control has the same-signed signature with no larger error"
            + (f" ({_compress(er)})" if er else "")
            + (f"; the controls' patch-test error over the mirrored split's "
               f"{fmt(min(ratio), 2)}-{fmt(max(ratio), 2)} (the smaller control)"
               if ratio else ""))
    return "; ".join(got)


def linear_check(cells):
    """Per base, on the mirrored split: each distinct model's signature in mm at 1e-3 of the
    push, scaled to the push (divided by LINEAR_SCALE), over its signature in mm at the push
    (same mesh; the signature at the push beyond round-off; models whose two signatures agree
    to SAME with one counted before are one observation): median [min-max], n of N, the cells
    that change by more than NEAR with the load (part of their signature is finite strain),
    and FEM P1's ratios (neo-Hookean P1: its change is the law's own finite strain). Near 1
    the pattern is a property of the linear regime."""
    at = _index(cells)
    out = {}
    for bc in sorted({c["bc"] for c in cells}):
        pairs = [(p, at.get((p["model"], p["split"], p["nodes_per_side"], bc, "linear")))
                 for p in cells if p["bc"] == bc and p["load"] == "paper"
                 and p["split"] == MIRRORED]
        pairs = [(p, q) for p, q in pairs if q is not None]
        fem, seen, rows = [], [], []
        pairs = [(p, q) for p, q in pairs if p.get("alternation_mm") is not None
                 and q.get("alternation_mm") is not None and p.get("alternation_rel")
                 is not None]
        for p, q in pairs:
            a, b = p["alternation_mm"], q["alternation_mm"] / LINEAR_SCALE
            if abs(p["alternation_rel"]) <= 1e3 * ROUND_OFF_FLOOR:
                continue
            if p["family"] == CONTROL:
                fem.append((p["nodes_per_side"], b / a))
                continue
            if any(same(a, x) and same(b, y) and n == p["nodes_per_side"]
                   for n, x, y in seen):
                continue
            seen.append((p["nodes_per_side"], a, b))
            rows.append((short(p["model"]), p["nodes_per_side"], b / a))
        ratios = [r for _, _, r in rows]
        out[bc] = {"n": len(rows), "of": len([p for p, _ in pairs if p["family"] != CONTROL]),
                   "median": float(np.median(ratios)) if ratios else None,
                   "range": [min(ratios), max(ratios)] if ratios else None,
                   "changed": [r for r in rows if abs(r[2] - 1) > NEAR], "fem": fem}
    return out


def paper_view(us):
    """The paper's own 5-layer view on the mirrored five split, sliding base (the paper's
    observation, the end layers bulging, needs a base free to move laterally): the distinct
    models whose signature is clear with the paper's sign (on both normalisations, against
    its uncertainty), those not decided, and how many distinct models; never a verdict (the
    configuration's metric check)."""
    u = next((u for u in us if u["n"] < DECISIVE and u["bc"] == "sliding"), None)
    if u is None:
        return {"shows": [], "at": [], "of": 0, "unit": None}
    rows = [r for r in u["rows"] if r["same_as"] is None and r.get("own") is not None]
    return {"shows": [r["name"] for r in rows if r["clear"] == "above" and r["five"] > 0],
            "reversed": [r["name"] for r in rows if r["clear"] == "above" and r["five"] < 0],
            "at": [r["name"] for r in rows if r["clear"] == "at"],
            "of": len(rows), "run": u["run"], "n": u["n"], "check": u["check"],
            "unit": (u["n"], u["bc"]),
            "top": max(rows, key=lambda r: abs(r["own"]), default=None)}


# ---------------------------------------------------------------------------- the answer

def _names(models):
    return ", ".join(models) if models else "none"


def _compress(names):
    """Names with a normal-stress term grouped by their reading: 'pbcm-corner
    +normal_edge/+normal_tet' for 'pbcm-corner +normal_edge, pbcm-corner +normal_tet'."""
    groups = {}
    for n in names:
        head, _, tail = n.partition(" +normal")
        groups.setdefault(head if tail else n, []).append("+normal" + tail if tail else "")
    out = []
    for head, tails in groups.items():
        terms = "/".join(t for t in tails if t)
        out.append(head if not terms else f"{head} {terms}" if "" not in tails
                   else f"{head} (also {terms})")
    return ", ".join(out) if names else "none"


def _where(unit):
    return f"{unit[0]} {unit[1]}"


def _clear_word(v):
    return {"above": "clear", "below": "below the clear level",
            "at": "at the threshold: not decided"}.get(v, "n/a")


def _resolve(unit, row):
    """The row a duplicate stands for (its observation's), else the row."""
    if row["same_as"] is None:
        return row
    return next(r for r in unit["rows"] if r["name"] == row["same_as"] and r["same_as"] is None)


def by_reading(us):
    """{model name: summary} over the configurations that read own parts: per configuration its
    class (a duplicate takes its observation's; 'not run' where it has no cell), the configurations where its own part is
    resolved and their sign, where the mirror's, on every split or not decided, and a label:
    '+' / '-' with 'n of N configurations' where every resolved part has one sign, '+-' where both
    occur, 'not decided (U only: not run at ...)' where the model ran on one deciding configuration,
    'not resolved' or 'failed' where no part is resolved."""
    dec = [u for u in us if counted(u)]
    out = {}
    for name in dict.fromkeys(r["name"] for u in dec for r in u["rows"]):
        got, dup = {}, set()
        for u in dec:
            r = next((x for x in u["rows"] if x["name"] == name), None)
            got[_where((u["n"], u["bc"]))] = None if r is None else _resolve(u, r)
            dup |= set() if r is None or r["same_as"] is None else {r["same_as"]}
        ran_rows = [r for r in got.values() if r is not None]
        kinds = {k: "not run" if r is None else r["kind"] for k, r in got.items()}
        ran = [k for k, r in got.items() if r is not None]
        resolved = {k: r for k, r in got.items() if r is not None and r["sign"]}
        signs = {r["sign"] for r in resolved.values()}
        mirror = [k for k, r in resolved.items() if r.get("mirror_vs") == "above"]
        every = [k for k, r in resolved.items() if r.get("mirror_vs") == "below"]
        open_ = [k for k in resolved if k not in mirror and k not in every]
        rest = {k: v for k, v in kinds.items() if k not in resolved}
        if dup and all(r["name"] != name for r in ran_rows):
            tag = "same"
            label = (f"one observation with {_names(sorted(dup))} on every configuration it ran ("
                     + ", ".join(ran) + ")")
        elif len({k.split(" ")[0] for k in ran}) == 1 and \
                len({u["n"] for u in dec}) > 1:     # one size only: no check under refinement
            tag = "not decided"
            label = (f"not decided ({', '.join(ran)} only: not run at "
                     + ", ".join(k for k in kinds if k not in ran) + ")")
        elif len(signs) == 2:
            tag, label = "+-", f"both signs over the configurations ({len(resolved)} of {len(dec)})"
        elif signs:
            tag = next(iter(signs))
            label = f"{tag} on {len(resolved)} of {len(dec)} configurations"
        elif all(v.startswith("failed") or v == "not run" for v in kinds.values()):
            tag, label = "failed", "failed"
        else:
            tag, label = "not resolved", "not resolved on any configuration"
        out[name] = {"tag": tag, "label": label, "units": kinds, "resolved": len(resolved),
                     "of": len(dec), "mirror": mirror, "every": every, "open": open_,
                     "rest": rest}
    return out


def times(x):
    """A ratio for a sentence: two significant figures, whole from 100, powers of ten from
    1e4; 'inf' for an unbounded one."""
    return ("n/a" if x is None else "inf" if x == np.inf else f"{x:.1e}" if x >= 1e4
            else f"{x:.0f}" if x >= 100 else fmt(x, 2))


def _by_value(d):
    out = {}
    for k, v in d.items():
        out.setdefault(v, []).append(k)
    return out


def _five_text(us):
    five = [u for u in us if u["n"] < DECISIVE]
    if not five:
        return "the paper's own 5-node cube was not run"
    return ("the paper's own 5-node cube ("
            + "; ".join(f"{u['bc']}: " + (
                f"smooth fields leak up to {fmt(u['check']['worst'], 2)} of their height "
                f"({u['check']['worst_field']}) on its {u['check']['free']} layers"
                if u["check"].get("worst") is not None else u["check"].get("why", ""))
                for u in five) + ")")


def _below_text(dec):
    """Where the finest deciding configurations say about the clear level: every distinct
    model below
    it on both normalisations (against its u), or which are not; with what an end-localised
    alternation reads there."""
    top = max((u["n"] for u in dec), default=None)
    fine = [u for u in dec if u["n"] == top]
    rows = [(u, r) for u in fine for r in u["rows"] if r["same_as"] is None
            and r["clear"] is not None]
    not_below = [f"{r['name']} ({_where((u['n'], u['bc']))}: {_clear_word(r['clear'])})"
                 for u, r in rows if r["clear"] != "below"]
    ends = ", ".join(f"{fmt(u['check']['ends'], 2)} ({u['bc']})" for u in fine)
    where = ", ".join(_where((u["n"], u["bc"])) for u in fine)
    head = (f"on {where} every model's signature is below the clear level {CLEAR:g} on "
            "both normalisations" if not not_below else
            f"on {where} not every model's signature is below the clear level {CLEAR:g}: "
            + ", ".join(not_below))
    return {"text": head + f" (an alternation confined to the {END_LAYERS} end layers at each "
            f"end reads {ends} of its amplitude there: such a pattern is not excluded)",
            "head": head, "all_below": not not_below, "n": top}


def layer_mean_scaling(cells, bc):
    """{model: largest over smallest of |signature [mm]| x n (n - 1) over the sizes from
    DECISIVE layers it has on the mirrored split (``bc``, the paper's push; the 5-layer view
    decides nothing), two sizes or more}: 1 where the layer
    mean's signature falls exactly as a node-level period-2 pattern of fixed strain (its mm
    amplitude ~ h) averaged over each layer's side nodes (~ 1 / n) would; the fall of a layer
    mean then says nothing about the nodes' own pattern. Models whose signatures agree to SAME
    at every size are one observation (the first kept)."""
    got = {}
    for c in cells:
        if (c["split"] == MIRRORED and c["bc"] == bc and c["load"] == "paper"
                and c["family"] != CONTROL and c.get("alternation_mm")
                and c["nodes_per_side"] >= DECISIVE):
            n = c["nodes_per_side"]
            got.setdefault(short(c["model"]), {})[n] = abs(c["alternation_mm"]) * n * (n - 1)
    out, seen = {}, []
    for m, v in got.items():
        if len(v) < 2 or any(v.keys() == w.keys() and all(same(v[n], w[n]) for n in v)
                             for w in seen):
            continue             # one observation with a model counted before it
        seen.append(v)
        out[m] = max(v.values()) / min(v.values())
    return out


def _lines(c):
    return None if c is None or c.get("failed") or c.get("line_alternation_mm") is None \
        else np.asarray(c["line_alternation_mm"], float)


def node_part(c, fem):
    """(rms, mean) [mm] over the side-face lines of a model's line signatures less FEM P1's
    on the same tetrahedra (``line_alternations``): the node-level period-2 part and what of
    it survives the layer mean (the mean of the lines is the layer profile's part); (None,
    None) where either lacks them."""
    a, b = _lines(c), _lines(fem)
    if a is None or b is None or a.shape != b.shape:
        return None, None
    d = a - b
    return float(np.sqrt(np.mean(d * d))), float(np.mean(d))


def node_u(fem):
    """u [mm] of a node-level part on ``fem``'s mesh: the rms over the side lines of the
    continuum's own line signatures (a smooth line shape as large as the whole field: the
    leak a part, a fraction of that field, stays below), with the solver's round-off."""
    if fem is None or fem.get("line_alternation_fem_mm") is None:
        return None
    r = np.asarray(fem["line_alternation_fem_mm"], float)
    scale = np.abs(np.asarray(fem["bulge_profile_fem_mm"], float)).mean()
    return float(np.hypot(np.sqrt(np.mean(r * r)), ROUND_OFF_FLOOR * scale))


def cell_node_u(c, fem, leak):
    """u [mm] of cell ``c``'s node-level part on its own split (``fem`` FEM P1 there):
    ``node_u`` with the configuration's ``leak`` (smooth, sharp) times the smooth amplitude
    and end step of (model - FEM P1)'s layer profile, in mm, in quadrature: a line's smooth
    shape leaks into its signature as the layer profile's does."""
    u0 = node_u(fem)
    p, q = _arr(c.get("bulge_profile_mm")), _arr(fem.get("bulge_profile_mm"))
    r = _arr(fem.get("bulge_profile_fem_mm"))
    if u0 is None or p is None or q is None or r is None:
        return u0
    lu = leak_u(p - q, r, _free_layers(c["bc"], len(r)), leak) * float(np.abs(r).mean())
    return float(np.hypot(u0, lu))


def node_pattern(cells):
    """The side nodes' own period-2 pattern, per configuration (size, base) of the mirrored
    split from DECISIVE layers at the push: per distinct model its node-level part (``node_part``
    rms, mm) with u (``cell_node_u``: the continuum's own line scores and the configuration's
    leaks, each split its own), resolved where RATIO times u, and the same part on each
    conforming control (its held model's where run); the share of it the layer mean keeps;
    FEM P1's own node-level pattern (FEM P1's lines less the continuum's) per split; and per
    base the two-point slope in h of each model's resolved node-level part from one size to
    the next (its strain, mm over h, falls at that slope less 1)."""
    at = _index(cells)
    check = metric_check(cells)
    out = []
    for n, bc in sorted({(c["nodes_per_side"], c["bc"]) for c in cells
                         if c["split"] == MIRRORED and c["nodes_per_side"] >= DECISIVE}):
        fem = {x: at.get((YARDSTICK_MODEL, x, n, bc, "paper"))
               for x in (MIRRORED,) + CONFORMING_CONTROLS}
        u = node_u(fem[MIRRORED])
        if u is None:
            continue
        leak = leaks_of(check.get((n, bc), {}))
        fem_own = {}
        for x, f in fem.items():
            if _lines(f) is not None:
                d = _lines(f) - np.asarray(f["line_alternation_fem_mm"], float)
                fem_own[x] = {"rms": float(np.sqrt(np.mean(d * d))), "u": node_u(f)}
        rows, seen = [], []
        for c in cells:
            if (c["split"] != MIRRORED or c["nodes_per_side"] != n or c["bc"] != bc
                    or c["load"] != "paper" or c["family"] == CONTROL
                    or c.get("constant") == HELD):
                continue
            rms, mean = node_part(c, fem[MIRRORED])
            if rms is None:
                continue
            if any(same(rms, r) and same(mean, m_) for r, m_ in seen):
                continue            # one observation with a model counted before it
            seen.append((rms, mean))
            cm = control_model(at, c["model"], n, bc)
            ctrls = {}
            for x in CONFORMING_CONTROLS:
                cx = at.get((cm, x, n, bc, "paper"))
                cr, _ = node_part(cx, fem[x])
                if cr is not None:
                    ctrls[x] = (cr, cell_node_u(cx, fem[x], leak))
            uc = cell_node_u(c, fem[MIRRORED], leak)
            row = {"name": short(c["model"]), "model": c["model"], "rms": rms, "mean": mean,
                   "u": uc, "kept": abs(mean) / rms if rms else None,
                   "resolved": against(rms / uc, RATIO), "controls": ctrls}
            if row["resolved"] == "above" and ctrls:
                lo, hi, call, why = _mirror_call(rms, uc, list(ctrls.values()))
                moved = _constants_moved(c, [at[(cm, x, n, bc, "paper")] for x in ctrls])
                if moved and call != "at":
                    call, why = "at", f"its constants are fitted per split ({moved})"
                row.update({"mirror_lo": lo, "mirror_hi": hi, "mirror_vs": call,
                            "mirror_why": why})
            rows.append(row)
        out.append({"n": n, "bc": bc, "u": u, "fem_own": fem_own, "rows": rows})
    slopes = {}
    by = {(x["n"], x["bc"]): x for x in out}
    for (n, bc), x in by.items():
        fine = by.get((2 * n - 1, bc))
        if fine is None:
            continue
        fr = {r["model"]: r for r in fine["rows"]}
        got = {}
        for r in x["rows"]:
            f = fr.get(r["model"])
            if f and r["resolved"] == "above" and f["resolved"] == "above":
                got[r["name"]] = two_point_order(r["rms"], r["u"], f["rms"], f["u"])
        slopes[bc] = {"sizes": (n, fine["n"]), "orders": got,
                      "of": sum(r["model"] in fr for r in x["rows"])}
    return {"units": out, "slopes": slopes}


def node_lead(nodes):
    """The node-level finding for the opening: per base, how the resolved node-level part's
    strain changes from one size to the next (median and range over the models), and how
    many of the largest size's parts are the mirror's; '' where no slope was read."""
    said = []
    for bc, o in nodes["slopes"].items():
        v = sorted(p - 1 for p, _ in o["orders"].values())
        fine = next((x for x in nodes["units"] if (x["n"], x["bc"]) == (o["sizes"][1], bc)),
                    None)
        if not v or fine is None:
            continue
        res = [r for r in fine["rows"] if r["resolved"] == "above"]
        said.append(f"{bc} base: its strain (mm over h) goes as h^{np.median(v):.2f} from "
                    f"{o['sizes'][0]} to {o['sizes'][1]} nodes (median; {v[0]:.2f} to "
                    f"{v[-1]:.2f} over {len(v)} models), and at {o['sizes'][1]} nodes "
                    f"{sum(r.get('mirror_vs') == 'above' for r in res)} of {len(res)} "
                    "resolved parts are the mirror's")
    return ("at the side nodes (each vertical line of side-face nodes, less FEM P1's; the "
            "layer mean cancels most of it across each face) the mirrored split's period-2 "
            "part on the " + "; on the ".join(said)
            + " (two sizes: not an order; a strain exponent near 0 is a pattern refinement "
            "does not remove)") if said else ""


def node_text(nodes):
    """The node-level pattern in a sentence per configuration and base: resolved, the
    mirror's, the share the layer mean keeps, FEM P1's own per split, and the slope."""
    parts = []
    for x in nodes["units"]:
        rs = x["rows"]
        res = [r for r in rs if r["resolved"] == "above"]
        mir = [r for r in res if r.get("mirror_vs") == "above"]
        ctrl_res = sum(any(against(p / pu, RATIO) == "above" for p, pu in r["controls"].values())
                       for r in rs)
        kept = [r["kept"] for r in res if r["kept"] is not None]
        fo = x["fem_own"]
        parts.append(
            f"{_where((x['n'], x['bc']))}: {len(res)} of {len(rs)} distinct models' node-level "
            f"parts resolved (u {fmt(min(r['u'] for r in rs), 2)}-"
            f"{fmt(max(r['u'] for r in rs), 2)} mm), "
            + (f"{fmt(min(r['rms'] for r in res), 2)}-{fmt(max(r['rms'] for r in res), 2)} mm, "
               if res else "")
            + f"{len(mir)} of them the mirror's, {ctrl_res} of {len(rs)} resolved on a "
            "control split"
            + (f"; the layer mean keeps {fmt(min(kept), 2)}-{fmt(max(kept), 2)} of it (the "
               "rest cancels across each face)" if kept else "")
            + ("; FEM P1's own " + ", ".join(
                f"{x_.split(' ')[0]} {fmt(v['rms'], 2)}" + (
                    "" if against(v["rms"] / v["u"], RATIO) == "above" else " (not resolved)")
                for x_, v in fo.items()) + " mm" if fo else ""))
    slopes = []
    for bc, o in nodes["slopes"].items():
        v = sorted(p for p, _ in o["orders"].values())
        if not v:
            slopes.append(f"{bc}: no model resolved at both {o['sizes'][0]} and "
                          f"{o['sizes'][1]} nodes")
            continue
        slopes.append(
            f"{bc}: h^{np.median(v):.2f} (median; {v[0]:.2f}-{v[-1]:.2f} over {len(v)} of "
            f"{o['of']} models resolved at {o['sizes'][0]} and {o['sizes'][1]} nodes, each +- "
            f"at most {fmt(max(q for _, q in o['orders'].values()), 2)}), its strain (mm over "
            f"h) at h^{np.median(v) - 1:.2f}")
    if not parts:
        return ""
    return ("The side nodes' own pattern (each vertical line of side-face nodes read with the "
            "layer profile's weights, less FEM P1's line on the same tetrahedra; rms over the "
            "lines; u the continuum's own line scores, a smooth shape as large as the field, "
            "and the configuration's leaks times the smooth shape and end step of the model's "
            "layer profile less FEM P1's, on each split its own): "
            + "; ".join(parts) + (". Under refinement the node-level part falls at "
                                  + "; ".join(slopes) + " (two sizes only: the order is not "
                                  "decided)" if slopes else ""))


def flutter_on_controls(cells):
    """'pbcm-balanced-literal (five 3.54, six 97, bcc 70.5 1/s)': per model, where its growth
    rate at rest (clamped, the paper's lattice) on a conforming control split is RATIO times
    its rate on the mirrored five and above GROWS: a cost of the pick that the pattern does
    not show."""
    rates = {}
    for c in cells:
        if (c["family"] != CONTROL and c["bc"] == "clamped" and c["load"] == "paper"
                and c.get("growth_rate_1_s") is not None and c.get("constant") != HELD
                and c["split"] in (MIRRORED,) + CONFORMING_CONTROLS):
            rates.setdefault(c["model"], {})[c["split"]] = c["growth_rate_1_s"]
    out = []
    for m, r in rates.items():
        five = r.get(MIRRORED)
        worse = {x: v for x, v in r.items() if x != MIRRORED and v > GROWS
                 and five is not None and v >= RATIO * max(five, 0.0)}
        if worse:
            out.append(f"{short(m)} (" + ", ".join(f"{'five' if x == MIRRORED else x} {fmt(v, 3)}"
                                                   for x, v in r.items()) + " 1/s)")
    return out


def stiffer_on_controls(cells):
    """'msm (six -0.997 against -0.59 on the mirrored five, 17 sliding)': per model at the
    largest size, where on a conforming control split the model keeps RATIO times less of the
    continuum's lateral motion (1 + its lateral displacement error) than on the mirrored
    split, of the same sign (it barely expands laterally there): a cost of the pick that the
    pattern does not show."""
    at = _index(cells)
    top = max((c["nodes_per_side"] for c in cells), default=0)
    out = []
    for m in dict.fromkeys(c["model"] for c in cells if c["family"] != CONTROL
                           and c["nodes_per_side"] == top):
        worst = None
        for bc in ("clamped", "sliding"):
            five = at.get((m, MIRRORED, top, bc, "paper"))
            e5 = None if five is None or five.get("failed") else lateral_error(five)
            for x in CONFORMING_CONTROLS:
                c = at.get((m, x, top, bc, "paper"))
                e = None if c is None or c.get("failed") else lateral_error(c)
                if e5 is None or e is None or e5 <= -1.0 or e <= -1.0:
                    continue
                kept = (1.0 + e) / (1.0 + e5)
                if kept * RATIO < 1.0 and (worst is None or kept < worst[0]):
                    worst = (kept, x, e, e5, bc)
        if worst:
            _, x, e, e5, bc = worst
            out.append(f"{short(m)} ({x.split(' ')[0]} {fmt(e, 3)} against {fmt(e5, 2)} on the "
                       f"mirrored five, {top} {bc})")
    return out


def mesh_pick(resolved, mirrors, against_, fem_units, nodes, stiffer=(), counted_at=None,
              flutter=()):
    """What to mesh a lattice with, given the bulge/neck pattern: from the layer-level parts
    (``resolved`` their counts by sign in words, ``mirrors`` the mirror's, ``against_`` on
    every split), FEM P1's own
    (``fem_units``: where it is the mirror's) and the node-level parts (``node_pattern``): the
    median over the models of the mirrored split's node-level part over its larger control's,
    per configuration. Only the configurations the answers count (``counted_at``, (n, bc)
    pairs; every one where None) enter. A split is named to avoid only where some part is the
    mirror's and none is on every split; with what the pick costs: the models it makes stiffer
    laterally (``stiffer``) or flutter faster (``flutter``), and how many models keep a
    resolved node-level part of their own on a control (the error changes shape there)."""
    units = [x for x in nodes["units"]
             if counted_at is None or (x["n"], x["bc"]) in counted_at]
    node_rows = [r for x in units for r in x["rows"] if r["resolved"] == "above"]
    node_mirror = [r for r in node_rows if r.get("mirror_vs") == "above"]
    ratios = {}
    for x in units:
        # the ratio's lower bound: a control below its u may be 0
        got = [r["mirror_lo"] for r in x["rows"]
               if r.get("mirror_vs") == "above" and r.get("mirror_lo") is not None]
        if got:
            ratios[_where((x["n"], x["bc"]))] = (float(np.median(got)), min(got), max(got))
    if against_ or not (mirrors or node_mirror or fem_units):
        return None
    on_ctrl = [r for r in node_rows
               if any(abs(v) >= RATIO * u for v, u in r["controls"].values())]
    return ("a conforming split without the mirror (six or bcc), not the mirrored five: at "
            "the side nodes the mirrored split's period-2 part over its larger control's is at "
            "least "
            + ", ".join(f"{w} {times(v[0])} [{times(v[1])}-{times(v[2])}]"
                        for w, v in ratios.items())
            + f" (median [range] of the lower bounds over the mirror's parts), {len(node_mirror)} of "
            f"{len(node_rows)} "
            "resolved parts (a model on a configuration each) the mirror's, "
            + ("the others not decided, " if len(node_mirror) < len(node_rows) else "")
            + "none on every split; in "
            f"the layer mean {resolved}"
            + (f"; FEM P1's own on {', '.join(fem_units)}" if fem_units else "")
            + " (one mesh per split and size: no spread over meshes; chosen on the pattern "
            "alone: each mesh family's model-form error is in the scorecard and its "
            "consistency limit in the table below, which this pick does not weigh)"
            + (f"; on a control {len(on_ctrl)} of {len(node_rows)} of these parts keep a "
               "resolved node-level part of their own, smaller: the error changes shape "
               "there, it does not vanish" if on_ctrl else "")
            + (f"; not for a model that keeps {RATIO:g} times less of the continuum's lateral "
               "motion there than on the mirrored split (its lateral displacement error, at "
               "the largest size): " + ", ".join(stiffer) if stiffer else "")
            + (f"; a control makes these models flutter {RATIO:g} times faster at rest "
               "(clamped, 5 nodes; growth rate per split): " + ", ".join(flutter)
               if flutter else ""))


def _period_text(dec):
    """What the signature tests under refinement: the pattern at the paper's own period read
    on each configuration that reads parts."""
    got = [f"{_where((u['n'], u['bc']))} {fmt(u['check']['paper_period'], 2)}" for u in dec
           if u["check"].get("paper_period") is not None]
    return (" What is tested: a pattern of the paper's own period (bulges 16 mm apart: on its "
            "5 layers the period-2 component itself) at amplitude 1 reads " + ", ".join(got)
            + ": under refinement these runs test a period-2 pattern at the mesh's own scale, "
            "not one at the paper's period, which this metric reads as smooth." if got else "")


def order_text(bc, o, scaling=None):
    """The two-point slope of one base's own parts, with its uncertainty: never a decided
    order (two sizes cannot show the asymptotic range)."""
    v = sorted(o["orders"].values())
    us = [x for x in (o.get("u") or {}).values() if x is not None]
    return (f"falls from {o['sizes'][0]} to {o['sizes'][1]} nodes on the {bc} base at a "
            f"two-point slope of h^{np.median(v):.2f} (median; {min(v):.2f}-{max(v):.2f} over "
            f"{len(v)} of {o['of']} distinct models, each "
            + (f"+- at most {fmt(max(us), 2)} from the parts' u propagated through the slope"
               if us else "from two sizes, no uncertainty")
            + "; two sizes only: the order is not decided)" + _scaling_text(o, scaling))


def _scaling_text(o, scaling):
    """What ``layer_mean_scaling`` says of the slope: the models whose layer-mean signature
    falls as a fixed node-level pattern averaged over a layer would, to 1 %."""
    if not scaling:
        return ""
    n_c, n_f = o["sizes"]
    same = sorted(m for m, r in scaling.items() if r <= 1.01)
    return (f"; the slope a fixed node-level period-2 pattern averaged over each layer's side "
            f"nodes would give is h^{np.log2(n_f * (n_f - 1) / (n_c * (n_c - 1))):.2f}, and "
            f"{len(same)} of {len(scaling)} models' signature [mm] times n (n - 1) is the same "
            f"at {n_c} and {n_f} nodes to 1 %" + (f" ({_compress(same)})" if same else "")
            + ": the layer mean may fall while the nodes' own pattern does not (read at the "
            "nodes below)" if same else "")


def mirror_counts(u):
    """Per configuration that reads: the distinct models by what their own part is: the
    mirror's (by sign), on every split, mirror not decided, at the threshold, not resolved,
    failed (its mirrored cell); and the models one of whose controls failed."""
    rows = [r for r in u["rows"] if r["same_as"] is None and not r["kind"].startswith("n/a")]
    out = {"of": len(rows), "+": [], "-": [], "every": [], "open": [], "at": [],
           "unresolved": [], "failed": [],
           "control_failed": [r["name"] for r in rows if r.get("failed_controls")]}
    for r in rows:
        k = r["kind"]
        key = ("failed" if k.startswith("failed") else
               r["sign"] if r["sign"] and r.get("mirror_vs") == "above" else
               "every" if r["sign"] and r.get("mirror_vs") == "below" else
               "open" if r["sign"] else "at" if k.startswith("at the") else "unresolved")
        out[key].append(r["name"])
    out["resolved"] = len(out["+"]) + len(out["-"]) + len(out["every"]) + len(out["open"])
    return out


def failed_cells(cells):
    """Every failed cell of the study (any split, base, load): (model, mesh, bc, load, why,
    whether FEM P1 solved the same cell: then the problem is well posed and the failure the
    model's)."""
    solved = {(c["mesh"], c["bc"], c["load"]) for c in cells
              if c["family"] == CONTROL and not c.get("failed")}
    return [(short(c["model"]), c["mesh"], c["bc"], c["load"], failure(c),
             (c["mesh"], c["bc"], c["load"]) in solved) for c in cells if c.get("failed")]


def _open_reasons(rows):
    """'24 with constants fitted per split, 15 with no control resolved, ...': why the mirror
    read of resolved parts is not decided, counted by kind of reason."""
    kinds = {}
    for r in rows:
        why = r.get("mirror_why") or ""
        k = ("constants fitted per split (no control holds the mirrored split's)"
             if why.startswith("its constants") else
             "a control failed" if why.startswith("a control failed") else
             "no control part resolved from 0" if "unbounded" in why else
             "the ratio at the threshold")
        kinds[k] = kinds.get(k, 0) + 1
    return ", ".join(f"{v} with {k}" for k, v in sorted(kinds.items(), key=lambda kv: -kv[1]))


def size_line(layer_orders, below, largest, units_):
    """The first sentence: how large the pattern the paper drew (the layer mean) is at the
    finest size, and how its own part falls under refinement, per base; with FEM P1's own
    signature on the mirrored split where it is resolved."""
    falls = []
    for bc, o in sorted(layer_orders.items()):
        v = sorted(o["orders"].values())
        if v:
            falls.append(f"as h^{np.median(v):.2f} on the {bc} base (median; "
                         f"{v[0]:.2f} to {v[-1]:.2f} over {len(v)} of {o['of']} models "
                         f"resolved at {o['sizes'][0]} and {o['sizes'][1]} nodes)")
    if below is None:
        seen = "not decided (no configuration's leak is below the deciding level)"
    else:
        top = [(w, v) for w, v in (largest or {}).items() if v and w.startswith(f"{below['n']} ")]
        seen = below["head"] + (" (largest: " + ", ".join(
            f"{v[0]} {fmt(abs(v[1]), 2)} over its own mean on {w}" for w, v in top) + ")"
            if top else "")
    fem = [f"{fmt(abs(u['fem_mm']), 2)} mm on {_where((u['n'], u['bc']))}" for u in units_
           if u["reads"] and u.get("fem_vs") == "above" and u.get("fem_mm") is not None]
    return ("Size (the paper's Figure 1 draws the layer mean): " + seen
            + (". The layer mean's own part (less FEM P1's) falls " + "; ".join(falls)
               + " (two sizes: not an order): the layer mean averages the side nodes' "
               "pattern over each face, so it falls as refinement adds nodes to a layer, "
               "while at the side nodes a period-2 pattern of about constant strain stays on "
               "the mirrored split ((a)): refinement does not remove the pattern" if falls
               else "")
            + (f". FEM P1's own layer signature on the mirrored split: {', '.join(fem)}"
               if fem else "") + ".")


def distinct_pairs(pairs):
    """The normal-stress pairs with those of one configuration, one base model and the same
    part with and without the term (to SAME) counted once: two terms that move the part alike
    are one observation; and one model's pairs on one base at two sizes whose ratios agree to
    COARSE counted once too (a pattern of fixed strain scales with h alike with and without
    the term: the same observation again)."""
    kept = []
    for p in pairs:
        if not any(((q["n"], q["bc"], q["base"]) == (p["n"], p["bc"], p["base"])
                    and same(q["with"], p["with"], SAME)
                    and same(q["without"], p["without"], SAME))
                   or ((q["model"], q["bc"]) == (p["model"], p["bc"]) and q["n"] != p["n"]
                       and same(q["ratio"], p["ratio"], COARSE))
                   for q in kept):
            kept.append(p)
    return kept


def verdict_lines(sign_rows, nodes, ns, cs, fem_units, size=None, nc=None):
    """The answer in one sentence per hypothesis, with the counts and ranges that decide it,
    after ``size`` (``size_line``): (a) at the side nodes (the largest size per base) and in
    the layer mean, by sign, with the parts the runs leave open and why; (b) the
    normal-stress pairs; (c) consistency. The evidence follows in the full text."""
    out = [size] if size else []
    node_bits = []
    sizes = next((o["sizes"] for o in nodes["slopes"].values()), (None, None))
    for bc, o in sorted(nodes["slopes"].items()):
        fine = next((x for x in nodes["units"] if (x["n"], x["bc"]) == (o["sizes"][1], bc)),
                    None)
        v = sorted(p - 1 for p, _ in o["orders"].values())
        if fine is None or not v:
            continue
        # beyond its u (the parts' u through the slope, which holds neither the fitted
        # constants nor a spread over meshes) a strain grows (exponent < 0) or falls
        grows = sum(p - 1 < -q for p, q in o["orders"].values())
        falls = sum(p - 1 > q for p, q in o["orders"].values())
        res = [r for r in fine["rows"] if r["resolved"] == "above"]
        mir = [r for r in res if r.get("mirror_vs") == "above"]
        # the ratio's lower bound (a control below its u may be 0: the point value overstates)
        # over the parts called the mirror's alone (an open part's ratio decides nothing)
        ratios = sorted(r["mirror_lo"] for r in mir if r.get("mirror_lo") is not None)
        node_bits.append(
            f"{bc} base, {fine['n']} nodes: {len(mir)} of {len(res)} resolved parts the "
            "mirror's" + (f" ({len(res) - len(mir)} not decided: "
                          f"{_open_reasons([r for r in res if r.get('mirror_vs') == 'at'])})"
                          if len(res) > len(mir) else "")
            + (f", mirrored over its larger control at least {times(float(np.median(ratios)))} "
               f"(median of the lower bounds over the mirror's parts; "
               f"{times(ratios[0])}-{times(ratios[-1])})"
               if ratios else "")
            + f"; its strain goes as h^{np.median(v):.2f} from {o['sizes'][0]} to "
            f"{o['sizes'][1]} nodes ({v[0]:.2f} to {v[-1]:.2f} over {len(v)} models; beyond "
            f"its u growing for {grows}, falling for {falls})")
    layer = []
    for s_, word in (("+", "the paper's sign"), ("-", "the reversed sign")):
        rows = [r for _, r in sign_rows[s_]]
        if not rows:
            continue
        mir = sum(r.get("mirror_vs") == "above" for r in rows)
        every = sum(r.get("mirror_vs") == "below" for r in rows)
        open_ = [r for r in rows if r.get("mirror_vs") not in ("above", "below")]
        per = {}                   # each configuration one mesh pair: the unit
        for w, r in sign_rows[s_]:
            per.setdefault(w, []).append(r.get("mirror_vs") == "above")
        layer.append(f"{word}: the mirror's on " + ", ".join(
            f"{w} {sum(v)} of {len(v)}" for w, v in per.items())
            + f" (in all {mir} of {len(rows)} parts), {every} on every split"
            + (f", {len(open_)} not decided: {_open_reasons(open_)}" if open_ else ""))
    if node_bits or layer:
        out.append(
            "(a) Mirror symmetry: the mirrored five split carries a period-2 pattern of its "
            "own at the side nodes (less FEM P1's on the same tetrahedra) whose strain goes "
            f"as h^e from {sizes[0]} to {sizes[1]} nodes, per base below (two sizes: not an "
            "order; the u of e holds neither the fitted constants nor a spread over meshes); "
            "whether the mirror alone causes it is "
            "decided model by model, against each model's own parts on the conforming splits "
            "it ran (six and bcc; cells.md shows every failed cell): "
            + "; ".join(node_bits)
            + (". In the layer mean, which averages it across each face (model cells at the "
               "push, 9 and 17 nodes, both bases, each configuration one mesh pair): "
               + "; ".join(layer) if layer else "")
            + (f". FEM P1 itself has a resolved mirrored pattern on {', '.join(fem_units)}"
               if fem_units else "") + ".")
    if ns.get("pairs"):
        ps = distinct_pairs(ns["pairs"])
        open_ = [p for p in ps if p["reduced"] == "at"]
        decided = [p for p in ps if p["reduced"] != "at"]
        flat = [p for p in decided if same(abs(p["with"]), abs(p["without"]), 0.02)]
        red = sum(p["reduced"] == "above" for p in decided)
        per = {}
        for p in decided:
            per.setdefault(_where((p["n"], p["bc"])), []).append(p["reduced"] == "above")
        out.append(
            f"(b) Normal stress: {red} of {len(decided)} decided pairs (a resolved part with "
            f"and without the term, the split held; distinct pairs, each configuration one "
            f"mesh pair: " + ", ".join(f"{w} {sum(v)} of {len(v)}" for w, v in per.items())
            + f") reduced {RATIO:g}-fold"
            + (f", |with| / |without| {fmt(min(p['ratio'] for p in decided), 2)}-"
               f"{fmt(max(p['ratio'] for p in decided), 2)}" if decided else "")
            + (f" (in {len(flat)} of them the term moves the part by under 2 %: a null, "
               "the term changes the pattern by nothing)" if flat else "")
            + (f"; {len(open_)} not decided (the part with the term not resolved from 0: "
               + _names(sorted({f"{p['model']} ({_where((p['n'], p['bc']))})"
                                for p in open_})) + ")" if open_ else "")
            + (": the missing normal stress is not shown to be the cause." if red == 0 else
               "."))
    else:
        out.append("(b) Normal stress: not tested (no term active beside a resolved part).")
    word = (_tracks_word(cs["rows"]) if cs.get("testable") else "not testable")
    out.append(f"(c) Consistency: {word}" + (
        f" ({'; '.join(r['mesh'] + ': ' + r['verdict'] for r in cs['rows'])})"
        if cs.get("rows") else "") + "; the linear load, which (c) reads, is run at 9 nodes, "
        "not at 17" + (
            "; at the side nodes (each model's node-level part against its patch-test "
            "error, one run: the linear load, sliding; the interval over the reading "
            "families, as variants of one reading share its kernel; a calibrated reading's "
            "patch-test error is in part what its fit left): "
            + "; ".join(f"{r['mesh']}: {r['verdict']}" + (
                f" (rho {r['rho']:.2f} [{r['interval'][0]:.2f}, {r['interval'][1]:.2f}], "
                f"{r['models']} distinct models in {r['families']} families)"
                if r["rho"] is not None
                and r.get("interval") else "") for r in nc["rows"])
            if nc and nc.get("rows") else "") + ".")
    return out



def short_answer(below, nodes, sign_rows, ns, cs, nc, fine_units=()):
    """The answer in a few plain sentences and a table, from what ``verdict_lines`` states in
    full: ``(sentences, rows)``, a row per question (size, each hypothesis): [question,
    answer, the numbers that decide it]. ``fine_units``: the counted configurations at the
    finest size, whose metric check says what a pattern at the paper's own period reads."""
    rows = []
    period = [f"{fmt(u['check']['paper_period'], 2)} ({u['bc']})" for u in fine_units
              if u["check"].get("paper_period") is not None]
    strain = {bc: (o["sizes"], float(np.median([e - 1 for e, _ in o["orders"].values()])))
              for bc, o in sorted(nodes["slopes"].items()) if o["orders"]}
    stays = [f"h^{e:.2f} {bc}" for bc, (_, e) in strain.items() if e < 0.5]
    nodes_said = (
        "; at the side nodes of the mirrored split, though, a period-2 strain stays as the "
        f"mesh is refined ({', '.join(stays)}, from {next(iter(strain.values()))[0][0]} to "
        f"{next(iter(strain.values()))[0][1]} nodes, median over the models: two sizes, not "
        "an order); the layer mean averages it away across each face" if stays else "")
    if below is None:
        rows.append(["Large enough to see (the layer mean the paper drew)?", "not decided",
                     "no configuration's leak is below the deciding level"])
    else:
        rows.append(["Large enough to see (the layer mean the paper drew)?",
                     (f"a period-2 pattern at the mesh's own scale: no, at {below['n']} nodes "
                      "per side" if below["all_below"] else
                      f"a period-2 pattern at the mesh's own scale: yes, for some models at "
                      f"{below['n']} nodes per side")
                     + ("; one at the paper's own period (bulges 16 mm apart): not decided, "
                        "these meshes read it as smooth" if period else "") + nodes_said,
                     below["head"] + (f"; a pattern at the paper's period reads "
                                      f"{', '.join(period)} of its amplitude there"
                                      if period else "")])
    node_said, mirror_any, every_any, open_any = [], False, False, False
    for bc, o in sorted(nodes["slopes"].items()):
        fine = next((x for x in nodes["units"] if (x["n"], x["bc"]) == (o["sizes"][1], bc)),
                    None)
        if fine is None:
            continue
        res = [r for r in fine["rows"] if r["resolved"] == "above"]
        mir = [r for r in res if r.get("mirror_vs") == "above"]
        every = [r for r in res if r.get("mirror_vs") == "below"]
        mirror_any |= bool(mir)
        every_any |= bool(every)
        open_any |= len(res) > len(mir) + len(every)
        fo = fine.get("fem_own") or {}
        node_said.append(f"{len(mir)} of {len(res)} resolved parts are the mirror's, "
                         f"{len(every)} on every split, {len(res) - len(mir) - len(every)} not "
                         f"decided ({bc}, {fine['n']} nodes; unsigned: rms over the lines)"
                         + ("; FEM P1's own there " + ", ".join(
                             f"{'five' if x == MIRRORED else x} {fmt(v['rms'], 2)}"
                             + ("" if against(v["rms"] / v["u"], RATIO) == "above"
                                else " (not resolved)") for x, v in fo.items()) + " mm"
                            if fo else ""))
    per = {}        # per configuration (the unit), by sign: (the mirror's, resolved)
    for s_ in ("+", "-"):
        for w, r in sign_rows[s_]:
            got = per.setdefault(w, {}).setdefault(s_, [0, 0, 0])
            got[0] += r.get("mirror_vs") == "above"
            got[1] += r.get("mirror_vs") == "below"
            got[2] += 1
    layer, open_parts, all_parts = [], 0, 0
    for w, by in per.items():
        mirror_any |= any(v[0] for v in by.values())
        every_any |= any(v[1] for v in by.values())
        open_parts += sum(v[2] - v[0] - v[1] for v in by.values())
        all_parts += sum(v[2] for v in by.values())
        layer.append(f"{w}: " + ", ".join(
            f"{s_} {v[0]} of {v[2]}" + (f" ({v[1]} on every split)" if v[1] else "")
            for s_, v in by.items()))
    open_any |= open_parts > 0
    whole = [w for w, by in per.items() if all(v[0] == v[2] for v in by.values())]
    a_answer = (("the mirror's where decided: every resolved part on " + ", ".join(whole)
                 if whole else "the mirror's where decided")
                + (f"; {open_parts} of {all_parts} layer-mean parts not decided (no control "
                   "part resolved)" if open_parts else "")
                + "; none on every split; one mesh per split and size, n = 1"
                if mirror_any and not every_any else
                "partly: some parts are on every split" if mirror_any else "not shown")
    evidence = ((["at the side nodes: " + "; ".join(node_said)] if node_said else [])
                + (["in the layer mean (model parts the mirror's, of those resolved, per "
                    "counted configuration and sign of the part): " + "; ".join(layer)]
                   if layer else []))
    rows.append(["(a) The mirror symmetry of the five split?", a_answer,
                 "; ".join(evidence) or "no resolved part"])
    ps = distinct_pairs(ns.get("pairs") or [])
    decided = [p for p in ps if p["reduced"] != "at"]
    red = sum(p["reduced"] == "above" for p in decided)
    nulls = [p for p in decided if same(abs(p["with"]), abs(p["without"]), 0.02)]
    spans = {s_: [p["ratio"] for p in decided if p["sign"] == s_] for s_ in ("+", "-")}
    raised = [p for p in decided if against(p["ratio"], RATIO) == "above"]
    raised_at = [p for p in decided if against(p["ratio"], RATIO) == "at"]
    lowered = {s_: [p for p in decided if p["sign"] == s_ and p["ratio"] < 1.0]
               for s_ in ("+", "-")}
    open_ = len(ps) - len(decided)
    b_answer = ("not tested" if not ps else
                f"not shown: no term reduces the pattern {RATIO:g}-fold"
                + (f" ({open_} at the threshold: not decided)" if open_ else "") if red == 0
                else f"for {red} pairs")
    if ps and red == 0:
        sign_word = {"+": "the paper's sign", "-": "the reversed sign"}
        b_answer += "".join(
            f"; with {sign_word[s_]} {len(v)} of {len(spans[s_])} decided pairs are reduced "
            f"less than that, to {fmt(min(p['ratio'] for p in v), 2)}-"
            f"{fmt(max(p['ratio'] for p in v), 2)} of the part"
            for s_, v in lowered.items() if v)
        if raised:
            b_answer += (f"; a term raises it {RATIO:g}-fold or more in {len(raised)} "
                         f"(up to {fmt(max(p['ratio'] for p in raised), 2)}-fold: "
                         + _names(sorted({p['model'] for p in raised})) + ")")
        if raised_at:
            b_answer += (f"; {len(raised_at)} raised about {RATIO:g}-fold (at the threshold: "
                         + _names(sorted({p['model'] for p in raised_at})) + ")")

    def how_set(fitted):
        got = [p for p in decided if bool(p.get("fitted")) == fitted]
        if not got:
            return None
        cns = [p["c_n"] for p in got if p.get("c_n") is not None]
        flat = [p for p in got if same(abs(p["with"]), abs(p["without"]), 0.02)]
        return (f"{'fitted' if fitted else 'fixed'} c_n ({len(got)} pairs"
                + (f", c_n {fmt(min(cns), 2)}-{fmt(max(cns), 2)}" if cns and fitted else
                   ", c_n = 1" if not fitted else "")
                + f"): |with| / |without| {fmt(min(p['ratio'] for p in got), 2)}-"
                f"{fmt(max(p['ratio'] for p in got), 2)}, {len(flat)} "
                + ("null" if len(flat) == 1 else "nulls"))
    rows.append(["(b) The missing normal stress?", b_answer,
                 (f"{red} of {len(decided)} decided distinct pairs (a resolved part with and "
                  f"without the term, the split held) reduced {RATIO:g}-fold; "
                  f"{len(ps) - len(decided)} not decided; {len(nulls)} of them nulls (the "
                  "term moves the part by under 2 %; a fitted c_n near 0 makes a null by "
                  "construction); by how c_n was set: "
                  + "; ".join(x for x in (how_set(False), how_set(True)) if x)) if ps else
                 "no term active beside a resolved part"])
    node_words = [r["verdict"] for r in (nc or {}).get("rows", [])]
    c_word = (_tracks_word(cs["rows"]) if cs.get("testable") else "not testable")
    node_word = _tracks_word(nc["rows"]) if node_words else "not read"
    # the two readings must agree: the layer signature at the linear load and the node part
    # at the push against the patch-test error
    c_answer = ("no: neither view tracks the patch-test error" if
                c_word == node_word == "does not track" else
                "yes: both views track the patch-test error" if c_word == node_word ==
                "tracks" else
                "not decided: the layer view and the node view disagree"
                if {c_word, node_word} == {"tracks", "does not track"} else
                "not decided: " + "; ".join(
                    f"the {v} view {w}" for v, w in (("layer", c_word), ("node", node_word))
                    if w not in ("tracks", "does not track")))
    rows.append(["(c) The model's consistency (its patch-test error)?", c_answer,
                 f"the layer signature at the linear load: {c_word}; the node-level part "
                 "at the linear load against the patch-test error, the interval over the "
                 "reading families"
                 + (f" (over {fam} families 'tracks' needs rho of {need[0]:.2f} or more and "
                    f"'does not track' {need[1]:.2f} or less: a test of little power)"
                    if (fam := min([r.get("families") or 0 for r in (nc or {}).get("rows", [])],
                                   default=0)) and (need := track_needs(fam)) else "")
                 + ": " + (", ".join(
                     f"{r['mesh']} {r['verdict']}" + (f" (rho {r['rho']:.2f})"
                                                     if r["rho"] is not None else "")
                     for r in nc["rows"]) if node_words else "not read")])
    said = [f"{q} {a}." for q, a, _ in rows]
    return said, rows


def answer(cells, models=None, estimates=None):
    """The paper's question answered hypothesis by hypothesis from the configurations that
    read own parts (DECISIVE or more layers): (a) where a resolved own part is the mirror's,
    by sign, with its order in h; (b) whether a normal-stress term reduces it, and for which
    sign that was tested; (c) whether it tracks the patch-test error, in the linear regime;
    then whether it is large enough to see (the clear level, on the configurations that
    decide it); 'not decided' for the paper's 5-node cube. ``estimates``: the references'
    error estimates {"bc/load": estimate}, where known."""
    m = mirror(cells, models)
    us = m["units"]
    every, cells = cells, main_cells(cells)    # the held models: the mirror's controls alone
    ns, cs = normal_stress(cells, us), consistency(cells)
    view, lin = paper_view(us), linear_check(cells)
    dec = [u for u in us if counted(u)]
    paper = _five_text(us)
    hyp = {"mirror": m, "normal_stress": ns, "consistency": cs}
    base = {"hypotheses": hyp, "paper_view": view, "linear": lin, "ratio": RATIO,
            "decisive": DECISIVE, "clear_level": CLEAR, "near": NEAR,
            "deciding": m["deciding"], "asymmetry": reference_asymmetry(cells),
            "inward": inward(cells), "failed": failed_cells(every)}
    if not dec:
        text = "Not decided: " + paper + f". No mesh with {DECISIVE} or more layers was run."
        return {**base, "decided": False, "cause": "not decided", "text": text,
                "numbers": text, "clear": False, "largest": {}, "by_reading": {},
                "causes": []}
    tags = by_reading(us)
    counts = {_where((u["n"], u["bc"])): mirror_counts(u) for u in dec}
    word = {"+": "the paper's sign", "-": "the reversed sign"}
    # per sign (the phenomenon's sign, never pooled): resolved parts, the mirror's, where
    sign_rows = {s_: [(w, r) for u in dec for r in u["rows"] for w in [_where((u["n"], u["bc"]))]
                      if r["same_as"] is None and r.get("sign") == s_] for s_ in ("+", "-")}
    against_ = sum(len(c["every"]) for c in counts.values())
    fem_units = [_where(x) for x in m["mesh_units"]]
    mirrored = {s_: [(w, r) for w, r in v if r.get("mirror_vs") == "above"]
                for s_, v in sign_rows.items()}
    a_holds = (any(mirrored.values()) or bool(fem_units)) and not against_
    slopes = [order_text(bc, o, layer_mean_scaling(cells, bc))
              for bc, o in m["orders"].items() if o["orders"]]
    nodes = node_pattern(every)
    pick = mesh_pick(", ".join(f"{len(mirrored[s_])} of {len(sign_rows[s_])} resolved parts "
                               f"with {w_} the mirror's" for s_, w_ in (
                                   ("+", "the paper's sign"), ("-", "the reversed sign"))
                               if sign_rows[s_]),
                     sum(len(v) for v in mirrored.values()), against_, fem_units, nodes,
                     stiffer_on_controls(cells), {(u["n"], u["bc"]) for u in dec},
                     flutter_on_controls(cells))
    across = consistency_across(every)
    across_said = across_text(across)
    nodes_said, lead_nodes = node_text(nodes), node_lead(nodes)

    def sign_text(s_):
        # the configuration (one mesh pair) is the unit: per configuration, its model parts
        per = {}
        for w, r in sign_rows[s_]:
            per.setdefault(w, []).append(r)
        if not per:
            return f"{word[s_]} ({s_}): no resolved part"
        held = [w for w, rs in per.items() if any(r.get("mirror_vs") == "above" for r in rs)]
        return (f"{word[s_]} ({s_}): the mirror's on {len(held)} of {len(per)} configurations "
                "with a resolved part (" + "; ".join(
                    f"{w}: {sum(r.get('mirror_vs') == 'above' for r in rs)} of {len(rs)} "
                    "resolved parts" + (f", {_compress(mv)}" if (mv := list(dict.fromkeys(
                        r["name"] for r in rs if r.get("mirror_vs") == "above"))) else "")
                    for w, rs in per.items()) + ")")
    fem_ratio = [f"{_where((u['n'], u['bc']))} ({fmt(u['fem_five'], 2)} +- "
                 f"{fmt(u['u_fem'], 2)}, {fmt(abs(u['fem_five']) / u['u_fem'], 2)} u; over its "
                 f"largest on the conforming splits {times(u['fem_ratio'])}" for u in dec
                 if not u["identity"] and u.get("fem_ratio") is not None
                 and u.get("fem_vs") != "above" and u.get("u_fem")]
    resolved_rows = [r for v in sign_rows.values() for _, r in v]
    with_ctrl = sum(any(p.get("resolved") == "above" for p in r["control_parts"].values())
                    for r in resolved_rows)
    a_text = ("; ".join(sign_text(s_) for s_ in ("+", "-"))
              + ("; none is on every split" if not against_ else
                 f"; on every split: {against_}")
              + (f" (only {with_ctrl} of {len(resolved_rows)} resolved parts have a resolved "
                 "control part, without which 'on every split' cannot be read: the test "
                 "can find the mirror's parts, and rarely the others)" if resolved_rows
                 else "")
              + (f"; FEM P1's own signature is resolved and the mirror's on "
                 f"{', '.join(fem_units)}" if fem_units else "")
              + (". FEM P1's own signature on the mirrored split is not resolved on "
                 + ", ".join(fem_ratio) + ", within the metric's leak bound)"
                 if fem_ratio else "")
              + (f". The own part {'; '.join(slopes)}" if slopes else "")
              + (f". {nodes_said}" if nodes_said else "")
              + ". Each configuration is one mesh pair (n = 1) that its models share; the "
              "classes are in the artefact report's tables")
    def b_sign(s_):
        ps = [p for p in distinct_pairs(ns["pairs"]) if p["sign"] == s_]
        if not ps:
            return f"{word[s_]} ({s_}): not tested" + (
                f" (beside {_names(ns['inactive_other_sign'])} every fitted term changes "
                "nothing: the fit sets its constant to 0 or near it, as cells.md states)"
                if ns["inactive_other_sign"] and s_ not in ns["signs"] else "")
        at_ = sum(p["reduced"] == "at" for p in ps)
        moved = [p["shear_c"] for p in ps if None not in p["shear_c"]
                 and not same(*p["shear_c"], SAME)]
        kept = [p for p in ps if None not in p["shear_c"] and same(*p["shear_c"], SAME)]
        kept_text = (f"; in {len(kept)} of them the shear's c is held (the reading's fit, 1 "
                     "for a literal reading; only the normal stress changes: "
                     f"{sum(p['reduced'] == 'above' for p in kept)} of {len(kept)} reduced)"
                     if kept else "")
        whys = _by_value({i: p["why"] for i, p in enumerate(ps) if p["reduced"] == "at"})
        decided = [p for p in ps if p["reduced"] != "at"]
        return (f"{word[s_]} ({s_}): {sum(p['reduced'] == 'above' for p in ps)} of {len(ps)} "
                f"reduced {RATIO:g}-fold" + (" (" + "; ".join(
                    f"{len(v)} not decided: {why}" for why, v in whys.items())
                    + (f", the sign changing in {sum(p['sign_change'] for p in ps)}"
                       if any(p["sign_change"] for p in ps) else "") + ")" if at_ else "")
                + f", |with| / |without| {fmt(min(p['ratio'] for p in ps), 2)}-"
                f"{fmt(max(p['ratio'] for p in ps), 2)}"
                + (f" (the {len(decided)} decided: {fmt(min(p['ratio'] for p in decided), 2)}-"
                   f"{fmt(max(p['ratio'] for p in decided), 2)})"
                   if decided and len(decided) < len(ps) else "") + " ("
                + _names(sorted({p["model"] for p in ps})) + "; on "
                + ", ".join(dict.fromkeys(_where((p["n"], p["bc"])) for p in ps)) + ")"
                + (f"; in {len(moved)} of them the shear's fitted c moves with the term ("
                   + ", ".join(sorted({f"{fmt(a, 3)} to {fmt(b, 3)}" for a, b in moved}))
                   + "): such a pair changes the normal stress and the shear at once"
                   if moved else "") + kept_text)
    b_text = ("distinct pairs (a reading's resolved own part with and without an active "
              "term, the split held fixed: a calibrated reading with each term fitted beside "
              f"its shear's own c, a literal one with {LITERAL_NORMAL} at c_n = "
              f"{FIXED_NORMAL_C:g}), by the sign of the part: "
              + "; ".join(b_sign(s_) for s_ in ("+", "-"))
              if ns["decided"] else "not tested (no term active beside a resolved own part)")
    c_text = ("not testable (" + "; ".join(
        f"{', '.join(meshes)}: {why}" for why, meshes in _by_value(
            {r["mesh"]: r["verdict"][len("not testable: "):] for r in cs["rows"]}).items())
        + ")" if not cs["testable"] else _tracks_word(cs["rows"]) + " (" + "; ".join(
            f"{r['mesh']}: {r['verdict']}, signed rho {fmt(r['rho'], 2)}"
            + (f" [{r['interval'][0]:.2f}, {r['interval'][1]:.2f}]" if r["interval"] else "")
            for r in cs["rows"]) + ")")
    causes = (["the mirror symmetry (a)"] if a_holds else []) + (
        ["the missing normal stress (b)"] if ns["holds"] else []) + (
        ["the model's inconsistency (c)"] if cs["holds"] else [])
    resting = [w for w, c in counts.items() if c["resolved"]]
    ref_est = max([v for k, v in (estimates or {}).items()
                   if k.endswith("/paper") and v is not None], default=None)
    seen_at = [u for u in us if u["decides"] and u["n"] >= DECISIVE]
    below = _below_text(seen_at) if seen_at else None
    by_sign = ", ".join(f"{len(mirrored[s_])} of {len(sign_rows[s_])} with {word[s_]}"
                        for s_ in ("+", "-") if sign_rows[s_])
    said = ([f"under refinement, of the resolved period-2 parts {by_sign} are the mirror's "
             "and none is on every split (a)" + (
                 f" (only {with_ctrl} of the {len(resolved_rows)} have a control part resolved "
                 "from 0, so 'on every split' could rarely occur; 'the mirror's' means the "
                 f"mirrored part is at least {RATIO:g} times every control's upper bound)"
                 if with_ctrl < len(resolved_rows) else "")
             + (f"; FEM P1 itself, the continuum's law on the same tetrahedra, has a resolved "
                f"period-2 signature on the mirrored split and not on the conforming ones on "
                f"{', '.join(fem_units)}" if fem_units else "")
             + "; its u holds the metric's leaks and the solver's tolerance; what the model "
             "and FEM P1 share, the reference's values among it, cancels from every part (both "
             "are read with one reference's weights, and the signature is linear in the "
             "profile); the reference enters a part only through the smooth shape its weights "
             "ignore and the mean the part is divided by" + (
                 f", whose error estimate (at most {fmt(ref_est, 2)} at the push) moves a part "
                 "by that fraction" if ref_est is not None else "")] if a_holds else []) + (
        [lead_nodes] if lead_nodes else []) + (
        ["a normal-stress term removes it (b)"] if ns["holds"] else []) + (
        ["it tracks the patch-test error (c)"] if cs["holds"] else [])
    lead = (f"Not decided for {paper}; the paper's 374-tetrahedron "
            "mesh is not among the meshes run, so whether its mesh is mirrored is not known. "
            + ("; ".join(said)[0].upper() + "; ".join(said)[1:] if said else
               "Under refinement, no hypothesis holds on the configurations that read own "
               "parts"))
    text = (f"{lead}. (a) Mirror symmetry, on the configurations (size, base) where own parts "
            f"are resolved ({', '.join(resting) or 'none'}; one mesh per split each, n = 1; a "
            f"part is resolved where it is {RATIO:g} times its u, the metric's leaks of smooth "
            f"fields and of sharp end layers; the mirror's where it is also {RATIO:g} times the model's part on each "
            f"conforming split without the mirror, within both u), by sign: {a_text}. (b) "
            f"Normal stress: {b_text}. (c) Consistency (the linear regime: the signature at "
            f"the linear load against the patch-test error): {c_text}"
            + (f"; within each model across the splits: {across_said}" if across_said else "")
            + ". "
            + (f"Large enough to see? {below['text'][0].upper()}{below['text'][1:]}: the "
               "period-2 part over the whole height these runs resolve is below the clear "
               "level there."
               if below and below["all_below"] else
               f"Large enough to see? {below['head'][0].upper()}{below['head'][1:]}."
               if below else
               f"Large enough to see: not decided (no configuration's leak is below "
               f"{DECIDING_LEAK:g}).")
            + _period_text(dec)
            + (f" One observation each (cells that agree to two significant figures on every split): {'; '.join(_duplicates(dec))}."
               if _duplicates(dec) else ""))
    largest = {}
    for u in dec:
        rows = [r for r in u["rows"] if r["same_as"] is None and r.get("own") is not None]
        top = max(rows, key=lambda r: abs(r["own"]), default=None)
        largest[_where((u["n"], u["bc"]))] = None if top is None else [top["name"],
                                                                      top["own"]]
    nc = node_consistency(cells)
    hyp["node_consistency"] = nc
    verdicts = verdict_lines(sign_rows, nodes, ns, cs, fem_units,
                             size_line(m["orders"], below, largest, dec), nc)
    short, short_rows = short_answer(below, nodes, sign_rows, ns, cs, nc,
                                     [u for u in seen_at if below and u["n"] == below["n"]])
    if apart(us):
        verdicts.append("Not counted: " + "; ".join(apart(us)) + ": its parts are in the "
                        "tables and the two-point orders in h, not in the counts above.")
    return {**base, "decided": bool(causes), "cause": lead, "text": text, "numbers": text,
            "verdicts": verdicts, "short": short, "short_rows": short_rows,
            "clear": any(r["clear"] == "above" for u in seen_at for r in u["rows"]
                         if r["same_as"] is None),
            "all_below": bool(below and below["all_below"]), "by_reading": tags,
            "largest": largest, "causes": causes, "counts": counts, "nodes": nodes,
            "across": across, "mesh_pick": pick}


def _duplicates(units_):
    """'b+n = b (9 sliding, 17 sliding)': the models that are one observation with another,
    with the configurations where they are."""
    where = {}
    for u in units_:
        for r in u["rows"]:
            if r["same_as"]:
                where.setdefault((r["same_as"], r["name"]), []).append(_where((u["n"], u["bc"])))
    merged = {}
    for (other, name), w in where.items():
        merged.setdefault((other, tuple(w)), []).append(name)
    return [f"{_compress(v)} = {other} ({', '.join(w)})" for (other, w), v in merged.items()]


def _tracks_word(rows):
    """(c) over the meshes where it is testable: 'tracks' or 'does not track' where every one
    says so, else 'not decided'."""
    said = {r["verdict"] for r in rows if not r["verdict"].startswith("not testable")}
    return said.pop() if len(said) == 1 and said <= {"tracks", "does not track"} else \
        "not decided"


# the conventions the answers rest on, each tried at a value either side of this study's: the
# clear level (a fraction of the lateral bulge), the dominance factor, the tracking correlation
THRESHOLDS_TRIED = {"CLEAR": (0.005, 0.02), "RATIO": (2.0, 5.0), "TRACKS": (0.5, 0.9)}
THRESHOLD_WORDS = {"CLEAR": "the clear level", "RATIO": "the dominance factor",
                   "TRACKS": "the tracking correlation"}


def threshold_moves(cells, models=None, estimates=None):
    """How the short answers move with each fixed threshold (THRESHOLDS_TRIED): per threshold
    and value tried, the questions whose answer changes and the answer there. The thresholds
    are this study's conventions, not the paper's: an answer that moves with them is
    provisional on them."""
    base = answer(cells, models, estimates)["short_rows"]
    g = globals()
    out = []
    for name, values in THRESHOLDS_TRIED.items():
        for v in values:
            keep = {k: g[k] for k in (name, "DECIDING_LEAK")}
            g[name] = v
            g["DECIDING_LEAK"] = LEAK_SHARE * g["CLEAR"]
            try:
                rows = answer(cells, models, estimates)["short_rows"]
            finally:
                g.update(keep)
            out.append({"threshold": name, "word": THRESHOLD_WORDS[name], "value": v,
                        "ours": keep[name],
                        "changed": [[q, a] for (q, a, _), (_, a0, _) in zip(rows, base)
                                    if a != a0]})
    return out


def constant_spread(units):
    """How far the fitted shear constant alone moves a model's own part: per counted
    configuration and reading, |part| of its calibrated model over its literal one's (c = 1;
    the same kernel, the same split), both parts resolved; (largest factor either way, the
    reading, the configuration), or None. A bound of the u the fitted constants would add."""
    best = None
    for u in units:
        if not counted(u):
            continue
        by = {r["name"]: r for r in u["rows"] if r.get("part") is not None}
        for name, r in by.items():
            lit = by.get(f"{name}-literal")
            if (lit is None or not r.get("sign") or not lit.get("sign")
                    or not r["part"] or not lit["part"]):
                continue
            f = max(abs(r["part"]) / abs(lit["part"]), abs(lit["part"]) / abs(r["part"]))
            if best is None or f > best[0]:
                best = (f, name, _where((u["n"], u["bc"])))
    return best


def how_sure(ans, verdict):
    """The report's 'how sure' line: what the answers rest on, what the uncertainty holds and
    leaves out, what is at a threshold, and every failed cell."""
    us = ans["hypotheses"]["mirror"]["units"]
    dec = [u for u in us if counted(u)]
    at = [f"{r['name']} ({u['n']} {u['bc']}: "
          + (r["kind"][len("at the threshold ("):-1] if r["kind"].startswith("at the")
             else r.get("mirror_why") or "")
          + ")" for u in dec for r in u["rows"]
          if r["same_as"] is None and (r["kind"].startswith("at the")
                                       or (r.get("sign") and r.get("mirror_why")
                                           == "the ratio at the threshold"))]
    rows = [r for u in dec for r in u["rows"] if r["same_as"] is None
            and not r["kind"].startswith("n/a")]
    lost = sum(r["kind"].startswith("failed") for r in rows)
    failed = ans.get("failed") or []
    by_model, built = {}, {}
    control_solved = sum(f[5] for f in failed if "build:" not in f[4])
    for model, mesh, bc, load, why, _ in failed:
        where = f"{mesh} {bc}" + (f" ({load} load)" if load != "paper" else "")
        if "build:" in why:            # the model could not be made: one cause, stated
            built.setdefault((model, why), []).append(where)
        else:
            by_model.setdefault(model, []).append(where)
    resting = [_where((u["n"], u["bc"])) for u in dec
               if any(r.get("sign") for r in u["rows"] if r["same_as"] is None)]
    return ("**How sure.** " + (
        f"The cause rests on the configurations (size, base) where own parts are resolved "
        f"({', '.join(resting) or 'none'}; {len(dec)} of {len(us)} have {DECISIVE} and more "
        f"layers): {len(rows)} model parts (a distinct model on one configuration each) on "
        f"those {len(dec)} configurations, {len(rows) - lost} "
        f"with an own part"
        + (f", {lost} failed on the mirrored split" if lost else "")
        + "; one mesh per split and size (no spread over meshes of one continuum problem); "
        "each u holds the metric's leaks (the worst smooth test field's and the worst sharp "
        "end layer's) and the solver's "
        f"tolerance ({ROUND_OFF_FLOOR:g}), not the sensitivity to the fitted constants (fitted "
        "per split (the calibration reads the split's own cells: the same constant at every "
        "size), stored in cells.md, not varied; a calibrated reading's controls hold its "
        "mirrored fit's, every fitted constant, so its mirror is not read across two "
        "constants) nor a spread over "
        "meshes: the verdicts are provisional on those"
        + (f" (the shear constant alone, a calibrated reading against its literal one on "
           f"the same split, moves a part up to {spread[0]:.2g}-fold: {spread[1]}, "
           f"{spread[2]})" if (spread := constant_spread(us)) else "")
        + ("; orders from two sizes only; " if any(
            o["orders"] for o in ans["hypotheses"]["mirror"]["orders"].values()) else "; ")
        + (f"at a threshold (within {NEAR:.0%}): {', '.join(at)}; " if at
           else f"none within {NEAR:.0%} of a threshold; ")
        if dec else "No configuration reads own parts; ")
        + (f"failed cells ({len(failed)}, each a hole counted against its model)"
           + "".join(f"; {model} on {len(v)} cells: {why[len('failed ('):-1]}"
                     for (model, why), v in built.items())
           + (f"; failed static solves (the push split into up to {SPLITS_TRIED[-1]} equal "
              f"steps, each Newton step backtracked down to {SHORTEST_STEP:g} of its length; FEM "
              "P1 solved "
              f"{control_solved} of these {sum(map(len, by_model.values()))} cells on the same "
              "tetrahedra" + (", so the problem is well posed and the failure the model's"
                              if control_solved == sum(map(len, by_model.values())) else "")
              + "): " + "; ".join(
                  f"{k} on {', '.join(v)}" for k, v in by_model.items()) if by_model else "")
           + "; " if failed else "")
        + "the reading: " + (verdict["sure"] if verdict["decided"] else _reading_sure(verdict))
        + ".")


def _reading_sure(v):
    """Why the reading is not decided: which observable is open for which readings."""
    why = [f"the cost's range over the bench's rounds on the paper's cube reaches the threshold "
           f"({_names(v['cost_open'])})" if v.get("cost_open") else "",
           f"not timed ({_names(v['untimed'])})" if v.get("untimed") else "",
           "stability (clamped base only) depends on the mesh or on a damping the paper does "
           "not state ("
           + _names(v["stability_depends"]) + "), and the paper's own mesh is not among "
           "those linearised" if v.get("stability_depends") else ""]
    return "not decided (" + "; ".join(x for x in why if x) + ")"


# ---------------------------------------------------------------------------- the paper's figure

PAPER_BULGES_MM, PAPER_NECKS_MM = (0.0, 16.0, 32.0), (8.0, 24.0)   # its Figure 1


def extrema(profile, size_mm=P.SIZE_MM, held=()):
    """(bulges, necks) of a layer profile: the layers' heights y [mm] where it is above
    (below) every neighbouring layer by more than SAME of its mean |value| (a uniform profile
    to round-off has neither), the end layers against their one neighbour; the layers
    ``held`` (a base holding them laterally) are neither."""
    p = np.asarray(profile, float)
    y = np.linspace(0.0, size_mm, len(p))
    tol = SAME * float(np.abs(p).mean())
    up, down = [], []
    for k in range(len(p)):
        if k in held:
            continue
        nb = [p[j] for j in (k - 1, k + 1) if 0 <= j < len(p)]
        if all(p[k] > x + tol for x in nb):
            up.append(float(y[k]))
        elif all(p[k] < x - tol for x in nb):
            down.append(float(y[k]))
    return up, down


def reproduces(profile, size_mm=P.SIZE_MM, held=()):
    """Whether a 5-layer profile shows the paper's alternation: bulges at exactly
    PAPER_BULGES_MM and necks at exactly PAPER_NECKS_MM."""
    up, down = extrema(profile, size_mm, held)
    return tuple(up) == PAPER_BULGES_MM and tuple(down) == PAPER_NECKS_MM


def visible(c, leak=0.0):
    """Whether a cell's signature is clear on both normalisations (the reference's mean and its
    own) within its u (``cell_clear`` with the configuration's ``leak``): True where clear,
    'at' where not decided, False where below (a shape with a smaller period-2 part is not
    one a picture shows)."""
    call = cell_clear(c, leak)[0]
    return True if call == "above" else "at" if call == "at" else False


def paper_figure(cells, names):
    """{base: [(name, reproduced, bulges, necks)]} of the models ``names``, msm and the
    continuum on the paper's setting: the mirrored five split at 5 nodes per side, the paper's
    push; ``reproduced`` True where the profile has the figure's bulges and necks and its
    signature is visible (``visible``, within its u), 'at' where that is not decided, 'faint'
    where it has them below the clear level."""
    names = list(names) + [m for m in ("msm", YARDSTICK_MODEL) if m not in names]
    check = metric_check(cells)
    out = {}
    for bc in sorted({c["bc"] for c in cells}):
        got = {c["model"]: c for c in cells if c["split"] == MIRRORED and c["bc"] == bc
               and c["load"] == "paper" and c["nodes_per_side"] < DECISIVE}
        rows = []
        first = next(iter(got.values()), None)
        n = len((first or {}).get("bulge_profile_fem_mm") or [])
        held = (0, n - 1) if bc == "clamped" else ()    # held laterally: neither
        if first and first.get("bulge_profile_fem_mm"):
            rows.append(("the continuum", reproduces(first["bulge_profile_fem_mm"], held=held),
                         *extrema(first["bulge_profile_fem_mm"], held=held)))
        for m in names:
            c = got.get(m)
            if c is None or not c.get("bulge_profile_mm"):
                rows.append((short(m), None, [], []))
                continue
            shape = reproduces(c["bulge_profile_mm"], held=held)
            seen = visible(c, leaks_of(check.get((n, bc), {})))
            rows.append((short(m), ("faint" if seen is False else seen) if shape else False,
                         *extrema(c["bulge_profile_mm"], held=held)))
        out[bc] = rows
    return out


def _ys(v):
    return ", ".join(f"{x:g}" for x in v) or "none"


def paper_figure_text(fig, bc="clamped"):
    """One sentence: whether each model of ``fig`` (``paper_figure``) reproduces the paper's
    Figure 1 on the base ``bc`` (the paper's setting: clamped), the other bases after it."""
    def one(b):
        rows = fig.get(b, [])
        yes = [n for n, r, _, _ in rows if r is True]
        shape = _by_value({n: "no profile" if r is None else
                           f"the figure's bulges and necks, but its period-2 part below the "
                           f"clear level {CLEAR:g}" if r == "faint" else
                           f"the figure's bulges and necks, its period-2 part not decided "
                           f"against the clear level {CLEAR:g} (within its u)" if r == "at" else
                           "flat (no bulge, no neck)" if not up and not down else
                           f"bulges at {_ys(up)}, necks at {_ys(down)}"
                           for n, r, up, down in rows if r is not True})
        return (f"{b} base: reproduced (visibly: the signature clear within its u) "
                f"by {_names(yes)}; " + "; ".join(
                    f"{', '.join(v)}: {k}" for k, v in shape.items()))
    others = [b for b in fig if b != bc]
    return ("The paper's Figure 1 (bulges at y = " + _ys(PAPER_BULGES_MM) + " mm, necks at "
            + _ys(PAPER_NECKS_MM) + " mm) on the paper's setting (mirrored five, 5 nodes per "
            "side, the paper's push), each layer a bulge where it is out further than every "
            "neighbouring layer and a neck where it is in further (read on the raw profile of "
            "5 layers, the paper's own view, its period-2 part read against the clear level "
            "with its u (the 5-layer leak): it decides nothing): "
            + " ".join([one(bc) + "."] + [f"Beside it, the {one(b)}." for b in others])
            + " On the clamped base the top and bottom layers are held laterally, so the "
            "figure's end bulges cannot appear there.")


# ---------------------------------------------------------------------------- the reading

# the observables a run can decide; the paper's pattern is seen on its 5 layers only, where
# the metric's check fails: shown, never scored
OBSERVABLES = {"cost": f"a step over {PAPER_COST:g} times msm's (the paper's Figure 2)",
               "stable": "no growing mode (the linearised growth rate at rest)"}


def _median(v):
    v = [x for x in v if x is not None]
    return float(np.median(v)) if v else None


def _form(model, readings):
    if model not in readings:
        return "+ a normal-stress term (not in the paper)"
    return ("the paper's equations, c = 1" if model.endswith("-literal") else
            "the paper's equations, c fitted (the paper's c is 1)")


STABILITY_SPLITS = (MIRRORED,) + CONFORMING_CONTROLS   # the conforming splits of the lattice
STABLE_WORDS = {True: "stable (rate 0)", False: "grows beyond the damping",
                "damping": "flutters, damped out by the damping we assume",
                "at": "flutters, at the damping's threshold"}


def stability_call(rate, damping):
    """(damped, undamped, stable) of one growth rate at rest, with the glossary's one
    definition: a rate above GROWS (0) flutters (undamped 'above'); it grows beyond the mass
    damping we assume where it exceeds half of it (``damping`` / 2, damped 'above'). stable
    True (rate 0: no mode grows, whatever the damping) or False (grows even with the damping
    we assume), None where it flutters only without damping or is at the damping's
    threshold."""
    damped = against(rate, damping / 2)
    undamped = "above" if rate > GROWS else "below"
    calls = {damped, undamped}
    return damped, undamped, (None if "at" in calls or len(calls) > 1 else damped == "below")


def _stable_class(rate, damping):
    damped, undamped, stable = stability_call(rate, damping)
    if stable is not None:
        return stable
    return "damping" if (damped, undamped) == ("below", "above") else "at"


def mesh_stability(rates, damping):
    """(stable, why) of a model over the meshes it was linearised on, ``rates`` [(mesh, rate)]:
    stability is a property of the model on a mesh, so True only where its rate is 0 on every
    mesh, False only where it grows beyond the damping we assume on every mesh; else None:
    'depends on the mesh' where the meshes' calls differ, 'depends on the damping' where it
    flutters (rate above 0) but is damped out on every mesh; why names each call's meshes and
    rates."""
    if not rates:
        return None, "no growth rate"
    kinds = [(mesh, rate, _stable_class(rate, damping)) for mesh, rate in rates]
    order = list(dict.fromkeys(k for _, _, k in kinds))
    # the rate a damping removes is half of it: said, so that a rate below the damping's own
    # value that grows beyond it reads as it is
    by = "; ".join(f"{STABLE_WORDS[k]}" + (f" ({damping:g} 1/s, which removes rates up to "
                                            f"{damping / 2:g} 1/s)"
                                            if k in ("damping", False) else "")
                   + " on " + ", ".join(
        f"{m} ({fmt(r, 3)} 1/s)" for m, r, kk in kinds if kk == k) for k in order)
    top = max(r for _, r, _ in kinds)
    if top > GROWS:       # the damping each model needs: the paper states none
        by += (f"; damped out on each of these meshes by mass damping above {fmt(2 * top, 3)} 1/s "
               "(twice its largest rate)")
    if len(order) > 1:
        return None, "depends on the mesh: " + by
    k = order[0]
    if k is True or k is False:
        return k, by
    return None, ("depends on the damping: " if k == "damping" else "at a threshold: ") + by


def cost_call(point, span):
    """(call, why) of a step / msm ratio against PAPER_COST: read on its spread ``span``
    [smallest, largest] over the bench's rounds on the paper's cube (``bounded``: 'above'
    where even the
    smallest is above the threshold beyond NEAR, 'below' where even the largest is below it,
    else 'at': the range reaches the threshold, not decided); a ratio without a spread is
    not decided (one timing carries no uncertainty)."""
    if point is None:
        return None, "not timed"
    if not span:
        return None, "one timing, no spread: not decided"
    call = bounded(span[0], span[1], PAPER_COST)
    return call, {"above": f"above {PAPER_COST * (1 + NEAR):g} ({PAPER_COST:g} beyond its "
                           f"{NEAR:.0%} band) over the bench's rounds on the paper's cube",
                  "below": f"below {PAPER_COST * (1 - NEAR):g} ({PAPER_COST:g} less its "
                           f"{NEAR:.0%} band) over the bench's rounds on the paper's cube",
                  "at": f"the range reaches {PAPER_COST:g} (within {NEAR:.0%}): not decided"
                  }[call]


def size_call(call, why, sizes):
    """(call, why) of the paper-size call held against every bench size (``sizes``
    {tetrahedra: [smallest, largest]}, each size its own population): the paper's Figure 2
    reads the cost and its growth with mesh size, so a call stands only where every size
    reads the same; else not decided, with the sizes that differ."""
    if call not in ("above", "below") or not sizes:
        return call, why
    other = {t: bounded(lo, hi, PAPER_COST) for t, (lo, hi) in sizes.items()}
    off = {t: c for t, c in other.items() if c != call}
    if not off:
        return call, why + f", and at every size the bench ran ({', '.join(map(str, sizes))} tetrahedra)"
    return "at", (why + "; not at every size: " + ", ".join(
        f"{t} tetrahedra {fmt(sizes[t][0], 3)}-{fmt(sizes[t][1], 3)} "
        + ("reaches" if c == "at" else c) + f" {PAPER_COST:g}" for t, c in off.items())
        + ": not decided")


def reading_table(cells, step_vs_msm, readings, damping=50.0, extra=(), step_range=None,
                  step_sizes=None):
    """One row per reading (``readings``, calibrated and literal) and per model of ``extra``
    (a reading with a normal-stress term, which the paper's equations lack): the paper's
    observables on its own lattice (5 nodes per side) and which of the decidable ones
    (OBSERVABLES) it matches.

    Cost: the stored step / msm ratio on the paper's cube read on its spread over the
    bench's rounds (``step_range``, ``cost_call``; a literal reading's is its calibrated
    reading's, the same kernel), and held against each size the bench ran (``step_sizes``,
    ``size_call``); None (not decided) where not timed, without a spread, where the range
    reaches the threshold or a size reads otherwise, or for a model with a normal-stress
    term (its added cost is this implementation's term, no evidence about the paper's
    reading).
    Stability: the largest growth rate of the undamped model linearised at rest (clamped) on
    each conforming split of the lattice (mirrored five, six, bcc; ``mesh_stability``), each
    against half the mass damping we assume (``damping`` / 2) and, without damping, against
    1 / RUN_S; the non-conforming unmirrored five split's rate is shown apart. The row's
    largest rate, its calls and the damping below which a mode grows (2 x the rate) are the
    conforming meshes' largest."""
    rows = []
    for model in list(readings) + list(extra):
        mine = [c for c in cells if c["model"] == model and c["nodes_per_side"] < DECISIVE]
        five = [c for c in mine if c["split"] == MIRRORED]
        sliding = [c for c in five if c["bc"] == "sliding" and c["load"] == "paper"]
        clamped = [c for c in five if c["bc"] == "clamped" and c["load"] == "paper"]
        rated = [c for c in mine if c["bc"] == "clamped" and c["load"] == "paper"
                 and c.get("growth_rate_1_s") is not None]
        by_mesh = {c["mesh"]: c["growth_rate_1_s"] for x in STABILITY_SPLITS
                   for c in rated if c["split"] == x}
        apart = {c["mesh"]: c["growth_rate_1_s"] for c in rated
                 if c["split"] not in STABILITY_SPLITS}
        patch = [c["disp_rel_l2"] for c in five if c["bc"] == "sliding"
                 and c["load"] == "linear" and c.get("disp_rel_l2") is not None]
        finite = [c["disp_rel_l2"] for c in clamped if c.get("disp_rel_l2") is not None]
        in_paper = model in readings
        # a literal reading runs its calibrated reading's kernel (c only scales the forces):
        # one step costs the same, so the bench's ratio is its own
        timed = step_vs_msm.get(model) is not None
        cost = step_vs_msm.get(model) if timed else None
        span = (step_range or {}).get(model) if timed else None
        cost_vs, cost_why = size_call(*cost_call(cost, span),
                                      (step_sizes or {}).get(model) if timed else None)
        if not in_paper and cost is not None:
            cost_why += "; not scored (a term the paper lacks)"
        grow = max(by_mesh.values()) if by_mesh else None
        damped, undamped, _ = (None, None, None) if grow is None else \
            stability_call(grow, damping)
        stable, stable_why = mesh_stability(list(by_mesh.items()), damping)
        matches = {"cost": None if not in_paper or cost_vs in (None, "at")
                   else cost_vs == "above", "stable": stable}
        rows.append({"model": model, "name": short(model), "in_paper": in_paper,
                     "form": _form(model, readings),
                     "pattern_own": _median([signature_own(c) for c in sliding]),
                     "pattern_rel": _median([c.get("alternation_rel") for c in sliding]),
                     "lateral": _median([lateral_error(c) for c in sliding]),
                     "step_vs_msm": cost, "step_range": span, "timed": timed,
                     "cost_vs": cost_vs, "cost_why": cost_why,
                     "step_assumed": step_vs_msm.get(model) if not timed else None,
                     "growth_max_1_s": grow, "growth_by_mesh": by_mesh,
                     "growth_apart": apart, "damped": damped, "undamped": undamped,
                     "stable_why": stable_why,
                     "growth_over_run": None if grow is None else float(np.exp(grow * RUN_S)),
                     "flutters_below_damping": None if not grow else 2 * grow,
                     "sliding_disp_median": _median(patch),
                     "paper_push_disp_median": _median(finite),
                     "matches": matches, "score": sum(v is True for v in matches.values()),
                     "possible": sum(v is not False for v in matches.values())})
    return rows


MATCH_WORDS = {True: "matched", False: "missed", None: "not decided"}


def _span(r):
    lo, hi = r["step_range"]
    return f"{fmt(r['step_vs_msm'], 3)} [{fmt(lo, 3)}-{fmt(hi, 3)}]"


def per_second_words(per_second, names):
    """'pbcm-corner 6.6 [5.1-7.5] at 320 and 11 [10-12] at 98415 tetrahedra, ...': each
    kernel's cost of a simulated second over msm's (``per_simulated_second``) at the paper's
    size and the largest the bench measured it, a literal reading left to its calibrated one
    (the same kernel); '' where none is known."""
    said = []
    for m in names:
        got = (per_second or {}).get(m)
        if m.endswith("-literal") or not got:
            continue
        sizes = sorted({min(got, key=lambda t: abs(int(t) - FIVE_TETS)), max(got, key=int)},
                       key=int)
        said.append(f"{m} " + " and ".join(
            f"{fmt(got[t][0], 2)} [{fmt(got[t][1], 2)}-{fmt(got[t][2], 2)}] at {t}"
            for t in sizes))
    return "; ".join(said) + (" tetrahedra" if said else "")


def reading_verdict(table, damping, spread=None, figure=None, per_second=None):
    """Which reading of the paper's equations its decidable observables point to: a reading
    is decided only where its matches (True) exceed every other reading's possible matches
    (True or not decided); else 'not decided', with why. Whether no reading reproduces all
    the observables (each has a measured mismatch), or no timed one does. Stability is said
    per mesh: a reading stable on one mesh and growing on another is not stable. The
    readings with a normal-stress term are said apart: their cost is not decided (this
    implementation's term). ``spread`` the bench's sizes and rounds the cost ranges cover;
    ``figure`` (``paper_figure``) the paper's Figure 1 on its 5 layers, said beside the
    verdict, never scored; ``per_second`` the cost of a simulated second over msm's
    (``per_second_words``), said beside the paper's measure, never scored."""
    readings = [r for r in table if r["in_paper"]]
    extra = [r for r in table if not r["in_paper"]]
    total = len(OBSERVABLES)
    best = max(readings, key=lambda r: r["score"], default=None)
    rivals = [r for r in readings if r is not best and r["possible"] >= best["score"]] \
        if best else []
    decided = best is not None and best["score"] > 0 and not rivals
    timed = [r for r in readings if r["timed"]]
    untimed = [r["name"] for r in readings if not r["timed"]]
    none_all = bool(readings) and all(any(v is False for v in r["matches"].values())
                                      for r in readings)
    none_timed = bool(timed) and all(any(v is False for v in r["matches"].values())
                                     for r in timed)
    rated = [r for r in readings if r["growth_max_1_s"] is not None]
    stable = [r["name"] for r in rated if r["matches"]["stable"] is True]
    unstable = [r["name"] for r in rated if r["matches"]["stable"] is False]
    depends = [r for r in rated if r["matches"]["stable"] is None]
    cost_miss = [r["name"] for r in timed if r["matches"]["cost"] is False]
    cost_open = [r["name"] for r in timed if r["matches"]["cost"] is None]
    why = (f"{best['name']} matches {best['score']} of {total} and no other reading can match "
           "as many" if decided else
           f"no reading matches more of the {total} decidable observables than every other "
           "could (matched / at most, were the undecided to go its way: " + ", ".join(
               f"{r['name']} {r['score']}/{r['possible']}" for r in readings) + ")")
    meshes = list(dict.fromkeys(m for r in rated for m in r["growth_by_mesh"]))
    apart = list(dict.fromkeys(m for r in rated for m in r["growth_apart"]))
    stability = (
        "Stability (the largest growth rate of the undamped model linearised at rest, read on "
        "the clamped base only: the paper fixes its nodes at y = 0 (yet reports that layer "
        "bulging, which a fixed base cannot), so every stability call "
        "here holds for the clamped base alone (the sliding base's rates, linearised alike, "
        "are in cells.json, not read); on this "
        "study's own cells of each conforming split of the paper's lattice at 5 nodes "
        f"per side: {', '.join(meshes) or 'none'} (the mirrored five has 320 tetrahedra; the "
        "paper's own 374-tetrahedron mesh and the paper-cube case's unstructured mesh are not "
        "among them, so their rates are not used); no RK4 run in this study; a property of "
        "the model on a mesh, so a reading is stable only where it is stable on every one): "
        f"one definition, the glossary's: a mode flutters where its rate is above {GROWS:g} "
        f"1/s, and it grows beyond the mass damping we assume ({damping:g} 1/s; the paper "
        f"states none) where its rate exceeds {damping / 2:g} 1/s; stable means rate 0 (below "
        f"{P.RATE_ROUND_OFF:g} of the model's largest frequency: the eigensolver's round-off). "
        + "; ".join(f"{r['name']}: {r['stable_why']}" for r in rated) + ". "
        + "The paper states no damping and its mesh is none of these: stability (clamped "
        f"base) is decided (rate 0 on every mesh) for {_names(stable)}"
        + (f" and not decided for {_names([r['name'] for r in depends])}" if depends else "")
        + (f"; {_names(unstable)} grow beyond the damping on every mesh" if unstable else "")
        + "." + (" Shown apart (not conforming, never a verdict): " + "; ".join(
            f"{r['name']} " + ", ".join(f"{m} {fmt(v, 3)} 1/s"
                                        for m, v in r["growth_apart"].items())
            for r in rated if r["growth_apart"]) + "." if apart else ""))
    bench = ("" if not spread else f" over the bench's {spread['rounds']} rounds at "
             + ", ".join(str(t) for t in spread["tets"]) + " tetrahedra")
    ranged = [r for r in timed if r["step_range"]]
    cost = (f"Cost (the paper's Figure 2: the time of one step, more than {PAPER_COST:g} "
            "times msm's; the in-round ratio on the 320-tetrahedron five split of the paper's "
            "125 nodes (the paper's own mesh had 374 tetrahedra) [its range"
            f"{bench}], read on the range: a range that reaches within {NEAR:.0%} of "
            f"{PAPER_COST:g} is not decided; the figure reads the cost's growth with mesh "
            "size, so a call stands only where the range at every size the bench ran, each "
            "its own population, reads the same): "
            + (", ".join(f"{r['name']} {_span(r)} ({MATCH_WORDS[r['matches']['cost']]})"
                         for r in ranged) if ranged else "no range timed")
            + "".join(f"; {_names(v)} {w}" for v, w in (
                ([r["name"] for r in ranged if r["matches"]["cost"] is False],
                 f"miss the paper's cost: every round below {PAPER_COST * (1 - NEAR):g}, "
                 f"under the {NEAR:.0%} band around {PAPER_COST:g}"),
                ([r["name"] for r in ranged if r["matches"]["cost"] is None
                  and r["step_range"][1] < PAPER_COST],
                 f"below {PAPER_COST:g} in every round, the largest within {NEAR:.0%} of it: "
                 "not decided")) if v)
            + "".join(f"; {r['name']}: {r['cost_why']}" for r in ranged
                      if "not at every size" in r["cost_why"])
            + (f"; one timing without a spread, not decided: "
               f"{_names([r['name'] for r in timed if not r['step_range']])}"
               if any(not r["step_range"] for r in timed) else "")
            + (f"; not timed: {_names(untimed)}" if untimed else "") + ". ")
    per = "; ".join(f"{r['name']}: cost {MATCH_WORDS[r['matches']['cost']]}, stability "
                    f"{MATCH_WORDS[r['matches']['stable']]}" for r in readings)
    fig = ""
    if figure:
        names = {r["name"] for r in readings}
        fig = (" Figure 1 (the pattern on the paper's 5 layers, its own view: shown, never "
               "scored: a match on 5 layers decides nothing, the metric's check of that "
               "view in the evidence says why): " + "; ".join(
                   f"on the {b} base the paper's pattern shows (visibly, within its u) for the "
                   "readings "
                   + _names([n for n, ok, _, _ in figure[b] if ok is True and n in names])
                   + (f" and for {_names(other)}" if (other := [
                       n for n, ok, _, _ in figure[b] if ok is True and n not in names]) else "")
                   for b in figure) + ".")
    literal = any(m.endswith("-literal") for m in cost_miss)
    plain = "; ".join(x for x in (
        f"{_names(cost_miss)} miss the paper's cost (Figure 2's measure: the time of one "
        f"step over msm's, which is how the paper's text reads its figure, at the paper's "
        f"size, with this implementation's kernels"
        + ("; a literal reading is timed as its calibrated one, the same kernel"
           if literal else "") + "; CPU time per simulated second, each at its own stable "
        "step, what a user pays but not the paper's claim, x msm: "
        + (per_second_words(per_second, cost_miss) or "not measured") + ")"
        if cost_miss else "",
        f"the cost is not decided for {_names(cost_open)}" if cost_open else "") if x)
    text = ((f"Plainly: {plain}. " if plain else "")
            + (f"Not decided: {why}. " if not decided else f"{why}. ")
            + (f"Each reading, observable by observable: {per}." if per else "") + fig + " "
            + ("No reading reproduces all the paper's observables. " if none_all else
               f"No timed reading reproduces all the paper's observables ({_names(cost_miss)} "
               "each miss the cost); the literal readings were not timed, so whether they do "
               "is not decided. " if none_timed else "")
            + cost + stability
            + (f" With a normal-stress term the paper's equations lack "
               f"({_compress([r['name'] for r in extra])}) the cost is not decided (this "
               "implementation's added term: no evidence about the paper's reading"
               + ("; " + ", ".join(f"{r['name']} {_span(r)}" for r in extra
                                   if r["step_range"]) if any(r["step_range"] for r in extra)
                  else "")
               + "); stable (rate 0) on every mesh, clamped base: "
               + _compress([r["name"] for r in extra if r["matches"]["stable"] is True])
               + "; not decided: "
               + _compress([r["name"] for r in extra if r["matches"]["stable"] is None
                            and r["growth_max_1_s"] is not None]) + "."
               if extra else ""))
    margin = 0
    if decided:
        margin = best["score"] - max([r["possible"] for r in readings if r is not best],
                                     default=0)
    return {"model": best["model"] if decided else None, "decided": decided,
            "sure": "decided" if decided else "not decided", "why": why, "margin": margin,
            "plain": plain,
            "none_reproduces": none_all, "none_reproduces_timed": none_timed,
            "cost_miss": cost_miss, "cost_open": cost_open, "untimed": untimed,
            "cost_span": {r["name"]: _span(r) for r in ranged},
            "growth_max": {r["name"]: r["growth_max_1_s"] for r in rated},
            "stable": stable, "unstable": unstable,
            "stability_depends": [r["name"] for r in depends],
            "stability_why": {r["name"]: r["stable_why"] for r in rated},
            "cost_why": {r["name"]: r["cost_why"] for r in readings},
            "meshes": meshes, "text": text,
            "with_normal_term": [r["name"] for r in extra]}
