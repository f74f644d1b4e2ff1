"""Time and peak memory of a large P1 reference solve (the README quotes its output).

    python -m cases.fem_scaling [--n 70]    # n nodes per side of the unit cube: 3 n^3 unknowns
"""
import argparse
import resource
import time

import numpy as np

from model.mesh import cube
from reference import linear


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=70)
    a = p.parse_args(argv)
    t0 = time.perf_counter()
    mesh = cube(a.n, 1.0, "six")
    bc = {i: (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("y", 0.0)}
    bc.update({i: (0.0, -0.01, 0.0) for i in mesh.nodes_on_plane("y", 1.0)})
    t1 = time.perf_counter()
    r = linear.solve(mesh, 10e3, 0.3, bc, element="P1")
    t2 = time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
    print(f"P1, {mesh.n_nodes} nodes, {mesh.n_tets} tetrahedra, {r.info['dofs']} unknowns, "
          f"solver {r.info['solver']} ({r.info['iterations']} iterations): mesh {t1 - t0:.1f} s, "
          f"solve {t2 - t1:.1f} s, peak memory {peak:.1f} GiB, "
          f"max |u| {np.abs(r.u).max():.4g} m")


if __name__ == "__main__":
    main()
