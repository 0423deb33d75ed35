"""Small valve-train documents for tests: an oscillator on a spring, variants of the thesis presets."""

from __future__ import annotations

import copy
import math

from vtool.presets import PRESET_DIR, load_document, read_document
from vtool.solvers.model.spec import MechanismSpec

SDOF_STIFFNESS = 1000.0  # lbf/in
SDOF_MASS = 3.0e-3  # lbf s^2/in, member total; consistent mass puts m/3 at the free end
SDOF_OMEGA = math.sqrt(SDOF_STIFFNESS / (SDOF_MASS / 3.0))  # rad/s


def sdof_doc(*, amplitude: float = 0.01, rpm: float = 1e-3, degrees: float = 1e-4, time_step: float = 1e-5,
             beta: float = 0.25, damping: float = 0.0, restitution: float = 0.0, seat: float | None = None) -> dict:
    """One coordinate on a grounded spring. The cam is removed (never touched);
    the static start displaces q1 by the cam amplitude, with (tiny) cam velocity."""
    doc = {
        "kind": "valvetrain", "title": "oscillator", "units": "in-lbf-s",
        "coordinates": [{"name": "mass", "motion": "translation"}],
        "members": {"spring": {"element": "bar", "length": 1.0, "stiffness": SDOF_STIFFNESS,
                               "mass": SDOF_MASS, "area": 1.0, "coordinates": [0, 1]}},
        "cam": {"coordinate": 2, "amplitude": amplitude},
        "clearances": [{"name": "cam", "ahead": 1, "behind": 2, "kind": "external", "state": "removed"}],
        "initial": {"closed": [], "spring_preload": 0.0, "lever_ratio": 1.0},
        "damping": {"default_ratio": damping},
        "run": {"rpm": rpm, "degrees": degrees, "time_step": time_step, "beta": beta, "gamma": 0.5},
    }
    if seat is not None:
        doc["seat"] = {"coordinate": 3, "position": seat}
        doc["clearances"].append({"name": "seat", "ahead": 1, "behind": 3, "kind": "external",
                                  "restitution": restitution})
    return doc


def thesis_doc(name: str) -> dict:
    return copy.deepcopy(read_document(PRESET_DIR / f"{name}.toml"))


def spec_from(doc: dict) -> MechanismSpec:
    return load_document(doc)


def base_excited_response(mechanism, t, x0: float, v0: float, amplitude: float = 0.01):  # noqa: ANN001, ANN201
    """Closed form (x, a) of the mass q2 of the base-excited oscillator (test_backends.base_excited_doc),
    the follower q1 riding the cam x1 = amplitude sin ωt + offset, from x2(0) = x0, x2'(0) = v0."""
    import numpy as np

    M, K = mechanism.M, mechanism.K
    omega_cam, offset = mechanism.omega, mechanism.start.cam_offset
    w2 = K[1, 1] / M[1, 1]
    forcing_0 = -K[1, 0] * offset / M[1, 1]
    forcing_s = (-K[1, 0] + M[1, 0] * omega_cam**2) * amplitude / M[1, 1]
    steady_s = forcing_s / (w2 - omega_cam**2)
    c1 = x0 - forcing_0 / w2
    c2 = (v0 - steady_s * omega_cam) / math.sqrt(w2)
    free = c1 * np.cos(math.sqrt(w2) * t) + c2 * np.sin(math.sqrt(w2) * t)
    x = forcing_0 / w2 + steady_s * np.sin(omega_cam * t) + free
    a = -omega_cam**2 * steady_s * np.sin(omega_cam * t) - w2 * free
    return x, a
