"""Edits a user makes by hand to a finished run's results, shared by the door tests of a
results directory touched by hand (tests/test_doors46h.py, 47k.py): a claim edited, a private
copy of a tiny run."""

from __future__ import annotations

import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq


def edit_first_value(d: Path) -> float:
    """Add 1 to the first claim's ``value`` in ``d/claims.parquet``, its metadata kept (as a
    careful edit with pyarrow keeps it); the value now there."""
    p = d / "claims.parquet"
    t = pq.read_table(p)
    i = t.column_names.index("value")
    v = t["value"].to_pylist()
    v[0] += 1.0
    pq.write_table(t.set_column(i, t.schema.field(i), pa.array(v, t.schema.field(i).type)), p)
    return v[0]


def copy_of_tiny(tiny_run, tmp_path: Path, name: str = "network_plate") -> Path:
    """A private copy of the session's tiny run of ``studies/<name>.toml`` under
    ``tmp_path/res/<name>`` (the shared run is read only)."""
    d = tmp_path / "res" / name
    shutil.copytree(tiny_run(name), d, symlinks=True)
    return d
