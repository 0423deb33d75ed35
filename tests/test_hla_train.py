"""The HLA in a valve train (presets/ohc-finger-follower-hla.toml on the scipy back end) against closed forms."""

from __future__ import annotations

import copy
import dataclasses
import math
import os

import numpy as np
import pytest

from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, load_preset, read_document
from vtool.solvers import backends
from vtool.solvers.model.attached import elements_of
from vtool.solvers.model.hla import closed_stiffness
from vtool.solvers.run import simulate
from vtool.solvers.studies.hla import hla_series

NAME = "ohc-finger-follower-hla"


def document(**hla: object) -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / f"{NAME}.toml"))
    doc["train"]["hla"].update(hla)
    return doc


def short(spec, degrees: float, interval: float = 0.5, rpm: float | None = None):  # noqa: ANN001, ANN201
    run = dataclasses.replace(spec.run, cycles=0, degrees=degrees, output_interval=interval,
                              rpm=spec.run.rpm if rpm is None else rpm)
    return dataclasses.replace(spec, run=run)


def test_the_pivot_member_is_the_closed_chamber():
    """The pivot member's linear stiffness is K A²/V₀ of the oil at the supply pressure (model units)."""
    spec = load_preset(NAME)
    pivot = next(m for m in spec.members if m.name == "pivot")
    oil = dataclasses.replace(spec.hla.hla, air_fraction=0.0)
    expected = 1500e6 * (math.pi * 0.008**2 / 4) ** 2 / 200e-9 * 1e-3  # N/m -> N/mm; K = 1,500 MPa at 0.3 MPa
    assert math.isclose(pivot.stiffness, closed_stiffness(oil, 3e5) * 1e-3, rel_tol=1e-12)
    assert math.isclose(pivot.stiffness, expected * (1 + 0.3 / 10 * 200 / 1500), rel_tol=1e-9)  # table at 0.3 MPa


def test_closed_chamber_through_the_train():
    """Check valve shut, no gap, one bulk modulus: along the run the chamber pressure follows the closed
    chamber's law p - p₀ = K ln(V₀/V) (tangent stiffness K A²/V) with V from the chain's pivot coordinate,
    to 1e-6 of the pressure swing."""
    spec = load_document(document(check_conductance=0.0, gap=0.0, air_fraction=0.0, bulk_pressures=[0.0],
                                  bulk_moduli=[1600.0]))
    trace = simulate(short(spec, 40.0))
    series = hla_series(trace)
    p = series.columns["hla_pressure"]  # MPa
    x = series.columns["hla_plunger_extension"]  # mm
    area, volume = math.pi * 8.0**2 / 4, 200.0
    expected = p[0] + 1600.0 * np.log((volume + area * x[0]) / (volume + area * x))
    swing = float(np.ptp(p))
    assert swing > 1.0  # the lift loads and unloads the chamber by MPa
    assert np.max(np.abs(p - expected)) <= 1e-6 * swing
    # the pivot force is the chamber's: p A + F_s(x) (the linear member's share cancelled exactly)
    force = series.columns["hla_force"]
    assert np.allclose(force, p * area + 10.0 - 2.0 * x, rtol=0, atol=1e-9 * float(np.max(force)))


def test_leak_down_through_the_train():
    """Check valve shut, a wide gap: over a lift the plunger (the chain's pivot coordinate) sinks by the gap
    formula's leakage Q = π d h³ Δp / (12 μ L) plus the closed chamber's compression, within 1 % of the
    leakage."""
    gap = 0.03  # mm: a worn adjuster, the leakage is seen within one lift
    spec = load_document(document(check_conductance=0.0, gap=gap, air_fraction=0.0, bulk_pressures=[0.0],
                                  bulk_moduli=[1600.0]))
    trace = simulate(short(spec, 60.0, interval=0.05))
    series = hla_series(trace)
    p, x = series.columns["hla_pressure"], series.columns["hla_plunger_extension"]
    area, volume, K = math.pi * 8.0**2 / 4, 200.0, 1600.0
    q = math.pi * 8.0 * gap**3 * (p - 0.3) / (12 * 8e-9 * 6.0)  # mm^3/s (8 mPa*s = 8e-9 MPa*s)
    assert np.allclose(series.columns["hla_leak_flow"], q, rtol=1e-12)
    V = volume + area * x
    # dp/K + dV/V = -Q dt / V: the chamber's volume balance with the gap's outflow
    leak = np.concatenate([[0.0], np.cumsum(0.5 * (q[1:] / V[1:] + q[:-1] / V[:-1]) * np.diff(trace.time))])
    predicted = -(p - p[0]) / K - leak
    measured = np.log(V / V[0])
    assert leak[-1] > 1e-4  # the leakage moved the plunger by more than the integrator's noise
    assert np.max(np.abs(measured - predicted)) <= 0.01 * leak[-1]
    # and x moves with the chain's pivot coordinate (q1, compression positive)
    assert np.allclose(x, -trace.coordinate(1), rtol=0, atol=1e-15)


class LooseScipy(backends.get("scipy")):  # type: ignore[misc, valid-type]  # the registry's class, subclassed
    """The scipy back end at rtol 1e-6 (a pump-up run's cycles in half the time)."""

    @staticmethod
    def options_from_run(run, every_step: bool = False):  # noqa: ANN001, ANN205
        from vtool.solvers.scipy.backend import ScipyOptions

        return ScipyOptions(rtol=1e-6, output_interval=run.output_interval, every_step=every_step)


def pump_up(cycles: int):  # noqa: ANN201
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.studies.steady import simulate_cycles

    spec = load_preset(NAME)
    spec = dataclasses.replace(spec, run=dataclasses.replace(spec.run, cycles=cycles))
    return simulate_cycles(LooseScipy(), assemble(spec))


@pytest.mark.parametrize("cycles", [2, pytest.param(4, marks=pytest.mark.skipif(
    not os.environ.get("VTOOL_SLOW_TESTS"), reason="a minute: VTOOL_SLOW_TESTS=1"))])
@pytest.mark.slow
def test_pump_up_closes_the_lash_and_settles(cycles: int):
    """Supply pressure and the seat's 0.08 mm lash: the plunger extends in the first cycle until the lash
    closes (the cam contact carries the adjuster's push on every base circle), and the drift per cycle
    settles: below 1 % of the take-up from the second cycle on (4 cycles: it shrinks cycle by cycle)."""
    trace = pump_up(cycles)
    report = trace.summary()["hla"]
    ratio = 36.0 / (36.0 - 21.0)  # the pivot lifts the roller by (b - a)/b of its own rise
    start = hla_series(trace).columns["hla_plunger_extension"][0]
    take_up = report["extension_per_cycle"][0] - start
    assert 0.9 * 0.08 * ratio < take_up < 1.3 * 0.08 * ratio  # about the lash at the pivot (+ the static load's)
    theta = report["base_circle_angle_deg"]
    on_base = [int(np.argmin(np.abs(trace.cam_angle - (theta + 360.0 * k)))) for k in range(cycles)]
    assert all(trace.force("cam")[i] > 0.0 for i in on_base)  # the lash closed
    drift = np.abs(report["drift_per_cycle"])
    assert len(drift) == cycles - 1 and drift[0] < 0.01 * take_up
    if cycles > 2:
        assert drift[-1] < 0.1 * drift[0]


def test_back_ends_without_the_flag_refuse_it():
    spec = load_preset(NAME)
    takes = backends.with_flag("nonlinear_elements")
    assert takes and spec.run.backend in takes
    for name in backends.available():
        if name in takes:
            continue
        with pytest.raises(InputError) as error:
            simulate(dataclasses.replace(spec, run=dataclasses.replace(spec.run, backend=name, cycles=0,
                                                                       degrees=10.0)))
        assert "run.backend" in str(error.value) and "[hla]" in str(error.value) and "\n" not in str(error.value)


def test_csv_json_and_text_carry_the_adjuster():
    spec = short(load_preset(NAME), 20.0, interval=2.0)
    trace = simulate(spec)
    header = trace.csv_text().splitlines()[0]
    assert "hla_pressure (MPa)" in header and "hla_plunger_extension (mm)" in header
    summary = trace.summary()["hla"]
    assert summary["pressure_unit"] == "MPa" and summary["length_unit"] == "mm"
    assert "HLA chamber pressure" in trace.summary_text()
    assert len(elements_of(spec).elements) == 1


def test_hla_round_trips_as_a_train_and_explicit():
    from vtool.presets.trains import expand
    from vtool.presets.valvetrain import dump, load

    spec = load_preset(NAME)
    assert load_document(dump(spec)) == spec
    explicit = expand(document())
    assert explicit["hla"]["member"] == "pivot"
    assert load(copy.deepcopy(explicit)).hla == spec.hla


@pytest.mark.parametrize("key, value", [("gap", -1.0), ("plunger_diameter", 0.0), ("air_fraction", 1.0),
                                        ("bulk_moduli", [1.0, 2.0])])
def test_bad_hla_input_is_one_line(key: str, value: object):
    with pytest.raises(InputError) as error:
        load_document(document(**{key: value}))
    assert f"train.hla.{key}" in str(error.value) or "train.hla.bulk" in str(error.value)


def test_hydraulic_bucket_takes_up_its_lash():
    """[train.hla] on a direct-acting bucket: the adjuster in the bucket member's place pumps up the 0.15 mm
    lash on the base circle (the bucket's ratio is 1), after which the cam contact carries its push."""
    doc = copy.deepcopy(read_document(PRESET_DIR / "direct-acting-bucket.toml"))
    del doc["train"]["bucket"]["stiffness"]
    hla = dict(read_document(PRESET_DIR / f"{NAME}.toml")["train"]["hla"])
    del hla["plunger_mass"]
    doc["train"]["hla"] = hla
    doc["run"].update(backend="scipy", degrees=360.0, output_interval=1.0)
    spec = load_document(doc)
    assert spec.hla is not None and spec.hla.member == "bucket" and spec.hla.sense == "extension"
    trace = simulate(spec)
    report = trace.summary()["hla"]
    theta = report["base_circle_angle_deg"]
    x = hla_series(trace).columns["hla_plunger_extension"]
    base = int(np.argmin(np.abs(trace.cam_angle - theta)))
    assert 0.9 * 0.15 < x[base] - x[0] < 1.2 * 0.15
    assert trace.force("cam")[base] > 0.0
    with pytest.raises(InputError, match="train.bucket.stiffness"):
        doc["train"]["bucket"]["stiffness"] = 1.5e5
        load_document(doc)
