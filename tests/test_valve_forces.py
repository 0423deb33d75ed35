"""Guide friction (Stribeck) and the gas force acting on the valve's motion (solvers/model/valveforces.py, scipy)."""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import simpson

from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, read_document
from vtool.solvers.model.configurations import partition
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.valveforces import ValveForces, cylinder_pressure, friction_force
from vtool.solvers.run import simulate

FRICTION = {"guide_friction": 15.0, "guide_velocity": 20.0, "static_friction": 25.0, "stribeck_velocity": 100.0,
            "viscous": 0.002}
GAS = {"gas_crank_angles": [0.0, 180.0, 300.0, 360.0, 420.0, 540.0], "gas_pressures": [0.1, 0.05, 0.8, 2.0, 0.8, 0.1],
       "head_diameter": 30.0, "seat_side": "cylinder", "gas_phase": 90.0}


def bucket(**forces: object) -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / "direct-acting-bucket.toml"))
    doc["run"].update(backend="scipy", degrees=360.0, output_interval=0.02)
    doc["valve_forces"] = dict(forces)
    return doc


def test_stribeck_law_by_hand():
    vf = ValveForces(coordinate=1, **FRICTION)
    for v in (-300.0, -5.0, 0.0, 1.0, 20.0, 100.0, 1e4):
        level = 15.0 + 10.0 * math.exp(-((v / 100.0) ** 2))
        assert math.isclose(float(friction_force(vf, v)), level * math.tanh(v / 20.0) + 0.002 * v, abs_tol=1e-12)
    plain = ValveForces(coordinate=1, guide_friction=15.0, guide_velocity=20.0)
    assert plain.law == "tanh" and vf.law == "stribeck"
    assert math.isclose(float(friction_force(plain, 7.0)), 15.0 * math.tanh(7.0 / 20.0), rel_tol=1e-15)


@settings(max_examples=50, deadline=None)
@given(st.floats(-1e4, 1e4, allow_nan=False))
def test_friction_opposes_the_motion(v: float):
    """F_f(v) v >= 0: the friction only dissipates (hypothesis over velocities)."""
    vf = ValveForces(coordinate=1, **FRICTION)
    assert float(friction_force(vf, v)) * v >= 0.0


def test_cylinder_pressure_table_by_crank_angle():
    vf = ValveForces(coordinate=1, gas_angles=tuple(GAS["gas_crank_angles"]), gas_pressures=tuple(GAS["gas_pressures"]),
                     head_diameter=30.0, gas_phase=90.0)
    # cam 135 deg -> crank 360: the table's peak; cam 100 -> crank 290: between 180 (0.05) and 300 (0.8)
    assert math.isclose(float(cylinder_pressure(vf, 135.0)), 2.0, rel_tol=1e-15)
    assert math.isclose(float(cylinder_pressure(vf, 100.0)), 0.05 + (0.8 - 0.05) * 110.0 / 120.0, rel_tol=1e-12)
    # periodic: crank 630 lies between 540 (0.1) and 720 = 0 (0.1)
    assert math.isclose(float(cylinder_pressure(vf, 270.0)), 0.1, rel_tol=1e-12)


@pytest.mark.slow
def test_whole_model_power_balance_with_friction_and_gas():
    """Between two events the cam's work plus the gas force's equals the change of kinetic and spring energy
    plus the modal damping's and the friction's dissipation (everything integrated by Simpson's rule on 0.02 deg
    rows of a DOP853 run at rtol 1e-9): closes to 1e-7 of the cam's absolute work (measured 1e-10)."""
    spec = load_document(bucket(**FRICTION, **GAS))
    trace = simulate(spec)
    mechanism = assemble(spec)
    n = spec.n_coordinates
    q, v = trace.q[:, :n], trace.qd[:, :n]
    energy = 0.5 * np.einsum("ri,ij,rj->r", v, mechanism.M, v) + 0.5 * np.einsum("ri,ij,rj->r", q, mechanism.K, q)
    cam_power = trace.force("cam") * trace.qd[:, trace.coordinate_numbers.index(spec.cam.coordinate)]
    columns = {name: column(slice(None)) for name, _, column in trace.element_columns()}
    valve = trace.valve_coordinate()
    gas_power = columns["valve_gas_force"] * trace.qd[:, trace.coordinate_numbers.index(valve)]
    damping = np.zeros(len(trace.time))
    for mask in np.unique(trace.configuration):
        part = partition(mechanism, int(mask))
        rows = trace.configuration == mask
        vz = np.zeros((int(rows.sum()), part.layer.size))
        vz[:, part.group] = v[rows]
        damping[rows] = np.einsum("ri,ij,rj->r", vz, part.C, vz)
    times = [0.0] + [e.time for e in trace.events] + [float(trace.time[-1])]
    checked = 0
    for a, b in zip(times[:-1], times[1:], strict=True):
        w = np.flatnonzero((trace.time > a + 1e-7) & (trace.time < b - 1e-7))
        if len(w) < 200:
            continue
        t = trace.time[w]
        friction = simpson(columns["valve_friction_power"][w], x=t)
        if friction < 1.0:  # the valve at rest in this stretch
            continue
        supplied = simpson(cam_power[w], x=t) + simpson(gas_power[w], x=t)
        residual = supplied - (energy[w[-1]] - energy[w[0]]) - simpson(damping[w], x=t) - friction
        assert abs(residual) <= 1e-7 * simpson(np.abs(cam_power[w]), x=t)
        assert abs(simpson(gas_power[w], x=t)) > 1e3 * abs(residual)  # the gas force did work that counts
        checked += 1
    assert checked >= 1


@pytest.mark.slow
def test_the_gas_force_pushes_the_valve_to_its_seat():
    """Cylinder pressure on the head's cylinder side pushes towards the seat: the valve seats earlier at the end
    of the lift (the port side: later)."""
    def seating(doc: dict) -> float:
        doc["run"].update(degrees=115.0, output_interval=1.0)
        trace = simulate(load_document(doc))
        return next(e.cam_angle for e in trace.events if e.clearance == "seat" and e.kind == "closed")

    high = dict(GAS, gas_pressures=[0.3] * 6)
    port = dict(high, seat_side="port")
    base = seating(bucket(**FRICTION))
    assert seating(bucket(**FRICTION, **high)) < base < seating(bucket(**FRICTION, **port))


def test_newmark_refuses_valve_forces():
    doc = bucket(**FRICTION)
    doc["run"].update(backend="newmark", degrees=10.0)
    spec = load_document(doc)
    with pytest.raises(InputError) as error:
        simulate(spec)
    assert "[valve_forces]" in str(error.value)
    assert dataclasses.replace(spec.valve_forces, guide_friction=0.0, static_friction=None, viscous=0.0).active is False


@pytest.mark.parametrize("key, value", [("static_friction", 1.0), ("gas_crank_angles", [0.0, 100.0, 200.0, 300.0, 400.0, 800.0]),
                                        ("seat_side", "head")])
def test_bad_valve_forces_are_one_line(key: str, value: object):
    forces = dict(FRICTION, **GAS)
    forces[key] = value
    with pytest.raises(InputError) as error:
        load_document(bucket(**forces))
    assert f"valve_forces.{key}" in str(error.value)
