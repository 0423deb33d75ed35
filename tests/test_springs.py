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


def _slow_pitch_bucket(backend: str = "newmark") -> dict:
    """The bucket on a harmonic cam (mid-stroke at angle 0, the nose at 90 deg: every coil open at the start)
    at 60 rev/min, with a pitch diagram whose free coil gaps n_i (p_i - d) = 2 x 1.65, 1.75 x 1.4, 1.5 x 1.5 mm
    (8 mm: free 37 mm to solid 29 mm) close at 1.65 C, 1.4 C and 1.5 C = 302.9, 257.0, 275.3 N (C = G d^4/(8 D^3)
    = 183.565 N/mm); preload 3 mm x 34.965 N/mm = 104.9 N at 34 mm; 7.85 mm of lift past the 0.15 mm lash
    takes the spring 2.85 mm past solid."""
    doc = _bucket_doc()
    spring = doc["train"]["spring"]
    del spring["elements"]
    spring.update(segment_coils=[2.0, 1.75, 1.5], segment_pitches=[5.65, 5.4, 5.5], free_length=37.0,
                  installed_length=34.0)
    doc["train"]["cam"] = {"law": "harmonic", "lift": 8.0}
    doc["run"].update(rpm=60.0, degrees=100.0, time_step=1e-5, output_interval=0.25, backend=backend)
    doc["checks"] = {"coil_bind_margin_min": 0.0}
    return doc


def series_law_length(sheet, force: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    """By hand: the spring's length at a force when each segment is k_i up to its coil gap g_i = close_i / k_i
    and k_i + k_b,i past it (the block stiffness k_b,i = 100 k_i in series), all carrying the same force."""
    k, close = C / np.asarray(sheet.segment_coils), closing_forces(sheet)
    F = np.asarray(force)[:, None]
    deflection = np.where(F <= close, F / k, close / k + (F - close) / (101.0 * k)).sum(axis=1)
    return sheet.free_length - deflection


def test_slow_compression_past_solid_closes_the_coils_in_order_and_follows_the_table() -> None:
    from vtool.solvers.model.spring import end_force
    from vtool.solvers.run import simulate

    spec = load_document(_slow_pitch_bucket())
    sheet = spec.springs[0]
    np.testing.assert_allclose(closing_forces(sheet), [1.65 * C, 1.4 * C, 1.5 * C], rtol=1e-12)
    assert sheet.preload == pytest.approx(3.0 * C / 5.25, rel=1e-12)
    assert sheet.contacts == ("valve_spring coils 1", "valve_spring coils 2", "valve_spring coils 3")
    trace = simulate(spec)
    first = [min(e.cam_angle for e in trace.events if e.clearance == name and e.kind == "closed")
             for name in sheet.contacts]
    assert sorted(range(3), key=lambda i: first[i]) == [1, 2, 0]  # smallest coil gap first (hand order)
    angle = np.asarray(trace.cam_angle)
    rising = angle <= 90.0  # mid-stroke to the nose
    length = sheet.rest_length - trace.coordinate(sheet.coordinate)
    force = end_force(sheet, trace)
    assert length[rising].min() < sheet.solid_length - 2.5  # 2.85 mm past solid at the nose
    # each coil closes at its force G d^4 (p - d)/(8 D^3): the output row before its closing (past the last one
    # the force rises 3.5 kN/mm, 60 N a row)
    for a, close in zip(first, closing_forces(sheet), strict=True):
        assert force[int(np.searchsorted(angle, a)) - 1] == pytest.approx(close, rel=1e-2)
    # the force-length curve follows the pitch diagram's (the table) up to the last coil's closing ...
    table = pitch_force_length(sheet, length)
    inside = rising & np.isfinite(table)
    assert inside.sum() > 40
    np.testing.assert_allclose(force[inside], table[inside], rtol=1e-2)
    # ... and, past solid, the coils' block springs in series: the length by hand at the run's force
    np.testing.assert_allclose(series_law_length(sheet, force[rising]), length[rising], atol=1.5e-2)  # surge at closing
    assert force[rising].max() > 10_000.0
    report = trace.summary()["springs"][0]
    assert report["first_coil_bind_deg"] == pytest.approx(min(first))
    peak = report["coil_contact_peak_force"]
    assert peak == pytest.approx(float(trace.peak_force[[c.name for c in spec.clearances].index(sheet.contacts[1])]))
    assert peak > 9_000.0 and report["force_unit"] == "N"
    text = trace.summary_text()
    assert "peak coil contact force" in text and "not to be trusted" not in text
    check = next(c for c in trace.summary()["checks"] if c["name"] == "coil_bind_margin_min")
    assert check["passed"] is False


@pytest.mark.parametrize("backend", ["exact", "scipy"])
def test_coil_contacts_agree_on_every_back_end(backend: str) -> None:
    """The coil contacts' opening (a constant force term, gaps shifted) on the piecewise back ends: the
    clashing preset's events and peak coil contact force as the Newmark back end's."""
    from vtool.presets import load_preset
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate

    spec = with_run_overrides(load_preset("nested-spring-clash"), degrees=400.0)
    newmark, other = simulate(spec), simulate(with_run_overrides(spec, backend=backend))
    assert [(e.clearance, e.kind) for e in other.events] == [(e.clearance, e.kind) for e in newmark.events]
    coils = [i for i, c in enumerate(spec.clearances) if "coils" in c.name]
    assert newmark.peak_force[coils].max() > 100.0
    np.testing.assert_allclose(other.peak_force[coils], newmark.peak_force[coils], rtol=2e-3, atol=1e-6)


def test_an_opening_needs_a_compliant_contact() -> None:
    from vtool.presets import find_preset

    doc = read_document(find_preset("gnilka-1a"))
    doc["clearances"][1]["opening"] = 0.01
    with pytest.raises(InputError, match=r"clearances\[1\]\.opening.*contact = \"linear\""):
        load_document(doc)
    doc["clearances"][1]["contact"], doc["clearances"][1]["contact_stiffness"] = "linear", 1e5
    assert load_document(doc).clearances[1].opening == 0.01


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
    assert "first coil clash at" in text and "peak coil contact force" in text and "not to be trusted" not in text
    report = fast.summary()["springs"][0]
    assert report["first_coil_bind_deg"] is not None
    assert (report["stress_unit"], report["length_unit"], report["force_unit"]) == ("MPa", "mm", "N")
    slow = simulate(with_run_overrides(spec, rpm=3000.0))
    assert slow.summary()["springs"][0]["first_coil_bind_deg"] is None
    assert run_metrics(slow)["coil_bind_margin"] > 0.0 > run_metrics(fast)["coil_bind_margin"]
    fast_metrics, slow_metrics = run_metrics(fast), run_metrics(slow)
    assert report["coil_contact_peak_force"] > 100.0
    assert 100.0 < fast_metrics["coil_contact_peak_force"] <= report["coil_contact_peak_force"]  # 2nd revolution
    assert 360.0 < fast_metrics["coil_bind_angle"] < 720.0  # in the evaluated (second) revolution
    assert slow_metrics["coil_contact_peak_force"] == 0.0 and math.isnan(slow_metrics["coil_bind_angle"])
    assert {"F4", "F5", "F2"} <= {fast.force_label(i) for i in range(len(fast.spec.clearances))}


def test_modes_lists_the_surge_frequencies_and_their_cam_orders() -> None:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    result = CliRunner().invoke(cli, ["modes", "direct-acting-bucket"])
    assert result.exit_code == 0, result.output
    f1 = 0.5 * math.sqrt(79300.0 * 256.0 / (8.0 * 13824.0 * 5.25) / 3.904810e-5)  # 473.1 Hz
    assert f"{f1:.1f} Hz (order {f1 / 50.0:.1f})" in result.output
    assert f"{2 * f1:.1f} Hz (order {2 * f1 / 50.0:.1f})" in result.output


def test_spring_end_force_is_a_csv_column_and_a_cam_order_quantity() -> None:
    """One bar, table-free: the end force is k q_end (q = 0 unloaded), so its cam-order amplitudes are k times
    q_end's; a CSV column with its unit; ``--orders valve_spring_force`` accepted, a wrong name refused."""
    from vtool.presets import load_preset
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.orders import spectrum, with_orders

    spec = with_run_overrides(load_preset("direct-acting-bucket"), degrees=720.0)
    sheet = spec.springs[0]
    trace = simulate(with_orders(spec, ("valve_spring_force",)))
    header, columns = trace.csv_columns()
    column = columns[header.index("valve_spring_force (N)")](slice(None))
    np.testing.assert_allclose(column, sheet.rate * trace.coordinate(sheet.coordinate), rtol=1e-12, atol=1e-9)
    force, lift = spectrum(trace, "valve_spring_force"), spectrum(trace, f"q{sheet.coordinate}")
    assert force.unit == "N" and force.amplitude[1:].max() > 10.0
    np.testing.assert_allclose(force.amplitude, sheet.rate * lift.amplitude, rtol=1e-9, atol=1e-9)
    with pytest.raises(InputError, match="valve_spring_force"):
        with_orders(spec, ("outer_force",))


def test_elliptic_wire_rate_mass_and_stress_by_hand() -> None:
    """Elliptic wire 4 mm radial x 3.2 mm axial (a = 2, b = 1.6): J_t = pi a^3 b^3/(a^2 + b^2) = pi 32.768/6.56
    = 15.69264 mm^4, k = 4 G J_t/(pi D^3 n_a) = 4 * 79300 * 4.99512/(13824 * 5.25) = 21.8316 N/mm; tau = K F D/(pi a b^2)
    (K Bergstraesser on D/d = 6: 6.5/5.25); solid length n_t h = 23.2 mm; mass rho pi a b pi D n_a."""
    from vtool.solvers.model.spring import elliptic_torsion_constant

    assert elliptic_torsion_constant(2.0, 2.0) == pytest.approx(math.pi * 4.0 ** 4 / 32.0, rel=1e-15)
    s = _sheet(wire_height=3.2, installed_length=40.0, free_length=45.0)
    J = math.pi * 2.0 ** 3 * 1.6 ** 3 / (2.0 ** 2 + 1.6 ** 2)
    assert J == pytest.approx(15.69264, rel=1e-6)
    assert s.rate == pytest.approx(4.0 * 79300.0 * J / (math.pi * 24.0 ** 3 * 5.25), rel=1e-14)
    assert s.rate == pytest.approx(21.8316, rel=1e-5)
    assert s.solid_length == pytest.approx(7.25 * 3.2)
    assert s.active_mass == pytest.approx(7.85e-9 * math.pi * 2.0 * 1.6 * math.pi * 24.0 * 5.25, rel=1e-14)
    assert s.stress(300.0) == pytest.approx(6.5 / 5.25 * 300.0 * 24.0 / (math.pi * 2.0 * 1.6 ** 2), rel=1e-14)
    with pytest.raises(InputError, match="wire_height"):
        _sheet(wire_height=1.0)


def test_tensile_strength_against_wire_diameter_feeds_the_fatigue_factor() -> None:
    """R_m = A / d^m: the VDSiCrV fit meets each point of its table within 1 %; {A, m} given; the Goodman
    factor takes R_m at the wire's diameter."""
    from vtool.solvers.model.spring import VDSICRV_TABLE, fitted_strength_law

    A, m = fitted_strength_law(VDSICRV_TABLE)
    for d, rm in VDSICRV_TABLE:
        assert A / d ** m == pytest.approx(rm, rel=1e-2)
    small = SHEET | {"wire_diameter": 2.5, "coil_diameter": 15.0}
    s = read_sheet(Table(small | {"tensile_strength": "VDSiCr" + "V"}, "train.spring"), MM, "valve_spring", 2)
    assert s.tensile_strength == pytest.approx(A / 2.5 ** m, rel=1e-12) and s.strength_law == (A, m)
    assert 2060.0 < s.tensile_strength < 2160.0  # between its neighbours in the table
    given = read_sheet(Table(small | {"tensile_strength": {"A": 2300.0, "m": 0.1}}, "train.spring"), MM, "v", 2)
    assert given.tensile_strength == pytest.approx(2300.0 / 2.5 ** 0.1, rel=1e-14)
    tau_lo, tau_hi = float(given.stress(100.0)), float(given.stress(300.0))
    assert given.fatigue_factor(100.0, 300.0) == pytest.approx(
        1.0 / (0.5 * (tau_hi - tau_lo) / 450.0 + 0.5 * (tau_hi + tau_lo) / (0.67 * 2300.0 / 2.5 ** 0.1)), rel=1e-14)
    with pytest.raises(InputError, match="wire_diameter"):
        read_sheet(Table(SHEET | {"tensile_strength": "VDSiCrV"}, "train.spring"), MM, "v", 2)  # 4 mm: off the table


def test_the_clashing_preset_round_trips_through_its_explicit_form() -> None:
    from dataclasses import replace

    from vtool.presets import load_preset
    from vtool.presets.valvetrain import dump, load

    spec = load_preset("nested-spring-clash")
    explicit = dump(replace(spec, train=""))
    assert [c.get("opening") for c in explicit["clearances"]][2:] == pytest.approx([3.25, 6.0, 7.0])
    again = load(copy.deepcopy(explicit))
    assert again.clearances == spec.clearances and again.springs == spec.springs


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-5.0, 5.0), min_size=5, max_size=5))
def test_every_clearances_monitor_is_its_gap_with_opening_and_sense(q: list) -> None:
    """Open (nothing closed): each monitored clearance's monitor is sense (q_ahead - q_behind) + opening
    (behind = 0: the ground at 0; the cam and seat at their sources), plus the round-off allowance."""
    from vtool.presets import load_preset
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.model.mechanism import Mechanism

    spec = load_preset("nested-spring-clash")
    problem = ContactProblem(Mechanism(spec))
    x, v = np.array(q), np.zeros(5)
    src = problem.sources_at(0.0)
    values = problem.monitors(0, 0.0, x, v, np.zeros(5))
    for k, c in enumerate(spec.clearances):
        behind = x[c.behind - 1] if 0 < c.behind <= 5 else 0.0 if c.behind == 0 else \
            src[3 * problem.source_numbers.index(c.behind)]
        assert values[k] == pytest.approx(c.gap(x[c.ahead - 1], behind) + problem.gap_noise, abs=1e-12)


def test_a_start_with_coils_touching_closes_them_in_static_equilibrium() -> None:
    """The polydyne bucket starts at the nose (angle 0), 3.9 mm past solid: the static start closes the coil
    contacts it overlaps (an affine start: their constant forces k o w), its follower force is the spring's end
    force, and its length is the hand series law's at that force; every back end opens them alike."""
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.model.mechanism import Mechanism
    from vtool.solvers.model.spring import end_force
    from vtool.solvers.run import simulate

    doc = _bucket_doc()
    spring = doc["train"]["spring"]
    del spring["elements"]
    spring.update(segment_coils=[2.0, 1.75, 1.5], segment_pitches=[6.0, 5.0, 5.5], free_length=37.0,
                  installed_length=33.0)
    doc["run"].update(rpm=300.0, degrees=75.0, time_step=2e-6)
    spec = load_document(doc)
    sheet = spec.springs[0]
    start = Mechanism(spec).start
    assert start.closed == sheet.contacts
    length = sheet.rest_length - start.q[sheet.coordinate - 1]
    assert length < sheet.solid_length - 3.5
    assert series_law_length(sheet, np.array([start.follower_force]))[0] == pytest.approx(length, abs=1e-9)
    runs = [simulate(with_run_overrides(spec, backend=b)) for b in ("newmark", "exact", "scipy")]
    assert end_force(sheet, runs[0])[0] == pytest.approx(start.follower_force, rel=1e-9)
    opened = [[(e.clearance, round(e.cam_angle, 3)) for e in run.events if e.kind == "opened"][:3] for run in runs]
    # the largest closing force opens first: the hand closing order (2, 3, 1) reversed
    assert [name for name, _ in opened[0]] == ["valve_spring coils 1", "valve_spring coils 3", "valve_spring coils 2"]
    assert opened[1] == opened[0] == opened[2]
