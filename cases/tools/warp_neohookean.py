"""The fem-neohookean tetrahedron (model/terms/fem.py) as a Warp kernel, run on the CPU: the
same law in float64, so that `pbcm bench` compares two compilers on one computation. Imported
only where warp-lang is installed (cases.tools.engines)."""
import numpy as np
import warp as wp

wp.config.quiet = True


@wp.kernel
def neohookean_forces(x: wp.array(dtype=wp.vec3d), tets: wp.array2d(dtype=wp.int32),
                      Dinv: wp.array(dtype=wp.mat33d), vol0: wp.array(dtype=wp.float64),
                      lam: wp.float64, mu: wp.float64, f: wp.array(dtype=wp.vec3d)):
    """P = mu (F - F^-T) + lam ln J F^-T, H = -V0 P Dm^-T: columns are the forces on 1..3."""
    t = wp.tid()
    i, j, k, l = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]
    x0 = x[i]
    F = wp.matrix_from_cols(x[j] - x0, x[k] - x0, x[l] - x0) * Dinv[t]
    FinvT = wp.transpose(wp.inverse(F))
    P = mu * (F - FinvT) + lam * wp.log(wp.determinant(F)) * FinvT
    H = -vol0[t] * P * wp.transpose(Dinv[t])
    f1 = wp.vec3d(H[0, 0], H[1, 0], H[2, 0])
    f2 = wp.vec3d(H[0, 1], H[1, 1], H[2, 1])
    f3 = wp.vec3d(H[0, 2], H[1, 2], H[2, 2])
    wp.atomic_add(f, i, -(f1 + f2 + f3))
    wp.atomic_add(f, j, f1)
    wp.atomic_add(f, k, f2)
    wp.atomic_add(f, l, f3)


class WarpNeoHookean:
    """Forces of a built fem-neohookean term at positions x, by Warp on the CPU."""

    def __init__(self, term, x):
        mesh = term.mesh
        self.n = mesh.n_tets
        self.args = [wp.array(np.asarray(x, dtype=np.float64), dtype=wp.vec3d, device="cpu"),
                     wp.array(mesh.tets.astype(np.int32), dtype=wp.int32, device="cpu"),
                     wp.array(term.Dinv, dtype=wp.mat33d, device="cpu"),
                     wp.array(term.vol0, dtype=wp.float64, device="cpu"),
                     wp.float64(term.lam), wp.float64(term.mu)]
        self.f = wp.zeros(mesh.n_nodes, dtype=wp.vec3d, device="cpu")

    def __call__(self):
        self.f.zero_()
        wp.launch(neohookean_forces, dim=self.n, inputs=self.args, outputs=[self.f],
                  device="cpu")
        wp.synchronize_device("cpu")
        return self.f
