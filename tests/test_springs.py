"""Data-sheet valve springs (issue 40): rate, surge, pitch diagram, stress, fatigue, checks; against hand figures."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.errors import InputError
from vtool.presets import load_document, read_document
from vtool.presets.fields import Table
from vtool.presets.springs import read_sheet, sheet_spring_model
from vtool.solvers.model.elements import bar_matrices
from vtool.solvers.model.spring import closing_forces, goodman, pitch_force_length
from vtool.units import UNIT_SYSTEMS

MM = UNIT_SYSTEMS["mm-N-s"]
# d = 4 mm, D = 24 mm, n_a = 5.25, G = 79,300 MPa: k = 79300 * 256 / (8 * 13824 * 5.25) = 34.9647 N/mm
SHEET = {"wire_diameter": 4.0, "coil_diameter": 24.0, "active_coils": 5.25, "total_coils": 7.25,
         "free_length": 45.0, "installed_length": 38.0, "shear_modulus": 7.93e4, "density": 7.85e-9,
         "tensile_strength": 1900.0, "fatigue_limit": 450.0}


def _sheet(**changes: object):
    return read_sheet(Table(SHEET | changes, "train.spring"), MM, "valve_spring", 2)


def test_rate_mass_preload_from_the_data_sheet() -> None:
    s = _sheet()
    assert s.rate == pytest.approx(79300.0 * 256.0 / (8.0 * 13824.0 * 5.25), rel=1e-14)
    assert s.rate == pytest.approx(34.96473, rel=1e-6)
    # active mass rho (pi d^2/4) (pi D n_a) = 9.864601e-8 * 395.84067 = 3.904810e-5
    assert s.active_mass == pytest.approx(3.904810e-5, rel=1e-6)
    assert s.preload == pytest.approx(s.rate * 7.0, rel=1e-14)
    assert s.solid_length == pytest.approx(29.0)


def test_bucket_preset_members_carry_the_derived_rate_and_mass() -> None:
    from vtool.presets import find_preset

    spec = load_document(read_document(find_preset("direct-acting-bucket")))
    member = next(m for m in spec.members if m.name == "valve_spring")
    sheet = spec.springs[0]
    assert member.stiffness == pytest.approx(79300.0 * 4.0 ** 4 / (8.0 * 24.0 ** 3 * 5.25), rel=1e-12)
    assert member.mass == pytest.approx(sheet.active_mass, rel=1e-12)
    assert spec.initial.spring_preload == pytest.approx(7.0 * member.stiffness, rel=1e-12)


def _fixed_fixed_first(n: int) -> float:
    """First frequency (Hz) of the spring model's chain of n segments with both ends held."""
    sheet = SHEET | {"segment_coils": [5.25 / n] * n, "segment_pitches": [8.0] * n}
    model = sheet_spring_model(Table(dict(sheet), "train.spring"), MM, 1, 2, (0.0, 0.0))
    K, M = np.zeros((n + 1, n + 1)), np.zeros((n + 1, n + 1))
    for i, member in enumerate(model.members.values()):
        k_e, m_e = bar_matrices(member["stiffness"], member["mass"])
        K[i:i + 2, i:i + 2] += k_e
        M[i:i + 2, i:i + 2] += m_e
    inner = slice(1, n)
    w2 = np.linalg.eigvals(np.linalg.solve(M[inner, inner], K[inner, inner])).real
    return math.sqrt(w2.min()) / (2.0 * math.pi)


def test_first_surge_frequency_converges_at_second_order_to_the_closed_form() -> None:
    s = _sheet()
    exact = 0.5 * math.sqrt(s.rate / s.active_mass)
    assert s.surge_frequencies(2) == pytest.approx([exact, 2.0 * exact], rel=1e-14)
    errors = [_fixed_fixed_first(n) / exact - 1.0 for n in (4, 8, 16, 32)]
    assert all(e > 0.0 for e in errors)  # consistent mass: from above
    ratios = [a / b for a, b in zip(errors, errors[1:], strict=False)]
    assert ratios == pytest.approx([4.0] * 3, rel=0.02)  # O(h^2)
    assert errors[-1] < 2e-3


# pitch diagram: d = 4, three segments of 1, 3 and 1.25 active coils with free pitches 6, 8, 5 mm.
# A segment closes at G d^4 (p - d) / (8 D^3) = 79300 * 256 / 110592 * (p - d) = 183.5650 (p - d) N:
# the 5 mm segment at 183.565 N, then the 6 mm one at 367.130 N, then the 8 mm one at 734.260 N.
PITCH = {"segment_coils": [1.0, 3.0, 1.25], "segment_pitches": [6.0, 8.0, 5.0]}
C = 79300.0 * 256.0 / (8.0 * 24.0 ** 3)  # G d^4 / (8 D^3): a one-coil segment's rate


def test_pitch_diagram_closes_smallest_pitch_first_and_follows_the_hand_curve() -> None:
    s = _sheet(**PITCH)
    np.testing.assert_allclose(closing_forces(s), [2.0 * C, 4.0 * C, 1.0 * C], rtol=1e-14)
    assert list(np.argsort(closing_forces(s))) == [2, 0, 1]
    # rates: 1 coil C, 3 coils C/3, 1.25 coils C/1.25; all open in series: C/5.25
    # until F = C (5 mm segment closes) at deflection 5.25 mm; then C/4 until F = 2C (deflection 5.25 + 4 = 9.25);
    # then C/3 until F = 4C (deflection 9.25 + 6 = 15.25): solid, every coil touching
    lengths = 45.0 - np.array([0.0, 5.25, 7.25, 9.25, 12.25, 15.25])
    hand = C * np.array([0.0, 1.0, 1.5, 2.0, 3.0, 4.0])
    np.testing.assert_allclose(pitch_force_length(s, lengths), hand, rtol=1e-12, atol=1e-9)
    assert pitch_force_length(s, 45.0 - 15.3) == math.inf


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(0.2, 3.0), st.floats(4.2, 12.0)), min_size=1, max_size=6),
       st.floats(0.0, 1.0))
def test_pitch_force_length_is_continuous_and_progressive(segments: list, where: float) -> None:
    coils = [c for c, _ in segments]
    pitches = [p for _, p in segments]
    s = _sheet(active_coils=sum(coils), total_coils=sum(coils) + 2.0, segment_coils=coils, segment_pitches=pitches,
               free_length=60.0, installed_length=59.0)
    travel = float(np.sum(np.asarray(coils) * (np.asarray(pitches) - 4.0)))
    x = np.linspace(0.0, travel * (1.0 - 1e-9), 400)
    force = pitch_force_length(s, 60.0 - x)
    slopes = np.diff(force) / np.diff(x)
    assert np.all(np.diff(force) > 0.0)
    assert np.all(np.diff(slopes) > -1e-6 * slopes.max())  # never softer: progressive
    assert force[-1] == pytest.approx(float(closing_forces(s).max()), rel=1e-6)


def test_table_spring_rate_and_preload() -> None:
    s = _sheet(lengths=[45.0, 40.0, 35.0, 30.0], forces=[0.0, 170.0, 360.0, 580.0])
    assert s.rate == pytest.approx(190.0 / 5.0)  # the 40 .. 35 interval holds 38
    assert s.preload == pytest.approx(170.0 + 2.0 / 5.0 * 190.0)
    assert float(s.force_at(32.5)) == pytest.approx(470.0)


@pytest.mark.parametrize("force", [244.75, 524.5])
def test_bergstrasser_and_wahl_stress_closed_form(force: float) -> None:
    s = _sheet()
    w = 6.0
    k_b, k_w = (w + 0.5) / (w - 0.75), (4 * w - 1) / (4 * w - 4) + 0.615 / w
    nominal = 8.0 * force * 24.0 / (math.pi * 4.0 ** 3)
    assert s.stress(force) == pytest.approx(k_b * nominal, rel=1e-14)
    assert s.stress(force, "wahl") == pytest.approx(k_w * nominal, rel=1e-14)
    assert k_b == pytest.approx(1.238095238, rel=1e-9)


def test_goodman_fatigue_factor_by_hand() -> None:
    s = _sheet()
    # forces 245 .. 525 N: tau = 1.2380952 * 8 F 24 / (pi 64) = 1.182294 F MPa: 289.662 .. 620.704 MPa;
    # tau_a = 165.521, tau_m = 455.183; tau_u = 0.67 * 1900 = 1273;
    # S = 1 / (165.521/450 + 455.183/1273) = 1 / (0.367824 + 0.357567) = 1.378568
    assert s.fatigue_factor(245.0, 525.0) == pytest.approx(1.378568, rel=1e-5)
    assert goodman(100.0, 300.0, 400.0, 1000.0) == pytest.approx(1.0 / (100.0 / 400.0 + 200.0 / 1000.0))
    no_limit = {k: v for k, v in SHEET.items() if k != "fatigue_limit"}
    assert read_sheet(Table(no_limit, "s"), MM, "s", 2).fatigue_factor(245.0, 525.0) is None


@pytest.mark.parametrize(("key", "value", "field"), [
    ("coil_diameter", 7.9, "train.spring.coil_diameter"),
    ("active_coils", 8.0, "train.spring.active_coils"),
    ("installed_length", 46.0, "train.spring.installed_length"),
    ("segment_pitches", [3.0], "train.spring.segment_pitches"),
])
def test_bad_data_sheet_names_the_field(key: str, value: object, field: str) -> None:
    changes = {key: value}
    if key == "segment_pitches":
        changes["segment_coils"] = [5.25]
    with pytest.raises(InputError) as err:
        _sheet(**changes)
    assert err.value.field == field


def _bucket_doc() -> dict:
    from vtool.presets import find_preset

    return read_document(find_preset("direct-acting-bucket"))


def test_nested_spring_adds_rate_and_preload_in_parallel() -> None:
    doc = _bucket_doc()
    single = load_document(copy.deepcopy(doc))
    inner = {"wire_diameter": 2.8, "coil_diameter": 16.0, "active_coils": 6.0, "total_coils": 8.0,
             "free_length": 43.0, "installed_length": 38.0, "shear_modulus": 7.93e4, "density": 7.85e-9,
             "tensile_strength": 2000.0}
    doc["train"]["spring"]["inner"] = inner
    nested = load_document(doc)
    k_inner = 79300.0 * 2.8 ** 4 / (8.0 * 16.0 ** 3 * 6.0)
    assert [s.name for s in nested.springs] == ["valve_spring", "inner_spring"]
    assert nested.initial.spring_preload == pytest.approx(single.initial.spring_preload + 5.0 * k_inner, rel=1e-12)
    assert next(m for m in nested.members if m.name == "inner_spring").stiffness == pytest.approx(k_inner, rel=1e-12)


def test_explicit_form_round_trip_keeps_the_data_sheet() -> None:
    from dataclasses import replace

    from vtool.presets.valvetrain import dump, load

    spec = load_document(_bucket_doc())
    explicit = dump(replace(spec, train=""))
    assert "train" not in explicit and explicit["springs"][0]["wire_diameter"] == 4.0
    again = load(copy.deepcopy(explicit))
    assert again.springs == spec.springs
    assert again.members == spec.members


def _pitch_bucket(rpm: float) -> dict:
    """The bucket with a pitch-diagram spring whose segments close at 2C, C and 1.5C (C = 183.565 N), all
    inside the lift: 140 N installed, 35 N/mm in series, 420 N at full lift (8 mm), past solid (29 mm)."""
    doc = _bucket_doc()
    spring = doc["train"]["spring"]
    del spring["elements"]
    spring.update(segment_coils=[2.0, 1.75, 1.5], segment_pitches=[6.0, 5.0, 5.5], free_length=37.0,
                  installed_length=33.0)
    doc["run"].update(rpm=rpm, degrees=360.0, time_step=2e-6, output_interval=0.25)
    doc["checks"] = {"coil_bind_margin_min": 0.0}
    return doc


def test_slow_compression_closes_the_segments_in_the_pitch_diagrams_order() -> None:
    from vtool.solvers.run import simulate

    spec = load_document(_pitch_bucket(300.0))
    sheet = spec.springs[0]
    np.testing.assert_allclose(closing_forces(sheet), [2.0 * C, C, 1.5 * C], rtol=1e-12)
    assert sheet.preload == pytest.approx(4.0 * C / 5.25, rel=1e-12)
    trace = simulate(spec)
    report = trace.summary()["springs"][0]
    first = report["segment_first_touch_deg"]
    assert all(a is not None for a in first)
    # the cam turns from the nose (0 deg): the spring compresses from the start and relaxes towards 180 deg;
    # the run starts at full lift, so every segment is closed at once: look at the re-closing on the next lift
    angle = np.asarray(trace.cam_angle)
    from vtool.solvers.model.spring import segment_gaps

    gaps = segment_gaps(sheet, trace)
    second_lift = angle >= 180.0
    touch = [float(angle[second_lift][np.argmax(gaps[second_lift, i] <= 0.0)]) for i in range(3)]
    assert sorted(range(3), key=lambda i: touch[i]) == [1, 2, 0]  # smallest pitch first (hand order)
    # at each closing the spring's force (35 N/mm in series from the rest length) equals G d^4 (p - d)/(8 D^3)
    length = sheet.rest_length - compression_sign_of(trace, sheet) * trace.coordinate(sheet.coordinate)
    for i, a in enumerate(touch):
        row = int(np.flatnonzero(angle == a)[0])
        assert sheet.model_rate * (sheet.rest_length - length[row]) == pytest.approx(closing_forces(sheet)[i],
                                                                                      rel=2e-2)
    assert report["coil_bind_margin"] < 0.0 and "COIL BIND" in trace.summary_text()
    check = next(c for c in trace.summary()["checks"] if c["name"] == "coil_bind_margin_min")
    assert check["passed"] is False


def compression_sign_of(trace, sheet) -> float:  # type: ignore[no-untyped-def]
    from vtool.solvers.model.spring import compression_sign

    return compression_sign(trace, sheet.coordinate)


def test_clashing_preset_reports_coil_clash_only_at_high_speed() -> None:
    from vtool.presets import load_preset
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.metrics import run_metrics

    spec = load_preset("nested-spring-clash")
    fast = simulate(spec)
    text = fast.summary_text()
    assert "first coil clash at" in text and "not to be trusted" in text
    report = fast.summary()["springs"][0]
    assert report["first_coil_bind_deg"] is not None
    assert (report["stress_unit"], report["length_unit"], report["force_unit"]) == ("MPa", "mm", "N")
    slow = simulate(with_run_overrides(spec, rpm=3000.0))
    assert slow.summary()["springs"][0]["first_coil_bind_deg"] is None
    assert run_metrics(slow)["coil_bind_margin"] > 0.0 > run_metrics(fast)["coil_bind_margin"]


def test_modes_lists_the_surge_frequencies_and_their_cam_orders() -> None:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    result = CliRunner().invoke(cli, ["modes", "direct-acting-bucket"])
    assert result.exit_code == 0, result.output
    f1 = 0.5 * math.sqrt(79300.0 * 256.0 / (8.0 * 13824.0 * 5.25) / 3.904810e-5)  # 473.1 Hz
    assert f"{f1:.1f} Hz (order {f1 / 50.0:.1f})" in result.output
    assert f"{2 * f1:.1f} Hz (order {2 * f1 / 50.0:.1f})" in result.output
