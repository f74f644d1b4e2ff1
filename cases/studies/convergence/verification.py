"""The verification ladder's declaration: ``verification.toml`` (the manufactured-solution
ladders of the references and the patch test of every model), read once, checked, as plain
values for ``manufactured`` and ``patch``."""
import tomllib
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

from model.material import Material
from model.errors import ModelError
from model.units import MM
from reference import manufactured as mms

SPEC = "verification.toml"


@dataclass(frozen=True)
class Entry:
    """One [[manufactured]] entry of the spec."""

    name: str
    material: str
    element: str
    mixed: bool
    nu: float
    amplitude: float
    faces: str
    formal_order: float
    finest_bound: float
    cells: dict
    quick: bool = True        # run by the quick study too (else the full run and the tests)
    faster: tuple = ()        # families where only order >= formal - tolerance is asserted
    load_steps: int = 1       # Newton's load steps (the neo-Hookean ladders)

    def problem(self, size, E):
        return mms.manufactured(mms.waves(size, self.amplitude), self.material,
                                Material(E, self.nu))


@lru_cache(maxsize=1)
def spec():
    """The spec as read from the package: {"size": m, "E": Pa, "tolerance": ..., "manufactured":
    [Entry], "patch": {nodes, strain, perturbation, seed, exact_below, rtol}}."""
    data = tomllib.loads(resources.files(__package__).joinpath(SPEC).read_text())
    try:
        entries = [Entry(**{**e, "faster": tuple(e.get("faster", ()))})
                   for e in data["manufactured"]]
    except TypeError as exc:
        raise ModelError(f"{SPEC}: a [[manufactured]] entry is malformed ({exc}); see the "
                         "fields of cases.studies.convergence.verification.Entry") from None
    return {"size": data["size_mm"] * MM, "E": float(data["E_Pa"]),
            "tolerance": float(data["order_tolerance"]), "manufactured": entries,
            "patch": data["patch"]}


__all__ = ["Entry", "spec", "SPEC"]
