"""Stress read from a FEM solution: averaged over each input tetrahedron, and its measures."""
import numpy as np

from .discretisation import parent_of


def cell_average(basis, field):
    """Volume average per element of a quadrature field (..., nel, nqp)."""
    return np.einsum("...eq,eq->...e", field, basis.dx) / basis.dx.sum(axis=1)


def stress_on_input(basis, W, mesh, sigma):
    """The volume average over each input tetrahedron of a quadrature stress field sigma
    (3, 3, nel, nqp) on the (possibly refined) ``basis``: (m, 3, 3), and the input volumes."""
    sig_fine = np.moveaxis(cell_average(basis, sigma), -1, 0)         # (m_fine, 3, 3)
    vol_fine = basis.dx.sum(axis=1)
    parent = parent_of(basis.mesh, W, mesh.tets)
    vol = np.bincount(parent, weights=vol_fine, minlength=mesh.n_tets)
    stress = np.stack([np.bincount(parent, weights=vol_fine * sig_fine[:, i, j],
                                   minlength=mesh.n_tets)
                       for i in range(3) for j in range(3)], axis=1).reshape(-1, 3, 3)
    return stress / vol[:, None, None], vol


def stress_measures(sigma):
    """von Mises, maximum shear (sigma_1 - sigma_3) / 2 and pressure -tr/3 of (m, 3, 3)."""
    eig = np.linalg.eigvalsh(sigma)
    dev = sigma - np.trace(sigma, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    return (np.sqrt(1.5 * np.einsum("mij,mij->m", dev, dev)),
            0.5 * (eig[:, -1] - eig[:, 0]), -np.trace(sigma, axis1=1, axis2=2) / 3)
