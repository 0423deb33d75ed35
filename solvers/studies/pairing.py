"""Pairing the events of two runs of one mechanism: which event of one is which event of the other.

Two runs of the same mechanism (two back ends, two steps) produce event lists
that mostly agree, but one may have an extra micro-separation or miss one.
Pairing events in sequence order then pairs events a cycle apart once the
sequences differ. Events are paired by time instead:

* only events of the same clearance and kind (``closed``, ``opened``,
  ``released``) can be partners;
* reference event i of such a group, at time t_i, owns the window
  |t − t_i| < w_i with

      w_i = max(½ min(t_i − t_{i−1}, t_{i+1} − t_i), resolution)

  over its neighbours of the same clearance and kind in the reference (a
  group of one event: ½ of the reference's duration). Above the resolution
  the windows of one group never overlap, so no event lies in two windows;
  ``resolution`` (the caller's: ``accuracy`` uses 0.1° of cam rotation)
  covers the bursts of contacts a few microseconds apart that a run places
  as a whole slightly earlier or later;
* within each group the pairs keep the order of both runs and are the most
  pairs possible inside the windows, and among those the ones with the least
  total |Δt| (dynamic programming); for well-separated events that is the
  nearest event in the window. Reference events without a partner are
  *missing*, events of the other run without one are *extra*; both are
  unmatched.

Angle errors are then taken over the pairs only, and the unmatched events are
counted beside them.
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

from vtool.solvers.trace import Event


@dataclass(frozen=True)
class EventPairing:
    """Pairs ``(i, j)``: reference event i is event j of the other run (indices into the lists)."""

    pairs: tuple[tuple[int, int], ...]
    missing: tuple[int, ...]  # reference events without a partner
    extra: tuple[int, ...]  # events of the other run without a partner

    @property
    def unmatched(self) -> int:
        return len(self.missing) + len(self.extra)


def pair_events(
    reference: Sequence[Event], other: Sequence[Event], duration: float | None = None, resolution: float = 0.0
) -> EventPairing:
    """Pair ``other``'s events with ``reference``'s (see the module doc).

    ``duration`` (s) sets the window of an event that is alone of its clearance
    and kind in the reference (half of it); default: the span of the reference's
    event times. ``resolution`` (s) is the smallest window: the spacing of a
    burst of contacts microseconds apart is below any run's resolution.
    """
    if duration is None:
        times = [e.time for e in reference]
        duration = max(times) - min(times) if times else 0.0
    ours: dict[tuple[str, str], list[int]] = defaultdict(list)
    for j, e in enumerate(other):
        ours[(e.clearance, e.kind)].append(j)
    theirs: dict[tuple[str, str], list[int]] = defaultdict(list)
    for i, e in enumerate(reference):
        theirs[(e.clearance, e.kind)].append(i)
    pairs: list[tuple[int, int]] = []
    for key, indices in theirs.items():
        order = sorted(ours.get(key, []), key=lambda j: other[j].time)
        t = [reference[i].time for i in indices]
        s = [other[j].time for j in order]
        windows = []
        for n in range(len(t)):
            gaps = [t[n] - t[n - 1]] if n > 0 else []
            gaps += [t[n + 1] - t[n]] if n + 1 < len(t) else []
            windows.append(max(0.5 * (min(gaps) if gaps else duration), resolution))
        pairs += [(indices[a], order[b]) for a, b in _aligned(t, s, windows)]
    paired = {j for _, j in pairs}
    missing = sorted(set(range(len(reference))) - {i for i, _ in pairs})
    extra = [j for j in range(len(other)) if j not in paired]
    return EventPairing(tuple(sorted(pairs)), tuple(missing), tuple(extra))


def _aligned(t: list[float], s: list[float], windows: list[float]) -> list[tuple[int, int]]:
    """The order-keeping pairs (a, b), |t_a − s_b| < windows[a] (or equal), most pairs, then least Σ|Δt|.

    Dynamic programming over the two time-sorted lists; only pairs inside a
    window are candidates, so a burst shifted as a whole keeps its order.
    """
    n, m = len(t), len(s)
    # best[a][b]: (pairs, -sum |dt|) over t[:a], s[:b]
    best = [[(0, 0.0)] * (m + 1) for _ in range(n + 1)]
    for a in range(1, n + 1):
        lo = bisect_left(s, t[a - 1] - windows[a - 1])
        hi = bisect_right(s, t[a - 1] + windows[a - 1])
        row, above = best[a], best[a - 1]
        for b in range(1, m + 1):
            candidate = max(above[b], row[b - 1])
            if lo <= b - 1 < hi:
                dt = abs(t[a - 1] - s[b - 1])
                if dt < windows[a - 1] or dt == 0.0:
                    diagonal = above[b - 1]
                    candidate = max(candidate, (diagonal[0] + 1, diagonal[1] - dt))
            row[b] = candidate
    result = []
    a, b = n, m
    while a > 0 and b > 0:
        if best[a][b] == best[a - 1][b]:
            a -= 1
        elif best[a][b] == best[a][b - 1]:
            b -= 1
        else:
            result.append((a - 1, b - 1))
            a, b = a - 1, b - 1
    return result[::-1]
