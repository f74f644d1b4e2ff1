"""Modal analysis: the lowest eigenfrequencies of linear elasticity with consistent or lumped
mass (scikit-fem assembly, scipy's shift-invert Lanczos)."""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh
from skfem import BilinearForm, asm
from skfem.helpers import dot

from model.bc import bc_arrays
from model.errors import ModelError
from model.material import as_material
from .assembly import stiffness
from .discretisation import dirichlet_dofs, element_basis, refine_with_data, skfem_mesh


@BilinearForm
def mass_form(u, v, w):
    return dot(u, v)


# the product of two shape functions of degree p has degree 2p: the stiffness's quadrature
# (reference.discretisation.INTORDER, exact for gradients) under-integrates it, and a one-point rule makes
# every P1 element's mass matrix rho V / 16 in every entry instead of rho V (1 + delta_ij) / 20
MASS_INTORDER = {"P1": 2, "P2": 4}


def mass_matrix(m, element, rho):
    """The consistent mass matrix (CSR) of ``element`` on the scikit-fem mesh ``m``,
    integrated exactly; its dofs are those of ``reference.discretisation.element_basis(m, element)``."""
    return (rho * asm(mass_form, element_basis(m, element,
                                               intorder=MASS_INTORDER[element]))).tocsr()


@dataclass
class ModalResult:
    """``frequencies`` (k,) [Hz] ascending; ``modes`` (k, n, 3) at the input mesh nodes."""

    frequencies: np.ndarray
    modes: np.ndarray
    info: dict


def lumped(M):
    """HRZ lumping: the diagonal scaled to keep the total mass (row sums go negative at P2
    vertices; for P1 both agree)."""
    d = M.diagonal()
    return sp.diags(d * M.sum() / d.sum()).tocsr()


def frequencies(mesh, material, dirichlet, k=6, mass="consistent", element="P2", refine=0):
    """The ``k`` lowest eigenfrequencies [Hz] of the structure of ``material`` (the
    model.material.Material: E [Pa], nu, rho [kg/m^3]) clamped by ``dirichlet`` (values must be
    zero there; ``{}`` for free-free, whose six rigid modes come first at 0 Hz)."""
    material = as_material(material, "reference.modal.frequencies")
    lam, mu, rho = *material.lame, material.rho
    if mass not in ("consistent", "lumped"):
        raise ModelError(f"mass must be 'consistent' or 'lumped', got {mass!r}")
    mask, vals = bc_arrays(dirichlet, mesh.n_nodes)
    m, mask_f, vals_f, _ = refine_with_data(skfem_mesh(mesh), mask, vals, None, refine)
    basis = element_basis(m, element)
    D, _ = dirichlet_dofs(basis, mask_f, vals_f, None)
    K = stiffness(basis, lam, mu)
    M = mass_matrix(m, element, rho)
    if mass == "lumped":
        M = lumped(M)
    I = np.setdiff1d(np.arange(basis.N), D)
    Kf, Mf = K[I][:, I], M[I][:, I]
    # shift-invert just below zero: also works free-free, where K is singular
    # ARPACK starts from a random vector unless given one: fixed, for the same bits every run
    start = np.random.default_rng(0).standard_normal(Kf.shape[0])
    w2, vecs = eigsh(Kf, k=k, M=Mf, sigma=-1.0, which="LM", v0=start)
    order = np.argsort(w2)
    full = np.zeros((basis.N, k))
    full[I] = vecs[:, order]
    modes = np.moveaxis(full[basis.nodal_dofs[:, :mesh.n_nodes]], -1, 0)  # (k, 3, n)
    return ModalResult(frequencies=np.sqrt(np.maximum(w2[order], 0.0)) / (2 * np.pi),
                       modes=np.moveaxis(modes, 1, 2),
                       info={"element": element, "refine": refine, "mass": mass,
                             "dofs": int(basis.N)})
