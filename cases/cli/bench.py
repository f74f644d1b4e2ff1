"""`pbcm bench`: what every model costs."""
import shutil
from pathlib import Path

from ..running.output import StagedFolder
from .common import UsageError, add_term_files, chosen_models, number
import model

def add(sub):
    """The command's parser."""
    bn = sub.add_parser(
        "bench", help="time every model: force evaluation, RK4 step, calibration, memory",
        description="Time every preset on cubes of about 1e2 to 1e6 tetrahedra (--quick: 1e2 "
                    "and 1e3): ns per tetrahedron per force evaluation, microseconds per RK4 "
                    "step, calibration seconds, memory, and the step ratios to msm and "
                    "fem-linear as medians of per-round ratios (models timed round-robin). "
                    "Writes bench.json, bench.md and step_time.png (the paper's Figure 2).")
    bn.add_argument("--out", default="reports/bench", help="output folder (default reports/bench)")
    bn.add_argument("--quick", action="store_true", help="sizes 1e2 and 1e3, three rounds")
    bn.add_argument("--sizes", nargs="+",
                    type=number("--sizes", "tetrahedron counts, numbers >= 5", low=4),
                    help="approximate tetrahedron counts (default 1e2 1e3 1e4 1e5 1e6)")
    bn.add_argument("--rounds", type=number("--rounds", "an integer >= 1", low=0, integer=True),
                    default=7, help="timing rounds (default 7)")
    bn.add_argument("--models", nargs="+", help="model presets or composed models "
                                                "(default: every preset)")
    bn.add_argument("--merge", action="store_true",
                    help="add the rows of --models to the bench.json in --out (timed against "
                         "the baselines in this process) and keep every other row")
    bn.add_argument("--family", action="store_true",
                    help="time only the real-time family (the paper's push on cubes of 320 to "
                         "1.1e5 tetrahedra, read by `pbcm run realtime`) and put its rows into "
                         "the bench.json in --out, keeping every other row")
    bn.add_argument("--rewrite", action="store_true",
                    help="draw bench.md and step_time.png again from the bench.json in --out "
                         "without timing anything (after a change of the report's code)")
    bn.add_argument("--device", help="also time the Warp kernels of the covered presets on this "
                                      "Warp device (cpu, cuda, cuda:0 ...), float32 and "
                                      "float64; needs warp-lang (default: not timed)")
    add_term_files(bn)
    bn.set_defaults(func=run)


def check_device(device):
    """A UsageError unless warp-lang is installed and has the device ``device``."""
    import importlib.util
    if importlib.util.find_spec("warp") is None:
        raise UsageError(f"--device {device} times Warp kernels: install warp-lang "
                         "(pip install warp-lang) or drop --device")
    from ..tools.warp_forces import check_device as warp_device
    try:
        warp_device(device)
    except ValueError as exc:
        raise UsageError(f"--device {device}: {exc}") from None


def run(args):
    from ..reporting import costs
    from ..tools import bench
    models = chosen_models(args.models, list(model.PRESETS))
    sizes = args.sizes or (bench.QUICK_SIZES if args.quick else bench.SIZES)
    # checked before any timing starts
    if args.device is not None:
        check_device(args.device)
    old = None
    if args.rewrite:
        if args.family or args.merge or args.models or args.sizes or args.device or args.quick:
            raise UsageError("--rewrite times nothing: drop --family, --merge, --models, "
                             "--sizes, --device and --quick, or drop --rewrite")
        where = Path(args.out) / costs.FILE
        if not where.is_file():
            raise UsageError(f"--rewrite draws the report from {where}, which does not exist; "
                             "run `pbcm bench` first")
        data = costs.read(where)
        with StagedFolder(Path(args.out), mark=costs.FILE) as out:
            bench.write(data, out.path)
            keep_folders(Path(args.out), out.path)
            print(f"bench rewritten from its bench.json in {out.commit()}")
        return 0
    if args.family and (args.merge or args.models or args.sizes or args.device):
        raise UsageError("--family times the real-time family alone: drop --merge, --models, "
                         "--sizes and --device, or drop --family")
    if args.merge or args.family:
        if not models and not args.family:
            raise UsageError("--merge adds the rows of the --models given to a bench.json: "
                             "name the models to time")
        where = Path(args.out) / costs.FILE
        if not where.is_file():
            flag = "--family" if args.family else "--merge"
            raise UsageError(f"{flag} needs an existing {where}; run `pbcm bench` first or "
                             f"drop {flag}")
        old = costs.read(where)
        models = tuple(m for m in models or () if m not in bench.BASELINES)
    with StagedFolder(Path(args.out), mark=costs.FILE) as out:
        if args.family:
            from ..tools import realtime_bench
            bench.write({**old, "realtime_machine": bench.machine(),
                         "realtime_rows": realtime_bench.run(quick=args.quick)}, out.path)
            keep_folders(Path(args.out), out.path)
            print(f"bench written to {out.commit()}")
            return 0
        data = bench.run(sizes=sizes, models=models, rounds=3 if args.quick else args.rounds,
                         with_engines=old is None, device=args.device,
                         family=None if args.models or args.sizes else
                         ("quick" if args.quick else "full"))
        bench.write(bench.merge(old, data) if old else data, out.path)
        keep_folders(Path(args.out), out.path)
        path = out.commit()
    print(f"bench written to {path}")
    return 0


def keep_folders(target, staged):
    """Copy the folders inside ``target`` that this run does not write into ``staged``: they
    hold other commands' output (the Warp device timings of `python -m
    cases.tools.warp_forces --out reports/bench/cuda`), which replacing the folder must not
    lose."""
    if not target.is_dir():
        return
    for sub in target.iterdir():
        if sub.is_dir() and not (staged / sub.name).exists():
            shutil.copytree(sub, staged / sub.name)
