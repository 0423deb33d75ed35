"""CSV rows of numbers formatted by a compiled kernel: the text of Python's ``'%.10g' % x``, 10-20x faster.

A row is the values of one row of a float array, each as ``'%.10g' % x``,
separated by commas, then a comma, the row's label (a preset-dependent text
such as ``VI,cam+seat``) and a newline. Python's own formatting costs about
30 µs per row of 46 values; a long ``--every-step`` run has a million rows.

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
"""

from __future__ import annotations

import math

import numpy as np

from vtool import numba_cache

numba_cache.configure()

from numba import njit  # noqa: E402 (after the cache folder is chosen)

jit = njit(cache=numba_cache.CACHE_ENABLED, nogil=True, error_model="numpy")

#: Characters one value can take at most (``-1.234567891e-100``) plus its comma.
VALUE_WIDTH = 18
#: Outputs of at least this many rows compile the kernel when it is not cached yet (smaller ones
#: are written by Python: about 25 µs per row of 46 values, under a second for 20,000 rows).
WORTH_COMPILING_ROWS = 20_000
#: Fractions of s this close to one half are left to Python's correctly rounded formatting.
TIE_MARGIN = 1e-5
#: Decimal shifts 10^k, |k| <= MAX_SHIFT, are one multiplication by the nearest double.
MAX_SHIFT = 44
LOG10_2 = 0.30102999566398120
COMMA, NEWLINE, MINUS, PLUS, DOT, ZERO, LETTER_E = 44, 10, 45, 43, 46, 48, 101


@jit
def put_value(x, bits, powers, out, pos):  # noqa: ANN001, ANN201 (a numba kernel)
    """Write ``'%.10g' % x`` at out[pos:] (``bits``: x's IEEE bits, for its binary exponent); returns the
    new position, or -1 when Python must write it."""
    if x != x or x - x != 0.0:  # nan or inf
        return -1
    if x == 0.0:
        if np.signbit(x):
            out[pos] = MINUS
            pos += 1
        out[pos] = ZERO
        return pos + 1
    ax = abs(x)
    e = int(math.floor((((bits >> 52) & 0x7FF) - 1023) * LOG10_2))  # e or e - 1 (subnormals: Python)
    scaled = 0.0
    for _ in range(3):
        k = 9 - e
        if k > MAX_SHIFT or k < -MAX_SHIFT:
            return -1
        scaled = ax * powers[k + MAX_SHIFT]
        if scaled >= 1e10:
            e += 1
        elif scaled < 1e9:
            e -= 1
        else:
            break
    if not 1e9 <= scaled < 1e10:
        return -1
    whole = np.floor(scaled)
    fraction = scaled - whole
    if abs(fraction - 0.5) < TIE_MARGIN:
        return -1
    m = np.int64(whole) + (1 if fraction > 0.5 else 0)
    if m == 10_000_000_000:
        m = 1_000_000_000
        e += 1
    if x < 0.0:
        out[pos] = MINUS
        pos += 1
    if 0 <= e < 10:  # d0..de . d(e+1)..d9 in place, then trailing zeros (and a bare point) cut
        for j in range(9, -1, -1):
            out[pos + j + (1 if j > e else 0)] = ZERO + m % 10
            m //= 10
        out[pos + e + 1] = DOT
        end = pos + 11
        while end > pos + e + 2 and out[end - 1] == ZERO:
            end -= 1
        return end - 1 if end == pos + e + 2 else end
    if -4 <= e < 0:  # 0.000d0..d9
        out[pos] = ZERO
        out[pos + 1] = DOT
        start = pos - e + 1
        for j in range(pos + 2, start):
            out[j] = ZERO
        for j in range(9, -1, -1):
            out[start + j] = ZERO + m % 10
            m //= 10
        end = start + 10
        while out[end - 1] == ZERO:  # d0 is not zero
            end -= 1
        return end
    for j in range(9, -1, -1):  # d0 . d1..d9 e±XX
        out[pos + j + (1 if j > 0 else 0)] = ZERO + m % 10
        m //= 10
    out[pos + 1] = DOT
    end = pos + 11
    while end > pos + 2 and out[end - 1] == ZERO:
        end -= 1
    pos = end - 1 if end == pos + 2 else end
    out[pos] = LETTER_E
    out[pos + 1] = MINUS if e < 0 else PLUS
    pos += 2
    ae = -e if e < 0 else e
    if ae >= 100:
        out[pos] = ZERO + ae // 100
        pos += 1
    out[pos] = ZERO + (ae // 10) % 10
    out[pos + 1] = ZERO + ae % 10
    return pos + 2


@jit
def put_rows(values, bits, same, powers, label_text, label_start, label_of_row, out, offsets,  # noqa: ANN001, ANN201
             fallback):
    """Rows of ``values`` with their labels into ``out`` (see the module doc); returns the bytes written.

    ``label_text[label_start[i]:label_start[i + 1]]`` is label i (UTF-8);
    row r ends with label ``label_of_row[r]``. ``offsets[r]`` is where row r
    starts (``offsets[rows]`` the end); ``fallback[r]`` is set for a row that
    Python must write (its bytes here are incomplete). A column c with
    ``same[c] = j >= 0`` holds the values of the earlier column j: its text is
    copied, not formatted again.
    """
    rows, cols = values.shape
    starts = np.zeros(cols, dtype=np.int64)
    ends = np.zeros(cols, dtype=np.int64)
    pos = 0
    for r in range(rows):
        offsets[r] = pos
        for c in range(cols):
            j = same[c]
            if j >= 0:
                end = pos + ends[j] - starts[j]
                out[pos:end] = out[starts[j]:ends[j]]
            else:
                end = put_value(values[r, c], bits[r, c], powers, out, pos)
                if end < 0:
                    fallback[r] = True
                    end = pos
            starts[c] = pos
            ends[c] = end
            out[end] = COMMA
            pos = end + 1
        label = label_of_row[r]
        for j in range(label_start[label], label_start[label + 1]):
            out[pos] = label_text[j]
            pos += 1
        out[pos] = NEWLINE
        pos += 1
    offsets[rows] = pos
    return pos


#: 10^k for k = -MAX_SHIFT..MAX_SHIFT, each the double nearest to it (exact for 0 <= k <= 22).
POWERS = np.array([float(f"1e{k}") for k in range(-MAX_SHIFT, MAX_SHIFT + 1)])


def python_row(values: np.ndarray, label: str) -> str:
    """One row as Python formats it (the reference, and the fallback)."""
    return ",".join("%.10g" % value for value in values.tolist()) + "," + label + "\n"  # noqa: UP031


def repeated_columns(values: np.ndarray) -> np.ndarray:
    """For each column, the first earlier column with the same values (bit for bit), or -1.

    A trace's CSV repeats some columns (the preset's quantities ``q9``, ``F1``
    ... beside the coordinates and forces): their text is copied."""
    same = np.full(values.shape[1], -1, dtype=np.int64)
    first: dict[bytes, list[int]] = {}
    for c in range(values.shape[1]):
        column = np.ascontiguousarray(values[:, c])
        with np.errstate(all="ignore"):  # inf - inf in the sum is only a key
            key = column.tobytes()[:64] + column.sum(dtype=np.float64).tobytes()
        for j in first.get(key, []):
            if np.array_equal(column.view(np.int64), values[:, j].view(np.int64)):
                same[c] = j
                break
        else:
            first.setdefault(key, []).append(c)
    return same


def ready() -> bool:
    """True when the kernel needs no compiling: loaded in this process, or in numba's cache."""
    if not hasattr(put_rows, "signatures") or put_rows.signatures:
        return True  # NUMBA_DISABLE_JIT (plain Python), or compiled or loaded already
    return compile_notice() is None


def use_kernel(rows: int, compiled: bool | None) -> bool:
    """``compiled`` if given; else the kernel when it is ready or the output is large enough to pay
    for its compile (a few seconds, once): a per-degree CSV does not wait for it."""
    return compiled if compiled is not None else (rows >= WORTH_COMPILING_ROWS or ready())


def _encode(values: np.ndarray, labels: list[str], label_of_row: np.ndarray,
            compiled: bool | None = None) -> list:  # type: ignore[type-arg]
    """The rows' UTF-8 text as a list of byte buffers (the kernel's, and Python's rows where it gave up)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must be a 2-D array (got {values.ndim} dimensions)")
    rows = values.shape[0]
    if rows == 0:
        return []
    if not use_kernel(rows, compiled):
        text = "".join(python_row(values[r], labels[int(label_of_row[r])]) for r in range(rows))
        return [text.encode("utf-8")]
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
    end = put_rows(values, values.view(np.int64), repeated_columns(values), POWERS, label_text, label_start,
                   label_of_row, out, offsets, fallback)
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

    ``compiled``: True for the kernel, False for Python's formatting (the same text), None to
    choose (:func:`use_kernel`)."""
    pieces = _encode(values, labels, label_of_row, compiled)
    return b"".join(bytes(piece) for piece in pieces).decode("utf-8")


def write_rows(handle, values: np.ndarray, labels: list[str], label_of_row: np.ndarray,  # type: ignore[no-untyped-def]
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


#: First compile of the formatter on a 2-core machine (s); later processes load it from numba's cache.
COMPILE_ESTIMATE_S = 5.0


_cached: list[bool] = []  # the cache's answer, read once per process


def compile_notice() -> str | None:
    """The line to show before the first large CSV output compiles the formatter, or None when it is
    cached (or compiled in this process)."""
    if not hasattr(put_rows, "signatures") or put_rows.signatures:
        return None
    if not _cached:
        try:
            _cached.append(bool(put_rows._cache._cache_file._load_index()))
        except Exception:  # noqa: BLE001 (numba internals: a missing or unreadable index means "compile")
            _cached.append(False)
    if _cached[0]:
        return None
    return (f"compiling the CSV writer, once (about {COMPILE_ESTIMATE_S:.0f} s); "
            "later runs load it from the cache")
