"""The patch test of every model on every mesh family (Irons' test): each of the six unit
affine strains, scaled to the linear regime, is imposed on the boundary nodes of a small cube
and the interior nodes relax; a consistent discretisation reproduces the affine field exactly.
The error is the strain the model's solution misses: the RMS over the tetrahedra of
|eps_h - eps| / |eps| (Frobenius), eps_h the symmetric gradient of the solution's linear
interpolation; the worst of the six strains is the model's patch error on the family (a strain
error with every boundary node prescribed: not a fit's consistency limit).
The irregular families are the unstructured one and each lattice with its interior nodes moved
at random (``model.mesh.perturbed``)."""
import numpy as np

from model import build
from model.geometry import displacement_gradients
from model.material import as_material
from model.mesh import cube, perturbed
from reference import linear
from ...running import stop
from ...running.runner import FINDINGS
from ...running.store import OFF, key
from .verification import spec as verification_spec

PERTURBED = "-perturbed"
# the six unit strains in Voigt order (xx, yy, zz, yz, xz, xy), as symmetric tensors
VOIGT = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))


def unit_strains():
    out = []
    for i, j in VOIGT:
        e = np.zeros((3, 3))
        e[i, j] = e[j, i] = 1.0
        out.append(e)
    return out


def families(lattices):
    """The patch families of ``lattices``: each one, and each but the unstructured perturbed."""
    return list(lattices) + [f + PERTURBED for f in lattices if f != "unstructured"]


def patch_mesh(family, spec, size):
    base = family.removesuffix(PERTURBED)
    mesh = cube(spec["nodes"], size, base)
    if family.endswith(PERTURBED):
        mesh = perturbed(mesh, spec["perturbation"], spec["seed"])
    return mesh


def boundary(mesh):
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    tol = 1e-9 * mesh.size
    return ((np.abs(mesh.points - lo) < tol) | (np.abs(mesh.points - hi) < tol)).any(axis=1)


def strain_error(mesh, u, eps):
    """RMS over the tetrahedra of |sym grad u_h - eps| / |eps|."""
    g = displacement_gradients(mesh.points, mesh.tets, u)
    e = 0.5 * (g + np.swapaxes(g, 1, 2)) - eps
    return float(np.sqrt(np.mean(np.sum(e * e, axis=(1, 2)))) / np.linalg.norm(eps))


def solve(model, mesh, material, eps, rtol):
    """The nodal displacement of ``model`` ("FEM P1" for the scikit-fem reference) with the
    boundary nodes at eps x (about the cube's centre) and the interior free."""
    centre = 0.5 * (mesh.points.min(axis=0) + mesh.points.max(axis=0))
    affine = (mesh.points - centre) @ eps.T
    bc = {int(i): tuple(affine[i]) for i in np.flatnonzero(boundary(mesh))}
    if model == "FEM P1":
        return linear.solve(mesh, material, bc, element="P1").u
    return build(model, mesh, material).solve_static(bc, rtol=rtol).u


def run_model(model, family, spec, material, size, rtol, store=OFF):
    """One row: the model on the family's patch, its error per strain and the worst."""
    k = key(kind="patch", model=model, mesh=family, spec=spec, E=material.E, nu=material.nu,
            size=size, rtol=rtol)
    found = store.get(k)
    if found is not None:
        return found
    mesh = patch_mesh(family, spec, size)
    row = {"mesh": family, "model": model, "nodes": mesh.n_nodes,
           "interior": int((~boundary(mesh)).sum()), "failed": None}
    try:
        errs = []
        for eps in unit_strains():
            stop.checkpoint()
            u = solve(model, mesh, material, spec["strain"] * eps, rtol)
            errs.append(strain_error(mesh, u, spec["strain"] * eps))
        row.update(patch_errors=errs, patch_error=max(errs))
    except FINDINGS as exc:      # a model without equilibrium on the patch: a finding
        row.update(failed=str(exc), patch_errors=None, patch_error=None)
    return store.put(k, row)


def units(models, lattices, material, store=OFF):
    """The table's rows as work units ``(run_model, args, cost)``: every one of ``models``
    ("FEM P1" for the scikit-fem reference) on every patch family of ``lattices``, as the
    spec's [patch] declares the test, on the spec's cube, of ``material`` (the study's
    model.material.Material; cost: one each)."""
    material = as_material(material, "cases.studies.convergence.patch.units")
    s = verification_spec()
    spec = dict(s["patch"])
    rtol = spec.pop("rtol")
    return [(run_model, (m, fam, spec, material, s["size"], rtol, store), 1.0)
            for fam in families(lattices) for m in models]


def table(models, lattices, material, store=OFF):
    """The rows of :func:`units`, computed here."""
    return [fn(*args) for fn, args, _ in units(models, lattices, material, store)]


__all__ = ["unit_strains", "families", "patch_mesh", "strain_error", "solve", "run_model",
           "units", "table", "PERTURBED"]
