"""What the artefact study's cells say: the paper's question (section 5: do the alternating
bulges and necks come from the mirror symmetry of the tetrahedra or from the missing normal
stress?) answered from the period-2 signature, and which reading of the paper's equations its
own observables point to. Everything here is computed from the cells' rows.

The order of the analysis:

1. The metric's own check (``metric_check``): on each (size, base) the signature's weights are
   applied to smooth test fields (a barrel, Gaussian bulges, an end boundary layer); a unit
   whose smooth fields leak more than the clear level decides nothing.
2. The decomposition (``units``): on the mirrored five split each model's signature is FEM P1's
   on the same tetrahedra (the mesh's own error, shared by every model) plus the model's part
   (model - FEM P1), each read against its uncertainty and against the same parts on the
   conforming splits without the mirror.
3. The hypotheses: (a) the mirror, from the decomposition; (b) the normal stress, on pairs
   where a term changes the signature; (c) the model's consistency, a signed rank
   correlation with its interval.
4. The reading: the paper's decidable observables on its own lattice, with and without the
   damping we assume.

The unit of analysis is a (size, base) of the mirrored mesh; two models whose signatures agree
to SAME are one observation there, and every count is "n of N" over the distinct ones."""
import numpy as np
from scipy.stats import spearmanr

from ...document import fmt, rel
from ...metrics import ALTERNATION_CLEAR, nyquist_weights
from .study import DECISIVE, SPLITS, YARDSTICK as YARDSTICK_MODEL, _free_layers, short

PAPER_COST = 10.0      # the paper: a step costs more than 10 times msm's
SURE_MARGIN = 2        # observables by which the verdict must lead to be called clear
REMOVES = 0.5          # a factor holds as the cause where it removes the pattern this often
TRACKS = 0.7           # a rank correlation from which the signature tracks the patch error
RATIO = 3.0            # one signature dominates another (or its uncertainty) from this factor
NEAR = 0.2             # a value within this fraction of a threshold is "at the threshold"
CLEAR = ALTERNATION_CLEAR   # a signature is clear from this fraction of the lateral bulge
ROUND_OFF_FLOOR = 1e-8      # no uncertainty below this (the static solves' own tolerance)
SAME = 1e-3            # two signatures agreeing to this (relative): one observation
ACTIVE = 1e-6          # a term changes a signature beyond round-off from this (relative)
WIDTHS = (2, 4)        # the test Gaussians' standard deviations, in layer spacings
DECAY = 2              # the test boundary layer's decay length, in layer spacings
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


def one_observation(a, b):
    """Whether two models' rows of a unit are one observation: the same mirrored signature to
    round-off (ACTIVE: a term that changes nothing on that mesh), or the same to SAME on every
    cell both have there (mirrored, controls, unmirrored)."""
    if same(a["five"], b["five"], ACTIVE):
        return True
    pairs = [(a["five"], b["five"]), (a["unmirrored"], b["unmirrored"])] + [
        (a["controls"][x], b["controls"][x]) for x in a["controls"]]
    return all(same(x, y) or (x is None and y is None) for x, y in pairs
               if not isinstance(x, str) and not isinstance(y, str))


def same(a, b, tol=SAME):
    """Whether two signatures are one observation (agree to ``tol`` of the larger, or both
    below the round-off floor)."""
    if a is None or b is None:
        return False
    return abs(a - b) <= max(tol * max(abs(a), abs(b)), ROUND_OFF_FLOOR)


# ---------------------------------------------------------------------------- the metric

def test_fields(n, free):
    """{name: [profiles]}: the smooth fields the signature must score (almost) 0 on, over
    ``n`` layers, ``free`` the layers it reads: a half-sine barrel over the cube, Gaussian
    bulges of standard deviation WIDTHS layer spacings centred on each free layer, and an
    end boundary layer (decay length DECAY spacings) at the base and at the top; and the pure
    (-1)^k pattern, which must read as its amplitude."""
    k = np.arange(n, dtype=float)
    centres = np.flatnonzero(free)
    out = {"barrel": [np.sin(np.pi * k / (n - 1))]}
    for s in WIDTHS:
        out[f"Gaussian, sd {s} layers"] = [np.exp(-(k - c) ** 2 / (2 * s ** 2))
                                           for c in centres]
    out["end boundary layer"] = [np.exp(-k / DECAY), np.exp(-(n - 1 - k) / DECAY)]
    return out


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
    absorb, their gain (sum |w|: the most a field of height 1 can score), what the pure
    (-1)^k pattern reads (1), and per test field its largest |score| over its height on the
    free layers; ``worst`` the largest of those and the field. None where no signature exists
    (three free layers)."""
    reference = np.asarray(reference, float)
    free = np.asarray(free, bool)
    k = np.flatnonzero(free)
    w = nyquist_weights(reference[free], k)
    if w is None:
        return None
    leaks = {name: max(abs(w @ f[free]) / np.abs(f[free]).max() for f in fields)
             for name, fields in test_fields(len(reference), free).items()}
    worst = max(leaks, key=leaks.get)
    return {"free": int(free.sum()), "degree": absorbed_degree(w, len(k)),
            "gain": float(np.abs(w).sum()),
            "alternation_reads": float(w @ (-1.0) ** k.astype(float)),
            "leaks": leaks, "worst": leaks[worst], "worst_field": worst,
            "versus_clear": against(leaks[worst], CLEAR)}


def _profile(cells, n, bc):
    """The continuum's layer profile of (n, bc) at the paper's push (the same layers on every
    split of a size)."""
    return next((c["bulge_profile_fem_mm"] for c in cells if c["nodes_per_side"] == n
                 and c["bc"] == bc and c["load"] == "paper" and c.get("bulge_profile_fem_mm")),
                None)


def metric_check(cells):
    """{(n, bc): leakage row + 'decides'}: every (size, base) the cells have; a unit decides
    where it has DECISIVE or more layers and its smooth fields leak below the clear level
    (not within NEAR of it)."""
    out = {}
    for n, bc in sorted({(c["nodes_per_side"], c["bc"]) for c in cells}):
        ref = _profile(cells, n, bc)
        row = None if ref is None else leakage(ref, _free_layers(bc, n))
        if row is None:
            out[(n, bc)] = {"n": n, "bc": bc, "free": int(_free_layers(bc, n).sum()),
                            "decides": False, "why": f"{int(_free_layers(bc, n).sum())} free "
                            "layers, no signature (they absorb less than a quadratic)"}
            continue
        reasons = ([f"fewer than {DECISIVE} layers"] if n < DECISIVE else []) + (
            [] if row["versus_clear"] == "below" else
            [f"smooth fields leak {fmt(row['worst'], 2)} of their height "
             + ("at" if row["versus_clear"] == "at" else "above") + f" the clear level "
             f"{CLEAR:g}"])
        why = "; ".join(reasons) or None
        out[(n, bc)] = {"n": n, "bc": bc, **row, "decides": why is None, "why": why}
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
    """The cell's lateral stiffness error: its mean lateral displacement over the free layers
    over the continuum's, minus 1 (negative: stiffer laterally)."""
    m, r = own_mean(c), _arr(c.get("bulge_profile_fem_mm"))
    if m is None or r is None:
        return None
    ref = float(np.abs(r[_free_layers(c["bc"], len(r))]).mean())
    return m / ref - 1.0 if ref else None


def signature_own(c):
    """The signature over the model's own mean lateral displacement on the free layers: what
    a picture of the model's own bulge shows."""
    m = own_mean(c)
    if c.get("failed") or c.get("alternation_mm") is None or not m:
        return None
    return c["alternation_mm"] / m


def smooth_amplitude(diff, reference, free):
    """The largest |diff - alpha reference| over the free layers (alpha the least-squares
    scale, to which the signature is blind), over the reference's mean |profile| (the
    normaliser of ``alternation_rel``): how large a smooth field could leak."""
    d, r = np.asarray(diff, float)[free], np.asarray(reference, float)
    rf = r[free]
    alpha = float(d @ rf / (rf @ rf)) if rf @ rf else 0.0
    return float(np.abs(d - alpha * rf).max() / np.abs(r).mean())


def pattern(row):
    """'paper' (the paper's sign: the layers of even index from the base out bulge, the
    signature over the model's own mean at least the clear level), 'reversed', 'at' (within
    NEAR of the clear level: at the threshold, not decided), 'none', or None where the
    signature is not defined or the run failed."""
    a = signature_own(row)
    if a is None:
        return None
    v = against(abs(a), CLEAR)
    return "at" if v == "at" else "none" if v == "below" else "paper" if a > 0 else "reversed"


def alternating(row):
    """True where the signature is clear, either sign; None where it is not defined."""
    p = pattern(row)
    return None if p is None else p in ("paper", "reversed")


def failure(c):
    """'failed (why)' of a failed cell, the solver's message shortened to its cause."""
    why = str(c.get("failed") or "")
    if "inverted" in why:
        return "failed (inverted element: " + why.split(" is ")[0] + ", " + \
            why.split("in term ")[-1].split(";")[0] + " term)"
    return f"failed ({why.split(';')[0][:80]})"


# ---------------------------------------------------------------------------- decomposition

def decisive(cells):
    """The cells at the paper's push with at least DECISIVE layers."""
    return [c for c in cells if c["load"] == "paper" and c["nodes_per_side"] >= DECISIVE]


def _index(cells):
    return {(c["model"], c["split"], c["nodes_per_side"], c["bc"], c["load"]): c
            for c in cells}


def _law_change(at, n, bc):
    """The relative change of FEM P1's signature on the mirrored split between the linear
    regime and the paper's push at (n, bc): what comparing a small-strain control at a finite
    push to a neo-Hookean reference moves it by (None where the linear load was not run)."""
    p = at.get((YARDSTICK_MODEL, MIRRORED, n, bc, "paper"))
    q = at.get((YARDSTICK_MODEL, MIRRORED, n, bc, "linear"))
    if not p or not q or p.get("alternation_rel") is None or q.get("alternation_rel") is None:
        return None
    a, b = p["alternation_rel"], q["alternation_rel"]
    return abs(a - b) / abs(a) if abs(a) > ROUND_OFF_FLOOR else 0.0


def units(cells, models=None):
    """Per (size, base) of the mirrored five split: the metric's check, FEM P1's signature
    there and on the conforming controls (six, bcc: those run for every model at that size),
    and per distinct model its signature split into FEM P1's and its own part (model - FEM P1
    on the same tetrahedra), each with its uncertainty and class.

    u of the model's part: sqrt(leak^2 + law^2 + round-off^2): ``leak`` the unit's worst
    smooth-field leakage times the smooth amplitude of (model - FEM P1); ``law`` the change of
    FEM P1's signature between the linear regime and the push (the control is small-strain
    FEM), times FEM P1's signature; the reference cancels in the difference. FEM P1's own
    signature is read against the floor (its largest on the controls, at least round-off):
    on the sliding base FEM P1 is exact (a homogeneous field), so the floor is an identity
    check there, not a measured error.

    A model's class: 'failed (...)' where its mirrored cell or a control failed; 'at the
    threshold' where its part over u, or its mirrored part over the controls', is within NEAR
    of RATIO; 'own +' / 'own -' (the paper's sign or reversed) where its part is RATIO times u
    and RATIO times its part on every control; 'own on every split' where resolved but not
    the mirror's; 'mesh only' where its part is not resolved and FEM P1's is; 'none'
    otherwise. A model whose mirrored signature agrees with one counted before it (SAME) is
    one observation with it."""
    check = metric_check(cells)
    at = _index(cells)
    order = list(models or dict.fromkeys(c["model"] for c in cells))
    out = []
    for n, bc in sorted({(c["nodes_per_side"], c["bc"]) for c in cells
                         if c["split"] == MIRRORED}):
        chk = check.get((n, bc), {})
        fem = at.get((YARDSTICK_MODEL, MIRRORED, n, bc, "paper"))
        ref = _arr(fem and fem.get("bulge_profile_fem_mm"))
        free = _free_layers(bc, n)
        mirrored = [m for m in order if (m, MIRRORED, n, bc, "paper") in at
                    and at[(m, MIRRORED, n, bc, "paper")]["family"] != CONTROL]
        ctrls = [x for x in CONFORMING_CONTROLS
                 if all((m, x, n, bc, "paper") in at for m in mirrored + [YARDSTICK_MODEL])]
        missing = {x: [short(m) for m in mirrored if (m, x, n, bc, "paper") not in at]
                   for x in CONFORMING_CONTROLS if x not in ctrls}
        fem_five = None if fem is None else fem.get("alternation_rel")
        fem_ctrl = {x: at[(YARDSTICK_MODEL, x, n, bc, "paper")].get("alternation_rel")
                    for x in ctrls}
        floor = max([ROUND_OFF_FLOOR] + [abs(v) for v in fem_ctrl.values() if v is not None])
        identity = all(v is not None and abs(v) < ROUND_OFF_FLOOR for v in fem_ctrl.values())
        law, law_from = _law_change(at, n, bc), n
        if law is None:     # the linear load is not run on the finest meshes: the base's largest
            got = [(x, k) for k in range(n) for x in [_law_change(at, k, bc)] if x is not None]
            law, law_from = max(got, default=(None, None))
        fem_vs = None if fem_five is None else against(abs(fem_five) / floor, RATIO)
        rows, seen = [], []
        for m in mirrored:
            c = at[(m, MIRRORED, n, bc, "paper")]
            row = {"model": m, "name": short(m), "family": c["family"],
                   "constant": c["constant"], "five": c.get("alternation_rel"),
                   "five_mm": c.get("alternation_mm"), "own": signature_own(c),
                   "lateral": lateral_error(c), "controls": {},
                   "unmirrored": (at.get((m, UNMIRRORED, n, bc, "paper")) or {}).get(
                       "alternation_rel"), "same_as": None}
            row["clear"] = None if row["own"] is None else against(abs(row["own"]), CLEAR)
            for x in CONFORMING_CONTROLS:
                y = at.get((m, x, n, bc, "paper"))
                row["controls"][x] = ("not run" if y is None else failure(y)
                                      if y.get("failed") else y.get("alternation_rel"))
            bad = [f"{x}: {v}" for x, v in row["controls"].items()
                   if x in ctrls and isinstance(v, str)]
            if c.get("failed") or bad:
                row["kind"] = failure(c) if c.get("failed") else "failed control (" + \
                    "; ".join(bad) + ")"
                rows.append(row)
                continue
            if row["five"] is None or fem_five is None or ref is None:
                row["kind"] = "n/a (no signature)"
                rows.append(row)
                continue
            dup = next((r for r in seen if one_observation(r, row)), None)
            if dup is not None:
                row["same_as"] = dup["name"]
                row["kind"] = f"same as {dup['name']}"
                rows.append(row)
                continue
            d = row["five"] - fem_five
            amp = smooth_amplitude(np.asarray(c["bulge_profile_mm"])
                                   - np.asarray(fem["bulge_profile_mm"]), ref, free)
            u = float(np.sqrt((chk.get("worst", 0.0) * amp) ** 2
                              + ((law or 0.0) * abs(fem_five)) ** 2 + ROUND_OFF_FLOOR ** 2))
            dctrl = [row["controls"][x] - fem_ctrl[x] for x in ctrls]
            spec = abs(d) / max([ROUND_OFF_FLOOR] + [abs(v) for v in dctrl])
            row.update({"part": d, "u": u, "part_vs_u": against(abs(d) / u, RATIO),
                        "mirror_ratio": spec if dctrl else None,
                        "mirror_vs": against(spec, RATIO) if dctrl else None})
            if not chk.get("decides"):
                kind = "not decided (the unit's check)"
            elif row["part_vs_u"] == "at":
                kind = "at the threshold (part / u)"
            elif row["part_vs_u"] == "below":
                kind = "mesh only" if fem_vs == "above" else "none"
            elif not dctrl:
                kind = "not decided (no control run)"
            elif row["mirror_vs"] == "at":
                kind = "at the threshold (mirror ratio)"
            elif row["mirror_vs"] == "below":
                kind = "own on every split"
            else:
                kind = "own +" if d > 0 else "own -"
            row["kind"] = kind
            seen.append(row)
            rows.append(row)
        distinct = [r for r in rows if r["same_as"] is None]
        out.append({"n": n, "bc": bc, "check": chk, "decides": bool(chk.get("decides")),
                    "controls": ctrls, "missing_controls": missing, "fem_five": fem_five,
                    "fem_controls": fem_ctrl, "floor": floor, "identity": identity,
                    "fem_ratio": None if fem_five is None else abs(fem_five) / floor,
                    "fem_vs": fem_vs, "law": law, "law_from": law_from, "rows": rows,
                    "distinct": len(distinct), "run": len(rows)})
    return out


def classes(unit):
    """{class: [model names]} over a unit's distinct models (failed ones under their
    class 'failed')."""
    out = {}
    for r in unit["rows"]:
        if r["same_as"] is None:
            k = "failed" if r["kind"].startswith("failed") else r["kind"]
            out.setdefault(k, []).append(r["name"])
    return out


def orders(us):
    """Per base: each distinct model's order in h of its own part from the smallest to the
    next size (h halved) where both units decide and the part is resolved at both: log2 of
    the ratio; with how many of the models at both sizes it covers."""
    by = {(u["n"], u["bc"]): u for u in us}
    out = {}
    for (n, bc), u in by.items():
        fine = by.get((2 * n - 1, bc))
        if fine is None:
            continue
        if not (u["decides"] and fine["decides"]):
            out[bc] = {"orders": {}, "of": 0, "sizes": (n, fine["n"]),
                       "why": f"the {n}-node {bc} unit does not decide"
                       if not u["decides"] else f"the {fine['n']}-node unit does not decide"}
            continue
        fr = {r["model"]: r for r in fine["rows"] if r["same_as"] is None}
        both = [r for r in u["rows"] if r["same_as"] is None and r["model"] in fr]
        got = {}
        for r in both:
            f = fr[r["model"]]
            if r.get("part_vs_u") == "above" and f.get("part_vs_u") == "above" \
                    and np.sign(r["part"]) == np.sign(f["part"]):
                got[r["name"]] = float(np.log2(abs(r["part"]) / abs(f["part"])))
        out[bc] = {"orders": got, "of": len(both), "sizes": (n, fine["n"]), "why": None}
    return out


# ---------------------------------------------------------------------------- hypotheses

def mirror(cells, models=None):
    """Hypothesis (a), the mirror symmetry: the decomposition (``units``), the orders, and
    whether the mirrored split's period-2 error (FEM P1's or a model's own) dominates the
    conforming splits' in a unit that decides."""
    us = units(cells, models)
    dec = [u for u in us if u["decides"] and u["n"] >= DECISIVE]
    mesh = [u for u in dec if u["fem_vs"] == "above"]
    own = [u for u in dec if any(k.startswith("own +") or k.startswith("own -")
                                 for k in classes(u))]
    return {"units": us, "orders": orders(us), "deciding": [(u["n"], u["bc"]) for u in dec],
            "holds": bool(mesh or own), "mesh_units": [(u["n"], u["bc"]) for u in mesh],
            "own_units": [(u["n"], u["bc"]) for u in own]}


def normal_stress(cells, us):
    """Hypothesis (b), the missing normal stress: pairs (a deciding unit of the mirrored split,
    a calibrated reading whose own part is resolved there, a normal-stress term) where the
    term changes the signature beyond round-off (ACTIVE); each pair's signature without and
    with, and whether the term reduces the model's own part RATIO-fold. The rest are listed
    as not tested, with why (the term inactive: the fit set its constant to 0, or it changes
    nothing; no resolved own part; the unit does not decide; failed)."""
    at = {(c["nodes_per_side"], c["bc"], c["reading"], c["normal"]): c for c in cells
          if c["family"] == "particle" and c["constant"] == "calibrated"
          and c["split"] == MIRRORED and c["load"] == "paper"}
    rows = {(u["n"], u["bc"]): {r["model"]: r for r in u["rows"]} for u in us}
    dec = {(u["n"], u["bc"]): u for u in us}
    fem = {(u["n"], u["bc"]): u["fem_five"] for u in us}
    pairs, untested = [], []
    for (n, bc, reading, normal), w in sorted(at.items()):
        if normal == "none":
            continue
        base = at.get((n, bc, reading, "none"))
        name = short(w["model"])
        if base is None:
            continue
        if not dec[(n, bc)]["decides"] or n < DECISIVE:
            untested.append((n, bc, name, "the unit does not decide"))
            continue
        if base.get("failed") or w.get("failed"):
            untested.append((n, bc, name, "failed"))
            continue
        a, b = base.get("alternation_rel"), w.get("alternation_rel")
        if same(a, b, ACTIVE):
            untested.append((n, bc, name, "the term changes nothing here (to 1e-6: its "
                             "fitted constant is 0 on this mesh)"))
            continue
        r = rows[(n, bc)].get(base["model"], {})
        if r.get("part_vs_u") != "above":
            untested.append((n, bc, name, f"{short(base['model'])} has no resolved own part"))
            continue
        without, with_ = a - fem[(n, bc)], b - fem[(n, bc)]
        ratio = abs(with_) / abs(without)
        pairs.append({"n": n, "bc": bc, "term": normal, "model": name,
                      "base": short(base["model"]), "without": without, "with": with_,
                      "ratio": ratio, "reduced": against(
                          abs(without) / max(abs(with_), ROUND_OFF_FLOOR), RATIO)})
    removed = sum(p["reduced"] == "above" for p in pairs)
    at_ = sum(p["reduced"] == "at" for p in pairs)
    return {"pairs": pairs, "untested": untested, "tested": len(pairs), "removed": removed,
            "at_threshold": at_, "decided": bool(pairs),
            "holds": bool(pairs) and removed >= REMOVES * len(pairs)}


def rank_interval(rho, n):
    """The 95 % interval of a Spearman correlation ``rho`` over ``n`` points by Fisher's z,
    with the variance 1.06 / (n - 3) of Fieller, Hartley and Pearson; None below 4 points."""
    if rho is None or n < 4:
        return None
    z, se = np.arctanh(np.clip(rho, -0.999999, 0.999999)), np.sqrt(1.06 / (n - 3))
    return [float(np.tanh(z - Z95 * se)), float(np.tanh(z + Z95 * se))]


def consistency(cells):
    """Hypothesis (c), the model's consistency: per conforming mesh with the linear regime
    (the sliding cube at 1e-3 of the push is a patch test) from DECISIVE layers, the signed
    rank correlation over the distinct approximations (the control left out; models whose
    signature and patch error agree to SAME counted once) between the signature at the push
    on the sliding base and the patch-test error, with its 95 % interval; not testable on a
    mesh where no model has a clear signature (nothing to explain)."""
    per = {}
    for c in cells:
        if (c["nodes_per_side"] < DECISIVE or c["bc"] != "sliding" or c["family"] == CONTROL
                or c["split"] == UNMIRRORED):
            continue
        per.setdefault(c["mesh"], {}).setdefault(c["model"], {})[c["load"]] = c
    rows = []
    for mesh, by_model in per.items():
        pts, names, clear, failed = [], [], 0, []
        for model, v in by_model.items():
            if "paper" not in v or "linear" not in v:
                continue
            if v["paper"].get("failed") or v["linear"].get("failed"):
                failed.append(short(model))
                continue
            s, e = v["paper"].get("alternation_rel"), v["linear"].get("disp_rel_l2")
            if s is None or e is None:
                continue
            if any(same(s, a) and same(e, b) for a, b in pts):
                continue
            pts.append((s, e))
            names.append(short(model))
            clear += bool(alternating(v["paper"]))
        if len(pts) < 3:
            continue
        sig, err = np.array(pts).T
        rho = float(spearmanr(sig, err).statistic) if np.ptp(sig) and np.ptp(err) else None
        ci = rank_interval(rho, len(pts))
        if not clear:
            verdict = "not testable: no clear signature"
        elif ci is None:
            verdict = "not resolved (too few models)"
        elif ci[0] > 0 and rho >= TRACKS:
            verdict = "tracks"
        elif ci[1] < TRACKS:
            verdict = "does not track"
        else:
            verdict = "not resolved"
        rows.append({"mesh": mesh, "models": len(pts), "of": len(by_model), "rho": rho,
                     "interval": ci, "clear": clear, "failed": failed, "verdict": verdict})
    verdicts = {r["verdict"] for r in rows}
    return {"rows": rows, "holds": verdicts == {"tracks"},
            "testable": any(not r["verdict"].startswith("not testable") for r in rows)}


def linear_check(cells):
    """Per base, on the mirrored split: each distinct model's signature at 1e-3 of the push
    over its signature at the push (same mesh; the signature at the push beyond round-off;
    models whose two signatures agree to SAME with one counted before are one observation):
    median [min-max], n of N, the cells that change by more than NEAR with the load (part of
    their signature is finite strain), and FEM P1's ratios. Near 1 the pattern is a property
    of the linear regime."""
    at = _index(cells)
    out = {}
    for bc in sorted({c["bc"] for c in cells}):
        pairs = [(p, at.get((p["model"], p["split"], p["nodes_per_side"], bc, "linear")))
                 for p in cells if p["bc"] == bc and p["load"] == "paper"
                 and p["split"] == MIRRORED]
        pairs = [(p, q) for p, q in pairs if q is not None]
        fem, seen, rows = [], [], []
        pairs = [(p, q) for p, q in pairs if p.get("alternation_rel") is not None
                 and q.get("alternation_rel") is not None]
        for p, q in pairs:
            a, b = p["alternation_rel"], q["alternation_rel"]
            if abs(a) <= 1e3 * ROUND_OFF_FLOOR:
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
    models whose signature over their own mean has the paper's sign at the clear level, at the
    threshold, and how many distinct models; never a verdict (the unit's metric check)."""
    u = next((u for u in us if u["n"] < DECISIVE and u["bc"] == "sliding"), None)
    if u is None:
        return {"shows": [], "at": [], "of": 0, "unit": None}
    rows = [r for r in u["rows"] if r["same_as"] is None and r.get("own") is not None]
    return {"shows": [r["name"] for r in rows if r["clear"] == "above" and r["own"] > 0],
            "at": [r["name"] for r in rows if r["clear"] == "at"],
            "of": len(rows), "run": u["run"], "n": u["n"], "check": u["check"],
            "top": max(rows, key=lambda r: abs(r["own"]), default=None)}


# ---------------------------------------------------------------------------- the answer

def _names(models):
    return ", ".join(models) if models else "none"


def _where(unit):
    return f"{unit[0]} {unit[1]}"


def _largest(us):
    """(unit, row) of the distinct model (not the control) with the largest |signature over
    its own mean| on the deciding units of ``us``."""
    rows = [(u, r) for u in us if u["decides"] for r in u["rows"]
            if r["same_as"] is None and r.get("own") is not None]
    return max(rows, key=lambda ur: abs(ur[1]["own"]), default=None)


def _clear_word(v):
    return {"above": "clear", "below": "below the clear level",
            "at": "at the threshold: not decided"}.get(v, "n/a")


def by_reading(us):
    """{model name: (tag, [(unit, class)])} over the deciding units, the distinct models: tag
    '+' or '-' where every own part that is resolved and the mirror's has that sign, '+-'
    where both occur, 'not the mirror's' where the resolved parts are on every split, 'at
    the threshold' where the only resolved-or-not call is at a threshold, 'none' where no own
    part is resolved (FEM P1's alone, or nothing), 'failed' where every unit failed."""
    per = {}
    for u in us:
        if not u["decides"]:
            continue
        for r in u["rows"]:
            if r["same_as"] is None:
                per.setdefault(r["name"], []).append(((u["n"], u["bc"]), r["kind"]))
    out = {}
    for name, got in per.items():
        kinds = [k for _, k in got]
        signs = {k[-1] for k in kinds if k in ("own +", "own -")}
        tag = ("+-" if len(signs) == 2 else signs.pop() if signs else
               "not the mirror's" if "own on every split" in kinds else
               "at the threshold" if any(k.startswith("at the") for k in kinds) else
               "failed" if all(k.startswith("failed") for k in kinds) else "none")
        out[name] = (tag, got)
    return out


def _groups(tags):
    g = {}
    for name, (tag, _) in tags.items():
        g.setdefault(tag, []).append(name)
    return g


def _mesh_text(dec):
    """FEM P1's signature on the mirrored split per deciding unit: against its floor, or
    exact (an identity check) on the sliding base."""
    exact = [f"{u['n']}" for u in dec if u["identity"]]
    parts = [f"{u['n']} {u['bc']}: {rel(u['fem_five'], 2)} of the reference's mean, "
             f"{times(u['fem_ratio'])} times the conforming splits' "
             f"({', '.join(x.split(' ')[0] for x in u['controls'])})"
             + (" (at the threshold)" if u["fem_vs"] == "at" else "" if u["fem_vs"] == "above"
                else ": not resolved")
             for u in dec if not u["identity"]]
    if exact:
        parts.append(f"none on the sliding base ({', '.join(exact)} nodes: P1 is exact for "
                     "the homogeneous field, an identity check)")
    return "; ".join(parts)


def times(x):
    """A ratio for a sentence: two significant figures, whole from 100, powers of ten from
    1e4."""
    return ("n/a" if x is None else f"{x:.1e}" if x >= 1e4 else f"{x:.0f}" if x >= 100
            else fmt(x, 2))


def _five_text(us):
    five = [u for u in us if u["n"] < DECISIVE]
    if not five:
        return "The paper's own 5-node cube was not run."
    return ("On the paper's own 5-node cube: not decided ("
            + "; ".join(f"{u['bc']}: " + (
                f"smooth fields leak up to {fmt(u['check']['worst'], 2)} of their height "
                f"({u['check']['worst_field']}) on its {u['check']['free']} layers"
                if u["check"].get("worst") is not None else u["check"].get("why", ""))
                for u in five) + ").")


def answer(cells, models=None):
    """The paper's question answered from the units that decide: the metric's check, the
    decomposition of the mirrored split's signature into FEM P1's and each model's part, the
    three hypotheses, and the cause per reading; 'not decided' for the paper's 5-node cube
    and wherever no unit decides."""
    m = mirror(cells, models)
    us = m["units"]
    ns, cs = normal_stress(cells, us), consistency(cells)
    view, lin = paper_view(us), linear_check(cells)
    dec = [u for u in us if u["decides"]]
    paper = _five_text(us)
    hyp = {"mirror": m, "normal_stress": ns, "consistency": cs}
    base = {"hypotheses": hyp, "paper_view": view, "linear": lin, "ratio": RATIO,
            "decisive": DECISIVE, "clear_level": CLEAR, "near": NEAR,
            "deciding": m["deciding"]}
    big = [u for u in us if u["n"] >= DECISIVE]
    if not dec:
        text = paper + " " + (
            f"Not decided: no unit of {DECISIVE} or more layers passes the metric's check ("
            + "; ".join(f"{u['n']} {u['bc']}: {u['check'].get('why')}" for u in big) + ")."
            if big else f"Not decided: no mesh with {DECISIVE} or more layers was run.")
        return {**base, "decided": False, "cause": "not decided", "text": text,
                "numbers": text, "clear": False, "largest": {}, "by_reading": {}}
    tags = by_reading(us)
    g = _groups(tags)
    skipped = "; ".join(f"{u['n']} {u['bc']} does not: {u['check'].get('why')}"
                        for u in big if not u["decides"])
    where = ", ".join(_where(x) for x in m["deciding"]) + (f"; {skipped}" if skipped else "")
    tops = {_where((u["n"], u["bc"])): _largest([u]) for u in dec}
    largest = "; ".join(f"{r['name']} {fmt(r['own'], 3)} on {where_} "
                        f"({_clear_word(r['clear'])})" for where_, ur in tops.items() if ur
                        for _, r in [ur])
    any_clear = any(r["clear"] == "above" for u in dec for r in u["rows"]
                    if r["same_as"] is None)
    classes_txt = "; ".join(f"{label} in {_names(g[k])}" for k, label in (
        ("+", "the paper's sign, from the mirror,"), ("-", "reversed, from the mirror,"),
        ("+-", "both signs over the units"), ("not the mirror's", "on every split, not the "
                                              "mirror's,"),
        ("at the threshold", "at a threshold (not decided)"), ("none", "none resolved"),
        ("failed", "failed")) if g.get(k))
    normal = (f"the normal-stress terms reduce the model's own part {RATIO:g}-fold in "
              f"{ns['removed']} of {ns['tested']} pairs where a term is active"
              + (f" ({ns['at_threshold']} at the threshold)" if ns["at_threshold"] else "")
              if ns["decided"] else "the normal-stress terms are not tested (no term active "
              "beside a resolved own part)")
    cons = ("not testable (no clear signature on the sliding base)" if not cs["testable"]
            else "supported" if cs["holds"] else "not supported (" + "; ".join(
                f"{r['mesh']} {r['verdict']}" for r in cs["rows"]) + ")")
    text = (f"{paper} On the units that decide ({where}), the mirrored five split's "
            "signature is FEM P1's on the same tetrahedra, the mesh's own error shared by "
            f"every model ({_mesh_text(dec)}), plus the model's own part (model - FEM P1), "
            f"whose sign depends on the reading: {classes_txt}. Over the model's own mean "
            f"lateral displacement the largest is {largest} (clear from {CLEAR:g}). "
            f"{normal[0].upper()}{normal[1:]}; the consistency hypothesis is {cons}.")
    cause = ("conditional on the reading, on the units that decide ("
             + ", ".join(_where(x) for x in m["deciding"]) + "): "
             + ("FEM P1's own period-2 error on the mirrored split where the base is clamped "
                "(the mesh's, shared by every model) plus " if m["mesh_units"] else "")
             + f"the model's own part, {classes_txt}; {normal}; the paper's 5-node cube: "
             "not decided")
    numbers = (f"FEM P1 on the mirrored split: {_mesh_text(dec)}. The largest signature over "
               f"the model's own mean lateral displacement: {largest} (clear from {CLEAR:g}). "
               f"The consistency hypothesis is {cons}. {paper}")
    return {**base, "decided": m["holds"], "cause": cause, "text": text, "numbers": numbers,
            "clear": any_clear, "by_reading": {k: v[0] for k, v in tags.items()},
            "largest": {k: None if ur is None else [ur[1]["name"], ur[1]["own"]]
                        for k, ur in tops.items()}}


def how_sure(ans, verdict):
    """The report's 'how sure' line: what the answers rest on and what is at a threshold."""
    us = ans["hypotheses"]["mirror"]["units"]
    dec = [u for u in us if u["decides"]]
    at = [f"{r['name']} ({u['n']} {u['bc']}: "
          + ("the clear level" if r["clear"] == "at" else r["kind"][len("at the threshold ("):-1])
          + ")" for u in dec for r in u["rows"]
          if r["same_as"] is None and (r["kind"].startswith("at the") or r["clear"] == "at")]
    distinct = sum(u["distinct"] for u in dec)
    failed = [f"{r['name']} ({u['n']} {u['bc']})" for u in us for r in u["rows"]
              if r["kind"].startswith("failed")]
    return ("**How sure.** " + (
        f"The cause rests on {len(dec)} of {len(us)} (size, base) units (those whose smooth "
        f"test fields leak below {CLEAR:g}), {distinct} distinct model signatures there, one "
        "mesh per split and size (no spread over meshes of one continuum problem)"
        + (", orders from two sizes only; " if any(
            o["orders"] for o in ans["hypotheses"]["mirror"]["orders"].values()) else "; ")
        + (f"within {NEAR:.0%} of a threshold, not decided: {', '.join(at)}; " if at
           else f"none within {NEAR:.0%} of a threshold; ")
        + (f"failed: {', '.join(failed)}; " if failed else "")
        if dec else "No unit decides; ")
        + "the reading verdict is " + verdict["sure"] + " and depends on the damping "
        "nobody measured (" + verdict["undamped_text"] + ").")


# ---------------------------------------------------------------------------- the reading

# the observables a run can decide; the paper's pattern is seen on its 5 layers only, where
# the metric's check fails: shown, never scored
OBSERVABLES = {"cost": f"a step over {PAPER_COST:g} times msm's",
               "stable": "a clamped RK4 run without flutter"}


def _median(v):
    v = [x for x in v if x is not None]
    return float(np.median(v)) if v else None


def reading_table(cells, step_vs_msm, readings, damping=50.0, extra=()):
    """One row per reading (``readings``, calibrated and literal) and per model of ``extra``
    (a reading with a normal-stress term, which the paper's equations lack): the paper's
    observables on its own lattice (the mirrored five split, 5 nodes per side) and which of
    the decidable ones (OBSERVABLES) it matches, with the damping we assume (a mode grows
    where its undamped rate exceeds damping / 2) and without damping (a mode grows where its
    rate is above round-off, which the eigen-solve sets to 0). A literal reading's step cost
    is the calibrated one's, not timed: its cost match is None (not measured), as is any
    model's never timed."""
    rows = []
    for model in list(readings) + list(extra):
        mine = [c for c in cells if c["model"] == model and c["split"] == MIRRORED
                and c["nodes_per_side"] < DECISIVE]
        sliding = [c for c in mine if c["bc"] == "sliding" and c["load"] == "paper"]
        clamped = [c for c in mine if c["bc"] == "clamped" and c["load"] == "paper"]
        rates = [c["growth_rate_1_s"] for c in clamped if c.get("growth_rate_1_s") is not None]
        patch = [c["disp_rel_l2"] for c in mine if c["bc"] == "sliding"
                 and c["load"] == "linear" and c.get("disp_rel_l2") is not None]
        finite = [c["disp_rel_l2"] for c in clamped if c.get("disp_rel_l2") is not None]
        timed = not model.endswith("-literal") and step_vs_msm.get(model) is not None
        cost = step_vs_msm.get(model) if timed else None
        grow = max(rates) if rates else None
        damped = None if grow is None else grow <= damping / 2
        undamped = None if grow is None else grow == 0.0
        matches = {"cost": None if cost is None else cost > PAPER_COST, "stable": damped}
        matches_undamped = {"cost": matches["cost"], "stable": undamped}
        rows.append({"model": model, "name": short(model), "in_paper": model in readings,
                     "pattern_own": _median([signature_own(c) for c in sliding]),
                     "pattern_rel": _median([c.get("alternation_rel") for c in sliding]),
                     "lateral": _median([lateral_error(c) for c in sliding]),
                     "step_vs_msm": cost, "timed": timed,
                     "step_assumed": step_vs_msm.get(model) if not timed else None,
                     "growth_max_1_s": grow, "stable_damped": damped,
                     "stable_undamped": undamped,
                     "sliding_disp_median": _median(patch),
                     "paper_push_disp_median": _median(finite),
                     "matches": matches, "score": sum(v is True for v in matches.values()),
                     "matches_undamped": matches_undamped,
                     "score_undamped": sum(v is True for v in matches_undamped.values())})
    return rows


def _rank(table, key):
    """(best, next, margin, tied, sure): the best row, the first row below the tied group,
    the lead over it, the tied group's models, and 'tied' (more than one best), 'clear' (a
    lead of SURE_MARGIN observables) or 'weak' (one)."""
    ranked = sorted(table, key=lambda r: (-r[key], r["sliding_disp_median"] or np.inf))
    best = ranked[0]
    tied = [r["model"] for r in ranked if r[key] == best[key]]
    below = next((r for r in ranked if r[key] < best[key]), None)
    margin = best[key] - (below[key] if below else 0)
    sure = "tied" if len(tied) > 1 else "clear" if margin >= SURE_MARGIN else \
        "weak" if margin >= 1 else "tied"
    return best, below, margin, tied, sure


def _lead_text(best, below, margin, tied, sure, key, total):
    lead = f", {margin} more than the other readings" if below is not None and margin else ""
    if sure == "tied":
        return f"{', '.join(tied)} tie at {best[key]} of {total}{lead}"
    return f"{best['model']} leads with {best[key]} of {total}{lead} (a {sure} verdict)"


def reading_verdict(table, damping):
    """The reading that matches most of the paper's decidable observables with the damping we
    assume, and without damping (the paper states none); how sure: clear from a lead of
    SURE_MARGIN observables, weak from one, tied without. Only the readings of the paper's
    equations compete; a reading with a normal-stress term is said apart."""
    readings = [r for r in table if r["in_paper"]]
    extra = [r for r in table if not r["in_paper"]]
    total = len(OBSERVABLES)
    best, second, margin, tied, sure = _rank(readings, "score")
    ub, us_, um, ut, usure = _rank(readings, "score_undamped")
    costs = [r["step_vs_msm"] for r in readings if r["step_vs_msm"] is not None]
    untimed = [r["model"] for r in readings if r["step_vs_msm"] is None]
    fails = {r["model"]: [OBSERVABLES[k] for k, v in r["matches"].items() if v is False]
             for r in readings}
    none_all = all(r["score"] < total for r in readings)
    both = [r["name"] for r in extra if r["score"] == total and r["score_undamped"] == total]
    undamped_text = ("without damping (a mode grows where its rate is above round-off), "
                     + _lead_text(ub, us_, um, ut, usure, "score_undamped", total))
    text = (("No reading reproduces all the paper's observables. " if none_all else "")
            + f"With the mass damping we assume ({damping:g} 1/s: a mode grows only where its "
            f"undamped rate exceeds {damping / 2:g} 1/s), "
            + _lead_text(best, second, margin, tied, sure, "score", total)
            + f"; {undamped_text}; the paper states no damping. No reading's step is over "
            f"{PAPER_COST:g} times msm's ("
            + (f"{fmt(min(costs), 3)}-{fmt(max(costs), 3)}" if costs else "none timed")
            + (f"; not timed: {', '.join(untimed)}, whose stored ratio is the calibrated "
               "reading's, not a measurement" if untimed else "") + ")"
            + (f". With a normal-stress term the paper's equations lack, {', '.join(both)} "
               "match both observables with and without damping (their step cost is this "
               "implementation's)" if both else "") + ".")
    return {"model": best["model"], "sure": sure, "margin": margin, "tied": tied,
            "none_reproduces": none_all, "fails": fails, "text": text,
            "undamped": {"model": ub["model"], "sure": usure, "margin": um, "tied": ut},
            "undamped_text": undamped_text, "with_normal_term": both}
