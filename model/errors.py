"""Errors raised by the model. Each message names what is wrong and what to do."""


class PbcmError(Exception):
    """Base class of every error the suite raises on purpose."""


class MeshError(PbcmError, ValueError):
    """The mesh is unusable: bad coordinates, indices, or degenerate tetrahedra."""


class MaterialError(PbcmError, ValueError):
    """A material parameter is outside its physical range."""


class ModelError(PbcmError, ValueError):
    """A model, term or boundary condition was specified wrongly."""


class CalibrationDroppedError(ModelError):
    """Every fitted constant came out 0: the fitted terms add nothing on this mesh."""


class DegenerateTetError(PbcmError, FloatingPointError):
    """A tetrahedron inverted or flattened during a computation."""

    def __init__(self, message, tets=()):
        super().__init__(message)
        self.tets = tuple(int(t) for t in tets)


class BlowUpError(PbcmError, FloatingPointError):
    """Time integration became unstable."""

    def __init__(self, message, step, time, dt_suggested):
        super().__init__(message)
        self.step, self.time, self.dt_suggested = step, time, dt_suggested


class ConvergenceError(PbcmError, RuntimeError):
    """An iterative solve did not reach its stated tolerance."""
