"""The compiled CSV number formatter (numba): ``'%.10g' % x`` for every value of a table's rows.

The method, and why the text is Python's to the last character, are in
:mod:`vtool.csvrows`, which chooses between this kernel and Python's own
formatting. ``NUMBA_DISABLE_JIT=1`` runs the same source as plain Python (the
reference). The decimal shifts come in as ``powers`` (10^k for k = -S..S, S
from its length).
"""

from __future__ import annotations

import math

import numpy as np

from vtool.jit import jit

#: Fractions of s this close to one half are left to Python's correctly rounded formatting.
TIE_MARGIN = 1e-5
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
    max_shift = (powers.shape[0] - 1) // 2
    e = int(math.floor((((bits >> 52) & 0x7FF) - 1023) * LOG10_2))  # e or e - 1 (subnormals: Python)
    scaled = 0.0
    for _ in range(3):
        k = 9 - e
        if k > max_shift or k < -max_shift:
            return -1
        scaled = ax * powers[k + max_shift]
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
def put_rows(values, bits, powers, label_text, label_start, label_of_row, out, offsets,  # noqa: ANN001, ANN201
             fallback):
    """Rows of ``values`` with their labels into ``out`` (see the module doc); returns the bytes written.

    ``label_text[label_start[i]:label_start[i + 1]]`` is label i (UTF-8);
    row r ends with label ``label_of_row[r]``. ``offsets[r]`` is where row r
    starts (``offsets[rows]`` the end); ``fallback[r]`` is set for a row that
    Python must write (its bytes here are incomplete).
    """
    rows, cols = values.shape
    pos = 0
    for r in range(rows):
        offsets[r] = pos
        for c in range(cols):
            end = put_value(values[r, c], bits[r, c], powers, out, pos)
            if end < 0:
                fallback[r] = True
                end = pos
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
