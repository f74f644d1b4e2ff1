"""`pbcm sweep`: a parameter sweep declared in TOML, on the one executor."""
from .common import add_executor, add_store, add_term_files

def add(sub):
    """The command's parser."""
    sw = sub.add_parser(
        "sweep", help="run a parameter sweep (TOML spec): table, runs and report",
        description="Run every point of a sweep spec (cases, fixed settings, axes over E, nu, "
                    "rho, resolution, load, mesh, bc and model; see cases/cli/sweeps/nu.toml) as "
                    "tasks on --workers local processes, or on the Dask cluster at "
                    "--scheduler. Finished runs are kept (runs/<key>/metrics.json) "
                    "and skipped on a rerun; a failing run is a row with its error. Writes "
                    "table.parquet (table.csv without pyarrow), report.md and its plots. Exit "
                    "status 1 when a task was lost with its workers (rerun to finish).")
    sw.add_argument("spec", help="a sweep spec .toml, or the name of a shipped one (nu)")
    add_executor(sw)
    sw.add_argument("--out", help="output folder (default reports/sweeps/SPEC-NAME)")
    sw.add_argument("--serial", action="store_true",
                    help="run every task in this process (same results)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="compute again the runs an earlier sweep recorded as failed")
    sw.add_argument("--plan", action="store_true",
                    help="print the tasks and runs the sweep would compute (and those already "
                         "in --out), then stop: nothing is computed or written")
    add_term_files(sw)
    add_store(sw)
    sw.set_defaults(func=run)


def run(args):
    from .sweeps import command
    return command.run(args)

