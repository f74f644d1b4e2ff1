"""Parameter sweeps on dask.distributed (``pbcm sweep SPEC.toml``): a TOML spec declares the
cases, fixed settings and swept axes (``spec``); each (case, point, mesh, bc) is a task
(``task``) that a LocalCluster or a remote cluster runs (``engine``); every run is stored as
it finishes and the tidy table (``table``) and the report with its plots (``report``) are
drawn from the stored runs. The shipped specs (``*.toml``) sit beside this file."""
from pathlib import Path

SHIPPED = Path(__file__).parent
