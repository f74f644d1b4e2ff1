"""`pbcm problem new NAME`: the commented template of a problem's TOML (``pbcm run --problem``
runs it)."""
import os
import sys
from pathlib import Path

from .common import UsageError


def add(sub):
    """The command's parser."""
    p = sub.add_parser("problem", help="write the template of a problem of your own",
                       description="A problem of your own: a mesh file, its material, "
                                   "boundary conditions and measures, declared in a TOML file "
                                   "that `pbcm run --problem FILE` runs as a case.")
    actions = p.add_subparsers(dest="action", required=True, parser_class=type(p))
    new = actions.add_parser("new", help="write a commented template TOML (every key "
                                         "explained) that runs as is on the example mesh",
                             description="Write a commented template of a problem's TOML. As "
                                         "written it compresses the example cylinder "
                                         "(examples/cylinder) between sliding ends; edit it "
                                         "for your mesh.")
    new.add_argument("name", help="the problem's name (its output folder "
                                  "reports/problems/NAME)")
    new.add_argument("--out", metavar="FILE", help="the file to write (default NAME.toml); an "
                                                   "existing file is never overwritten")
    new.set_defaults(func=run)


def run(args):
    from ..library.problem import EXAMPLE_MESH, template
    from ..library.problem.spec import check_name
    check_name(args.name, lambda what: UsageError(f"NAME {what}"))
    out = Path(args.out) if args.out else Path(f"{args.name}.toml")
    if out.exists():
        raise UsageError(f"{out} exists; give another --out, or remove it first")
    if not out.parent.is_dir():
        raise UsageError(f"--out {out}: the folder {out.parent} does not exist; create it "
                         "first")
    out.write_text(template(args.name, _mesh_path(EXAMPLE_MESH, out), out.as_posix()))
    print(f"{out}: the template of the problem {args.name}; run it with "
          f"`pbcm run --problem {out} --quick`")
    if not EXAMPLE_MESH.is_file():      # an installation without the checkout's examples
        print(f"pbcm: warning: the example mesh {EXAMPLE_MESH} is not installed (a checkout "
              f"of pbcm has it): set [mesh] file in {out} to your mesh", file=sys.stderr)
    return 0


def _mesh_path(mesh, toml):
    """``mesh`` as the TOML at ``toml`` refers to it: relative to its folder where the two
    share a folder below the root (a checkout), else absolute."""
    mesh, folder = mesh.resolve(), toml.parent.resolve()
    try:
        shared = Path(os.path.commonpath([mesh, folder]))
    except ValueError:           # another drive
        return mesh
    return mesh if shared == Path(shared.anchor) else Path(os.path.relpath(mesh, folder))
