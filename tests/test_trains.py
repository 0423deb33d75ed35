"""Train types (presets/trains.py): the ohv-pushrod type reproduces gnilka-1a; expansion; field errors."""

from __future__ import annotations

import numpy as np
import pytest

from vtool.errors import InputError
from vtool.presets import load_document, load_preset, read_document
from vtool.presets.trains import expand
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.run import simulate


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


def test_ohv_pushrod_type_equals_gnilka_1a_matrices() -> None:
    thesis, train = Mechanism(load_preset("gnilka-1a")), Mechanism(load_preset("ohv-pushrod-1a"))
    assert _relative(train.M, thesis.M) <= 1e-12 and _relative(train.K, thesis.K) <= 1e-12
    for closed in (frozenset(), frozenset({"rocker"})):
        ours, theirs = train.layer(closed), thesis.layer(closed)
        for name in ("M", "K", "C"):
            assert _relative(getattr(ours, name), getattr(theirs, name)) <= 1e-12, (closed, name)


def test_ohv_pushrod_type_gives_gnilka_1a_events() -> None:
    thesis, train = simulate(load_preset("gnilka-1a")), simulate(load_preset("ohv-pushrod-1a"))
    assert len(thesis.events) > 5
    assert [(e.clearance, e.kind, e.before, e.after) for e in train.events] == \
        [(e.clearance, e.kind, e.before, e.after) for e in thesis.events]
    np.testing.assert_allclose([e.cam_angle for e in train.events], [e.cam_angle for e in thesis.events],
                               rtol=0, atol=1e-9)


def _doc(name: str) -> dict:
    from vtool.presets import find_preset

    return read_document(find_preset(name))


def test_expanded_form_loads_to_the_same_spec() -> None:
    import tomllib

    import tomli_w

    doc = _doc("ohv-pushrod-1a")
    explicit = tomllib.loads(tomli_w.dumps(expand(doc)))
    assert "train" not in explicit and "members" in explicit
    assert load_document(explicit) == load_document(doc)


@pytest.mark.parametrize(("path", "value", "field"), [
    (("train", "type"), "ohc", "train.type"),
    (("train", "rocker", "cam_arm"), -1.0, "train.rocker.cam_arm"),
    (("train", "spring", "rate"), 0.0, "train.spring.rate"),
    (("train", "cam", "law"), "sine", "train.cam.law"),
    (("train", "pushrod", "lenght"), 9.0, "train.pushrod.lenght"),
])
def test_bad_train_fields_name_the_field(path: tuple[str, ...], value: object, field: str) -> None:
    doc = _doc("ohv-pushrod-1a")
    table = doc
    for key in path[:-1]:
        table = table[key]
    table[path[-1]] = value
    with pytest.raises(InputError) as error:
        load_document(doc)
    assert error.value.field == field


def test_explicit_tables_beside_a_train_are_refused() -> None:
    doc = _doc("ohv-pushrod-1a") | {"members": {}}
    with pytest.raises(InputError, match="members"):
        load_document(doc)


# ----- the engineering presets: stress, checks, outputs, back ends, studies ---------------------------

NEW = ("ohc-finger-follower", "direct-acting-bucket")


def _short(name: str, degrees: float = 420.0, **run):  # type: ignore[no-untyped-def]
    from vtool.presets.valvetrain import with_run_overrides

    return with_run_overrides(load_preset(name), degrees=degrees, **run)


def test_max_contact_pressure_over_the_cycle_is_the_largest_closed_form_row() -> None:
    import math

    from vtool.solvers.model.camshape import law_derivatives

    spec = _short("direct-acting-bucket")
    trace = simulate(spec)
    follower = spec.follower
    L, _, ddL, _ = law_derivatives(spec.lift_law, np.radians(trace.cam_angle))
    R = follower.base_radius + L + ddL  # flat face: R* is the cam's radius r_b + L + L''
    E = 1.0 / ((1 - follower.cam_poisson**2) / follower.cam_modulus
               + (1 - follower.follower_poisson**2) / follower.follower_modulus)
    F = np.maximum(trace.force("cam"), 0.0)
    p0 = np.sqrt(F * E / (math.pi * follower.width * R))
    stress = trace.summary()["contact_stress"]
    assert stress["max_contact_pressure"] == pytest.approx(p0.max(), rel=1e-6)
    assert stress["max_contact_pressure_angle_deg"] == trace.cam_angle[np.argmax(p0)]
    assert stress["pressure_unit"] == "MPa" and 300.0 < stress["max_contact_pressure"] < 1500.0
    assert stress["min_film_thickness"] is not None and stress["length_unit"] == "mm"
    text = trace.summary_text()
    assert "max pressure" in text and "MPa" in text and "PASS" in text


def test_csv_has_the_contact_stress_columns_with_units() -> None:
    trace = simulate(_short("ohc-finger-follower", 60.0))
    header = trace.csv_text().splitlines()[0].split(",")
    for column in ("cam_normal_force (N)", "cam_contact_pressure (MPa)", "cam_half_width (mm)",
                   "cam_film_thickness (mm)"):
        assert column in header


def test_checks_fail_with_a_negative_margin_and_unknown_names_are_refused() -> None:
    import dataclasses

    from vtool.solvers.model.spec import CheckLimit
    from vtool.solvers.studies.checks import evaluate

    spec = _short("direct-acting-bucket", 60.0)
    tight = dataclasses.replace(spec, checks=(CheckLimit("contact_pressure_max", 100.0),
                                              CheckLimit("cam_radius_min", 100.0)))
    trace = simulate(tight)
    pressure, radius = evaluate(tight, trace)
    assert not pressure.passed and pressure.margin == pytest.approx(100.0 - pressure.value)
    assert pressure.unit == "MPa" and radius.unit == "mm" and not radius.passed
    assert "FAIL" in trace.summary_text()
    doc = _doc("direct-acting-bucket")
    doc["checks"]["contact_presure_max"] = 1.0
    with pytest.raises(InputError, match="did you mean `contact_pressure_max`"):
        load_document(doc)


@pytest.mark.slow
@pytest.mark.parametrize("name", NEW)
def test_new_presets_agree_on_every_back_end(name: str) -> None:
    from vtool.solvers.backends import available

    spec = _short(name, 200.0)
    traces = {backend: simulate(_short(name, 200.0, backend=backend)) for backend in available()}
    events = {b: [(e.clearance, e.kind) for e in t.events] for b, t in traces.items()}
    assert len(set(map(tuple, events.values()))) == 1, events
    peak = {b: t.summary()["contact_stress"]["max_contact_pressure"] for b, t in traces.items()}
    assert max(peak.values()) - min(peak.values()) <= 1e-3 * max(peak.values()), peak
    assert spec.unit_system.name == "mm-N-s"


@pytest.mark.parametrize("name", NEW)
def test_new_presets_have_a_jump_speed(name: str) -> None:
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.studies.sweep import SerialRunner, find_speed

    spec = load_preset(name)
    result = find_speed("jump-speed", lambda rpm: with_run_overrides(spec, rpm=rpm),
                        list(range(1000, 8001, 1000)), SerialRunner())
    assert result.speed is not None and 1000 < result.speed < 8000


def test_crank_degrees_are_halved_and_a_free_length_gives_the_preload() -> None:
    doc = _doc("direct-acting-bucket")
    cam = doc["train"]["cam"]
    cam.update(angle_basis="crank", ramp_deg=2 * cam["ramp_deg"], flank_deg=2 * cam["flank_deg"])
    # the rate-and-mass spring (the preset's is a data sheet: tests/test_springs.py)
    doc["train"]["spring"] = {"rate": 35.0, "mass": 4.5e-5, "installed_length": 38.0,
                              "free_length": 38.0 + 230.0 / 35.0, "elements": 2}
    crank, cam_degrees = load_document(doc), load_preset("direct-acting-bucket")
    assert crank.cam == cam_degrees.cam
    assert crank.initial.spring_preload == pytest.approx(230.0, rel=1e-12)


def test_presets_expand_and_cam_show_csv(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    runner = CliRunner()
    result = runner.invoke(cli, ["presets", "expand", "ohc-finger-follower"])
    assert result.exit_code == 0 and "[members.finger_roller_arm]" in result.output
    explicit = tmp_path / "explicit.toml"
    explicit.write_text(result.output.split("\n", 1)[1], encoding="utf-8")
    assert load_preset(explicit) == load_preset("ohc-finger-follower")
    target = tmp_path / "profile.csv"
    result = runner.invoke(cli, ["cam", "show", "direct-acting-bucket", "--csv", str(target)])
    assert result.exit_code == 0 and "no undercut" in result.output
    lines = target.read_text(encoding="utf-8").splitlines()
    assert lines[0].startswith("law_angle (deg),lift (mm),x (mm),y (mm),polar_radius (mm)") and len(lines) == 721
    result = runner.invoke(cli, ["cam", "show", "gnilka-1a", "--csv", str(tmp_path / "x.csv")])
    assert result.exit_code == 2 and "[follower]" in result.output


def test_an_undercut_cam_warns_on_loading() -> None:
    from vtool.errors import PresetWarning

    doc = _doc("direct-acting-bucket")
    doc["train"]["follower"]["base_radius"] = 10.0
    with pytest.warns(PresetWarning, match="undercuts at law angles"):
        load_document(doc)


def rocker_doc() -> dict:
    """ohc-finger-follower's parts on a centre-pivot roller rocker (a shaft instead of the finger's pivot)."""
    doc = _doc("ohc-finger-follower")
    train = doc["train"]
    train["type"] = "centre-pivot-rocker"
    del train["finger"], train["pivot"]
    train["rocker"] = {"roller_arm": 30.0, "valve_arm": 45.0, "roller_height": 2.0, "cam_offset": 1.0,
                       "area": 80.0, "inertia": 1500.0, "modulus": 2.05e5, "density": 9e-9}
    doc["run"]["quantities"] = ["q6", "F1"]
    return doc


def test_centre_pivot_rocker_follows_its_geometric_valve_lift_on_every_back_end() -> None:
    from vtool.solvers.backends import available
    from vtool.solvers.model.camshape import contact
    from vtool.solvers.model.lash import base_and_ratio

    spec = load_document(rocker_doc())
    assert spec.follower.arrangement == "rocker" and spec.initial.lever_ratio == 1.5
    assert [c.name for c in spec.clearances] == ["cam", "seat"]
    # the model's lever: the roller coordinate moves 1/1.5 of the valve's, up to the beams' bending
    assert base_and_ratio(spec)[1] == pytest.approx(1 / 1.5, rel=1e-3)
    # and the cam coordinate is the geometric valve lift over that ratio
    angles = np.array(spec.cam.angles)
    c = contact(spec.follower, spec.lift_law, np.radians(angles))
    lift = c.valve_lift / 1.5
    np.testing.assert_allclose(np.array(spec.cam.lifts), lift - lift.min(), atol=1e-12)
    assert np.ptp(c.ratio[c.lift > 0.5]) > 0.005  # the ratio varies with the angle
    from vtool.presets.valvetrain import with_run_overrides

    traces = [simulate(with_run_overrides(spec, degrees=120.0, backend=b)) for b in available()]
    assert len({tuple((e.clearance, e.kind) for e in t.events) for t in traces}) == 1
    assert all("cam contact (Hertz" in t.summary_text() for t in traces)


def test_compare_and_size_take_a_train_preset() -> None:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    runner = CliRunner()
    result = runner.invoke(cli, ["compare", "direct-acting-bucket", "--impact", "local,thesis", "--degrees", "200"])
    assert result.exit_code == 0, result.output
    assert "local" in result.output and "thesis" in result.output and "(mm/s)" in result.output
    result = runner.invoke(cli, ["size", "direct-acting-bucket", "--rpm-max", "3000", "--max-elements", "2"])
    assert result.exit_code == 0, result.output
    assert "harmonics" in result.output and "valve_spring" in result.output
