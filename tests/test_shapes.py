"""Deformed shapes: ends follow their coordinates, joints stay joined."""

from __future__ import annotations

import numpy as np

from vtool.presets import load_preset
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.shapes import deformed_members


def test_member_ends_follow_the_system_coordinates_at_the_static_start() -> None:
    spec = load_preset("gnilka-1a")
    q = assemble(spec).start.q
    shapes = deformed_members(spec, q, scale=1.0)
    pushrod_x, pushrod_y = shapes["pushrod"]
    left_x, left_y = shapes["left_rocker"]
    right_x, right_y = shapes["right_rocker"]
    valve_x, valve_y = shapes["valve"]
    assert np.isclose(pushrod_y[0], -9.0 + q[0]) and np.isclose(pushrod_y[-1], q[7])
    assert np.isclose(left_y[0], q[1]) and left_y[-1] == 0.0  # pivot fixed
    assert right_y[0] == 0.0 and np.isclose(right_y[-1], q[3])
    assert np.allclose(pushrod_x, 0.0) and np.allclose(valve_x, 2.5) and np.allclose(right_x, np.linspace(1, 2.5, 21))
    assert np.allclose(left_x, np.linspace(0, 1, 21))
    assert np.isclose(valve_y[-1], q[3]) and np.isclose(valve_y[0], -3.0 - q[6])  # q7 points down
    assert q[1] > 0 > q[3]  # the cam lifts the left tip and the rocker pushes the valve down
    assert np.isclose(pushrod_y[-1], left_y[0])  # rocker closed: pushrod top on the left tip
