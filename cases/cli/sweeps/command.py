"""``pbcm sweep SPEC [--scheduler ADDRESS] [--workers N] [--out DIR] [--serial]
[--retry-failed]``: everything is checked (the spec, the flags, the output folder) before the
first task starts."""
import json
from pathlib import Path

from model import PbcmError
from ...running.output import SWEEP_MARK as MARK, OutputError, owned, writable_folder, write_atomic
from ...registry import CASES
from ...running.store import RunStore
from . import SHIPPED
from . import engine, report, spec as specs, table



class SweepUsageError(PbcmError):
    """A flag of ``pbcm sweep`` that cannot be honoured: it says what to give instead."""


def spec_path(given):
    """The spec file: ``given`` itself, or the shipped cases/cli/sweeps/<given>.toml."""
    path = Path(given)
    if not path.is_file() and (SHIPPED / f"{given}.toml").is_file():
        return SHIPPED / f"{given}.toml"
    return path


def output_folder(given, spec_file):
    """The checked output folder (default reports/sweeps/<spec name>): empty, new or a
    sweep's, and writable."""
    out = Path(given) if given else Path("reports") / "sweeps" / Path(spec_file).stem
    if not owned(out, MARK):
        raise OutputError(f"--out {out} holds files that are not a sweep's (no {MARK}); give "
                          "an empty folder, a new one, or an earlier sweep's folder to resume")
    return writable_folder(out)


def run(args):
    path = spec_path(args.spec)
    spec = specs.load(path, CASES)
    if path.resolve().parent == SHIPPED.resolve():   # the same words however it was named
        spec.source = f"cases/cli/sweeps/{path.name}"
    if args.scheduler and (args.workers or args.serial):
        raise SweepUsageError("--scheduler runs on that cluster's workers: drop --workers and "
                              "--serial (start more workers with `dask worker ADDRESS`)")
    if spec.table == "parquet" and not table.parquet_available():
        raise SweepUsageError(f"{path} asks for table = \"parquet\" but pyarrow is not "
                              "installed; pip install pyarrow, or set table = \"csv\"")
    if args.plan:
        return _plan(spec, Path(args.out) if args.out else
                     Path("reports") / "sweeps" / path.stem, args.retry_failed)
    out = output_folder(args.out, path)
    write_atomic(out / MARK, json.dumps(
        {"spec": spec.source, "title": spec.title, "cases": list(spec.cases),
         "quick": spec.quick, "static_only": spec.static_only, "fixed": spec.fixed,
         "axes": spec.axes, "metrics": list(spec.metrics)}, indent=1) + "\n")
    outcome = engine.run(spec, CASES, out, scheduler=args.scheduler, workers=args.workers,
                         serial=args.serial, retry_failed=args.retry_failed,
                         store=RunStore(enabled=not args.no_cache))
    first = engine.PARAMS + ("run_key", "status", "error") + tuple(spec.fixed)
    path_table = table.write(outcome.rows, out, spec.table, first)
    for other in ("table.csv", "table.parquet"):      # one table: the other is an old one
        if other != path_table.name:
            (out / other).unlink(missing_ok=True)
    print(f"sweep {spec.title}: {len(outcome.rows)} runs ({outcome.computed} computed, "
          f"{outcome.found} found from an earlier run), {len(outcome.failed)} failed")
    report.write(spec, outcome.rows, out, CASES, path_table)
    print(f"table {path_table}; report {out / 'report.md'}")
    if outcome.lost:
        print(f"pbcm: {outcome.lost} runs were lost with their workers; rerun the same command "
              "to compute them")
        return 1
    return 0


def _plan(spec, out, retry_failed):
    """Print what the sweep would compute, per case, without computing or writing."""
    units, todo = engine.plan(spec, CASES, table.RunStore(out), retry_failed)
    for name in spec.cases:
        mine = [u for u in units if u.case == name]
        runs = sum(len(u.models) for u in mine)
        left = sum(len(u.models) for u in todo if u.case == name)
        print(f"{name}: {len(mine)} tasks, {runs} runs, {left} to compute "
              f"({runs - left} found in {out / 'runs'})")
    print(f"in all: {len(todo)} tasks to run, {sum(len(u.models) for u in todo)} runs; swept: "
          + (", ".join(f"{a} ({len(spec.axes[a])})" for a in spec.swept()) or "nothing"))
    return 0


__all__ = ["run", "spec_path", "output_folder"]
