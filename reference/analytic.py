"""Closed-form solutions of linear elasticity (SI units). Each returns displacements as a
function of points (k, 3) -> (k, 3), or a number; the frame is stated per function."""
import numpy as np

from model.material import as_material


def uniaxial_sliding(points, strain, material, axis=1):
    """Homogeneous uniaxial strain ``strain`` along ``axis`` of ``material`` (a
    model.material.Material; nu read) with free lateral faces and sliding ends, origin fixed:
    u_axis = strain x_axis, u_other = -nu strain x_other."""
    nu = as_material(material, "reference.analytic.uniaxial_sliding").nu
    u = -nu * strain * np.asarray(points, dtype=float)
    u[:, axis] = strain * points[:, axis]
    return u


def self_weight(points, material, g, height, axis=1):
    """Exact 3-D solution of a prismatic block of ``material`` (a model.material.Material)
    standing on its base x_axis = 0, top x_axis = height traction-free, lateral faces free,
    under gravity g [m/s^2] along -axis: sigma_aa = rho g (x_a - height), all other stresses
    zero. Lateral axes centred on 0."""
    material = as_material(material, "reference.analytic.self_weight")
    p = np.asarray(points, dtype=float)
    z = p[:, axis]
    lat = [k for k in range(3) if k != axis]
    E, nu, rho = material.E, material.nu, material.rho
    c = rho * g / E
    u = np.empty_like(p)
    u[:, axis] = c * (0.5 * z**2 - height * z) + 0.5 * nu * c * (p[:, lat] ** 2).sum(axis=1)
    for k in lat:
        u[:, k] = -nu * c * (z - height) * p[:, k]
    return u


def self_weight_stress(points, material, g, height, axis=1):
    """The stress [Pa] of :func:`self_weight` at ``points``: sigma_aa = rho g (x_a - height),
    rho the ``material``'s density."""
    rho = as_material(material, "reference.analytic.self_weight_stress").rho
    s = np.zeros((len(points), 3, 3))
    s[:, axis, axis] = rho * g * (np.asarray(points)[:, axis] - height)
    return s


def cantilever_tip_deflection(force, length, width, height, material, kappa=5 / 6):
    """Tip deflection [m] of a clamped rectangular beam of ``material`` (a
    model.material.Material; E [Pa] and nu read) under an end shear ``force`` [N], ``length``,
    ``width``, ``height`` [m]: Euler-Bernoulli bending P L^3 / (3 E I) plus Timoshenko shear
    P L / (kappa G A), bending about the width axis (I = width height^3 / 12)."""
    material = as_material(material, "reference.analytic.cantilever_tip_deflection")
    I = width * height**3 / 12
    E, G = material.E, material.G
    return force * length**3 / (3 * E * I) + force * length / (kappa * G * width * height)


def cantilever_first_frequency(length, width, height, material, kappa=5 / 6):
    """First bending frequency [Hz] of a clamped-free rectangular beam of ``material`` (a
    model.material.Material: E [Pa], nu, rho [kg/m^3]), ``length``, ``width``, ``height`` [m],
    bending across ``height``: Euler-Bernoulli (beta L = 1.87510) with the Timoshenko
    first-order correction for shear and rotary inertia,
    omega = omega_EB / sqrt(1 + (beta r)^2 (1 + E / (kappa G))) with r^2 = I / A: the
    first-order Timoshenko correction (exact in this form for a simply supported beam, an
    approximation here; about 1 % at length / height 10)."""
    material = as_material(material, "reference.analytic.cantilever_first_frequency")
    bl = 1.8751040687
    I, A = width * height**3 / 12, width * height
    E, G, rho = material.E, material.G, material.rho
    omega_eb = bl**2 / length**2 * np.sqrt(E * I / (rho * A))
    r2 = I / A
    omega = omega_eb / np.sqrt(1 + (bl / length) ** 2 * r2 * (1 + E / (kappa * G)))
    return omega / (2 * np.pi)
