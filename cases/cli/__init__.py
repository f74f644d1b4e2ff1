"""The ``pbcm`` command line: one module per command, each with ``add(sub)`` (its parser)
and ``run(args)``; ``common`` holds what they share and ``pipeline`` the main job (every case,
then every study).

Every argument is checked before any computing starts (names, numbers, output paths); errors,
and faults of the environment (a full disk, a permission), are one line ``pbcm: error: ...``
with exit status 2, Ctrl-C is one line with exit status 130.
"""
import argparse
import os
import sys

import model
import model.simulators
import model.terms
from model.errors import PbcmError
from ..running import stop
from . import (bench, bless, cache, check, fit, index, listing, mesh, problem, report, run,
               sweep)
from .common import Parser, UsageError

DESCRIPTION = """\
pbcm measures how far the particle soft-body model of Nakagawa et al. is from the continuum:
it runs cases against FEM references, writes reports, and gates CI on gold values."""
COMMANDS = (mesh, listing, run, problem, report, bench, fit, index, check, sweep, bless, cache)


def parser():
    p = Parser(prog="pbcm", description=DESCRIPTION,
               formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"pbcm {model.__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS:
        command.add(sub)
    return p


def main(argv=None):
    """Run the command line on ``argv``; return the exit status (also for --help and for
    argument errors, which argparse would raise as SystemExit)."""
    with stop.handling():   # staging folders are removed on SIGTERM as on Ctrl-C
        return _main(argv)


def console(argv=None):
    """The ``pbcm`` process: :func:`main`, and after a stop no report from a finaliser the
    signal cut off (the process is ending; its one line has been printed)."""
    status = main(argv)
    if status in (130, 143):
        stop.quiet_finalisers()
    return status


def _kept(args):
    """What an interrupted command leaves behind, for its last line."""
    if getattr(args, "command", None) == "sweep":
        return ("every run finished is kept in the sweep's runs/ folder: rerun the same "
                "command to resume")
    return "output folders hold what they held before the unfinished one"


def _main(argv):
    args = None
    try:
        try:
            args = parser().parse_args(argv)
        except SystemExit as exc:
            return exc.code if isinstance(exc.code, int) else 2
        for f in getattr(args, "term", []):   # before any model name is checked
            model.terms.add_user_file(f)
        for f in getattr(args, "model_file", []):
            model.simulators.add_user_file(f)
        status = args.func(args)
        stop.checkpoint()   # a signal whose exception a library swallowed still stops us
        return status
    except (UsageError, PbcmError) as exc:
        print(f"pbcm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"\npbcm: interrupted; {_kept(args)}", file=sys.stderr)
        return 130
    except stop.Terminated:
        print(f"\npbcm: terminated; {_kept(args)}", file=sys.stderr)
        return 143
    except BrokenPipeError:   # `pbcm check | head`: the reader left; say nothing more
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:    # the environment: a full disk, a permission, a vanished mount
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"pbcm: error: {where}{exc.strerror or exc} (errno {exc.errno}); free space, fix "
              "the permission or choose another --out, then run the command again (output "
              "folders hold what they held before)", file=sys.stderr)
        return 2



if __name__ == "__main__":
    sys.exit(console())
