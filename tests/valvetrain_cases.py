"""Small valve-train documents for tests: an oscillator on a spring, variants of the thesis presets."""

from __future__ import annotations

import copy
import math

from vtool.presets import PRESET_DIR, load_document, read_document
from vtool.solvers.spec import MechanismSpec

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
