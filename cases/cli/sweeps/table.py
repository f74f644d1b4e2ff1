"""The sweep's results: one metrics.json per run (what makes a sweep resumable) and one tidy
table, a row per run with every parameter and metric (Parquet when pyarrow is present, CSV
otherwise). Every file is written atomically: beside its target, then renamed over it.
"""
import csv
import io
import json
from pathlib import Path

from ...running.output import write_atomic

RUNS = "runs"


class RunStore:
    """The finished runs of a sweep folder: ``runs/<run key>/metrics.json`` each."""

    def __init__(self, folder):
        self.folder = Path(folder) / RUNS

    def path(self, key):
        return self.folder / key / "metrics.json"

    def get(self, key):
        """The stored row of run ``key``, or None (never run, or a file cut short)."""
        try:
            return json.loads(self.path(key).read_text())
        except (FileNotFoundError, json.JSONDecodeError):
            return None

    def put(self, key, row):
        write_atomic(self.path(key), json.dumps(row, indent=1, sort_keys=True) + "\n")


def parquet_available():
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def columns(rows, first):
    """Column names: ``first`` (those present), then the others in the order the rows
    first show them."""
    seen = dict.fromkeys(c for c in first if any(c in r for r in rows))
    for r in rows:
        seen.update(dict.fromkeys(k for k in r if k not in seen))
    return list(seen)


def cell(v):
    """A table value: numbers, text and booleans as they are; lists and dicts as JSON."""
    return json.dumps(v, sort_keys=True) if isinstance(v, (list, dict, tuple)) else v


# how long a run took says where it ran, not what it gave: kept in its runs/<key>/metrics.json,
# left out of the table, so that the same sweep writes the same table wherever it runs
TIMING = ("task_wall_s",)


def write(rows, folder, kind, first=()):
    """Write ``rows`` (less their TIMING columns) as ``folder/table.parquet`` or
    ``folder/table.csv`` (``kind`` auto: Parquet when pyarrow is present); return the path."""
    if kind == "auto":
        kind = "parquet" if parquet_available() else "csv"
    cols = [c for c in columns(rows, first) if c not in TIMING]
    table = [[cell(r.get(c)) for c in cols] for r in rows]
    if kind == "parquet":
        path = Path(folder) / "table.parquet"
        write_atomic(path, _parquet(cols, table))
    else:
        path = Path(folder) / "table.csv"
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(cols)
        w.writerows([["" if v is None else repr(v) if isinstance(v, float) else v
                      for v in row] for row in table])
        write_atomic(path, buf.getvalue())
    return path


def _parquet(cols, table):
    """Parquet bytes; a column's type from its values (float when any is, text when they
    mix kinds)."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    arrays = []
    for j, _ in enumerate(cols):
        values = [row[j] for row in table]
        kinds = {type(v) for v in values if v is not None}
        if kinds <= {bool}:
            arrays.append(pa.array(values, type=pa.bool_()))
        elif kinds <= {int}:
            arrays.append(pa.array(values, type=pa.int64()))
        elif kinds <= {int, float}:
            arrays.append(pa.array([None if v is None else float(v) for v in values],
                                   type=pa.float64()))
        else:
            arrays.append(pa.array([None if v is None else v if isinstance(v, str)
                                    else json.dumps(v) for v in values], type=pa.string()))
    buf = pa.BufferOutputStream()
    pq.write_table(pa.Table.from_arrays(arrays, names=cols), buf)
    return buf.getvalue().to_pybytes()


def read(path):
    """The rows of a table written by ``write`` (for tests and users without pandas):
    [{column: value}], CSV values parsed back to numbers where they are numbers."""
    path = Path(path)
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq
        return pq.read_table(path).to_pylist()
    with open(path, newline="") as f:
        return [{k: _parse(v) for k, v in r.items()} for r in csv.DictReader(f)]


def _parse(text):
    if text == "":
        return None
    if text in ("True", "False"):
        return text == "True"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


__all__ = ["RunStore", "write", "read", "parquet_available"]
