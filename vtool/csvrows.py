"""CSV rows of numbers formatted by a compiled kernel: the text of Python's ``'%.10g' % x``, faster.

A row is the values of one row of a float array, each as ``'%.10g' % x``,
separated by commas, then a comma, the row's label (a preset-dependent text
such as ``VI,cam+seat``) and a newline. A long ``--every-step`` run has a
million rows; ``python3 benchmarks/bench_output.py`` times the kernel against
Python's formatting (the same text).

How the kernel writes ``x`` with 10 significant digits (C's ``%.10g``):

1. e = ⌊log10 |x|⌋ (from the binary exponent, corrected by one until
   s = |x| · 10^(9-e) ∈ [10⁹, 10¹⁰)), with 10^(9-e) the double nearest to
   it, so s carries at most two roundings (|error| < 3·10⁻⁶);
2. m = s rounded to an integer (10 digits; 10¹⁰ becomes 10⁹ with e + 1);
   when the fraction of s is within 10⁻⁵ of one half the rounding is not
   certain and the row is written by Python instead (about one value in
   50,000), as are rows with non-finite values or |9 - e| beyond 44;
3. the C rule for ``%g``: fixed notation when -4 ≤ e < 10, else
   ``d.ddde±XX`` (at least two exponent digits); trailing zeros and a
   trailing decimal point removed; ``-0`` for negative zero. The ten digits
   and the point are written in place, then the trailing zeros cut (no
   branches on the digits: 20 % faster than writing them one by one).

So the text is identical to Python's for every value (a test compares them
on random and edge values). ``NUMBA_DISABLE_JIT=1`` runs the same source as
plain Python (the reference).

The kernel itself is :mod:`vtool.csvrows_kernel` (numba, ``@jit`` of
:mod:`vtool.jit`). This module imports no numba: numba is imported only when
its kernel is worth it (:func:`choose`).
"""

from __future__ import annotations

import csv
import io
import sys
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np

#: Characters one value can take at most (``-1.234567891e-100``) plus its comma.
VALUE_WIDTH = 18
#: Outputs of at least this many rows compile the kernel when it is not cached yet (smaller ones
#: are written by Python, in well under a second).
WORTH_COMPILING_ROWS = 20_000
#: Decimal shifts 10^k, |k| <= MAX_SHIFT, are one multiplication by the nearest double.
MAX_SHIFT = 44


#: 10^k for k = -MAX_SHIFT..MAX_SHIFT, each the double nearest to it (exact for 0 <= k <= 22).
POWERS = np.array([float(f"1e{k}") for k in range(-MAX_SHIFT, MAX_SHIFT + 1)])


def python_row(values: np.ndarray, label: str) -> str:
    """One row as Python formats it (the reference, and the fallback)."""
    return ",".join("%.10g" % value for value in values.tolist()) + "," + label + "\n"  # noqa: UP031


def ready() -> bool:
    """True when numba's kernel needs no compiling: plain Python, loaded in this process, or compiled into
    numba's cache before (:func:`vtool.jit.is_compiled`). Imports numba."""
    from vtool import jit
    from vtool.csvrows_kernel import put_rows

    return jit.is_compiled(put_rows, "put_rows", "csv")


def choose(rows: int, compiled: bool | None) -> Callable[..., int] | None:
    """The formatter for ``rows`` rows (:mod:`vtool.csvrows_kernel`'s ``put_rows``), or None for Python's
    formatting.

    ``compiled`` False: Python's; otherwise numba's kernel when ``compiled``
    is True, when the output is large enough to pay for the kernel's compile
    (a few seconds, once; a per-degree CSV does not wait for it), or when
    numba is loaded in this process already and the kernel is cached (not
    worth importing numba for).
    """
    if compiled is False:
        return None
    if compiled or rows >= WORTH_COMPILING_ROWS or ("numba" in sys.modules and ready()):
        from vtool.csvrows_kernel import put_rows

        return put_rows
    return None


def arguments(values: np.ndarray, labels: list[str], label_of_row: np.ndarray) -> tuple[Any, ...]:
    """``put_rows``' arguments for these rows (its buffers allocated); ``values`` C-contiguous float64."""
    rows = values.shape[0]
    encoded = [label.encode("utf-8") for label in labels]
    label_start = np.zeros(len(encoded) + 1, dtype=np.int64)
    label_start[1:] = np.cumsum([len(b) for b in encoded])
    label_text = np.frombuffer(b"".join(encoded) or b"\0", dtype=np.uint8)
    label_of_row = np.ascontiguousarray(label_of_row, dtype=np.int64)
    if label_of_row.shape != (rows,):
        raise ValueError(f"one label per row: {label_of_row.shape} for {rows} rows")
    width = max(len(b) for b in encoded) if encoded else 0
    out = np.empty(rows * (values.shape[1] * VALUE_WIDTH + width + 2), dtype=np.uint8)
    offsets = np.zeros(rows + 1, dtype=np.int64)
    fallback = np.zeros(rows, dtype=np.bool_)
    return values, values.view(np.int64), POWERS, label_text, label_start, label_of_row, out, offsets, fallback


def _encode(values: np.ndarray, labels: list[str], label_of_row: np.ndarray,
            compiled: bool | None = None) -> list:
    """The rows' UTF-8 text as a list of byte buffers (the kernel's, and Python's rows where it gave up)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must be a 2-D array (got {values.ndim} dimensions)")
    rows = values.shape[0]
    if rows == 0:
        return []
    put_rows = choose(rows, compiled)
    if put_rows is None:
        text = "".join(python_row(values[r], labels[int(label_of_row[r])]) for r in range(rows))
        return [text.encode("utf-8")]
    from vtool import jit

    args = arguments(values, labels, label_of_row)
    end, _ = jit.timed_call(put_rows, "put_rows", "csv", *args)  # the first call compiles it: timed, marked
    label_of_row, out, offsets, fallback = args[5:]
    pieces, done = [], 0
    for r in np.flatnonzero(fallback).tolist():
        pieces.append(out[offsets[done]:offsets[r]])
        pieces.append(python_row(values[r], labels[int(label_of_row[r])]).encode("utf-8"))
        done = r + 1
    pieces.append(out[offsets[done]:end])
    return pieces


def format_rows(values: np.ndarray, labels: list[str], label_of_row: np.ndarray,
                compiled: bool | None = None) -> str:
    """CSV text of the rows of ``values`` (2-D), each ending with ``labels[label_of_row[r]]``.

    ``compiled``: True for a compiled kernel, False for Python's formatting (the same text), None to
    choose (:func:`choose`)."""
    pieces = _encode(values, labels, label_of_row, compiled)
    return b"".join(bytes(piece) for piece in pieces).decode("utf-8")


def write_rows(handle, values: np.ndarray, labels: list[str], label_of_row: np.ndarray,
               compiled: bool | None = None) -> None:
    """Write :func:`format_rows`'s text to a text handle; to a UTF-8 file's binary buffer directly
    (no text copy) when it has one."""
    binary = getattr(handle, "buffer", None)
    if binary is None or (getattr(handle, "encoding", "") or "").lower().replace("-", "") != "utf8":
        handle.write(format_rows(values, labels, label_of_row, compiled))
        return
    handle.flush()  # what was written as text goes first
    for piece in _encode(values, labels, label_of_row, compiled):
        binary.write(piece)


def compile_notice() -> str | None:
    """The line to show before the first large CSV output compiles the formatter, or None when it is
    compiled (in numba's cache, or in this process). Imports numba."""
    if ready():
        return None
    from vtool import jit

    return jit.compile_notice("the CSV writer", "put_rows")


def csv_text(rows: Iterable[Sequence[object]]) -> str:
    """Rows of cells as CSV text (``\\n`` line ends), quoted by the csv module wherever a cell holds a
    comma, a quote or a line break: the one way vtool writes a CSV row that holds text."""
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows(rows)
    return buffer.getvalue()
