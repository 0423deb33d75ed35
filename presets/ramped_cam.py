"""The lift table of the shipped ``ramped-cam`` preset: dwell, ramps and a polydyne flank.

Run ``python -m vtool.presets.ramped_cam`` to rewrite ``presets/ramped-cam.csv``
(a test checks that the shipped file is what this script writes).

The lift is symmetric about the nose, placed at the preset's angle zero (so
the run starts with the valve open, as the thesis' runs do). Going from the
base circle towards the nose, with φ the cam angle from the start of the
event:

* opening ramp, 0 <= φ <= β_r: the velocity dL/dφ rises from 0 to the ramp
  velocity v_r along a cycloid, v = v_r (x - sin 2πx / 2π), x = φ/β_r, so
  L = v_r β_r (x²/2 + (cos 2πx - 1)/4π²); the ramp height is h_r = v_r β_r / 2.
  The acceleration v_r (1 - cos 2πx)/β_r and the jerk are 0 at both ends.
* flank, 0 <= u <= β_f from the end of the ramp to the nose: the polydyne
  polynomial L(u) = Σ_{j=0..6} p_j u^j that meets the ramp with L = h_r,
  L' = v_r, L'' = 0, L''' = 0 and the nose with L = h, L' = 0, L''' = 0
  (symmetry), so lift, velocity, acceleration and jerk are continuous.
* dwell on the base circle (L = 0) for the rest of the revolution.

Angles are cam degrees; lifts are in inches at the follower (gnilka-1a's
mechanism, rocker ratio 1.5: the valve lifts 1.5 times as much).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

LIFT = 0.40  # in, follower lift at the nose
RAMP_HEIGHT = 0.012  # in, above the preset's 0.008 in lash
RAMP_DEG = 15.0  # cam deg, each ramp
FLANK_DEG = 55.0  # cam deg, ramp end to nose
STEP_DEG = 1.0  # table spacing
CSV = Path(__file__).with_name("ramped-cam.csv")


def flank_coefficients(h: float, h_r: float, v_r: float, beta_f: float) -> np.ndarray:
    """p_0..p_6 of the flank polynomial (module doc), u in rad."""
    rows, rhs = [], []
    for u, derivative, value in ((0.0, 0, h_r), (0.0, 1, v_r), (0.0, 2, 0.0), (0.0, 3, 0.0),
                                 (beta_f, 0, h), (beta_f, 1, 0.0), (beta_f, 3, 0.0)):
        row = [0.0] * 7
        for j in range(derivative, 7):
            row[j] = math.perm(j, derivative) * u ** (j - derivative)
        rows.append(row)
        rhs.append(value)
    return np.linalg.solve(np.array(rows), np.array(rhs))


def ramped_lift(angles_deg: np.ndarray, lift: float = LIFT, ramp_height: float = RAMP_HEIGHT,
                ramp_deg: float = RAMP_DEG, flank_deg: float = FLANK_DEG) -> np.ndarray:
    """Lift at cam angles (deg from the nose); by default the shipped table's (in).

    The train types' ``law = "polydyne"`` (:mod:`vtool.presets.trains`) passes
    its own lift and ramp height (length units) and ramp and flank angles (cam deg).
    """
    beta_r, beta_f = math.radians(ramp_deg), math.radians(flank_deg)
    v_r = 2.0 * ramp_height / beta_r
    p = flank_coefficients(lift, ramp_height, v_r, beta_f)
    distance = np.radians(np.abs((np.asarray(angles_deg, dtype=float) + 180.0) % 360.0 - 180.0))
    phi = beta_r + beta_f - distance  # from the start of the opening ramp
    x = np.clip(phi / beta_r, 0.0, 1.0)
    ramp = v_r * beta_r * (x**2 / 2 + (np.cos(2 * math.pi * x) - 1) / (4 * math.pi**2))
    flank = np.polynomial.polynomial.polyval(phi - beta_r, p)
    return np.where(phi <= 0.0, 0.0, np.where(phi < beta_r, ramp, flank))


def table_text() -> str:
    angles = np.arange(0.0, 360.0, STEP_DEG)
    lines = ["cam_angle_deg,lift_in"]
    lines += [f"{a:g},{lift:.9f}" for a, lift in zip(angles, ramped_lift(angles), strict=True)]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    from vtool.files import write_atomic

    write_atomic(CSV, table_text())
    print(f"wrote {CSV}")
