"""Summary counts that mean something: physical episodes, and no ping-pong with the local law."""

from __future__ import annotations

import pytest

from vtool.presets import load_preset
from vtool.solvers.run import simulate
from vtool.solvers.trace import CLOSED, EPISODE_WINDOW_DEG, OPENED, RELEASED

PRESETS = ["gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-1d", "gnilka-2", "gnilka-3"]


@pytest.fixture(scope="module")
def traces() -> dict:
    return {name: simulate(load_preset(name)) for name in PRESETS}


@pytest.mark.parametrize("name", PRESETS)
def test_local_law_has_no_ping_pong(traces: dict, name: str) -> None:
    """No opening caused by an impact elsewhere that re-closes within 0.1 degrees."""
    trace = traces[name]
    impacts = [e for e in trace.events if e.kind == CLOSED]
    for e in trace.events:
        if e.kind not in (OPENED, RELEASED):
            continue
        caused = any(i.clearance != e.clearance and abs(i.time - e.time) < 1e-12 for i in impacts)
        reclosed = any(r.clearance == e.clearance and r.kind == CLOSED and 0 < r.cam_angle - e.cam_angle <= 0.1
                       for r in trace.events)
        assert not (caused and reclosed), f"{name}: {e.clearance} at {e.cam_angle:.4f} deg"


def hand_count(events: list[tuple[float, str]], closed_at_start: bool) -> dict[str, int]:
    """Episodes of one clearance counted the way a person reads an event list."""
    counts = {"separation": 0, "impact": 0, "bounce": 0, "flicker": 0}
    state = closed_at_start
    i = 0
    while i < len(events):
        j = i
        while j + 1 < len(events) and events[j + 1][0] - events[j][0] <= EPISODE_WINDOW_DEG:
            j += 1
        after = events[j][1] == CLOSED
        kind = {(True, False): "separation", (False, True): "impact", (False, False): "bounce",
                (True, True): "flicker"}[(state, after)]
        counts[kind] += 1
        state, i = after, j + 1
    return counts


def test_episode_counts_equal_a_hand_count_of_the_1b_event_list(traces: dict) -> None:
    trace = traces["gnilka-1b"]
    summary = {c["clearance"]: c for c in trace.summary()["clearances"]}
    rocker = [(e.cam_angle, e.kind) for e in trace.events if e.clearance == "rocker"]
    # what the list shows: the rocker opens twice, and after each opening it hits, springs open at once
    # (a bounce, within 0.1 deg) and settles; every cam event is its own episode
    assert [k for _, k in rocker] == [OPENED, CLOSED, OPENED, CLOSED] * 2
    assert hand_count(rocker, True) == {"separation": 2, "impact": 2, "bounce": 2, "flicker": 0}
    for name in ("cam", "rocker"):
        events = [(e.cam_angle, e.kind) for e in trace.events if e.clearance == name]
        assert summary[name]["episodes"] == hand_count(events, True)
        assert summary[name]["events"] == len(events)
