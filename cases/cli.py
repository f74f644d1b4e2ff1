"""The ``pbcm`` command line."""
import argparse
import sys

import model
from model.errors import PbcmError
from model.mesh import SCHEMES, box, read


def _mesh_command(args):
    if args.source == "cube":
        # millimetres at the edge, metres inside
        mesh = box(args.n, args.n, args.n, *(3 * [args.size * 1e-3]), scheme=args.scheme,
                   seed=args.seed)
        title = f"cube n={args.n} size={args.size:g} mm scheme={args.scheme}"
    else:
        mesh = read(args.source)
        title = args.source
    q = mesh.quality()
    print(title)
    print(f"  nodes               {q['nodes']}")
    print(f"  tetrahedra          {q['tets']}")
    print(f"  volume              {q['volume'] * 1e9:.6g} mm^3")
    print(f"  radius ratio        min {q['radius_ratio_min']:.3f}  mean {q['radius_ratio_mean']:.3f}"
          "  (1 = regular, 0 = sliver)")
    print(f"  dihedral angles     min {q['dihedral_min_deg']:.1f} deg  "
          f"max {q['dihedral_max_deg']:.1f} deg")
    if mesh.reoriented:
        print(f"  re-oriented         {mesh.reoriented} negatively ordered tetrahedra")
    return 0


def parser():
    p = argparse.ArgumentParser(prog="pbcm", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"pbcm {model.__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    m = sub.add_parser("mesh", help="print node/tetrahedron counts and quality of a mesh",
                       description="Mesh statistics: 'pbcm mesh FILE' for any meshio-readable "
                                   "file, or 'pbcm mesh cube [--n N --size MM --scheme S]'.")
    m.add_argument("source", help="a mesh file, or 'cube'")
    m.add_argument("--n", type=int, default=5, help="nodes per side (cube), default 5")
    m.add_argument("--size", type=float, default=32.0, help="side in mm (cube), default 32")
    m.add_argument("--scheme", choices=SCHEMES, default="five", help="cube tetrahedralisation")
    m.add_argument("--seed", type=int, default=0, help="seed of the 'unstructured' scheme")
    m.set_defaults(func=_mesh_command)
    return p


def main(argv=None):
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except PbcmError as exc:
        print(f"pbcm: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
