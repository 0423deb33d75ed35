"""Warnings where a run's result is not to be trusted (solvers/model/preflight.py, solvers/run.py).

* e = 1 under the local (or thesis) impact law does not conserve kinetic
  energy with the consistent mass matrix; the momentum law does
  (tests/test_impact_laws.py checks both laws' single impacts).
* A nearly undamped long run depends on the back end and the step: on
  gnilka-1a with the damping factor 0, newmark, exact and scipy give peak
  rocker forces of about 14, 94 and 86 klbf over four revolutions.
"""

from __future__ import annotations

import dataclasses
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


def test_contact_forces_of_the_wrong_sign_are_flagged_in_the_trace() -> None:
    """scipy at rtol 1e-6 misses a rocker release on gnilka-3 (the force crosses zero and back within one
    of its steps) and carries about -1 klbf on the closed rocker; newmark releases it."""
    from vtool.solvers import backends

    spec = short(thesis_doc("gnilka-3"), 850.0)
    scipy_spec = spec_from({**thesis_doc("gnilka-3"), "run": {**thesis_doc("gnilka-3")["run"], "backend": "scipy"}})
    options = dataclasses.replace(backends.get("scipy")().options_from_run(scipy_spec.run), rtol=1e-6)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        trace = simulate(scipy_spec, options=options)
    summary = trace.summary()
    rocker = next(c for c in summary["clearances"] if c["clearance"] == "rocker")
    assert rocker["tensile_force"] < -500.0
    assert all(c["tensile_force"] == 0.0 for c in summary["clearances"] if c["clearance"] != "rocker")
    flagged = [str(w.message) for w in caught if str(w.message).startswith("contact forces of the wrong sign: F2 ")]
    assert len(flagged) == 1 and "scipy back end missed" in flagged[0] and summary["warnings"] == flagged
    newmark = simulate(spec)
    assert not newmark.tensile_forces().any() and newmark.summary()["warnings"] == []


def test_scipy_on_stiff_contacts_is_refused_before_it_runs_for_minutes() -> None:
    """Every contact of gnilka-1a linear at k = 1e13 lbf/in: omega_max about 8e8 rad/s, 2.3e7 samples for
    720 deg (newmark's limit would let it run; scipy takes about 0.16 ms a sample: an hour)."""
    from vtool.solvers.cost import MAX_SCIPY_STEPS, CostError

    doc = thesis_doc("gnilka-1a")
    doc["run"].update(degrees=720.0, backend="scipy")
    for c in doc["clearances"]:
        c.update(contact="linear", contact_stiffness=1e13, contact_damping_ratio=1.0)
    with pytest.raises(CostError) as info:
        simulate(spec_from(doc))
    line = info.value.one_line()
    assert line.startswith("run too large: ") and f"more than the limit of {MAX_SCIPY_STEPS:.3g} steps" in line
    doc["run"]["backend"] = "newmark"  # the same run on newmark is within its own limit: not refused here
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.run import run_cost

    assert run_cost(assemble(spec_from(doc))).steps < 5e7
