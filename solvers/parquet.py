"""Parquet output (``--format parquet``) for every-step runs and sweeps, written in row groups.

pyarrow is an optional dependency (``pip install 'vtool[parquet]'``); without
it, asking for Parquet is one line (:func:`require_pyarrow`, an
:class:`~vtool.errors.InputError` naming the flag), before any run starts.

Columns are those of the CSV (the same names with their units, e.g.
``q1 (in)``, ``F2 (lbf)``; a name the CSV repeats is written once), as
float64, and for a run ``configuration`` (the thesis' number, null when it
has none) and ``closed`` (the closed clearances). The file's key-value
metadata carries ``vtool_version`` and ``title``.

Memory stays bounded: rows are buffered up to :data:`ROW_GROUP` and then
written as one row group, so a writer holds at most one group whatever the
length of the run or the number of points (benchmarks/bench_parquet.py
measures the peak against a ten times smaller output). The bytes go to the
handle of :func:`vtool.files.open_atomic_binary` (a temporary file renamed
over the target when the run succeeds), so a failed run leaves nothing.
"""

from __future__ import annotations

import math
import time as wallclock
from collections.abc import Sequence
from typing import Any, BinaryIO

import numpy as np

from vtool.errors import InputError
from vtool.solvers.trace import CsvStream, Trace

#: rows per row group (and the most rows a writer buffers)
ROW_GROUP = 16_384
FORMATS = ("csv", "parquet")


def require_pyarrow(field: str = "--format") -> Any:
    """``pyarrow.parquet``, or a one-line InputError saying how to install it."""
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise InputError(field, "parquet", "pyarrow installed for Parquet output (pip install 'vtool[parquet]'); "
                         "or --format csv") from None
    return pq


def output_format(path: Any, given: str | None, field: str = "--format") -> str:
    """``given``, else ``parquet`` for a ``.parquet``/``.pq`` file and ``csv`` otherwise; pyarrow checked."""
    chosen = given or ("parquet" if str(path).lower().endswith((".parquet", ".pq")) else "csv")
    if chosen not in FORMATS:
        raise InputError(field, chosen, f"one of: {', '.join(FORMATS)}")
    if chosen == "parquet":
        require_pyarrow(field)
    return chosen


class _GroupWriter:
    """Columns buffered up to :data:`ROW_GROUP` rows, then written as one row group."""

    def __init__(self, handle: BinaryIO, metadata: dict[str, str]) -> None:
        self.pq = require_pyarrow()
        self.handle = handle
        self.metadata = {k.encode(): v.encode() for k, v in metadata.items()}
        self.writer: Any = None
        self.buffer: dict[str, list[Any]] = {}
        self.buffered = 0
        self.groups = 0

    def add(self, columns: dict[str, Any], rows: int) -> None:
        for name, values in columns.items():
            self.buffer.setdefault(name, []).append(values)
        self.buffered += rows
        if self.buffered >= ROW_GROUP:
            self.flush()

    def flush(self) -> None:
        if not self.buffered:
            return
        import pyarrow as pa

        arrays = {}
        for name, parts in self.buffer.items():
            if isinstance(parts[0], np.ndarray) and parts[0].dtype.kind == "f":
                arrays[name] = pa.array(np.concatenate(parts), type=pa.float64())
            else:
                arrays[name] = pa.array([v for part in parts for v in part])
        table = pa.table(arrays)
        if self.writer is None:
            self.writer = self.pq.ParquetWriter(self.handle, table.schema.with_metadata(self.metadata))
        self.writer.write_table(table.replace_schema_metadata(self.metadata), row_group_size=self.buffered)
        self.groups += 1
        self.buffer = {}
        self.buffered = 0

    def close(self) -> None:
        self.flush()
        if self.writer is not None:
            self.writer.close()


class ParquetStream(CsvStream):
    """:class:`~vtool.solvers.trace.CsvStream`'s contract (rows in time order, ``thin``, :attr:`rows`,
    :attr:`seconds`), written as Parquet row groups. Call :meth:`close` when the run has ended."""

    def __init__(self, handle: BinaryIO, quantities: tuple[str, ...] = (), thin: bool = False,
                 title: str = "") -> None:
        super().__init__(handle, quantities, thin)
        from vtool import __version__

        self.groups = _GroupWriter(handle, {"vtool_version": __version__, "title": title})

    def write(self, block: Trace) -> None:
        started = wallclock.perf_counter()
        self.check_order(block)
        names, columns = block.csv_columns(self.quantities)
        rows = slice(None)
        data: dict[str, Any] = {}
        for name, column in zip(names, columns, strict=False):
            if name not in data:  # a copy: a back end may reuse the block's arrays once this returns
                data[name] = np.array(column(rows), dtype=float, copy=True)
        masks = np.unique(block.configuration)
        cells = {int(m): block.configuration_csv(int(m)).split(",", 1) for m in masks}
        data["configuration"] = [int(cells[int(m)][0]) if cells[int(m)][0] else None for m in block.configuration]
        data["closed"] = [cells[int(m)][1] for m in block.configuration]
        self.groups.add(data, len(block.time))
        self.header_written = True
        self.rows += len(block.time)
        self.seconds += wallclock.perf_counter() - started

    def close(self) -> None:
        """Write the last row group and the footer (also after a failed run: its file is then removed)."""
        started = wallclock.perf_counter()
        self.groups.close()
        self.seconds += wallclock.perf_counter() - started


class SweepParquet:
    """A sweep's points as Parquet (the sink of :func:`vtool.solvers.studies.sweep.run_points`).

    Columns: the swept fields (with units), ``status``, the metrics (with
    units), as the CSV's header names them. Points are written in the order
    they finish (a ``point`` column gives their grid index); not resumable
    (``--resume`` needs a CSV).
    """

    def __init__(self, handle: BinaryIO, fields: Sequence[tuple[str, str]], spec: Any, *,
                 timing: bool = False) -> None:
        from vtool import __version__
        from vtool.solvers.studies.sweep import column_title, report_columns

        self.fields = [f for f, _ in fields]
        self.field_titles = [column_title(f, u) for f, u in fields]
        self.metrics = report_columns(spec, timing)
        self.groups = _GroupWriter(handle, {"vtool_version": __version__, "title": spec.title})
        self.finished: set[int] = set()
        self.rows = 0

    def open(self, points: Sequence[Any]) -> None:
        pass

    def append(self, result: Any) -> None:
        from vtool.solvers.studies.sweep import column_title

        values = dict(result.values)
        data: dict[str, Any] = {"point": [result.index]}
        for field, title in zip(self.fields, self.field_titles, strict=True):
            value = values[field]  # numbers as float64 (a grid may mix 9000 and 9500.5), names as text
            data[title] = [float(value) if isinstance(value, int | float) and not isinstance(value, bool) else value]
        data["status"] = [result.status]
        for name, unit in self.metrics:
            data[column_title(name, unit)] = [float(result.metrics.get(name, math.nan))]
        self.groups.add(data, 1)
        self.rows += 1

    def finish(self) -> None:
        self.groups.close()

    def finished_results(self, points: Sequence[Any]) -> dict[int, Any]:
        return {}
