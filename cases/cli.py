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


def _choose(kind, given, valid):
    """The names asked for, or a one-line error listing the valid ones (exit status 2)."""
    if given is None:
        return tuple(valid)
    bad = [g for g in given if g not in valid]
    if bad:
        raise UsageError(f"unknown {kind} {', '.join(bad)}; valid: {', '.join(valid)}")
    return tuple(given)


class UsageError(Exception):
    pass


def _case(name):
    from .registry import CASES
    if name not in CASES:
        raise UsageError(f"unknown case {name}; valid: {', '.join(CASES)}")
    return CASES[name]


def _config(case, args):
    kw = {"meshes": _choose("mesh", args.meshes, case.MESHES),
          "bcs": _choose("boundary condition", args.bcs, case.BCS),
          "models": _choose("model", args.models, case.MODELS)}
    for k in ("E", "nu", "rho", "shear_scale"):
        if getattr(args, k) is not None:
            kw[k] = getattr(args, k)
    if args.quick:
        if args.meshes is None:
            kw.pop("meshes")
        return case.Config.quick_config(**kw)
    return case.Config(**kw)


def _run_case(name, args, out):
    from .report import write_case
    case = _case(name)
    cfg = _config(case, args)
    runs, fields = case.run(cfg)
    path = write_case(out, name, cfg, runs, fields)
    print(f"{name}: {len(runs)} runs written to {path}")
    return path


def _list_command(args):
    from .registry import CASES
    for name, case in CASES.items():
        print(f"{name}: {case.__doc__.strip().splitlines()[0]}")
        print(f"  meshes: {', '.join(case.MESHES)}")
        print(f"  bcs:    {', '.join(case.BCS)}")
        print(f"  models: {', '.join(case.MODELS)}")
    return 0


def _run_command(args):
    from pathlib import Path
    _run_case(args.case, args, Path(args.out) if args.out else Path("reports") / args.case)
    return 0


def _report_command(args):
    from pathlib import Path
    from .registry import CASES
    from .report import write_index
    root = Path(args.out or "reports")
    for name in CASES:
        _run_case(name, args, root / name)
    write_index(root, list(CASES))
    print(f"index written to {root / 'index.md'} and {root / 'index.html'}")
    return 0


def _check_command(args):
    from .thresholds import CheckError, check, load, measured
    try:
        rows, status = check(load(args.thresholds), measured(args.metrics))
    except CheckError as exc:
        print(f"pbcm check: error: {exc}", file=sys.stderr)
        return 2
    print(f"{'metric':<66} {'measured':>11} {'bound':>11} {'margin':>8}  result")
    for b, v, ok in rows:
        name = f"{b.case}/{b.mesh}/{b.bc}/{b.model}/{b.metric}"
        sign = "<=" if b.direction == "max" else ">="
        print(f"{name:<66} {v:>11.5g} {sign}{b.limit:>9.5g} {b.margin(v):>8.1%}  "
              f"{'PASS' if ok else 'FAIL'}")
    failed = [r for r in rows if not r[2]]
    print(f"{len(rows) - len(failed)} passed, {len(failed)} failed")
    for b, v, _ in failed:
        print(f"FAIL {b.metric} of {b.case}/{b.mesh}/{b.bc}/{b.model}: {v:.6g} "
              f"{'>' if b.direction == 'max' else '<'} {b.limit:.6g}")
    return status


def _bless_command(args):
    import tempfile
    from pathlib import Path
    from .registry import CASES
    from .thresholds import CheckError, bless, dumps, load, measured
    path = Path(args.thresholds)
    if args.metrics:
        folder = Path(args.metrics)
    else:  # a fresh run of every case, in the mode asked
        folder = Path(tempfile.mkdtemp(prefix="pbcm-bless-"))
        for name in CASES:
            _run_case(name, args, folder / name)
    try:
        values = measured(folder)
        old = load(path) if path.exists() else []
    except CheckError as exc:
        print(f"pbcm bless: error: {exc}", file=sys.stderr)
        return 2
    modes = {k[1] for k in values}
    keep = [b for b in old if b.mode not in modes]
    new, changes = bless(values, [b for b in old if b.mode in modes], rtol=args.margin)
    path.write_text(dumps(sorted(keep + new, key=lambda b: b.key)) + "\n")
    for line in changes or ["no change"]:
        print(line)
    print(f"{len(new)} bounds for mode {', '.join(sorted(modes))} written to {path}")
    return 0


def _selection(p):
    p.add_argument("--models", nargs="+", help="model presets (default: all)")
    p.add_argument("--meshes", nargs="+", help="meshes (default: all; --quick: five six)")
    p.add_argument("--bcs", nargs="+", help="boundary conditions (default: all)")
    p.add_argument("--quick", action="store_true",
                   help="five and six meshes, one P2 refinement, fewer timing repeats")
    p.add_argument("--E", type=float, help="Young's modulus [Pa] (default 10e3)")
    p.add_argument("--nu", type=float, help="Poisson's ratio (default 0.45)")
    p.add_argument("--rho", type=float, help="density [kg/m^3] (default 1000)")
    # test-only: scale the shear term, to prove that the error gate catches a worse model
    p.add_argument("--shear-scale", type=float, default=None, help=argparse.SUPPRESS)


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
    ls = sub.add_parser("list", help="list the cases with their meshes, conditions and models")
    ls.set_defaults(func=_list_command)
    r = sub.add_parser("run", help="run one case and write its report folder")
    r.add_argument("case", help="a case name (see pbcm list)")
    r.add_argument("--out", help="output folder (default reports/CASE)")
    _selection(r)
    r.set_defaults(func=_run_command)
    rep = sub.add_parser("report", help="run every case and write reports/ with its index")
    rep.add_argument("--out", help="output folder (default reports)")
    _selection(rep)
    rep.set_defaults(func=_report_command)
    c = sub.add_parser("check", help="compare the latest metrics with thresholds.toml "
                       "(exit 0 pass, 1 fail, 2 missing or malformed)")
    c.add_argument("--metrics", default="reports", help="a metrics.json or a folder of them "
                   "(default reports)")
    c.add_argument("--thresholds", default="thresholds.toml")
    c.set_defaults(func=_check_command)
    b = sub.add_parser("bless", help="rewrite the bounds from a fresh run and print what changed")
    b.add_argument("--margin", type=float, default=0.1, help="relative tolerance (default 0.1)")
    b.add_argument("--thresholds", default="thresholds.toml")
    b.add_argument("--metrics", help="bless these metrics instead of a fresh run")
    _selection(b)
    b.set_defaults(func=_bless_command)
    return p


def main(argv=None):
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except UsageError as exc:
        print(f"pbcm: error: {exc}", file=sys.stderr)
        return 2
    except PbcmError as exc:
        print(f"pbcm: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
