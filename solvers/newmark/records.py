"""The records the Newmark kernel computes on: named tuples of arrays (no numba here).

numba takes a :func:`collections.namedtuple` of arrays as one argument and
reads its fields by name, with no cost in the compiled code; Python builds
them once per run (the arrays inside are the ones the kernel writes into).
The slot numbers inside the arrays are in :mod:`vtool.solvers.newmark.layout`.

* :class:`Problem`: a mechanism's constant tables for one run (the integer and
  float parameters, the clearance tables, the sources' Fourier series, the
  mass matrix and its inverse);
* :class:`Tables`: every built configuration's operators, one slot each, and
  the open-addressing map from a configuration's mask to its slot
  (``index[h] = (mask, slot)``, -1 where empty; :func:`mask_hash`), grown by
  :class:`vtool.solvers.model.contact.ConfigurationTables` as the run visits
  new configurations;
* :class:`Config`: one configuration's operators (views of its slot);
* :class:`State`: the run's full state and counters (x, v, a, the integer and
  float state slots);
* :class:`Output`: the output buffers (rows, events, peaks);
* :class:`Motion`: a layer state (z, ż, z̈);
* :class:`Scratch`: the run loop's work vectors.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

Problem = namedtuple("Problem", "ip fp cl clf sc sa sb mass")
Tables = namedtuple("Tables", "index ci cm cp mk mon")
Config = namedtuple("Config", "mask ci cm cp mk mon")
State = namedtuple("State", "x v a ist fst")
Output = namedtuple("Output", "t q F c ev_f ev_i peak")
Motion = namedtuple("Motion", "z zd zdd")
Scratch = namedtuple("Scratch", "now end out src0 src1 srco rhs sol L phi phi_start tau closing")


def mask_hash(mask: int, capacity: int) -> int:
    """The first probe of ``mask`` in an index of ``capacity`` (a power of two) entries: the kernel's
    ``find_slot`` computes the same."""
    return (mask ^ (mask >> 7) ^ (mask >> 17)) & (capacity - 1)


def motion(n: int) -> Motion:
    return Motion(np.zeros(n), np.zeros(n), np.zeros(n))


def scratch(n: int, ns: int, ncl: int) -> Scratch:
    """The run loop's work vectors for n coordinates, ns sources and ncl clearances."""
    return Scratch(motion(n), motion(n), motion(n), np.zeros(3 * ns), np.zeros(3 * ns), np.zeros(3 * ns),
                   np.zeros(n + ncl), np.zeros(n), np.zeros((n, n)), np.zeros(ncl), np.zeros(ncl),
                   np.zeros(ncl), np.zeros(ncl, dtype=np.int64))
