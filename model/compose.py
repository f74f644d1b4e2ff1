"""Models named on the command line and in the API: a preset, or terms composed with ``+``.

>>> from model.compose import parse, label
>>> parse("shear(reading=variational, c=auto) + normal_edge(c=0.05) + volume")
[('shear', {'reading': 'variational', 'c': 'auto'}), ('normal_edge', {'c': 0.05}), ('volume', {})]
>>> label("shear(reading=variational,c=auto)+volume")
'shear(reading=variational, c=auto) + volume'

A component is a registered term with optional ``key=value`` parameters (numbers, words such as
``auto`` or ``variational``, ``true``/``false``), or a preset name without ``+`` (its terms
are inserted). A spec that is a preset name as a whole (``msm+volume``) is that preset.
"""
import re

from .errors import ModelError

_NAME = r"[A-Za-z_][A-Za-z0-9_.\-]*"
_COMPONENT = re.compile(rf"\s*({_NAME})\s*(?:\((.*?)\))?\s*$", re.S)
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _presets():
    from .presets import NAMED
    return NAMED


def _simulators():
    from .simulators import registered
    return registered()


def _value(text, where):
    text = text.strip()
    if _NUMBER.match(text):
        return int(text) if re.fullmatch(r"[+-]?\d+", text) else float(text)
    if text in ("true", "false"):
        return text == "true"
    if re.fullmatch(_NAME, text):
        return text
    raise ModelError(f"cannot read the value {text!r} in {where!r}: give a number, a word "
                     "(e.g. auto, variational) or true/false")


def _split(spec):
    """The components of ``spec``: split at ``+`` outside parentheses."""
    parts, depth, cur = [], 0, ""
    for ch in spec:
        depth += (ch == "(") - (ch == ")")
        if depth < 0:
            raise ModelError(f"unbalanced ')' in model {spec!r}")
        if ch == "+" and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    if depth:
        raise ModelError(f"unbalanced '(' in model {spec!r}")
    return parts + [cur]


def _params(args, spec, allowed, whose):
    """{key: value} of ``key=value, ...`` in ``args``, every key among ``allowed``."""
    params = {}
    for kv in filter(str.strip, (args or "").split(",")):
        if "=" not in kv:
            raise ModelError(f"parameter {kv.strip()!r} of {whose} in {spec!r} needs "
                             "key=value")
        k, v = (s.strip() for s in kv.split("=", 1))
        if k not in allowed:
            raise ModelError(f"{whose} has no parameter {k!r}; it takes "
                             f"{', '.join(sorted(allowed)) or 'none'}")
        params[k] = _value(v, spec)
    return params


def simulator(spec):
    """``(name, params)`` where ``spec`` names a registered simulator (``model.simulators``),
    alone and with optional ``key=value`` settings, e.g. ``newton-xpbd(iterations=20)``;
    None where it names terms or a preset."""
    from .simulators import registered
    if not isinstance(spec, str) or spec.strip() in _presets():
        return None
    m = _COMPONENT.match(spec)
    if not m or m.group(1) not in (sims := registered()):
        return None
    name = m.group(1)
    return name, _params(m.group(2), spec, set(sims[name].params), f"model {name!r}")


def parse(spec):
    """``[(term, params), ...]`` of a preset name or a composed spec; every term name and
    parameter name is checked against the registry (values are checked by the term when the
    model is built)."""
    from .terms import registered
    presets = _presets()
    if not isinstance(spec, str) or not spec.strip():
        raise ModelError(f"a model is a preset name or terms joined by '+', got {spec!r}")
    if simulator(spec):
        raise ModelError(f"model {spec!r} is a simulator (model.simulators), not force terms")
    if spec.strip() in presets:
        return [(t, dict(p)) for t, p in presets[spec.strip()]]
    terms = registered()
    out = []
    for part in _split(spec):
        m = _COMPONENT.match(part)
        if not m:
            raise ModelError(f"cannot read {part.strip()!r} in model {spec!r}: write "
                             "term(key=value, ...) joined by '+', e.g. "
                             "'shear(reading=variational, c=auto) + normal_edge(c=auto) + volume'")
        name, args = m.group(1), m.group(2)
        if name in presets and args is None:
            out += [(t, dict(p)) for t, p in presets[name]]
            continue
        if name not in terms:
            raise ModelError(f"unknown model {name!r} (a preset, a term or a simulator) in "
                             f"{spec!r}; valid: presets {', '.join(presets)}; terms "
                             f"{', '.join(sorted(terms))}; simulators "
                             f"{', '.join(sorted(_simulators()))} (a user term: pbcm --term FILE;"
                             " a user simulator: pbcm --model-file FILE)")
        out.append((name, _params(args, spec, set(terms[name].params) | {"scale"},
                                  f"term {name!r}")))
    names = [t for t, _ in out]
    twice = sorted({t for t in names if names.count(t) > 1})
    if twice:
        raise ModelError(f"term(s) {', '.join(twice)} appear twice in model {spec!r}; give "
                         "each term once")
    return out


def _fmt(v):
    return ("true" if v else "false") if isinstance(v, bool) else f"{v:g}" \
        if isinstance(v, float) else str(v)


def label(spec):
    """The canonical name of a model: a preset's name, or its terms written out in one form
    (so that equal specs gate and report under one name)."""
    if isinstance(spec, str) and spec.strip() in _presets():
        return spec.strip()
    sim = simulator(spec)
    if sim:
        terms = [sim]
    else:
        terms = parse(spec) if isinstance(spec, str) else list(spec)
    return " + ".join(t + (f"({', '.join(f'{k}={_fmt(v)}' for k, v in p.items())})" if p else "")
                      for t, p in terms)


def slug(name):
    """A file-name form of a model label (for .vtu and figure names).

    >>> slug("shear(reading=variational, c=auto) + volume")
    'shear.reading=variational.c=auto+volume'
    """
    name = name.replace(" ", "").replace("(", ".").replace(")", "").replace(",", ".")
    return re.sub(r"[^A-Za-z0-9_.+=\-]+", "_", name)


def checked(spec):
    """The canonical label of ``spec``, each of its terms built on one cell first, so that an
    unknown term or parameter, or a bad value, is a ModelError before any computing."""
    from .material import Material
    from .mesh import cube
    from .terms import make_term
    name = label(spec)        # names an unknown term or parameter
    cell = cube(2, 0.01, "five")
    sim = simulator(name)
    if sim:
        from .simulators import make_simulator
        make_simulator(sim[0], cell, Material(E=1e4, nu=0.3), **sim[1])
        return name
    for term, params in parse(name):
        make_term(term, cell, Material(E=1e4, nu=0.3), **params)
    return name

