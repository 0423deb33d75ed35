"""Impact laws against hand calculations on two- and three-mass chains (Gnilka eqs. 3.53, 3.54; Newton).

Chains: q1 and q2 joined by a bar (consistent mass couples them), q2 on a
spring to ground; the cam (q4) faces q1 through an external clearance. The
three-mass chain adds q3 on its own spring, facing q2 through an internal
clearance. The hand calculations use the diagonal masses M_aa of the
assembled mass matrix.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.valvetrain_cases import spec_from
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import assemble

BAR = {"element": "bar", "length": 2.0, "area": 0.1, "modulus": 3.0e7, "density": 7.3e-4}
SPRING = {"element": "bar", "length": 1.0, "stiffness": 500.0, "mass": 1.0e-3, "area": 1.0}


def chain_doc(masses: int, law: str, restitution: float, scale: float = 1.0) -> dict:
    cam = masses + 1
    doc = {
        "kind": "valvetrain", "title": "chain", "units": "in-lbf-s",
        "coordinates": [{"name": f"m{i}", "motion": "translation"} for i in range(1, masses + 1)],
        "members": {"rod": dict(BAR, coordinates=[1, 2]), "spring2": dict(SPRING, coordinates=[2, 0])},
        "cam": {"coordinate": cam, "amplitude": 0.01},
        "clearances": [{"name": "cam", "ahead": 1, "behind": cam, "kind": "external",
                        "restitution": restitution}],
        "initial": {"closed": ["cam"], "spring_preload": 10.0, "lever_ratio": 1.0},
        "contact": {"impact": law, "rocker_scale": scale},
        "damping": {"default_ratio": 0.0},
        "run": {"rpm": 1.0, "degrees": 1.0, "time_step": 1e-6},
    }
    if masses == 3:
        doc["members"]["spring3"] = dict(SPRING, coordinates=[0, 3])
        doc["clearances"].append({"name": "joint", "ahead": 3, "behind": 2, "kind": "internal",
                                  "restitution": restitution})
        doc["initial"]["closed"] = ["cam", "joint"]
    return doc


def problem_of(doc: dict) -> ContactProblem:
    return ContactProblem(assemble(spec_from(doc)))


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_local_external_impact_changes_exactly_one_velocity(e: float) -> None:
    problem = problem_of(chain_doc(2, "local", e))
    v = np.array([-30.0, 7.0])
    x = np.zeros(2)
    w = problem.sources_at(0.0)[1]  # the cam's velocity at t = 0
    mask, events = problem.impact(0, [0], 0.0, x, v)
    assert v[1] == 7.0  # the neighbour across the consistent-mass bar keeps its velocity
    assert v[0] == pytest.approx(w - e * (-30.0 - w), rel=1e-14)
    assert events[0][:2] == (0, "closed") and events[0][2] == pytest.approx(-30.0 - w)
    assert mask == (1 if e == 0.0 else 0)


def test_local_elastic_impact_keeps_the_impacting_pair_energy() -> None:
    problem = problem_of(chain_doc(2, "local", 1.0))
    w = problem.sources_at(0.0)[1]
    v = np.array([w - 25.0, 3.0])
    problem.impact(0, [0], 0.0, np.zeros(2), v)
    assert (v[0] - w) ** 2 == pytest.approx(25.0**2, rel=1e-12)  # relative speed kept: pair energy in the cam frame


@pytest.mark.parametrize("e", [0.0, 0.7, 1.0])
def test_local_internal_impact_conserves_the_merged_momentum(e: float) -> None:
    problem = problem_of(chain_doc(3, "local", e))
    M = problem.mass[0]
    m2, m3 = M[1, 1], M[2, 2]
    v = np.array([4.0, 10.0, -20.0])  # q3 approaches q2: gap q3 - q2 closing at -30
    cam_open = 0b01  # only the joint's bit may change; the cam is open
    mask, events = problem.impact(0, [1], 0.0, np.zeros(3), v)
    assert v[0] == 4.0
    assert m2 * v[1] + m3 * v[2] == pytest.approx(m2 * 10.0 + m3 * -20.0, rel=1e-12)
    assert v[2] - v[1] == pytest.approx(-e * (-30.0), abs=1e-12)
    if e == 1.0:  # elastic: the pair's kinetic energy (diagonal masses) is kept
        assert m2 * v[1] ** 2 + m3 * v[2] ** 2 == pytest.approx(m2 * 100.0 + m3 * 400.0, rel=1e-12)
    assert mask & cam_open == (1 if e == 0.0 else 0)
    assert events[0][1] == "closed"


def test_thesis_law_gives_the_pair_scale_times_the_ahead_velocity() -> None:
    problem = problem_of(chain_doc(3, "thesis", 0.0, scale=1.3))
    v = np.array([4.0, 10.0, -20.0])
    problem.impact(0, [1], 0.0, np.zeros(3), v)
    assert v[1] == pytest.approx(1.3 * -20.0) and v[2] == pytest.approx(1.3 * -20.0) and v[0] == 4.0


@pytest.mark.parametrize("e", [0.0, 1.0])
def test_momentum_law_conserves_generalised_momentum(e: float) -> None:
    problem = problem_of(chain_doc(3, "momentum", e))
    M = problem.mass[0]
    v0 = np.array([4.0, 10.0, -20.0])
    v = v0.copy()
    problem.impact(0, [1], 0.0, np.zeros(3), v)
    impulse = M @ (v - v0)  # generalised impulse: +P on q3, -P on q2, nothing on q1
    assert impulse[0] == pytest.approx(0.0, abs=1e-12 * np.abs(M @ v0).max())
    assert impulse[1] == pytest.approx(-impulse[2], rel=1e-10)
    assert v[2] - v[1] == pytest.approx(-e * (-30.0), abs=1e-9)
    if e == 1.0:  # elastic: the whole system's kinetic energy is kept
        assert v @ M @ v == pytest.approx(v0 @ M @ v0, rel=1e-12)
