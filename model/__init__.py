"""The particle-based continuum model of Nakagawa et al. and its mass-spring baseline.

>>> from model import Material, build
>>> from model.mesh import cube
>>> pm = build("pbcm-variational", cube(5, 0.032, "five"), Material(E=10e3, nu=0.45))
>>> bool(abs(pm.forces(pm.mesh.points)).max() < 1e-12)     # no force at rest
True
>>> round(pm.info["shear_c"], 4)                            # calibrated once per mesh
0.1136
"""
from .material import Material
from .errors import (PbcmError, MeshError, MaterialError, ModelError, DegenerateTetError,
                     BlowUpError, ConvergenceError, CalibrationDroppedError)

__version__ = "0.1.0"


def __getattr__(name):
    # the physics loads on first use, so that importing the material or the mesh (what the
    # references take from the model) loads none of it
    if name == "ParticleModel":
        from .system import ParticleModel
        return ParticleModel
    if name == "PRESETS":
        from .presets import PRESETS
        return PRESETS
    raise AttributeError(f"module 'model' has no attribute {name!r}")


def build(model, mesh, material, threads=1, **term_params):
    """A :class:`ParticleModel` from a preset name, a composed spec such as
    ``"shear(reading=variational, c=auto) + normal_edge(c=auto) + volume"`` (see
    :mod:`model.compose`), or a list of ``(term, params)``.

    ``term_params`` override parameters per term name, e.g.
    ``build("pbcm-variational", mesh, mat, shear={"scale": 0.5})``. ``threads`` > 1 runs the
    terms that have a threaded kernel (the shear readings, the volume term, the FEM baselines) on that many of numba's threads,
    with forces equal bit for bit to the serial ones.

    A name registered in ``model.simulators`` (``newton-xpbd``, ``newton-vbd``,
    ``newton-semi-implicit``, a user's ``--model-file``), alone and with its settings
    (``newton-vbd(iterations=20)``), builds that simulator instead (a
    ``model.simulators.Simulator``, the contract every model satisfies).
    """
    if isinstance(model, str):
        from .compose import label, parse, simulator
        sim = simulator(model)
        if sim:                       # a simulator pbcm does not integrate (model.simulators)
            if term_params:
                raise ModelError(f"model {model!r} is a simulator: it has no terms to set "
                                 f"({', '.join(term_params)})")
            from .simulators import make_simulator
            return make_simulator(sim[0], mesh, material, label(model), **sim[1])
        name, terms = label(model), parse(model)
    else:
        name, terms = "custom", list(model)
    unknown = set(term_params) - {t for t, _ in terms}
    if unknown:
        raise ModelError(f"parameters given for term(s) {', '.join(sorted(unknown))} that "
                         f"model {name!r} does not have ({', '.join(t for t, _ in terms)})")
    terms = [(t, {**p, **term_params.get(t, {})}) for t, p in terms]
    from .presets import IMPLICIT_STEP
    from .system import ParticleModel
    return ParticleModel(mesh, material, terms, name=name, threads=threads,
                         implicit_dt=IMPLICIT_STEP.get(name))


__all__ = ["Material", "build", "PRESETS", "ParticleModel", "PbcmError", "MeshError",
           "MaterialError", "ModelError", "DegenerateTetError", "BlowUpError",
           "ConvergenceError", "CalibrationDroppedError"]
