"""The effective elasticity of every model on every lattice (``model.homogenize``): a cube
patch of the lattice, its surface moved by each unit homogeneous strain, its interior relaxed.
"""
import numpy as np

from model import build
from model.homogenize import (anisotropy_index, asymmetry, directional_young,
                              effective_stiffness, engineering_constants, kelvin_moduli,
                              moduli_errors)
from model.mesh import cube
from model.units import MM
from ...library.common import CUBE_MM
from ...running import stop
from ...running.runner import FINDINGS
from ...running.store import OFF, key

PATCH_MM = CUBE_MM             # the patch cube: the paper's
# directions of the directional Young's modulus figure: the x-y plane, every 5 degrees
ANGLES_DEG = np.arange(0.0, 360.0 + 1e-9, 5.0)


def patch(family, n):
    """The lattice patch: a cube of ``n`` nodes per side (SI units)."""
    return cube(n, PATCH_MM * MM, family)


def entry(model_name, family, s):
    """C_eff of one model on one lattice and what it says, relative to the isotropic target
    (E, nu of the settings): its bulk modulus and five deviatoric Kelvin moduli, each against
    the target's (the criterion is the largest relative error of the six)."""
    mesh = patch(family, s.patch_n)
    pm = build(model_name, mesh, s.material)
    C = effective_stiffness(pm)
    const = engineering_constants(C)
    K, mu = kelvin_moduli(C)
    err = moduli_errors(C, s.E, s.nu)
    diag = np.array([[1, 1, 0], [1, -1, 0], [1, 1, 1]], float)
    E_dir = directional_young(C, diag)
    theta = np.radians(ANGLES_DEG)
    return {"model": model_name, "mesh": family, "C_eff_pa": C.tolist(),
            # the moduli in Pa carry the unit's suffix, the ratios none
            **{(k + "_pa" if k[0] in "EG" else k): v for k, v in const.items()},
            "E_110_pa": float(E_dir[0]), "E_111_pa": float(E_dir[2]),
            "anisotropy_AU": anisotropy_index(C), "K_eff_pa": K,
            "deviatoric_moduli_pa": mu.tolist(), "bulk_rel_err": err["bulk"],
            "deviatoric_rel_err": err["deviatoric"], "moduli_rel_err": err["largest"],
            "asymmetry": asymmetry(C),
            "E_xy_plane_pa": directional_young(
                C, np.column_stack([np.cos(theta), np.sin(theta), 0 * theta])).tolist()}


def table(s, store=OFF):
    """Every (model, lattice) entry, each from the run store ``store`` where kept; a model
    whose patch stiffness is singular (no interior equilibrium) is recorded with the
    reason."""
    out = []
    for family in s.meshes:
        for name in s.models:
            stop.checkpoint()
            k = key(kind="elasticity", model=name, mesh=family,
                    **s.material_record(), patch_n=s.patch_n)
            found = store.get(k)
            if found is None:
                try:
                    found = entry(name, family, s)
                except FINDINGS as exc:
                    found = {"model": name, "mesh": family, "failed": str(exc)}
                store.put(k, found)
            out.append(found)
    return out


__all__ = ["table", "entry", "patch", "ANGLES_DEG", "PATCH_MM"]
