"""The force terms' registry by name (:class:`model.plugins.Registry`): built-in modules of this
package, installed packages in the entry-point group ``pbcm.terms`` and user term files
(``PBCM_TERMS``, ``pbcm --term``), each loaded on first use."""
from pathlib import Path

from ..errors import ModelError
from ..plugins import Registry

ENTRY_POINT_GROUP = "pbcm.terms"
REGISTRY = Registry("force term", ENTRY_POINT_GROUP, "PBCM_TERMS", __package__,
                    Path(__file__).parent, "registers a term with @model.terms.register",
                    skip=("base", "registry"))
TERMS = REGISTRY.items
register = REGISTRY.register
load_file = REGISTRY.load_file
user_files = REGISTRY.user_files
add_user_file = REGISTRY.add_user_file
registered = REGISTRY.registered


def make_term(name, mesh, material, **params):
    """Instantiate the registered term ``name`` on ``mesh`` with ``params``, after its
    conformance checks (``model.conformance``: once per term and options in a process)."""
    from ..conformance import conform
    REGISTRY.load_all()
    if name not in TERMS:
        raise ModelError(f"unknown force term {name!r}; registered: {', '.join(sorted(TERMS))}")
    conform(TERMS[name], params)
    try:
        return TERMS[name](mesh, material, **params)
    except ModelError:
        raise
    except Exception as exc:      # a user term's own error on this mesh
        raise ModelError(f"force term {name!r} raised {type(exc).__name__} when made on a mesh "
                         f"of {mesh.n_tets} tetrahedra: {exc}; fix the term") from exc
