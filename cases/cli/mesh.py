"""`pbcm mesh`: node and tetrahedron counts and quality of a mesh file or a cube."""
from pathlib import Path

from model.mesh import SCHEMES, box, read
from model.units import MM
from ..library.common import CUBE_MM
from .common import UsageError, number

def add(sub):
    """The command's parser."""
    m = sub.add_parser("mesh", help="print node/tetrahedron counts and quality of a mesh",
                       description="Mesh statistics: 'pbcm mesh FILE' for any meshio-readable "
                                   "file, or 'pbcm mesh cube [--n N --size MM --scheme S]'.")
    m.add_argument("source", help="a mesh file, or 'cube'")
    m.add_argument("--n", type=number("--n", "an integer >= 2 (nodes per side)", low=2,
                                       integer=True, open_low=False),
                   default=5, help="nodes per side (cube), default 5")
    m.add_argument("--size", type=number("--size", "a side length in mm, a number > 0", low=0),
                   default=CUBE_MM, help=f"side in mm (cube), default {CUBE_MM:g}")
    m.add_argument("--scheme", choices=SCHEMES, default="five", help="cube tetrahedralisation")
    m.add_argument("--seed", type=int, default=0, help="seed of the 'unstructured' scheme")
    m.set_defaults(func=run)


def run(args):
    if args.source != "cube" and not Path(args.source).is_file():
        raise UsageError(f"mesh file {args.source} does not exist (or is not a file); give a "
                         "mesh file or 'cube'")
    if args.source == "cube":
        # millimetres at the edge, metres inside
        mesh = box(args.n, args.n, args.n, *(3 * [args.size * MM]), scheme=args.scheme,
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
    for line in mesh.warnings():
        print(f"  warning: {line}")
    return 0

