"""Runs to steady state (solvers/studies/steady.py) and cam-order spectra (solvers/studies/orders.py), checked
against the closed-form periodic response of a linear train, and the stop of a run that cannot settle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.test_backends import base_excited_doc
from tests.valvetrain_cases import spec_from
from vtool.presets import load_preset
from vtool.presets.valvetrain import dump, load
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.run import simulate
from vtool.solvers.studies.metrics import run_metrics, window_text
from vtool.solvers.studies.orders import spectrum

TOLERANCE = 1e-10


def linear_doc(**steady) -> dict:
    """The base-excited oscillator (the follower pinned to the cam by its preload: one configuration, no
    clearance changes), damped so that its start-up dies out (gravity only turns weights into masses)."""
    doc = base_excited_doc(degrees=360.0)
    doc["damping"] = {"default_ratio": 0.2}
    doc["run"].update(backend="exact", steady=steady or {"tolerance": TOLERANCE, "max_cycles": 60})
    return doc


def periodic_response(spec) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """Closed form of the periodic response of the free coordinates (full numbers, 0-based) to the cam
    z = offset + A sin(θ): mean x0 = -K_ff⁻¹ K_fp z0 and order 1 X = -(K_fp + iω C_fp - ω² M_fp) Z / (K_ff + iω C_ff
    - ω² M_ff), Z = -iA (z = Re(Z e^{iωt})): the harmonic balance of the linear equations of motion, exact for
    the one harmonic the cam has. Returns (x0, X) per full coordinate of the free ones."""
    mechanism = assemble(spec)
    problem = ContactProblem.for_run(mechanism)
    layer = problem.build(problem.start_mask)
    nf, w = layer.nf, mechanism.omega
    M, C, K = layer.M, layer.C, layer.K
    z0 = mechanism.start.cam_offset
    A = spec.cam.amplitude
    ff, fp = np.ix_(range(nf), range(nf)), np.ix_(range(nf), range(nf, layer.m))
    x0 = -np.linalg.solve(K[ff], K[fp] @ np.full(layer.m - nf, z0))
    X = -np.linalg.solve(K[ff] + 1j * w * C[ff] - w**2 * M[ff],
                         (K[fp] + 1j * w * C[fp] - w**2 * M[fp]) @ np.full(layer.m - nf, -1j * A))
    return layer.kept[:nf], x0, X


def test_a_linear_train_settles_to_its_closed_form_periodic_response_and_orders() -> None:
    spec = spec_from(linear_doc())
    trace = simulate(spec)
    assert trace.cycles is not None and trace.cycles.settled and 2 < trace.cycles.count < 60
    assert not trace.events
    kept, x0, X = periodic_response(spec)
    start, end = trace.cycles.window
    rows = trace.cam_angle >= start
    theta = np.radians(trace.cam_angle[rows])
    for j, full in enumerate(kept):
        exact = x0[j] + (X[j] * np.exp(1j * theta)).real
        q = trace.q[rows, trace.coordinate_numbers.index(full + 1)]
        scale = abs(X[j]) + abs(x0[j])
        assert np.abs(q - exact).max() / scale < 1e-8  # the stated tolerance is 1e-10 per cycle
        orders = spectrum(trace, f"q{full + 1}")
        assert orders.cycles == 1 and orders.orders[1] == 1.0
        assert orders.amplitude_of(0) == pytest.approx(abs(x0[j]), rel=1e-6)
        assert orders.amplitude_of(1) == pytest.approx(abs(X[j]), rel=1e-6)
        assert max(a for o, a in orders.top(5) if o != 1.0) < 1e-6 * abs(X[j])  # nothing at other orders
        assert math.cos(orders.phase[1]) == pytest.approx(math.cos(np.angle(X[j])), abs=1e-6)


def test_a_fixed_number_of_cycles_evaluates_the_last() -> None:
    doc = linear_doc()
    del doc["run"]["steady"]
    doc["run"]["cycles"] = 3
    trace = simulate(spec_from(doc))
    assert trace.cycles.count == 3 and trace.cycles.settled is None and trace.cycles.window == (720.0, 1080.0)
    assert trace.cam_angle[-1] == pytest.approx(1080.0) and np.all(np.diff(trace.time) > 0)
    assert "cycle 3 of 3" in window_text(trace) and "fixed number" in window_text(trace)
    assert run_metrics(trace)["cycles"] == 3


def test_a_cycle_continued_equals_one_long_run() -> None:
    """Three cycles cycle by cycle against one 1080-degree run (both Newmark): the same motion, to the
    differences of a step grid that restarts at each cycle (here 4e-7 of the motion, through the events)."""
    doc = dump(load_preset("gnilka-1a"))
    doc["run"].update(degrees=1080.0, rpm=9000.0)
    plain = simulate(load(doc))
    doc["run"]["cycles"] = 3
    cycled = simulate(load(doc))
    n = plain.spec.n_coordinates
    assert cycled.q.shape == plain.q.shape
    scale = np.abs(plain.q[:, :n]).max()
    assert np.abs(cycled.q[:, :n] - plain.q[:, :n]).max() / scale < 1e-5
    assert [(e.clearance, e.kind) for e in cycled.events] == [(e.clearance, e.kind) for e in plain.events]


def test_a_run_that_cannot_settle_stops_at_max_cycles_and_says_so() -> None:
    """The ramped cam at 10,500 rev/min: the follower and the valve bounce differently from cycle to cycle
    (16, 18, 16, 18, 18, 18, 17 events; the change does not decay nor repeat over 2 to 4 cycles); the run
    stops after max_cycles and says it did not settle, by how much, and how its events changed."""
    doc = dump(load_preset("ramped-cam"))
    doc["run"].update(rpm=10500.0, steady={"tolerance": 1e-3, "max_cycles": 12})
    trace = simulate(load(doc))
    assert trace.cycles.count == 12 and trace.cycles.settled is False and trace.cycles.period == 1
    assert trace.cycles.change > 1e-3 or trace.cycles.events_changed
    text = window_text(trace)
    assert text.startswith("warning: did not settle in 12 cycles") and "changed by" in text
    assert "nor repeat every 2 to 4 cycles" in text
    assert run_metrics(trace)["cycles"] == 12


def test_a_subharmonic_orbit_settles_with_its_period_and_its_spectrum_has_half_orders() -> None:
    """1A at 15,000 rev/min alternates two contact patterns (24 and 22 events a cycle): it settles with
    period 2, the last two cycles are evaluated, and their spectrum has orders in steps of 1/2."""
    doc = dump(load_preset("gnilka-1a"))
    doc["run"].update(rpm=15000.0, steady={"tolerance": 1e-3, "max_cycles": 40})
    trace = simulate(load(doc))
    cycles = trace.cycles
    assert cycles.settled and cycles.period == 2 and cycles.window == (360.0 * (cycles.count - 2), 360.0 * cycles.count)
    first = cycles.window[0]
    counts = [sum(first + 360.0 * k <= e.cam_angle < first + 360.0 * (k + 1) for e in trace.events) for k in (0, 1)]
    assert counts[0] != counts[1]  # the two cycles of the orbit: 24 and 22 events
    assert "repeating every 2 cycles" in window_text(trace)
    orders = spectrum(trace, "F1")
    assert orders.cycles == 2 and orders.orders[1] == 0.5  # orders in steps of 1/2 over the orbit


def test_order_amplitudes_as_sweep_metrics_and_their_campbell_data_follow_the_closed_form() -> None:
    """The linear train at three speeds: the order-1 column equals the closed form at each speed, the others
    vanish, and the Campbell data line up the same numbers by speed and order."""
    from vtool.solvers.studies.orders import campbell, with_orders
    from vtool.solvers.studies.sweep import Point, SerialRunner, run_points

    speeds = [2000.0, 3000.0, 4000.0]
    specs = [with_orders(spec_from(linear_doc() | {"run": linear_doc()["run"] | {"rpm": rpm}}), ("q2",))
             for rpm in speeds]
    results = run_points([Point(i, (("run.rpm", r),), s) for i, (r, s) in enumerate(zip(speeds, specs, strict=True))],
                         SerialRunner()).results
    data = campbell([(r, res.metrics) for r, res in zip(speeds, results, strict=True)], specs[0], "q2")
    for j, spec in enumerate(specs):
        kept, x0, X = periodic_response(spec)
        exact = abs(X[list(kept).index(1)])
        assert results[j].metrics["q2_order_1"] == pytest.approx(exact, rel=1e-6)
        assert data.amplitude[0, j] == results[j].metrics["q2_order_1"]
        assert np.nanmax(data.amplitude[1:, j]) < 1e-6 * exact
    assert data.unit == "in" and len(data.frequencies) >= 1


def test_orders_of_an_unknown_quantity_are_one_line_of_bad_input() -> None:
    from vtool.errors import InputError
    from vtool.solvers.studies.orders import with_orders

    with pytest.raises(InputError, match="--orders: got 'F9'"):
        with_orders(load_preset("gnilka-1a"), ("F9",))


def test_cli_orders_and_campbell() -> None:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    solved = CliRunner().invoke(cli, ["solve", "gnilka-1a", "--orders", "F7"])
    assert solved.exit_code == 0, solved.output
    assert "evaluated: after the first revolution (cam angle 360-850 deg)" in solved.output
    assert "start-up shock (first revolution): startup_peak_force" in solved.output
    assert "F7 in cam orders over 1 cycle (cam angle 360-720 deg" in solved.output
    assert "dominant orders near each natural frequency (within 15 %):" in solved.output
    swept = CliRunner().invoke(cli, ["sweep", "gnilka-1a", "--set", "run.rpm=9000:10000:500", "--campbell", "F7",
                                     "--steady", "--workers", "1"])
    assert swept.exit_code == 0, swept.output
    assert "F7: amplitude per cam order and speed" in swept.output and "natural frequencies: " in swept.output
    bad = CliRunner().invoke(cli, ["sweep", "gnilka-1a", "--set", "damping.factor=1,2", "--campbell", "F7"])
    assert bad.exit_code == 2 and "--campbell" in bad.output


@pytest.mark.slow
def test_the_committed_steady_cycles_table_is_regenerated_unchanged() -> None:
    """docs/valvetrain.md's steady-cycles block: cycle counts (not times), so a regeneration gives it back."""
    import importlib.util
    from pathlib import Path

    from vtool.markdown import read_block, table

    root = Path(__file__).resolve().parent.parent
    spec = importlib.util.spec_from_file_location("bench_steady", root / "benchmarks" / "bench_steady.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fresh = table(*module.rows(1e-3, 30))
    assert read_block(root / "docs" / "valvetrain.md", "steady-cycles") == fresh, \
        "run python3 benchmarks/bench_steady.py --write"


def _trace_of(values: np.ndarray, angle: np.ndarray):  # noqa: ANN202
    """A hand-built plain-run trace of 1A whose valve coordinate (q7) is ``values`` at cam angles ``angle``."""
    from vtool.solvers.trace import RunStatistics, Trace

    spec = load_preset("gnilka-1a")
    q = np.zeros((len(angle), 10))
    q[:, 6] = values
    force = np.zeros((len(angle), 3))
    statistics = RunStatistics("hand", len(angle), 0, 0.0, ())
    return Trace(spec, angle / 66000.0, angle, tuple(range(1, 11)), q, q * 0, q * 0, force,
                 np.full(len(angle), 0b110), (), force.max(axis=0), statistics)


@pytest.mark.filterwarnings("ignore")
def test_spectrum_recovers_any_trigonometric_polynomial_below_the_nyquist_order() -> None:
    """Property (hypothesis): a mean plus orders 1..60 with any amplitudes and phases, sampled at 1 deg over
    three revolutions (a plain run: the last two whole cycles evaluated), comes back order by order."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    orders = st.lists(st.tuples(st.integers(1, 60), st.floats(0.0, 10.0), st.floats(-math.pi, math.pi)),
                      min_size=1, max_size=6, unique_by=lambda t: t[0])

    @settings(max_examples=40, deadline=None)
    @given(orders, st.floats(-5.0, 5.0))
    def check(terms: list[tuple[int, float, float]], mean: float) -> None:
        angle = np.arange(0.0, 1081.0)
        theta = np.radians(angle)
        values = mean + sum(a * np.cos(k * theta + phi) for k, a, phi in terms)
        result = spectrum(_trace_of(values, angle), "q7")
        assert result.cycles == 2 and result.start == 360.0
        scale = 1.0 + abs(mean) + sum(a for _, a, _ in terms)
        assert result.amplitude_of(0) == pytest.approx(abs(mean), abs=1e-9 * scale)
        expected = {k: a for k, a, _ in terms}
        for k in range(1, 90):
            assert result.amplitude_of(k) == pytest.approx(expected.get(k, 0.0), abs=1e-9 * scale)
            assert result.amplitude_of(k - 0.5) == pytest.approx(0.0, abs=1e-9 * scale)  # nothing between orders
        for k, a, phi in terms:
            if a > 1e-6 * scale:
                assert math.cos(result.phase[2 * k] - phi) == pytest.approx(1.0, abs=1e-6)

    check()
