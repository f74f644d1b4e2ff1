"""`pbcm list`: the cases, studies, shipped sweeps, force terms and simulators."""
import sys
import textwrap

import model
import model.simulators
import model.terms
from .common import add_term_files

def add(sub):
    """The command's parser."""
    ls = sub.add_parser("list", help="list the cases, studies and force terms")
    add_term_files(ls)
    ls.set_defaults(func=run)


def run(args):
    from ..registry import CASES
    from ..registry import studies
    for name, case in CASES.items():
        print(textwrap.fill(f"{name}: {_summary(case)}", width=96, subsequent_indent="  "))
        print(f"  meshes: {', '.join(case.meshes)} (quick: {', '.join(case.quick_meshes)})")
        print(f"  bcs:    {', '.join(case.bcs)}")
        print(f"  models: {', '.join(case.models)}")
        knobs = [f"{axis}: {knob.label} ({knob.field})" for axis, knob in
                 (("resolution", case.resolution), ("load", case.load)) if knob is not None]
        if knobs:
            print(f"  sweep axes: {'; '.join(knobs)}")
    for name, study in studies().items():
        print(textwrap.fill(f"{name} (study): {_summary(study)}", width=96,
                            subsequent_indent="  "))
    from .sweeps import SHIPPED
    from .sweeps.spec import load
    from ..registry import CASES as cases
    for path in sorted(SHIPPED.glob("*.toml")):
        print(f"{path.stem} (sweep, pbcm sweep {path.stem}): {load(path, cases).title}")
    for title, registry in (("force terms (compose them with '+' in --models)", model.terms),
                            ("simulators (a model by name in --models, with its settings)",
                             model.simulators)):
        print(f"{title}:")
        for name, cls in sorted(registry.registered().items()):
            params = ", ".join(f"{k}={v}" for k, v in cls.params.items())
            doc = (cls.__doc__ or "").strip().split("\n")[0]
            print(textwrap.fill(f"{name}({params}): {doc}", width=96, initial_indent="  ",
                                subsequent_indent="    "))
    return 0


def _summary(case):
    """The first paragraph of the docstring of the module declaring a case, as whole
    sentences on one line."""
    doc = sys.modules[type(case).__module__].__doc__ or case.title
    return " ".join(doc.strip().split("\n\n")[0].split())

