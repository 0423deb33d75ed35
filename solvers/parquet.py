"""Parquet output (``--format parquet``) for every-step runs and sweeps, written in row groups.

pyarrow is an optional dependency (``pip install 'vtool[parquet]'``); without
it, asking for Parquet is one line (:func:`require_pyarrow`, an
:class:`~vtool.errors.InputError` naming the flag), before any run starts.

Columns are those of the CSV (the same names with their units, e.g.
``q1 (in)``, ``F2 (lbf)``; a name the CSV repeats is written once), as
float64, and for a run ``configuration`` (the thesis' number, null when it
has none) and ``closed`` (the closed clearances). The file's key-value
metadata carries ``vtool_version`` and ``title``.

Memory stays bounded: rows are buffered up to :data:`ROW_GROUP` (a sweep's:
:func:`group_rows`, about :data:`GROUP_BYTES` of numbers) and then written as
one row group, so a writer holds at most one group whatever the length of the
run or the number of points (benchmarks/bench_parquet.py measures the peak at
10^4, 10^5 and 2*10^5 points). The bytes go to the
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
#: a sweep's row group holds about this many bytes of numbers (8 a value): fewer rows than ROW_GROUP when a
#: point has many columns (see :func:`group_rows`)
GROUP_BYTES = 1 << 20


def group_rows(columns: int) -> int:
    """Rows of a sweep's row group with ``columns`` columns: :data:`GROUP_BYTES` of values, at most
    :data:`ROW_GROUP` rows (and at least 1,024). The writer's memory grows with the rows of one group (its
    buffers and the Parquet encoder's: benchmarks/bench_parquet.py), not with the points of the sweep."""
    return min(ROW_GROUP, max(1024, GROUP_BYTES // (8 * max(1, columns))))
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
    """Columns buffered up to ``rows`` rows (default :data:`ROW_GROUP`), then written as one row group."""

    def __init__(self, handle: BinaryIO, metadata: dict[str, str], rows: int | None = None) -> None:
        self.pq = require_pyarrow()
        self.rows = rows or ROW_GROUP
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
        if self.buffered >= self.rows:
            self.flush()

    def write(self, arrays: dict[str, Any]) -> None:
        """Columns (pyarrow arrays of one length) written now as one row group, after what is buffered."""
        import pyarrow as pa

        self.flush()
        self._write(pa.table(arrays), len(next(iter(arrays.values()))))

    def _write(self, table: Any, rows: int) -> None:
        if self.writer is None:
            self.writer = self.pq.ParquetWriter(self.handle, table.schema.with_metadata(self.metadata))
        self.writer.write_table(table.replace_schema_metadata(self.metadata), row_group_size=rows)
        self.groups += 1

    def flush(self) -> None:
        if not self.buffered:
            return
        import pyarrow as pa

        arrays = {}
        for name, parts in self.buffer.items():
            if all(isinstance(p, np.ndarray) for p in parts) and parts[0].dtype.kind in "fi":
                joined = np.concatenate(parts)
                arrays[name] = pa.array(joined, type=pa.float64() if joined.dtype.kind == "f" else pa.int64())
            elif isinstance(parts[0], np.ndarray) and parts[0].dtype.kind == "f":
                arrays[name] = pa.array([v for part in parts for v in part], type=pa.float64())
            else:
                arrays[name] = pa.array([v for part in parts for v in part])
        self._write(pa.table(arrays), self.buffered)
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

    Columns: ``point`` (the grid index), the swept fields (with units),
    ``status``, the metrics (with units), as the CSV's header names them.
    Points are written in the order they finish.

    Resumable: with ``resume`` (the existing file, ``--resume``), :meth:`open`
    reads its row groups one at a time, marks the points whose index and values
    belong to this sweep as finished and copies them into the new file first; the
    caller renames the new file over the old one when it ends (an interrupted sweep
    too, so that it keeps what finished: app/cli/sweep.py). The file is checked as
    a resumed CSV is (a regular file, not a link, a FIFO or a device), and must have
    this sweep's columns.
    """

    def __init__(self, handle: BinaryIO, fields: Sequence[tuple[str, str]], spec: Any, *,
                 timing: bool = False, resume: Any = None) -> None:
        from vtool import __version__
        from vtool.solvers.studies.sweep import column_title, report_columns

        self.fields = [f for f, _ in fields]
        self.field_titles = [column_title(f, u) for f, u in fields]
        self.metrics = report_columns(spec, timing)
        self.names = ["point", *self.field_titles, "status", *(column_title(n, u) for n, u in self.metrics)]
        self.spec = spec
        from vtool.solvers.studies.sweep import IndexSet

        self.finished = IndexSet()  # a resumed file's points (one bit a point)
        self.rows = 0
        # the points of the group being filled: the index and the metrics in arrays (8 bytes a number, a
        # metric's numbers contiguous: pyarrow takes them without a copy), the fields and statuses as lists
        self.size = group_rows(len(self.names))
        self.groups = _GroupWriter(handle, {"vtool_version": __version__, "title": spec.title}, self.size)
        self.index = np.empty(self.size, dtype=np.int64)
        self.block = np.empty((len(self.metrics), self.size))
        self.cells: dict[str, list[Any]] = {title: [] for title in [*self.field_titles, "status"]}
        self.held = 0
        self.resume = resume
        if resume is not None:
            with self._resumed():
                pass  # checked now, before any point runs

    def _resumed(self) -> Any:
        """The resumed file as a ``pyarrow.parquet.ParquetFile`` (a context manager), checked."""
        import contextlib
        import os
        import stat

        from vtool.files import open_no_follow

        pq = require_pyarrow()
        where = str(self.resume)

        @contextlib.contextmanager
        def opened() -> Any:
            fd = open_no_follow(self.resume, os.O_RDONLY | os.O_NONBLOCK, "--resume")  # a FIFO must not block
            with os.fdopen(fd, "rb") as raw:
                if not stat.S_ISREG(os.fstat(raw.fileno()).st_mode):
                    raise InputError("--resume", where, "a regular file (not a device, pipe or socket)")
                try:
                    file = pq.ParquetFile(raw)
                    names = file.schema_arrow.names
                except Exception:  # pyarrow's errors for a file that is not Parquet (ArrowInvalid, OSError)
                    raise InputError("--resume", where, "a partial Parquet sweep file (this one is not Parquet)"
                                     ) from None
                if names != self.names:
                    raise InputError("--resume", where, "a partial file of this same sweep (its columns differ)")
                yield file

        return opened()

    def _resumed_groups(self, points: Sequence[Any]) -> Any:
        """(row group as columns, the indices of its rows that are this sweep's points or None), group by group."""
        from vtool.solvers.studies.sweep import format_value, point_locator

        locate = point_locator(points)
        with self._resumed() as file:
            for group in range(file.metadata.num_row_groups):
                columns = file.read_row_group(group).to_pydict()
                indices = []
                for row, index in enumerate(columns["point"]):
                    texts = [format_value(columns[title][row]) for title in self.field_titles]
                    indices.append(index if index is not None and locate(texts) == index else None)
                yield columns, indices

    def open(self, points: Sequence[Any]) -> None:
        """With ``resume``: the finished points of the old file marked and copied into this one."""
        if self.resume is None:
            return
        for columns, indices in self._resumed_groups(points):
            rows = [row for row, index in enumerate(indices) if index is not None and index not in self.finished]
            self.finished.update(indices[row] for row in rows)
            if rows:
                self.groups.add({name: [columns[name][row] for row in rows] for name in self.names}, len(rows))
                self.rows += len(rows)

    def append(self, result: Any) -> None:
        values = dict(result.values)
        row = self.held
        self.index[row] = result.index
        for field, title in zip(self.fields, self.field_titles, strict=True):
            value = values[field]  # numbers as float64 (a grid may mix 9000 and 9500.5), names as text
            self.cells[title].append(float(value) if isinstance(value, int | float) and not isinstance(value, bool)
                                     else value)
        self.cells["status"].append(result.status)
        self.block[:, row] = [float(result.metrics.get(name, math.nan)) for name, _ in self.metrics]
        self.held += 1
        self.rows += 1
        if self.held == self.size:
            self._hand_over()

    def _hand_over(self) -> None:
        """The points held so far written as one row group (after the resumed rows the group writer holds)."""
        if not self.held:
            return
        import pyarrow as pa

        n = self.held
        data: dict[str, Any] = {"point": pa.array(self.index[:n])}
        for title in self.field_titles:
            cells = self.cells[title]
            numbers = all(isinstance(v, float) for v in cells)
            data[title] = pa.array(cells, type=pa.float64() if numbers else None)
        data["status"] = pa.array(self.cells["status"], type=pa.string())
        data |= {title: pa.array(self.block[k, :n]) for k, title in enumerate(self.names[len(self.fields) + 2:])}
        self.groups.write(data)
        self.cells = {title: [] for title in self.cells}
        self.held = 0

    def finish(self) -> None:
        self._hand_over()
        self.groups.close()

    def finished_results(self, points: Sequence[Any]) -> dict[int, Any]:
        """The points the resumed file held (read again from it: it is replaced only when the sweep ends)."""
        from vtool.solvers.studies.metrics import failed_metrics
        from vtool.solvers.studies.sweep import PointResult, point_values

        if self.resume is None:
            return {}
        values_of = point_values(points)
        results: dict[int, Any] = {}
        for columns, indices in self._resumed_groups(points):
            for row, index in enumerate(indices):
                if index is not None and index in self.finished and index not in results:
                    metrics = failed_metrics(self.spec)  # NaN for the columns the file leaves out (wall time)
                    metrics.update({name: _number(columns[title][row]) for (name, _), title
                                    in zip(self.metrics, self.names[len(self.fields) + 2:], strict=True)})
                    results[index] = PointResult(index, values_of(index), metrics, columns["status"][row])
        return results


def _number(value: Any) -> float:
    """A metric read back: NaN for a missing value, integers as integers (as the CSV reads them)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return math.nan
    return int(value) if float(value).is_integer() else float(value)
