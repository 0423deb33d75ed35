"""Compliant (linear spring-dashpot) contacts: a drop test against its closed form, every back end.

The drop test: one mass m on a soft spring k_s (tests.valvetrain_cases.sdof_doc),
released from rest 0.01 in above a seat at 0 whose contact is a spring k_c
and a dashpot c. While the mass overlaps the seat (x < 0),

    m ẍ + c ẋ + (k_s + k_c) x = 0,   x(0) = 0,  ẋ(0) = -v0

so x(t) = -(v0/ω_d) e^{-ζ ω_n t} sin ω_d t with ω_n² = (k_s + k_c)/m,
ζ = c / (2 m ω_n), ω_d = ω_n √(1 - ζ²): the contact lasts π/ω_d and the
mass leaves with v0 · exp(-ζ ω_n π/ω_d) (the rebound velocity).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tests.valvetrain_cases import SDOF_MASS, SDOF_STIFFNESS, sdof_doc, spec_from
from vtool.errors import InputError
from vtool.solvers import backends
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.trace import CLOSED, OPENED

K_CONTACT = 1.0e6  # lbf/in
RATIO = 0.2  # of critical, on the seat's local mass (the mass itself here)
TOLERANCE = {"exact": 1e-8, "scipy": 1e-5, "newmark": 1e-4}


def drop_doc(ratio: float = RATIO) -> dict:
    doc = sdof_doc(seat=0.0, time_step=1e-7, degrees=5e-5)
    doc["clearances"][1].update(contact="linear", contact_stiffness=K_CONTACT, contact_damping_ratio=ratio)
    return doc


def closed_form(ratio: float) -> tuple[float, float]:
    """(contact duration s, rebound velocity / approach velocity)."""
    m = SDOF_MASS / 3.0
    c = 2.0 * ratio * math.sqrt(K_CONTACT * m)
    omega_n = math.sqrt((SDOF_STIFFNESS + K_CONTACT) / m)
    zeta = c / (2.0 * m * omega_n)
    omega_d = omega_n * math.sqrt(1.0 - zeta**2)
    return math.pi / omega_d, math.exp(-zeta * omega_n * math.pi / omega_d)


def first_contact(name: str, ratio: float = RATIO):  # noqa: ANN201
    spec = spec_from(drop_doc(ratio))
    backend = backends.get(name)()
    options = backend.options_from_run(spec.run)
    if name == "scipy":
        options = type(options)(**{**options.__dict__, "rtol": 1e-10})
    trace = backend.simulate(assemble(spec), options)
    seat = [e for e in trace.events if e.clearance == "seat"]
    closing = next(e for e in seat if e.kind == CLOSED)
    opening = next(e for e in seat if e.kind == OPENED and e.time > closing.time)
    return trace, closing, opening


@pytest.mark.parametrize("name", backends.available())
def test_drop_test_matches_the_closed_form(name: str) -> None:
    trace, closing, opening = first_contact(name)
    duration, rebound = closed_form(RATIO)
    tolerance = TOLERANCE.get(name, 1e-4)
    assert opening.time - closing.time == pytest.approx(duration, rel=tolerance)
    assert opening.relative_velocity / -closing.relative_velocity == pytest.approx(rebound, rel=tolerance)
    # the approach velocity is the free fall on the soft spring: v0 = ω_s · 0.01 in
    assert -closing.relative_velocity == pytest.approx(0.01 * math.sqrt(SDOF_STIFFNESS / (SDOF_MASS / 3)),
                                                       rel=1e-3)
    peak_overlap, peak_force = closed_form_peaks(RATIO, -closing.relative_velocity)
    summary = {c["clearance"]: c for c in trace.summary()["clearances"]}["seat"]
    assert summary["contact"] == "linear"
    assert summary["peak_overlap"] == pytest.approx(peak_overlap, rel=max(tolerance, 1e-6) * 10)
    assert summary["peak_force"] == pytest.approx(peak_force, rel=max(tolerance, 2e-5) * 10)


def closed_form_peaks(ratio: float, v0: float) -> tuple[float, float]:
    """(peak overlap, peak contact force k x + c ẋ) over the closed form's contact, approached at v0."""
    m = SDOF_MASS / 3.0
    c = 2.0 * ratio * math.sqrt(K_CONTACT * m)
    omega_n = math.sqrt((SDOF_STIFFNESS + K_CONTACT) / m)
    zeta = c / (2.0 * m * omega_n)
    omega_d = omega_n * math.sqrt(1.0 - zeta**2)
    t = np.linspace(0.0, closed_form(ratio)[0], 200001)
    overlap = v0 / omega_d * np.exp(-zeta * omega_n * t) * np.sin(omega_d * t)
    rate = np.gradient(overlap, t)
    return float(overlap.max()), float((K_CONTACT * overlap + c * rate).max())


def test_exact_peak_force_of_a_contact_shorter_than_one_scan_interval() -> None:
    """A scan interval of a whole period (``scan_fraction`` 1): the contact (half a period) closes and
    opens with no scan sample in between. The peak force and overlap between the two events are still
    the closed form's (issue 37: the exact back end read them only at the samples and the event, so
    a stiff contact's force peak just after it closed, before the next event, was lost)."""
    spec = spec_from(drop_doc())
    backend = backends.get("exact")()
    options = dataclasses.replace(backend.options_from_run(spec.run), scan_fraction=1.0)
    trace = backend.simulate(assemble(spec), options)
    seat = [e for e in trace.events if e.clearance == "seat"]
    closing = next(e for e in seat if e.kind == CLOSED)
    opening = next(e for e in seat if e.kind == OPENED and e.time > closing.time)
    assert opening.time - closing.time == pytest.approx(closed_form(RATIO)[0], rel=1e-8)
    peak_overlap, peak_force = closed_form_peaks(RATIO, -closing.relative_velocity)
    summary = {c["clearance"]: c for c in trace.summary()["clearances"]}["seat"]
    assert summary["peak_overlap"] == pytest.approx(peak_overlap, rel=1e-5)
    assert summary["peak_force"] == pytest.approx(peak_force, rel=2e-4)


def test_an_undamped_contact_returns_the_approach_velocity() -> None:
    _, closing, opening = first_contact("exact", ratio=0.0)
    assert opening.relative_velocity == pytest.approx(-closing.relative_velocity, rel=1e-9)


def test_contact_keys_are_checked_in_one_line() -> None:
    doc = drop_doc()
    doc["clearances"][1]["contact_stiffness"] = -1.0
    with pytest.raises(InputError, match="contact_stiffness"):
        spec_from(doc)
    doc = drop_doc()
    doc["clearances"][1]["contact_damping"] = 3.0
    with pytest.raises(InputError, match="not both"):
        spec_from(doc)
    doc = drop_doc()
    doc["clearances"][1].update(contact="rigid")
    with pytest.raises(InputError, match="rigid contact"):
        spec_from(doc)
    doc = drop_doc()
    doc["clearances"][1].update(contact="hertz")
    with pytest.raises(InputError, match="hertz contact"):  # its damping comes from the restitution
        spec_from(doc)
    doc = drop_doc()
    doc["clearances"][1].update(contact="plastic")
    with pytest.raises(InputError, match="rigid, linear, hertz"):
        spec_from(doc)


# ----- gnilka-1a with every clearance linear (vtool.solvers.studies.compliance; docs/contact.md) -----
def test_stiffer_contacts_approach_the_rigid_momentum_run() -> None:
    from vtool.presets import load_preset
    from vtool.solvers.studies.compliance import figures, with_contacts

    spec = load_preset("gnilka-1a")
    rigid = figures(with_contacts(spec, None, impact="momentum"))
    errors = []
    for k in (1e6, 1e7, 1e8):
        f = figures(with_contacts(spec, k, 1.0))
        errors.append((abs(f.throw_off - rigid.throw_off), abs(f.seating_velocity / rigid.seating_velocity - 1),
                       abs(f.impulse / rigid.impulse - 1), abs(f.seating_angle - rigid.seating_angle)))
    throw_off, velocity, impulse, seating = zip(*errors, strict=True)
    assert throw_off[0] > throw_off[1] > throw_off[2] and throw_off[2] < 0.25  # deg
    assert impulse[0] > impulse[1] > impulse[2] and impulse[2] < 0.01
    assert velocity[2] < min(velocity[:2]) and velocity[2] < 0.001
    assert seating[2] < min(seating[:2]) and seating[2] < 0.05  # deg


def test_exact_and_newmark_agree_on_a_compliant_run() -> None:
    """Same event sequence; Newmark's event angles converge on the exact ones at second order (the
    largest difference is a grazing cam re-contact, 0.49 deg at 0.5 us)."""
    import dataclasses

    from vtool.presets import load_preset
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.compliance import with_contacts

    spec = with_contacts(load_preset("gnilka-1a"), 1e7, 1.0)
    exact = simulate(dataclasses.replace(spec, run=dataclasses.replace(spec.run, backend="exact")))
    worst = []
    for dt in (0.5e-6, 0.25e-6, 0.125e-6):
        newmark = simulate(dataclasses.replace(spec, run=dataclasses.replace(spec.run, time_step=dt)))
        assert [(e.clearance, e.kind) for e in newmark.events] == [(e.clearance, e.kind) for e in exact.events]
        worst.append(max(abs(a.cam_angle - b.cam_angle) for a, b in zip(newmark.events, exact.events, strict=True)))
    assert worst[2] < 0.05  # deg
    assert 3.0 < worst[0] / worst[1] < 5.0 and 3.0 < worst[1] / worst[2] < 5.0
    for a, b in zip(newmark.summary()["clearances"], exact.summary()["clearances"], strict=True):
        assert a["peak_overlap"] == pytest.approx(b["peak_overlap"], rel=0.01)


@pytest.mark.slow
def test_generated_stiffness_study_is_current() -> None:
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    import tables_compliant

    assert tables_compliant.main(check=True) == 0, "run python3 benchmarks/tables_compliant.py"


def test_table_differences_allow_the_last_digits_and_nothing_more() -> None:
    from vtool.markdown import table, table_differences

    committed = table(["contact", "events", "J"], [["k = 1e8", "1757", "0.03560"], ["rigid", "79", "-"]])
    assert table_differences(committed, committed, 5e-3) == []
    near = table(["contact", "events", "J"], [["k = 1e8", "1755", "0.03561"], ["rigid", "79", "-"]])
    assert table_differences(committed, near, 5e-3) == []
    assert table_differences(committed, near, 0.0) == ["line 3, column 2: committed 1757, generated 1755",
                                                       "line 3, column 3: committed 0.03560, generated 0.03561"]
    far = table(["contact", "events", "J"], [["k = 1e8", "1700", "0.03560"], ["rigid", "79", "0"]])
    assert table_differences(committed, far, 5e-3) == ["line 3, column 2: committed 1757, generated 1700",
                                                       "line 4, column 3: committed -, generated 0"]
    assert table_differences(committed, committed + "| one | more | row |\n", 5e-3) == [
        "4 lines committed, 5 generated"]
    bounds = table(["back end", "largest difference"], [["newmark", "< 1e-6"]])
    assert table_differences(bounds, bounds.replace("1e-6", "1e-7"), 0.0, decades=1) == []
    assert table_differences(bounds, bounds.replace("1e-6", "1e-8"), 0.0, decades=1) == [
        "line 3, column 2: committed < 1e-6, generated < 1e-8"]
    assert table_differences(bounds, bounds.replace("1e-6", "1e-7"), 0.0) == [
        "line 3, column 2: committed < 1e-6, generated < 1e-7"]


def test_vtool_solve_reports_the_peak_overlap(tmp_path) -> None:  # noqa: ANN001
    import json

    import tomli_w
    from click.testing import CliRunner

    from tests.valvetrain_cases import thesis_doc
    from vtool.app.cli.main import cli

    doc = thesis_doc("gnilka-1a")
    for c in doc["clearances"]:
        if c["name"] == "seat":
            c.update(contact="linear", contact_stiffness=1e7, contact_damping_ratio=1.0)
    preset = tmp_path / "soft-seat.toml"
    preset.write_text(tomli_w.dumps(doc))
    result = CliRunner().invoke(cli, ["solve", str(preset)])
    assert result.exit_code == 0, result.output
    assert "seat: linear contact, peak overlap" in result.output
    result = CliRunner().invoke(cli, ["solve", str(preset), "--json"])
    seat = next(c for c in json.loads(result.stdout)["clearances"] if c["clearance"] == "seat")
    assert seat["contact"] == "linear" and seat["peak_overlap_unit"] == "in" and 0 < seat["peak_overlap"] < 0.01


# ----- Hertz contacts: F = k δ^n (1 + 3(1 - e)/2 · δ̇/v⁻), Newmark with iteration and scipy -----
def hertz_doc(restitution: float = 1.0, backend: str = "newmark") -> dict:
    """The drop test on a Hertz seat, the mass on a 1 lbf/in spring (its share of the contact force,
    k_s δ / F, is 1.5e-5 at the peak): it reaches the seat at v0 = 0.316 in/s."""
    doc = sdof_doc(seat=0.0, time_step=1e-6, degrees=4e-4)
    doc["members"]["spring"]["stiffness"] = 1.0
    doc["clearances"][1].update(contact="hertz", contact_stiffness=1e7, contact_exponent=1.5,
                                restitution=restitution)
    doc["run"]["backend"] = backend
    return doc


def hertz_contact(restitution: float, backend: str):  # noqa: ANN201
    from vtool.solvers.run import simulate

    trace = simulate(spec_from(hertz_doc(restitution, backend)))
    seat = [e for e in trace.events if e.clearance == "seat"]
    return trace, seat[0], seat[1]


@pytest.mark.parametrize("backend", ["newmark", "scipy"])
def test_hertz_drop_matches_its_closed_form(backend: str) -> None:
    """Elastic Hertz impact (n = 3/2): δ_max = (5 m v0² / 4k)^(2/5), F_max = k δ_max^(3/2), the contact
    lasts 2 δ_max/v0 ∫₀¹ (1 - x^(5/2))^(-1/2) dx = 2 δ_max/v0 · (2/5) B(2/5, 1/2), the mass leaves at v0."""
    from scipy.special import beta

    trace, closing, opening = hertz_contact(1.0, backend)
    m, k, v0 = SDOF_MASS / 3.0, 1e7, -closing.relative_velocity
    delta = (5.0 * m * v0**2 / (4.0 * k)) ** 0.4
    duration = 2.0 * delta / v0 * 0.4 * beta(0.4, 0.5)
    seat = trace.summary()["clearances"][1]
    assert opening.kind == OPENED and closing.kind == CLOSED
    assert opening.time - closing.time == pytest.approx(duration, rel=5e-5)
    assert seat["peak_overlap"] == pytest.approx(delta, rel=5e-5)
    assert seat["peak_force"] == pytest.approx(k * delta**1.5, rel=5e-5)
    assert opening.relative_velocity == pytest.approx(v0, rel=1e-4)


@pytest.mark.parametrize("backend", ["newmark", "scipy"])
@pytest.mark.parametrize("restitution", [0.9, 0.5, 0.2, 0.05])
def test_a_hertz_drop_rebounds_at_the_asked_restitution(backend: str, restitution: float) -> None:
    """A lone mass on a Hunt-Crossley contact leaves at e v0 (solvers/model/hertz.py: the damping factor
    comes from the asked e, exactly; the 1 lbf/in spring's share of the force is 1.5e-5)."""
    _, closing, opening = hertz_contact(restitution, backend)
    assert opening.relative_velocity / -closing.relative_velocity == pytest.approx(restitution, abs=1e-3)


@pytest.mark.parametrize("exponent", [1.0, 1.5, 2.5])
@pytest.mark.parametrize("restitution", [0.01, 0.1, 0.488, 0.75, 0.999])
def test_the_damping_factor_rebounds_the_dimensionless_impact_at_e(exponent: float, restitution: float) -> None:
    """The closed relation a (1 + e) = ln((1 + a)/(1 - a e)) against x'' = -x^n (1 + a x') integrated."""
    from vtool.solvers.model.hertz import damping_factor, rebound

    assert rebound(damping_factor(restitution), exponent) == pytest.approx(restitution, rel=1e-8)
    assert damping_factor(0.488) == pytest.approx(1.5, rel=2e-3)  # the old law's "e = 0" rebounded at 0.488


@pytest.mark.parametrize("restitution", [0.0, 0.005])
def test_a_hertz_contact_refuses_a_restitution_it_cannot_give(restitution: float) -> None:
    doc = hertz_doc(restitution)
    with pytest.raises(InputError) as info:
        spec_from(doc)
    assert str(info.value).startswith(f"clearances[1].restitution: got {restitution}, expected >= 0.01 and <= 1 "
                                      "for a hertz contact")


def test_hertz_seat_on_1a_newmark_and_scipy_agree() -> None:
    import dataclasses

    from tests.valvetrain_cases import thesis_doc
    from vtool.solvers.run import simulate

    doc = thesis_doc("gnilka-1a")
    doc["run"]["degrees"] = 400.0
    for c in doc["clearances"]:
        if c["name"] == "seat":
            c.update(contact="hertz", contact_stiffness=1e8, restitution=0.1)
    spec = spec_from(doc)
    newmark = simulate(dataclasses.replace(spec, run=dataclasses.replace(spec.run, time_step=2.5e-7)))
    scipy = simulate(dataclasses.replace(spec, run=dataclasses.replace(spec.run, backend="scipy")))
    assert [(e.clearance, e.kind) for e in newmark.events] == [(e.clearance, e.kind) for e in scipy.events]
    assert max(abs(a.cam_angle - b.cam_angle) for a, b in zip(newmark.events, scipy.events, strict=True)) < 0.1
    a, b = newmark.summary()["clearances"][2], scipy.summary()["clearances"][2]
    assert a["peak_force"] == pytest.approx(b["peak_force"], rel=1e-3)
    assert a["peak_overlap"] == pytest.approx(b["peak_overlap"], rel=1e-3)


def test_exact_refuses_a_hertz_contact_in_one_line(tmp_path) -> None:  # noqa: ANN001
    import tomli_w
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    preset = tmp_path / "hertz.toml"
    preset.write_text(tomli_w.dumps(hertz_doc()))
    result = CliRunner().invoke(cli, ["solve", str(preset), "--backend", "exact"])
    assert result.exit_code == 2
    assert result.output.count("\n") == 1 and "hertz contact" in result.output


@pytest.mark.parametrize("command", [["solve"], ["compare", "--impact", "thesis"]])
def test_bad_input_is_one_line_even_when_a_compile_is_due(tmp_path, monkeypatch, command) -> None:  # noqa: ANN001
    """The compile notice comes after the input checks: a refused run prints its one line and no notice,
    whatever this process has compiled before (the notice forced on here); a good run prints the notice."""
    import tomli_w
    from click.testing import CliRunner

    from vtool.app.cli.main import cli
    from vtool.solvers.newmark import backend as newmark

    monkeypatch.setattr(newmark, "compile_notice", lambda *args: "compiling the solver (forced by the test)")
    refused, good = tmp_path / "exact.toml", tmp_path / "newmark.toml"
    refused.write_text(tomli_w.dumps(hertz_doc(backend="exact")))
    good.write_text(tomli_w.dumps(hertz_doc()))
    result = CliRunner().invoke(cli, [*command, str(refused)])
    assert result.exit_code == 2, result.output
    assert result.output.count("\n") == 1 and "hertz contact" in result.output
    result = CliRunner().invoke(cli, [*command, str(good)])
    assert result.exit_code == 0, result.output
    assert result.stderr.startswith("compiling the solver (forced by the test)\n")


def test_a_hertz_contact_starts_open() -> None:
    doc = hertz_doc()
    doc["clearances"][0]["state"] = "enabled"
    doc["clearances"][0].update(contact="hertz", contact_stiffness=1e7, restitution=0.5)
    doc["initial"]["closed"] = ["cam"]
    with pytest.raises(InputError, match="starts open"):
        spec_from(doc)


def test_kernel_law_switches_follow_the_clearances() -> None:
    """The kernel is compiled without the Hertz iteration (momentum-law LCP) for a mechanism that has no
    Hertz contact (momentum-law clearance): the switches say which, from the spec and from the table."""
    import dataclasses

    from vtool.presets import load_preset
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.newmark import layout as kernel_layout
    from vtool.solvers.newmark.backend import kernel_laws

    thesis = load_preset("gnilka-1a")
    momentum = dataclasses.replace(thesis, contact=dataclasses.replace(thesis.contact, impact="momentum"))
    hertz = spec_from(hertz_doc())
    for spec, expected in ((thesis, (None, None)), (momentum, (None, True)), (hertz, (True, None))):
        assert kernel_laws(spec) == expected
        assert kernel_layout.laws(ContactProblem(assemble(spec)).cl) == expected
    assert kernel_laws(thesis, impacts=("local", "momentum")) == (None, True)  # vtool compare's runs


def test_a_kernel_is_compiled_per_law_switch_pair() -> None:
    """One compiled run_chunk per (hertz, momentum) pair of argument types: the thesis presets' and a
    Hertz mechanism's are two."""
    import numba

    from vtool.presets import load_preset
    from vtool.solvers.newmark import kernel
    from vtool.solvers.run import simulate

    if not hasattr(kernel.run_chunk, "signatures"):
        pytest.skip("NUMBA_DISABLE_JIT: nothing is compiled")
    simulate(load_preset("gnilka-1a"))
    simulate(spec_from(hertz_doc()))
    switches = {tuple(signature[-2:]) for signature in kernel.run_chunk.signatures}
    assert {(numba.types.none, numba.types.none), (numba.types.boolean, numba.types.none)} <= switches


def test_a_rerun_of_a_hertz_mechanism_equals_its_first_run_to_the_last_bit() -> None:
    """A mechanism's reruns share its contact problem (``ContactProblem.for_run``), all but the run's own
    mechanism and the table the kernel writes, a Hertz contact's approach velocity: a lossy Hertz drop
    run three times in one process, and once more on a mechanism assembled afresh, gives the same run
    to the last bit; a rerun at the same speed with another length runs its own length."""
    from tests.valvetrain_cases import spec_from
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.newmark.backend import NewmarkBackend
    from vtool.solvers.run import simulate

    doc = hertz_doc(restitution=0.5)
    spec = spec_from(doc)
    backend = NewmarkBackend()

    def fresh(spec):  # noqa: ANN001, ANN202
        return backend.simulate(assemble(spec), backend.options_from_run(spec.run))

    runs = [simulate(spec) for _ in range(3)] + [fresh(spec)]
    assert len(runs[0].events) >= 2
    for other in runs[1:]:
        for name in ("time", "q", "qd", "qdd", "contact_force", "configuration", "peak_force", "peak_overlap"):
            np.testing.assert_array_equal(getattr(other, name), getattr(runs[0], name), err_msg=name)
    doc["run"]["degrees"] = 2e-4
    shorter = spec_from(doc)
    steps = simulate(shorter).statistics.steps  # (the output is per degree: the start's row alone)
    assert steps == fresh(shorter).statistics.steps < runs[0].statistics.steps
    mechanism = assemble(spec)
    first, second = ContactProblem.for_run(mechanism), ContactProblem.for_run(mechanism)
    assert first.clf is not second.clf and first.cl is second.cl  # each run writes its own clf
    np.testing.assert_array_equal(first.clf, second.clf)


# ----- stiff contacts: k = 1e10 lbf/in on every clearance of gnilka-1a (issue 37) -----
STIFF = 1e10  # lbf/in


def stiff_peaks(backend: str, degrees: float, time_step: float | None = None) -> np.ndarray:
    """Peak contact forces (cam, rocker, seat; lbf) of gnilka-1a with every clearance linear at
    k = 1e10 lbf/in, ζ = 1, over ``degrees``."""
    from vtool.presets import load_preset
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.compliance import with_contacts

    spec = with_contacts(load_preset("gnilka-1a"), STIFF, 1.0)
    run = dataclasses.replace(spec.run, backend=backend, degrees=degrees,
                              time_step=spec.run.time_step if time_step is None else time_step)
    trace = simulate(dataclasses.replace(spec, run=run), max_steps=1e7)
    return np.array([c["peak_force"] for c in trace.summary()["clearances"]])


def test_stiff_contacts_newmark_closes_on_the_exact_peak_forces() -> None:
    """Over 320 deg (the cam's peak, 646.6 klbf, where the cam closes 3.6 ns, less than one of the exact
    back end's scan intervals, before the rocker opens; the rocker's, 783.8 klbf, at 307 deg), Newmark's
    peak forces at 10, 5 and 2.5 ns close on the exact back end's: each halving at least 1.5 times closer
    on the cam and the rocker (first order: the peak is where a contact closes, a jump in its damper's
    force), within 1.6 % on every clearance at 2.5 ns. Before the fix the exact back end read the cam's
    and the rocker's 607.3 and 685.0 klbf (6 and 13 % below)."""
    exact = stiff_peaks("exact", 320.0)
    errors = np.array([np.abs(stiff_peaks("newmark", 320.0, dt) / exact - 1.0) for dt in (1e-8, 5e-9, 2.5e-9)])
    assert (errors[:-1, :2] > 1.5 * errors[1:, :2]).all(), errors
    assert errors[-1].max() < 0.016, errors


@pytest.mark.slow
def test_stiff_contacts_exact_and_scipy_agree_on_the_peak_forces() -> None:
    """Over 196 deg (the cam's peak force at 195 deg): scipy (DOP853, rtol 1e-9) and the exact back end
    within 1e-4 on the cam's peak force (measured 4e-6) and 1e-3 on the rocker's (2.3e-4: scipy's
    own error, its rocker peak moves 6.4e-4 from rtol 1e-9 to 1e-7); before the fix the exact back end
    read 607.3 klbf against scipy's 646.6 on the cam."""
    exact, scipy = stiff_peaks("exact", 196.0), stiff_peaks("scipy", 196.0)
    assert exact[0] == pytest.approx(646.6e3, rel=1e-3)
    assert exact[0] == pytest.approx(scipy[0], rel=1e-4)
    assert exact[1] == pytest.approx(scipy[1], rel=1e-3)


def test_lash_geometry_of_a_compliant_rocker_tends_to_the_rigid_one() -> None:
    """The follower's base on the base circle and the follower/valve ratio (solvers/model/lash.py, read by
    the speed criteria of every valve-train summary) with the rocker a linear contact closed at the start:
    its spring joins the two sides (it was left out, and ``vtool solve gnilka-1a --set
    clearances[1].contact=linear`` stopped with "no spring to ground" after the run). As k grows the base
    tends to the rigid rocker's, its excess the spring's deflection under the preload, falling as 1/k;
    the ratio is the rigid one (the spring's deflection moves both sides' coordinates alike)."""
    from tests.valvetrain_cases import thesis_doc
    from vtool.solvers.model.lash import base_and_ratio

    base, ratio = base_and_ratio(spec_from(thesis_doc("gnilka-1a")))
    excess = []
    for k in (1e6, 1e7, 1e8):
        doc = thesis_doc("gnilka-1a")
        doc["clearances"][1].update(contact="linear", contact_stiffness=k)
        soft_base, soft_ratio = base_and_ratio(spec_from(doc))
        assert soft_ratio == pytest.approx(ratio, rel=1e-12)
        excess.append(soft_base - base)
    assert excess[0] > 0.0
    assert excess[1] == pytest.approx(excess[0] / 10.0, rel=0.05) and excess[2] == pytest.approx(excess[1] / 10.0, rel=0.05)
