"""Isotropic material constants (SI units) and the compressible neo-Hookean law they enter."""
from dataclasses import dataclass
import math
import numbers

from numba import njit

from .errors import MaterialError


def poisson_problem(nu):
    """Why ``nu`` is not a Poisson's ratio the models and references accept, or None: the one
    check every entry (the command line, a problem file, a Material) makes."""
    if -1.0 < nu < 0.5:
        return None
    why = ("0.5 and above is incompressible, which the volume term cannot represent: use 0.49 "
           "at most" if nu >= 0.5 else "it must be above -1: at -1 and below the bulk "
           "modulus vanishes")
    return f"Poisson's ratio nu must satisfy -1 < nu < 0.5, got {nu:g} ({why})"


@dataclass(frozen=True)
class Material:
    """Young's modulus ``E`` [Pa], Poisson's ratio ``nu`` [-], density ``rho`` [kg/m^3]."""

    E: float
    nu: float
    rho: float = 1000.0

    def __post_init__(self):
        for name in ("E", "nu", "rho"):
            v = getattr(self, name)
            if not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise MaterialError(f"Material.{name} must be a finite number, got {v!r}")
        if self.E <= 0:
            raise MaterialError(f"Young's modulus E must be > 0 Pa, got {self.E}")
        if poisson_problem(self.nu):
            raise MaterialError(poisson_problem(self.nu))
        if self.rho <= 0:
            raise MaterialError(f"density rho must be > 0 kg/m^3, got {self.rho}")

    @property
    def G(self):
        """Shear modulus E / (2 (1 + nu))."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def K(self):
        """Bulk modulus E / (3 (1 - 2 nu))."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    @property
    def lam(self):
        """First Lame parameter."""
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    @property
    def lame(self):
        """The Lame parameters (lambda, mu), mu the shear modulus."""
        return self.lam, self.G

    @property
    def p_wave_speed(self):
        """Dilatational wave speed sqrt((K + 4G/3) / rho)."""
        return math.sqrt((self.K + 4.0 * self.G / 3.0) / self.rho)


def as_material(value, who):
    """``value`` when it is a :class:`Material`; otherwise a MaterialError naming ``who`` (the
    function that takes it): every reference takes the one Material, checked once where it is
    made, never loose constants."""
    if isinstance(value, Material):
        return value
    raise MaterialError(f"{who} takes a model.material.Material (E [Pa], nu, rho [kg/m^3]), "
                        f"got {type(value).__name__} {value!r}: pass Material(E=..., nu=...)")


# ---------------------------------------------------------------- the compressible neo-Hookean law
# one law for the FEM term's kernels, its numpy twin and the reference's elements; each function
# takes scalars or arrays, from Python or from compiled code

@njit(cache=True)
def neohookean_energy(I1, lnJ, lam, mu):
    """W = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2 [J/m^3] of the deformation gradient F with
    I1 = F:F and ln J = ln det F (lam = 0: its deviatoric part)."""
    return 0.5 * mu * (I1 - 3.0) - mu * lnJ + 0.5 * lam * lnJ * lnJ


@njit(cache=True)
def neohookean_stress(lnJ, lam, mu):
    """(a, b) of its first Piola stress P = dW/dF = a F + b F^-T: (mu, lam ln J - mu)."""
    return mu, lam * lnJ - mu
