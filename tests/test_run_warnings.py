"""Warnings where a run's result is not to be trusted (solvers/model/preflight.py, solvers/run.py).

* e = 1 under the local (or thesis) impact law does not conserve kinetic
  energy with the consistent mass matrix; the momentum law does
  (tests/test_impact_laws.py checks both laws' single impacts).
* A nearly undamped long run depends on the back end and the step: on
  gnilka-1a with the damping factor 0, newmark, exact and scipy give peak
  rocker forces of about 14, 94 and 86 klbf over four revolutions.
"""

from __future__ import annotations

import warnings

import pytest

from tests.valvetrain_cases import spec_from, thesis_doc
from vtool.errors import PresetWarning
from vtool.solvers.model.spec import MechanismSpec
from vtool.solvers.run import simulate


def run_messages(spec: MechanismSpec) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(spec)
    return [str(w.message) for w in caught if issubclass(w.category, PresetWarning)]


def short(doc: dict, degrees: float = 20.0) -> MechanismSpec:
    doc["run"]["degrees"] = degrees
    return spec_from(doc)


@pytest.mark.parametrize("law", ["local", "thesis"])
def test_restitution_one_under_a_law_that_does_not_conserve_energy_warns(law: str) -> None:
    doc = thesis_doc("gnilka-1a")
    doc["contact"]["impact"] = law
    doc["clearances"][2]["restitution"] = 1.0
    messages = [m for m in run_messages(short(doc)) if m.startswith("restitution:")]
    assert messages == [f"restitution: 1 at seat ({law}): these impact laws do not conserve kinetic energy with "
                        f"the consistent mass matrix (the energy drifts from impact to impact); "
                        f'impact = "momentum" does']


def test_restitution_one_under_the_momentum_law_or_below_one_does_not_warn() -> None:
    doc = thesis_doc("gnilka-1a")
    doc["clearances"][2].update(restitution=1.0, impact="momentum")
    assert run_messages(short(doc)) == []
    doc = thesis_doc("gnilka-1a")
    doc["clearances"][2]["restitution"] = 0.9
    assert run_messages(short(doc)) == []


def test_a_long_undamped_run_warns_that_back_ends_may_differ() -> None:
    doc = thesis_doc("gnilka-1a")
    doc["damping"]["factor"] = 0.0
    messages = run_messages(short(doc, 400.0))
    assert len(messages) == 1 and messages[0].startswith(
        "damping: a modal damping ratio of 0 (below 0.01) over 400 deg: a nearly undamped run is sensitive to "
        "the back end and the step")
    assert run_messages(short(thesis_doc("gnilka-1a"), 400.0)) == []  # damped (0.1): no warning
    assert run_messages(short(doc, 300.0)) == []  # shorter than a revolution: no time to drift apart
