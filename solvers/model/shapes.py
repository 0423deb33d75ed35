"""Deformed member shapes for drawings and animations (thesis subroutines BAR4, JOINT, AGT).

Each member is drawn from its element shape functions: a bar's axial
displacement is linear along its axis; a beam's transverse deflection is the
cubic Hermite interpolation of its end deflections and rotations, drawn at
+90 degrees to its axis. Displacements are multiplied by ``scale`` (the
thesis' display also used large scale factors). Members without a
``position`` are not drawn.
"""

from __future__ import annotations

import math

import numpy as np

from vtool.solvers.model.spec import BAR, MechanismSpec


def element_values(coordinate_map: tuple[int, ...], q: np.ndarray) -> np.ndarray:
    """u = β q for one member (q over the elastic coordinates, 0-based array)."""
    return np.array([q[abs(c) - 1] * (1.0 if c > 0 else -1.0) if c else 0.0 for c in coordinate_map])


def hermite(s: np.ndarray, L: float, w_a: float, w_b: float, theta_a: float, theta_b: float) -> np.ndarray:
    """Cubic Hermite deflection at s in [0, L] from end deflections and rotations."""
    xi = s / L
    h1 = 1 - 3 * xi**2 + 2 * xi**3
    h2 = L * (xi - 2 * xi**2 + xi**3)
    h3 = 3 * xi**2 - 2 * xi**3
    h4 = L * (-(xi**2) + xi**3)
    return h1 * w_a + h2 * theta_a + h3 * w_b + h4 * theta_b


def deformed_members(
    spec: MechanismSpec, q: np.ndarray, scale: float = 1.0, points: int = 21
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Polylines (x, y) of every placed member at the state q (elastic coordinates)."""
    shapes = {}
    for member in spec.members:
        if member.position is None:
            continue
        angle = math.radians(member.direction)
        axis = np.array([math.cos(angle), math.sin(angle)])
        normal = np.array([-axis[1], axis[0]])
        s = np.linspace(0.0, member.length, points)
        u = element_values(member.coordinates, q) * scale
        if member.element == BAR:
            along = s + u[0] + (u[1] - u[0]) * s / member.length
            across = np.zeros_like(s)
        else:
            along = s
            across = hermite(s, member.length, u[0], u[1], u[2], u[3])
        xy = np.asarray(member.position)[:, None] + axis[:, None] * along + normal[:, None] * across
        shapes[member.name] = (xy[0], xy[1])
    return shapes
