"""Effective elasticity of a model on a lattice (docs/model.md "Convergence and effective
elasticity"): the 6 x 6 tensor C_eff a patch of the lattice answers a homogeneous strain with,
and what it says: engineering constants per axis, the universal anisotropy index and the
directional Young's modulus.

Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains (gamma = 2 eps), so that
sigma = C eps_voigt and the strain energy density is eps_voigt . C eps_voigt / 2.
"""
import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .errors import ModelError

VOIGT = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))
VOIGT_NAMES = ("xx", "yy", "zz", "yz", "xz", "xy")


def strain_tensor(k):
    """The symmetric 3 x 3 strain of the k-th unit Voigt strain (engineering shear 1)."""
    i, j = VOIGT[k]
    e = np.zeros((3, 3))
    e[i, j] = e[j, i] = 1.0 if i == j else 0.5
    return e


def voigt_stress(sigma):
    """The Voigt vector (6,) of a 3 x 3 stress (no factor on the shear entries)."""
    return np.array([sigma[i, j] for i, j in VOIGT])


def boundary_nodes(mesh, tol=1e-9):
    """The nodes on the faces of the mesh's bounding box (the patch's surface)."""
    p = mesh.points
    lo, hi = p.min(axis=0), p.max(axis=0)
    t = tol * mesh.size
    return np.flatnonzero(((np.abs(p - lo) < t) | (np.abs(p - hi) < t)).any(axis=1))


def effective_stiffness(model, boundary=None):
    """C_eff (6, 6) [Pa] of ``model`` (a ParticleModel) on its mesh, a box-shaped patch.

    For each unit homogeneous strain the surface nodes move affinely, u = eps x, the interior
    nodes relax to equilibrium, and the mean stress is the volume average the supports impose,
    sigma = (1 / V) sum_b f_b (x) (x_b - c), with f_b the force the supports exert on surface
    node b. Linear response at rest: K = -df/dx (the model's finite-difference Jacobian), the
    interior condensed out, so this serves conservative and non-conservative readings alike.
    Column k of C_eff is the Voigt stress of the k-th unit strain; a conservative model gives a
    symmetric C_eff (its Jacobian is), a non-conservative one need not, and the symmetric part
    is not taken here: ``asymmetry`` reports it.
    """
    K = -model.jacobian(model.mesh.points).tocsc()
    return condensed_stiffness(K, model.mesh, boundary, model.name)


def condensed_stiffness(K, mesh, boundary=None, name="the model"):
    """C_eff (6, 6) [Pa] of the stiffness ``K`` = -df/dx (3n x 3n, sparse) on ``mesh``, a
    box-shaped patch: the ``boundary`` nodes (default its surface) moved by each unit
    homogeneous strain, the interior condensed out (see :func:`effective_stiffness`)."""
    b = boundary_nodes(mesh) if boundary is None else np.asarray(boundary)
    n = mesh.n_nodes
    on_b = np.zeros(n, bool)
    on_b[b] = True
    dof_b = np.flatnonzero(np.repeat(on_b, 3))
    dof_i = np.flatnonzero(~np.repeat(on_b, 3))
    K = sp.csc_matrix(K)
    x = mesh.points - mesh.points.mean(axis=0)
    U = np.stack([(x @ strain_tensor(k).T).ravel() for k in range(6)], axis=1)   # (3n, 6)
    if dof_i.size:
        Kii = K[dof_i][:, dof_i]
        rhs = -(K[dof_i][:, dof_b] @ U[dof_b])
        try:
            U[dof_i] = splu(sp.csc_matrix(Kii)).solve(np.ascontiguousarray(rhs))
        except RuntimeError as exc:      # SuperLU: "Factor is exactly singular"
            raise ModelError(f"the effective stiffness of {name} is undefined: the patch "
                             f"interior is not held by the model ({exc})") from None
    F = (K @ U).reshape(n, 3, 6)          # force the supports exert (zero inside)
    F[~on_b] = 0.0
    V = float(mesh.volumes.sum())
    C = np.empty((6, 6))
    for k in range(6):
        sigma = np.einsum("bi,bj->ij", F[:, :, k], x) / V
        C[:, k] = voigt_stress(0.5 * (sigma + sigma.T))
    if not np.isfinite(C).all():
        raise ModelError(f"the effective stiffness of {name} is not finite: the patch "
                         "interior is not held by the model (a singular stiffness)")
    return C


# Mandel weights: a Voigt C with engineering shear becomes W C W, whose eigenvalues are the
# Kelvin moduli (3K once and 2G five times for an isotropic material)
_MANDEL = np.array([1.0, 1.0, 1.0, np.sqrt(2.0), np.sqrt(2.0), np.sqrt(2.0)])


def _deviatoric_mandel():
    """Five orthonormal traceless directions (6, 5) in Mandel form."""
    s2, s6 = np.sqrt(2.0), np.sqrt(6.0)
    B = np.zeros((6, 5))
    B[:3, 0] = np.array([1.0, -1.0, 0.0]) / s2
    B[:3, 1] = np.array([1.0, 1.0, -2.0]) / s6
    B[3, 2] = B[4, 3] = B[5, 4] = 1.0
    return B


def kelvin_moduli(C):
    """(K, mu): the bulk modulus [Pa] of a Voigt stiffness C (engineering shear), v.M v / 3
    with M = W C W its Mandel form and v the unit volumetric direction, and its five
    deviatoric Kelvin moduli, ascending: the eigenvalues of the symmetric part of M on the
    deviatoric subspace (each 2G for an isotropic C). Of a non-conservative model's C the
    symmetric part is what stores energy."""
    M = _MANDEL[:, None] * np.asarray(C, float) * _MANDEL[None, :]
    M = 0.5 * (M + M.T)
    v = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]) / np.sqrt(3.0)
    B = _deviatoric_mandel()
    return float(v @ M @ v / 3.0), np.linalg.eigvalsh(B.T @ M @ B)


def moduli_errors(C, E, nu):
    """Isotropy judged by moduli: {"bulk": K / K_target - 1, "deviatoric": (5,) mu / 2G - 1}
    and "largest", the largest |relative error| of the six, against the isotropic E, nu."""
    K, mu = kelvin_moduli(C)
    K_t, G_t = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    bulk, dev = K / K_t - 1, mu / (2 * G_t) - 1
    return {"bulk": float(bulk), "deviatoric": dev.tolist(),
            "largest": float(max(abs(bulk), np.abs(dev).max()))}


def isotropic_stiffness(E, nu):
    """The isotropic C (6, 6) of Young's modulus E and Poisson's ratio nu (engineering shear:
    the shear diagonal is G)."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    G = E / (2 * (1 + nu))
    C = np.zeros((6, 6))
    C[:3, :3] = lam
    C[np.arange(3), np.arange(3)] += 2 * G
    C[np.arange(3, 6), np.arange(3, 6)] = G
    return C


def engineering_constants(C):
    """Young's moduli E_x, E_y, E_z, Poisson's ratios nu_ij = -S_ij / S_ii (lateral strain j
    under uniaxial stress i) and shear moduli G_yz, G_xz, G_xy of the compliance S = C^-1 of
    the symmetric part of C."""
    S = np.linalg.inv(0.5 * (C + C.T))
    out = {f"E_{a}": 1 / S[i, i] for i, a in enumerate("xyz")}
    for i, a in enumerate("xyz"):
        for j, c in enumerate("xyz"):
            if i != j:
                out[f"nu_{a}{c}"] = -S[i, j] / S[i, i]
    out.update({f"G_{VOIGT_NAMES[k]}": 1 / S[k, k] for k in range(3, 6)})
    return {k: float(v) for k, v in out.items()}


def voigt_reuss(C):
    """Bulk and shear moduli (K_V, G_V, K_R, G_R): Voigt's bounds from C, Reuss's from
    S = C^-1 (Hill 1952), of the symmetric part of C."""
    C = 0.5 * (C + C.T)
    S = np.linalg.inv(C)
    d, o, s = np.trace(C[:3, :3]), C[0, 1] + C[1, 2] + C[0, 2], np.trace(C[3:, 3:])
    K_V, G_V = (d + 2 * o) / 9, (d - o + 3 * s) / 15
    d, o, s = np.trace(S[:3, :3]), S[0, 1] + S[1, 2] + S[0, 2], np.trace(S[3:, 3:])
    K_R, G_R = 1 / (d + 2 * o), 15 / (4 * d - 4 * o + 3 * s)
    return float(K_V), float(G_V), float(K_R), float(G_R)


def anisotropy_index(C):
    """The universal anisotropy index A_U = 5 G_V / G_R + K_V / K_R - 6 (Ranganathan and
    Ostoja-Starzewski 2008): zero for an isotropic tensor, positive otherwise."""
    K_V, G_V, K_R, G_R = voigt_reuss(C)
    return float(5 * G_V / G_R + K_V / K_R - 6)


def directional_young(C, directions):
    """Young's modulus E(d) along unit vectors ``directions`` (k, 3): 1 / E = m . S m with
    m = (d1^2, d2^2, d3^2, d2 d3, d1 d3, d1 d2) (uniaxial stress along d, strain along d)."""
    d = np.asarray(directions, dtype=float)
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    m = np.stack([d[:, i] * d[:, j] for i, j in VOIGT], axis=1)
    S = np.linalg.inv(0.5 * (C + C.T))
    return 1.0 / np.einsum("ka,ab,kb->k", m, S, m)


def asymmetry(C):
    """||C - C^T|| / ||C||: zero for a model with an energy."""
    return float(np.linalg.norm(C - C.T) / np.linalg.norm(C))


__all__ = ["effective_stiffness", "condensed_stiffness", "kelvin_moduli", "moduli_errors",
           "isotropic_stiffness", "engineering_constants",
           "voigt_reuss", "anisotropy_index", "directional_young", "asymmetry",
           "boundary_nodes", "strain_tensor", "VOIGT", "VOIGT_NAMES"]
