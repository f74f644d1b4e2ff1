"""Time and peak memory of a large P1 reference solve, and the direct/AMG crossover that
sets ``reference.solvers.DIRECT_MAX_DOFS``; docs/architecture.md says where it is used.

    python -m cases.tools.fem_scaling [--n 70]    # n nodes per side of the unit cube: 3 n^3 unknowns
    python -m cases.tools.fem_scaling --solvers   # direct and AMG-CG on the same P1 and P2 systems
"""
import argparse
import resource
import time

import numpy as np

from model.mesh import cube
from reference import linear
from ..framework import DEFAULT_MATERIAL




def cube_problem(n):
    """The unit cube, clamped at y = 0 and pushed 1 % at y = 1 (n nodes per side)."""
    mesh = cube(n, 1.0, "six")
    bc = {i: (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("y", 0.0)}
    bc.update({i: (0.0, -0.01, 0.0) for i in mesh.nodes_on_plane("y", 1.0)})
    return mesh, bc


def solvers(sizes=((13, "P1"), (7, "P2"), (17, "P1"), (9, "P2"), (21, "P1"), (11, "P2"),
                   (25, "P1"), (13, "P2"), (29, "P1"), (15, "P2"))):
    """Wall time of the direct solver and of AMG-CG on the same cube problems, in one
    process, alternating, each the best of two runs."""
    print(f"{'element':>7} {'unknowns':>9} {'direct [s]':>11} {'AMG-CG [s]':>11} {'ratio':>6}")
    for n, element in sizes:
        mesh, bc = cube_problem(n)
        best = {"direct": float("inf"), "amg": float("inf")}
        for _ in range(2):
            for solver in best:
                t0 = time.perf_counter()
                r = linear.solve(mesh, DEFAULT_MATERIAL, bc, element=element, solver=solver)
                best[solver] = min(best[solver], time.perf_counter() - t0)
        print(f"{element:>7} {r.info['dofs']:>9} {best['direct']:>11.2f} {best['amg']:>11.2f} "
              f"{best['direct'] / best['amg']:>6.2f}", flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=70)
    p.add_argument("--solvers", action="store_true",
                   help="time direct against AMG-CG on P1 and P2 cubes instead")
    a = p.parse_args(argv)
    if a.solvers:
        return solvers()
    t0 = time.perf_counter()
    mesh, bc = cube_problem(a.n)
    t1 = time.perf_counter()
    r = linear.solve(mesh, DEFAULT_MATERIAL, bc, element="P1")
    t2 = time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
    print(f"P1, {mesh.n_nodes} nodes, {mesh.n_tets} tetrahedra, {r.info['dofs']} unknowns, "
          f"solver {r.info['solver']} ({r.info['iterations']} iterations): mesh {t1 - t0:.1f} s, "
          f"solve {t2 - t1:.1f} s, peak memory {peak:.1f} GiB, "
          f"max |u| {np.abs(r.u).max():.4g} m")


if __name__ == "__main__":
    main()
