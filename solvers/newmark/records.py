"""The records the Newmark kernel computes on: named tuples of arrays (no numba here).

numba takes a named tuple of arrays as one argument and reads its fields by
name; Python builds them once per run. The slots inside the arrays are in
:mod:`vtool.solvers.newmark.layout`.

* :class:`Problem`: a mechanism's constant tables (parameters, clearance tables,
  the sources' Fourier series as one table (:func:`~vtool.solvers.newmark.layout.series_table`),
  the mass matrix and its inverse);
* :class:`Tables`: every built configuration's operators, one slot each, and the
  map ``index[h] = (mask, slot)`` (open addressing, -1 where empty:
  :func:`mask_hash`), grown by :class:`vtool.solvers.model.contact.ConfigurationTables`;
* :class:`Config`: one configuration's operators (views of its slot);
* :class:`State`: the full state x, v, a and the integer and float state slots;
* :class:`Output`: the output buffers (rows, events, peaks);
* :class:`Scratch`: the run loop's work arrays, few arrays with named rows
  (every array of a record costs compile: docs/developer.md, "Records").
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

Problem = namedtuple("Problem", "ip fp cl clf series mass")
Tables = namedtuple("Tables", "index ci cm cp mk mon")
Config = namedtuple("Config", "mask ci cm cp mk mon")
State = namedtuple("State", "x v a ist fst")
Output = namedtuple("Output", "t q F c ev_f ev_i peak")
Scratch = namedtuple("Scratch", "y src cross system L closing")


def mask_hash(mask: int, capacity: int) -> int:
    """The first probe of ``mask`` in an index of ``capacity`` (a power of two) entries: the kernel's
    ``find_slot`` computes the same."""
    return (mask ^ (mask >> 7) ^ (mask >> 17)) & (capacity - 1)


def scratch(n: int, ns: int, ncl: int) -> tuple[Scratch, np.ndarray]:
    """The run loop's work arrays for n coordinates, ns sources and ncl clearances: the layer states
    ``y[Y_NOW]`` (the step's start), ``y[Y_END]`` (its end), ``y[Y_OUT]`` (an output row's), each a
    layer state (rows Z, ZD, ZDD); the sources' (x, v, a) at those instants ``src[SRC_NOW]``,
    ``src[SRC_END]``, ``src[SRC_OUT]``; per clearance ``cross[PHI]`` (the monitors at the step's end),
    ``cross[PHI_START]`` (at its start), ``cross[TAU]`` (a located crossing); the right side
    ``system[RHS]`` and the solution ``system[SOL]`` of a step's system, a Cholesky factor, and the
    closing clearances of an event.

    Returns the record and the one buffer its float arrays are views of: the caller zeroes the
    buffer and ``closing`` before each kernel call but one that goes on after a chunk's end (two
    fills), so that such a call starts as with fresh arrays (zeroing them in the kernel compiled four
    ``fill`` specialisations into its first compile)."""
    sizes = (9 * n, 9 * ns, 3 * ncl, 2 * (n + ncl), n * n)
    buffer = np.zeros(sum(sizes))
    parts, start = [], 0
    for size in sizes:  # (np.split's Python around the same slices took longer than the kernel's setup)
        parts.append(buffer[start:start + size])
        start += size
    y, src, cross, system, L = parts
    return Scratch(y.reshape(3, 3, n), src.reshape(3, 3 * ns), cross.reshape(3, ncl), system.reshape(2, n + ncl),
                   L.reshape(n, n), np.zeros(ncl, dtype=np.int64)), buffer
