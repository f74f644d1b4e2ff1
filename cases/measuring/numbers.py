"""How a measured number is written: significant figures, round-off said as such."""
from .error_model import ROUND_OFF


def rel(v, digits=3):
    """A relative quantity for a report: 'n/a' for None, '< 1e-09' where its magnitude is
    below round-off (``error_model.ROUND_OFF``, which differs from one processor to the next),
    else ``digits`` significant figures."""
    if v is not None and not isinstance(v, bool) and abs(v) < ROUND_OFF:
        return f"< {ROUND_OFF:.0e}"
    return fmt(v, digits)


def rel_range(lo, hi):
    """'lo-hi' of two relative values, or the round-off bound alone where both are below it."""
    return rel(hi) if rel(hi).startswith("<") else f"{rel(lo)}-{rel(hi)}"


def fmt_span(v, span, digits=3):
    """'v [lo-hi]' with ``digits`` significant figures, or 'v' alone where ``span`` is None
    (a range not recorded)."""
    return fmt(v, digits) + (f" [{fmt(span[0], digits)}-{fmt(span[1], digits)}]" if span
                             else "")


def fmt(v, digits=3):
    """A number for a report cell: 'n/a' for None, yes/no for a bool, ``digits`` significant
    figures for a float."""
    if v is None:
        return "n/a"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    return str(v)
