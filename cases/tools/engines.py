"""Optional engines that `pbcm bench` times beside pbcm's kernels, on the same meshes.

Each is used only where its package is installed (``pip install "pbcm[engines]"``); its
bench row says "not installed" otherwise. What is timed is one evaluation of the
tetrahedral forces on the CPU, as pbcm's force kernels are timed.

* ``warp-lang``: pbcm's fem-neohookean law written as a Warp kernel (cases.tools.warp_neohookean),
  float64: the same computation through another compiler (its forces equal ours; tested).
* ``newton``: the Newton engine's own tetrahedral FEM forces (its semi-implicit solver's
  ``eval_tetrahedra``: the stable neo-Hookean of Smith et al. 2018, float32, on a model built
  by ``ModelBuilder.add_soft_mesh``). Building a Newton model loops in Python per element, so
  it is timed up to ``NEWTON_MAX_TETS`` tetrahedra.
"""
import importlib.util

NEWTON_MAX_TETS = 120_000


class Engine:
    """An optional engine: its package, what it computes, and a timer factory."""

    name = ""
    module = ""
    law = ""
    max_tets = None

    def installed(self):
        return importlib.util.find_spec(self.module) is not None

    def force_evaluation(self, pm, x):
        """A callable doing one force evaluation at x on ``pm``'s mesh and material (``pm``
        a built fem-neohookean model)."""
        raise NotImplementedError


class Warp(Engine):
    name, module = "warp-lang", "warp"
    law = "pbcm's fem-neohookean as a Warp kernel (float64, CPU)"

    def force_evaluation(self, pm, x):
        from .warp_neohookean import WarpNeoHookean
        return WarpNeoHookean(pm.terms[0], x)


class Newton(Engine):
    name, module = "newton", "newton"
    law = "Newton's eval_tetrahedra: stable neo-Hookean, Smith et al. 2018 (float32, CPU)"
    max_tets = NEWTON_MAX_TETS

    def force_evaluation(self, pm, x):
        import warp as wp
        wp.config.quiet = True
        import newton
        try:    # not public API: where Newton keeps its tetrahedral forces (version 1.8)
            from newton._src.solvers.semi_implicit.kernels_particle import (
                eval_tetrahedra_forces)
        except ImportError as exc:
            raise RuntimeError("this newton version keeps its tetrahedral forces elsewhere: "
                               f"{exc}") from None
        mesh, mat = pm.mesh, pm.material
        b = newton.ModelBuilder()
        b.add_soft_mesh(pos=(0.0, 0.0, 0.0), rot=wp.quat_identity(), scale=1.0,
                        vel=(0.0, 0.0, 0.0), vertices=[tuple(p) for p in x],
                        indices=mesh.tets.ravel().tolist(), density=mat.rho, k_mu=mat.G,
                        k_lambda=mat.lam, k_damp=0.0)
        model = b.finalize(device="cpu")
        state, control = model.state(), model.control()
        f = wp.zeros(model.particle_count, dtype=wp.vec3, device="cpu")

        def once():
            f.zero_()
            eval_tetrahedra_forces(model, state, control, f)
            wp.synchronize_device("cpu")
            return f
        return once


ENGINES = {e.name: e for e in (Newton(), Warp())}
