"""What a sequence of errors at falling mesh sizes says: the observed order, the limit e_inf of
e(h) = e_inf + C h^p (docs/model.md "Convergence and effective elasticity") with its uncertainty,
and a verdict.

The limit is Richardson's extrapolation from the three finest levels, its uncertainty Roache's
grid convergence index (GCI, Roache 1994, J. Fluids Eng. 116: 405-413): the extrapolation's
correction times a safety factor, 1.25 with three or more levels, 3 with two. With two levels
no order can be observed: the extrapolation then assumes first order, the lowest a consistent
model shows, which gives the smallest floor the two errors allow. With four or more levels a
least-squares fit of all of them is reported as well, and the larger uncertainty kept. Every
uncertainty includes the values' own (``u``: the reference's error estimate, each error being
known to within it), combined in quadrature as u_val.

A floor is an error that has stopped falling within its uncertainty and stays above zero beyond
it; a sequence that is still falling is never one because its fit is poor:

- stopped: with three levels or more, the two finest changes are not both falls larger than
  ``u``, or the finest levels fall at an order below ORDER_MIN (log(e_-3 / e_-1) /
  log(h_-3 / h_-1)): a floor at the finest error, +- 1.25 x the larger of the two finest
  changes (and ``u``), where that is above zero;
- still falling with an observed order (e = e_inf + C h^p): a floor at the extrapolated e_inf
  where e_inf - u_val > 0 (a constant plus a decaying part), else converges;
- still falling without an observed order (the finest changes do not shrink as a power of h):
  not asymptotic, no limit extrapolated (at most the finest error): neither a floor nor an
  order the word "converges" would promise;
- two levels observe no order: first order assumed (a floor where e_inf - u_val > 0), which
  decides nothing the finer levels cannot overturn (the report says "not decided").
"""
from dataclasses import dataclass
import math

import numpy as np
from scipy.optimize import brentq, least_squares

from ...measuring.error_model import ROUND_OFF

FS_THREE, FS_TWO = 1.25, 3.0   # Roache's safety factors for 3+ and for 2 levels
ASSUMED_ORDER = 1.0            # the order assumed with two levels
GROWTH = 1.1                   # error at the finest level above this x the coarsest: diverges
RISE = 0.02                    # a finest rise below this share of the level is a floor's noise
# errors all below this are the reference itself: the static solver's tolerance (1e-12 of
# E h^2) and the nonlinearity left at the study's scaled load (strains about 5e-5)
EXACT = 1e-4
# at or below this an error (or a stiffness ratio's distance to 1) is round-off or the
# reference's own level: never an error that falls through zero
ROUND_LEVEL = max(EXACT, ROUND_OFF)
ORDER_RANGE = (0.05, 8.0)      # orders the three-level equation is solved over
# the finest levels falling at a lower order have stopped: halving h removes under 4 % of it
ORDER_MIN = ORDER_RANGE[0]
# a limit whose uncertainty exceeds the finest error times Roache's factor (with the values'
# own, in quadrature) bounds nothing the finest error does not: a clean extrapolation to zero
# carries exactly that band, so a wider one cannot tell convergence from a floor at the finest
# level: 'not decided'
# a level where every model's displacement error is the same to within this (relative to
# their median), while their stiffness ratios spread ten times as much, tests nothing: the
# error there is the mesh's, not the models'
SAME_ERROR = 0.02
UNDECIDED = "not decided"
UNDECIDED_WHY = "uncertainty larger than what it bounds"


@dataclass(frozen=True)
class Fit:
    """``order`` observed (None when the errors do not fall monotonically), ``e_inf`` the
    extrapolated limit (never below 0; None where no extrapolation is made), ``e_inf_err``
    its uncertainty, ``verdict`` 'exact', 'converges', 'floor', 'diverges' or 'not
    asymptotic' (a family that is not self-similar, or a limit the levels put below zero),
    ``why`` one sentence, ``levels`` the number of mesh sizes used; 'not decided' where the
    limit's uncertainty is larger than what it bounds (``bounds_nothing``)."""

    order: float
    e_inf: float
    e_inf_err: float
    verdict: str
    why: str
    levels: int

    def label(self):
        """The verdict as the report prints it."""
        if self.verdict == "converges":
            return ("converges" if self.order is None else f"converges (order {self.order:.2g})")
        if self.verdict == "exact":
            return f"exact (every error below {EXACT:g})"
        if self.verdict == "floor":
            return f"floor {self.e_inf:.2g} +- {self.e_inf_err:.1g}"
        if self.verdict == UNDECIDED:
            return f"{UNDECIDED} ({UNDECIDED_WHY})"
        return self.verdict


def bounds_nothing(err, finest, u=0.0):
    """Whether a limit's uncertainty ``err`` is larger than what it bounds: above the finest
    error ``finest`` times Roache's factor, the values' uncertainty ``u`` in quadrature (the
    band of a clean extrapolation to zero; a wider one leaves a floor at the finest level as
    likely as convergence)."""
    return err > math.hypot(FS_THREE * finest, u) * (1 + 1e-9)


def _undecided(n, e_inf, err, finest, why):
    return Fit(None, e_inf, err, UNDECIDED,
               f"{why}; the limit's uncertainty {err:.2g} exceeds the finest error {finest:.2g} "
               f"(times {FS_THREE:g}): it decides nothing", n)


def observed_order(h, e):
    """The order p of e = e_inf + C h^p through three points (h descending), or None when the
    differences change sign or do not shrink (no asymptotic range)."""
    (h1, h2, h3), (e1, e2, e3) = h, e
    d1, d2 = e1 - e2, e2 - e3
    if d1 == 0 or d2 == 0 or (d1 > 0) != (d2 > 0) or abs(d1) <= abs(d2):
        return None
    ratio = d1 / d2

    def gap(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - ratio
    lo, hi = ORDER_RANGE
    if gap(lo) * gap(hi) > 0:
        return None
    return float(brentq(gap, lo, hi, xtol=1e-12))


def _least_squares(h, e, p0, e0):
    """(e_inf, its standard error) of the least-squares fit e = e_inf + C h^p over all
    levels, or None when it is not determined (as many levels as unknowns)."""
    h, e = np.asarray(h, float), np.asarray(e, float)
    if len(h) <= 3:
        return None
    scale = h.max()
    c0 = (e[-1] - e0) / (h[-1] / scale) ** p0

    def resid(q):
        return q[0] + q[1] * (h / scale) ** q[2] - e
    sol = least_squares(resid, [e0, c0, p0], bounds=([-np.inf, -np.inf, ORDER_RANGE[0]],
                                                     [np.inf, np.inf, ORDER_RANGE[1]]))
    dof = len(h) - 3
    s2 = float(sol.fun @ sol.fun) / dof
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * s2
    except np.linalg.LinAlgError:
        return None
    return float(sol.x[0]), float(math.sqrt(max(cov[0, 0], 0.0)))


def extrapolate(h, v):
    """(limit, uncertainty, observed order or None) of values ``v`` at mesh sizes ``h`` (h
    descending, at least two): Richardson on the three finest levels with Roache's GCI, the
    least-squares fit of all when there are four or more; with two levels first order
    assumed; without an asymptotic range the last value within the last changes."""
    n = len(h)
    r = h[-2] / h[-1]
    p = observed_order(h[-3:], v[-3:]) if n >= 3 else None
    if p is not None:
        corr = (v[-2] - v[-1]) / (r**p - 1)
        limit, err = v[-1] - corr, FS_THREE * abs(corr)
        ls = _least_squares(h, v, p, limit)
        if ls is not None:
            limit, err = ls[0], max(err, ls[1])
        return limit, err, p
    if n >= 3:
        return v[-1], FS_THREE * max(abs(v[-1] - v[-2]), abs(v[-2] - v[-3])), None
    corr = (v[-2] - v[-1]) / (r**ASSUMED_ORDER - 1)
    return v[-1] - corr, FS_TWO * abs(corr), None


def still_falling(h, e, u=0.0):
    """(falling, order): whether errors ``e`` at mesh sizes ``h`` (h descending, two levels or
    more) are still falling at the finest levels beyond the values' uncertainty ``u``, and the
    order they fall at there (log(e_-3 / e_-1) / log(h_-3 / h_-1) over the three finest, the
    two finest with two levels; None where an error is not positive). Falling: each of the
    (up to two) finest changes is a fall larger than ``u``, at an order of ORDER_MIN or more."""
    k = min(len(h), 3)
    hs, es = h[-k:], e[-k:]
    falls = all(a - b > u for a, b in zip(es, es[1:]))
    q = (math.log(es[0] / es[-1]) / math.log(hs[0] / hs[-1])
         if es[0] > 0 and es[-1] > 0 else None)
    return falls and q is not None and q >= ORDER_MIN, q


def fit(h, e, nested=True, u=0.0):
    """The Fit of errors ``e`` at mesh sizes ``h`` (any order; NaN-free, at least two);
    ``nested`` False for a family whose meshes are not self-similar (unstructured), which is
    never extrapolated; ``u`` the values' own uncertainty (the reference's error estimate),
    part of every +- (u_val) and of what counts as a fall (the rule: the module's doc)."""
    order = np.argsort(h)[::-1]
    h = [float(h[i]) for i in order]
    e = [float(e[i]) for i in order]
    if len(h) < 2:
        raise ValueError("a convergence fit needs errors at two mesh sizes at least")
    if not all(math.isfinite(v) for v in h + e):
        raise ValueError(f"a convergence fit needs finite errors, got {e}")
    n = len(h)
    if max(e) < EXACT:
        return Fit(None, e[-1], max(e), "exact",
                   f"every error is below {EXACT:g}: the reference's own to within its "
                   "solver and the load's remaining nonlinearity", n)
    # growth beyond the values' own uncertainty, still rising over the finest levels (a dip
    # then a rise is no trend: not asymptotic below); a diverging sequence has no limit
    if e[-1] > GROWTH * e[0] and (n < 3 or (e[-1] - e[0] > u and e[-1] > e[-2] > e[-3])):
        return Fit(None, None, None, "diverges",
                   f"the error grows from {e[0]:.3g} to {e[-1]:.3g} as h falls: no limit", n)
    if not nested:
        return Fit(None, None, None, "not asymptotic",
                   "the meshes are not self-similar (no asymptotic expansion in h holds), so "
                   f"no limit is extrapolated; the finest error is {e[-1]:.3g}", n)
    falling, q = still_falling(h, e, u)
    rise = e[-1] - e[-2] if n >= 3 else 0.0
    # a rise at the finest level beyond the values' own uncertainty and either beyond
    # GROWTH's share of the level, or beyond the change before it and RISE of the level: the
    # sequence has not settled
    if n >= 3 and rise > u and (rise > (GROWTH - 1) * abs(e[-2]) or rise > max(
            FS_THREE * abs(e[-2] - e[-3]), RISE * abs(e[-2]))):
        # the finest refinement raises the error: neither a limit nor a level it stays at
        return Fit(None, None, None, "not asymptotic",
                   f"the finest refinement raises the error from {e[-2]:.3g} to {e[-1]:.3g}: "
                   "no level it stays at, no limit", n)
    if n >= 3 and not falling:
        # stopped within its uncertainty: the level it stopped at, +- its last changes
        e_inf = e[-1]
        err = math.hypot(FS_THREE * max(abs(e[-1] - e[-2]), abs(e[-2] - e[-3])), u)
        p_obs = None       # an order read off a sequence that stopped is its noise's
        changes = ", ".join(f"{b - a:+.2g}" for a, b in zip(e[-3:], e[-2:]))
        stopped = (f"stopped falling (finest changes {changes}"
                   + (f", the values' uncertainty {u:.2g}" if u else "")
                   + (f", order {q:.2g} there" if q is not None else "") + ")")
        if e_inf - err > 0:
            return Fit(p_obs, e_inf, err, "floor",
                       f"{stopped}: the error stays at {e_inf:.3g} +- {err:.2g}, which no "
                       "refinement removes", n)
        if bounds_nothing(err, e[-1], u):
            return _undecided(n, e_inf, err, e[-1], stopped)
        return Fit(p_obs, e_inf, err, "converges",
                   f"fell to {e_inf:.2g} +- {err:.2g}, not distinguishable from zero, and "
                   f"{stopped[0].lower()}{stopped[1:]}", n)
    e_inf, err, p = extrapolate(h, e)
    err = math.hypot(err, u)
    r = h[-2] / h[-1]
    p_obs = p if p is not None else (
        math.log(e[-2] / e[-1]) / math.log(r) if n == 2 and e[-1] > 0 and e[-2] > e[-1]
        else None)
    if e_inf + err < 0:     # an error cannot tend below zero: the levels are not asymptotic
        # and no limit is printed (a zero there would read as a limit the levels never gave)
        return Fit(p_obs, None, None, "not asymptotic",
                   f"the extrapolated limit {e_inf:.3g} +- {err:.2g} is below zero: the levels "
                   "are not in the asymptotic range", n)
    e_inf = max(e_inf, 0.0)
    if n >= 3 and e_inf - err <= 0 and bounds_nothing(err, e[-1], u):
        return _undecided(n, e_inf, err, e[-1], "still falling" + (
            f" at order {p:.2g}" if p is not None else ", without an observed order"))
    if n >= 3 and p is None:
        # still falling, but its changes do not shrink as a power of h: no limit, no floor
        return Fit(None, None, None, "not asymptotic",
                   f"still falling (order {q:.2g} over the finest levels), not yet in the "
                   f"asymptotic range: no limit extrapolated, at most the finest error "
                   f"{e[-1]:.2g}", n)
    if e_inf - err > 0:
        return Fit(p_obs, e_inf, err, "floor",
                   f"the error tends to {e_inf:.3g} +- {err:.2g}, which no refinement removes"
                   + (" (two levels, first order assumed)" if n == 2 else ""), n)
    why = (f"observed order {p_obs:.2g}" if p_obs is not None else
           "no order observed, but no floor distinguishable from zero")
    return Fit(p_obs, e_inf, err, "converges", why + f"; limit {e_inf:.2g} +- {err:.2g}", n)


def ratio_limit(h, ratios, nested=True):
    """(limit, uncertainty) of a stiffness ratio (model over FEM, > 0) over the levels, or
    (None, why) where none is credible: a family that is not self-similar, or a limit at or
    below zero."""
    if not nested:
        return None, "not self-similar: no extrapolation"
    r = [float(x) for x in ratios]
    if len(r) >= 3 and abs(r[-1] - r[-2]) > max(abs(r[-2] - r[-3]), ROUND_LEVEL):
        # changes that grow under refinement are not a sequence settling on a limit
        return None, (f"not asymptotic: its finest changes grow ({r[-2] - r[-3]:+.2g}, "
                      f"{r[-1] - r[-2]:+.2g})")
    limit, err, _ = extrapolate(h, ratios)
    if not limit > 0:
        return None, f"extrapolated to {limit:.3g}: not asymptotic"
    return limit, err


def cancellation(e, ratios=None):
    """Why the errors over the levels (h descending) may cancel rather than converge, or None:
    an error sequence that is not monotone, or a stiffness ratio that crosses 1 (an error that
    falls through zero looks small at one level by accident). Round-off is never cancellation:
    errors at or below ROUND_LEVEL count as equal, and a ratio within it of 1 is on neither
    side."""
    d = np.diff(np.maximum(np.asarray(e, float), ROUND_LEVEL))
    if len(d) and np.any(d > 0) and np.any(d < 0):
        return "the error is not monotone in h"
    if ratios is not None and len(ratios) > 1:
        gap = np.asarray(ratios, float) - 1.0
        side = np.where(np.abs(gap) <= ROUND_LEVEL, 0.0, np.sign(gap))
        if np.any(side > 0) and np.any(side < 0):
            return "the stiffness ratio crosses 1"
    return None


def blind_levels(runs):
    """{(case, bc, mesh, h_mm): why} of the levels that test nothing: three models or more
    solved there, their displacement errors (above EXACT) all within SAME_ERROR of their
    median while their stiffness ratios spread more than ten times as much (the models differ,
    the displacement does not: the mesh leaves them nothing to differ in). Such a level is
    left out of every fit of its family."""
    groups = {}
    for r in runs:
        if r.get("disp_rel_l2") is not None:
            groups.setdefault((r["case"], r["bc"], r["mesh"], r["h_mm"]), []).append(r)
    out = {}
    for k, rs in groups.items():
        e = np.array([r["disp_rel_l2"] for r in rs])
        ratios = np.array([r["reaction_ratio"] for r in rs
                           if r.get("reaction_ratio") is not None])
        if len(rs) < 3 or e.max() < EXACT or len(ratios) < 3 or ratios.min() <= 0:
            continue
        spread = float(np.abs(e / np.median(e) - 1).max())
        r_spread = float(ratios.max() / ratios.min() - 1)
        if spread <= SAME_ERROR and r_spread > 10 * spread:
            out[k] = {"error": float(np.median(e)), "error_spread": spread,
                      "ratios": [float(ratios.min()), float(ratios.max())],
                      "models": len(rs)}
    return out


__all__ = ["Fit", "fit", "extrapolate", "observed_order", "still_falling", "ratio_limit",
           "cancellation", "bounds_nothing", "EXACT", "ORDER_MIN", "ROUND_LEVEL", "UNDECIDED",
           "SAME_ERROR", "blind_levels"]
