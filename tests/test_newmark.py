"""Newmark back end against closed forms: energy, period, convergence order, impacts, kernel = reference."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from tests.valvetrain_cases import SDOF_OMEGA, sdof_doc, spec_from, thesis_doc
from vtool.errors import InputError, RunError
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark.backend import NewmarkBackend, NewmarkOptions, stability_limit
from vtool.solvers.run import simulate


def free_mechanism_doc(beta: float) -> dict:
    """Example 1A with the rocker pinned, cam and seat removed, no damping: free vibration."""
    doc = thesis_doc("gnilka-1a")
    for c in doc["clearances"]:
        c["state"] = {"cam": "removed", "rocker": "pinned", "seat": "removed"}[c["name"]]
    doc["initial"]["closed"] = ["rocker"]
    doc["damping"] = {"default_ratio": 0.0, "factor": 0.0}
    doc["run"].update(beta=beta, degrees=6000.0, time_step=1e-6)
    return doc


def test_undamped_linear_run_conserves_energy_with_average_acceleration() -> None:
    spec = spec_from(free_mechanism_doc(beta=0.25))
    mechanism = assemble(spec)
    trace = simulate(spec, every_step=True)
    n = spec.n_coordinates
    q, qd = trace.q[:, :n], trace.qd[:, :n]
    energy = 0.5 * np.einsum("ti,ij,tj->t", qd, mechanism.M, qd) + 0.5 * np.einsum("ti,ij,tj->t", q, mechanism.K, q)
    periods = trace.time[-1] * mechanism.layer({"rocker"}).modes.omega[0] / (2 * math.pi)
    assert periods > 9  # many periods of the fundamental, thousands of the highest mode
    assert np.abs(energy / energy[0] - 1).max() < 1e-9


@pytest.mark.parametrize("beta", [0.25, 1 / 6])
def test_newmark_period_matches_its_discrete_frequency(beta: float) -> None:
    """x_{n+1} + x_{n-1} = 2 cos(w̄h) x_n with cos(w̄h) = 1 - Ω²/(2(1 + βΩ²)), Ω = ωh."""
    h = 2e-4
    trace = simulate(spec_from(sdof_doc(time_step=h, beta=beta, degrees=2e-5)), every_step=True)
    on_grid = np.isclose(trace.time / h, np.round(trace.time / h), rtol=0, atol=1e-9)
    x = trace.q[on_grid, 0]  # the last step may be a partial one, to end on the requested angle
    omega_h = SDOF_OMEGA * h
    cos_bar = 1 - omega_h**2 / (2 * (1 + beta * omega_h**2))
    residual = x[2:] + x[:-2] - 2 * cos_bar * x[1:-1]
    assert np.abs(residual).max() < 1e-13 * np.abs(x).max()
    period_error = SDOF_OMEGA * h / math.acos(cos_bar) - 1
    assert period_error == pytest.approx((beta - 1 / 12) * omega_h**2 / 2, rel=0.02)


@pytest.mark.parametrize("beta", [0.25, 1 / 6])
def test_observed_convergence_order_is_two(beta: float) -> None:
    errors, steps = [], [4e-4, 2e-4, 1e-4, 5e-5]
    for h in steps:
        trace = simulate(spec_from(sdof_doc(time_step=h, beta=beta, degrees=5e-5)), every_step=True)
        t, x = trace.time, trace.q[:, 0]
        x0, v0 = trace.q[0, 0], trace.qd[0, 0]
        exact = x0 * np.cos(SDOF_OMEGA * t) + v0 / SDOF_OMEGA * np.sin(SDOF_OMEGA * t)
        errors.append(abs(x[-1] - exact[-1]))
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert slope == pytest.approx(2.0, abs=0.1)


def single_impact(restitution: float) -> tuple[float, float, float]:
    """The valve hits its (fixed) seat in configuration I under the ``momentum`` law; returns
    (KE before, KE after, plastic loss).

    Every coordinate has some velocity, so the impulse through the consistent
    mass matrix moves the valve's neighbours too.
    """
    doc = thesis_doc("gnilka-1a")
    for c in doc["clearances"]:
        c["restitution"] = restitution
    doc["contact"] = {"impact": "momentum"}
    mechanism = assemble(spec_from(doc))
    problem = ContactProblem(mechanism)
    v = np.random.default_rng(7).normal(size=mechanism.spec.n_coordinates)
    v[6] = -50.0  # the valve (q7) approaches the seat at 50 in/s
    x = np.zeros_like(v)
    x[6] = mechanism.spec.seat.position
    M = mechanism.M
    before = 0.5 * v @ M @ v
    mask, _ = problem.impact(0, [2], 0.0, x, v)
    after = 0.5 * v @ M @ v
    plastic_loss = 0.5 * 50.0**2 / np.linalg.inv(M)[6, 6]
    assert v[6] == pytest.approx(50.0 * restitution, rel=1e-12)
    assert mask == (1 if restitution == 0.0 else 0)  # plastic: the seat stays closed; elastic: bounces off
    return before, after, plastic_loss


def test_elastic_impact_conserves_kinetic_energy() -> None:
    before, after, _ = single_impact(1.0)
    assert after == pytest.approx(before, rel=1e-12)


def test_plastic_impact_loses_exactly_the_plastic_amount() -> None:
    before, after, loss = single_impact(0.0)
    assert before - after == pytest.approx(loss, rel=1e-10)


def test_numba_kernel_equals_numpy_reference_on_example_1a(tmp_path) -> None:
    """The same source with NUMBA_DISABLE_JIT=1 is the plain-NumPy reference.

    Both make the same events in the same order. The compiled and the
    interpreted arithmetic differ in the last bits (fused operations), and each
    impact amplifies such differences a little, so over 850 degrees event
    times agree to 1e-11 s (ten location tolerances) and displacements to 1e-9 in (of about 1 in).
    """
    code = (
        "import json, sys\n"
        "from vtool.presets import load_preset\n"
        "from vtool.solvers.run import simulate\n"
        "t = simulate(load_preset('gnilka-1a'))\n"
        "json.dump({'q': t.q.tolist(), 'F': t.contact_force.tolist(),"
        " 'events': [[e.time, e.clearance, e.kind] for e in t.events]}, sys.stdout)\n"
    )
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    reference = json.loads(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                          text=True, check=True).stdout)
    compiled = simulate(load_preset("gnilka-1a"))
    assert [e[1:] for e in reference["events"]] == [[e.clearance, e.kind] for e in compiled.events]
    np.testing.assert_allclose([e.time for e in compiled.events], [e[0] for e in reference["events"]],
                               rtol=0, atol=1e-11)  # ten event-location tolerances (1e-12 s)
    np.testing.assert_allclose(compiled.q, reference["q"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(compiled.contact_force, reference["F"], rtol=0, atol=1e-6 * compiled.peak_force.max())


def test_quiet_steps_cam_angle_by_rotation_equals_libm_every_step() -> None:
    """The quiet steps carry cos and sin of the cam angle by rotation, taken afresh every
    ANCHOR_STEPS steps (kernel.quiet.advance); with ANCHOR_STEPS = 0 they take libm's at every step.
    Over 1A (59 events, refined steps after each) the two runs (the plain-Python kernel, whose
    module constant can be changed) agree to the reference test's tolerances."""
    code = (
        "import json, sys\n"
        "from vtool.presets import load_preset\n"
        "from vtool.solvers.newmark.kernel import quiet\n"
        "from vtool.solvers.run import simulate\n"
        "def run():\n"
        "    t = simulate(load_preset('gnilka-1a'))\n"
        "    return {'q': t.q.tolist(), 'F': t.contact_force.tolist(), 'peak': float(t.peak_force.max()),"
        " 'events': [[e.time, e.clearance, e.kind] for e in t.events]}\n"
        "rotated = run()\n"
        "quiet.ANCHOR_STEPS = 0\n"
        "json.dump([rotated, run()], sys.stdout)\n"
    )
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    rotated, exact = json.loads(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                               text=True, check=True).stdout)
    assert [e[1:] for e in rotated["events"]] == [e[1:] for e in exact["events"]]
    np.testing.assert_allclose([e[0] for e in rotated["events"]], [e[0] for e in exact["events"]], rtol=0, atol=1e-11)
    np.testing.assert_allclose(rotated["q"], exact["q"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(rotated["F"], exact["F"], rtol=0, atol=1e-6 * exact["peak"])
    assert rotated["q"] != exact["q"]  # (the switch did change the arithmetic)


@pytest.mark.parametrize("preset", ["gnilka-1a", "gnilka-2", "gnilka-3", "gnilka-1d"])
def test_a_quiet_steps_force_rows_give_the_contact_force_at_the_steps_end(preset: str) -> None:
    """A quiet step reads each closed rigid contact's force off its own product (the step operators'
    force rows, ``ConfigurationTables._force_rows``); that number is the force row of the step's end
    state (``linear_force``, term by term), in every configuration, standard and refined step, from
    random states, to round-off. (The kernel's functions as plain Python: ``py_func``.)"""
    from vtool.solvers.newmark import layout
    from vtool.solvers.newmark.kernel import algebra, forces, step
    from vtool.solvers.newmark.records import Config

    def plain(function):  # noqa: ANN001, ANN202
        return getattr(function, "py_func", function)

    problem = ContactProblem(assemble(load_preset(preset)))
    tables = problem.tables
    dt, beta, gamma, fine = 1e-6, 0.25, 0.5, 1e-7
    tables.use_step(dt, beta, gamma, fine)
    n, ns, ncl = problem.n, problem.ns, problem.ncl
    rng = np.random.default_rng(7)
    checked = 0
    for c in range(2**ncl):
        tables.build(c)
        C = Config(c, *tables.of(c))
        nf = C.ci[layout.CI_NF]
        for plane, h in ((layout.CP_STD, dt), (layout.CP_FINE, fine)):
            for _ in range(10):
                z, zd, zdd = rng.normal(size=n) * 1e-2, rng.normal(size=n) * 10, rng.normal(size=n) * 1e4
                src = rng.normal(size=3 * ns) * np.tile([1e-2, 10, 1e4], ns)
                # a layer state: rows (z, ż, z̈)
                end = np.array([z + h * zd + h * h * (0.5 - beta) * zdd, zd + h * (1 - gamma) * zdd, zdd])
                plain(step.prescribed)(C.ci, n, src, end[0], end[1], end[2])
                out = np.zeros(n + ncl)
                plain(algebra.apply_operator)(C.cp, C.ci, plane, C.ci[layout.CI_ROWS], C.ci[layout.CI_SRCSTEP], src,
                                              end[0], end[1], end[2], out)
                end[2, :nf] = out[:nf]
                end[0, :nf] += beta * h * h * out[:nf]
                end[1, :nf] += gamma * h * out[:nf]
                for k in range(ncl):
                    if C.mk[k, layout.MK_KIND] != layout.MK_FORCE:
                        continue
                    expected = plain(forces.linear_force)(C.mon, k, n, ns, C.mk[k, layout.MK_M], *end, src)
                    row = C.mk[k, layout.MK_ROW]
                    assert nf <= row < C.ci[layout.CI_ROWS]
                    scale = np.abs(C.mon[k, :3 * n + 3 * ns]).max() * 1e4
                    assert C.mon[k, 3 * n + 3 * ns] + out[row] == pytest.approx(expected, rel=1e-11, abs=1e-13 * scale)
                    checked += 1
    assert checked > 0


def chain_doc(masses: int) -> dict:
    """A chain of ``masses`` masses on springs, each a gap of 0.002 in behind the next (masses - 1
    internal clearances) and the first riding the cam (one more): a clearance per link."""
    doc = sdof_doc(amplitude=0.05, rpm=3000.0, degrees=40.0, time_step=1e-6, restitution=0.3)
    doc["coordinates"] = [{"name": f"m{i}", "motion": "translation"} for i in range(1, masses + 1)]
    members = {"ground": {"element": "bar", "length": 1.0, "stiffness": 50.0, "mass": 0.001, "area": 1.0,
                          "coordinates": [masses, 0]}}
    for i in range(1, masses):
        members[f"link{i}"] = {"element": "bar", "length": 1.0, "stiffness": 2000.0, "mass": 0.001, "area": 1.0,
                               "coordinates": [i, i + 1]}
    doc["members"] = members
    doc["cam"] = {"coordinate": masses + 1, "amplitude": 0.05}
    doc["clearances"] = [{"name": "cam", "ahead": 1, "behind": masses + 1, "kind": "external"}]
    doc["clearances"] += [{"name": f"gap{i}", "ahead": i, "behind": i + 1, "kind": "internal"}
                          for i in range(1, masses)]
    doc["initial"]["closed"] = ["cam"]
    return doc


def test_the_row_buffer_holds_a_run_at_its_output_interval_or_4096_rows() -> None:
    """KernelRun allocates its output rows per run (newmark.row_buffer): the rows at the output
    interval, the start's and a round-off's included, up to ROW_BUFFER; an every-step run takes the
    cap (the kernel flushes a full buffer and goes on, so any size is correct, only slower)."""
    from vtool.solvers.newmark.backend import ROW_BUFFER, row_buffer

    assert row_buffer(850.0, 1.0, every_step=False) == 853  # 1A: 851 rows at 1 degree (0 to 850)
    assert row_buffer(850.0 * (1 + 1e-15), 1.0, every_step=False) == 853
    assert row_buffer(36000.0, 1.0, every_step=False) == ROW_BUFFER
    assert row_buffer(850.0, 1.0, every_step=True) == ROW_BUFFER
    assert row_buffer(850.0, 0.0, every_step=False) == ROW_BUFFER
    assert row_buffer(850.0, math.nan, every_step=False) == ROW_BUFFER
    trace = simulate(load_preset("gnilka-1a"))
    assert len(trace.time) == 851 <= row_buffer(trace.time[-1], trace.time[1] - trace.time[0], False)


def test_stability_limit_of_linear_acceleration() -> None:
    assert stability_limit(1 / 6, 0.5, 1.0) == pytest.approx(math.sqrt(12))
    assert stability_limit(0.25, 0.5, 1.0) == math.inf
    mechanism = assemble(load_preset("gnilka-1a"))
    t_min = 2 * math.pi / mechanism.layer(frozenset()).modes.omega.max()
    limit = stability_limit(1 / 6, 0.5, mechanism.layer(frozenset()).modes.omega.max())
    assert limit == pytest.approx(math.sqrt(3) / math.pi * t_min)


@pytest.mark.parametrize(
    "changes, field, text",
    [
        ({"time_step": 0.0}, "run.time_step", ">= 1e-12"),
        ({"time_step": -1e-6}, "run.time_step", ">= 1e-12"),
        ({"time_step": 3e-6}, "run.time_step", "<= 2.52654e-06 (stability limit"),
        ({"rpm": 0.0}, "run.rpm", ">= 0.001 and <= 1e+06 rev/min"),
        ({"degrees": -5.0}, "run.degrees", ">= 1e-06 and <= 3.6e+06 deg"),
    ],
)
def test_bad_run_settings_are_refused_with_the_limit(changes: dict, field: str, text: str) -> None:
    with pytest.raises(InputError) as info:
        simulate(with_run_overrides(load_preset("gnilka-1a"), **changes))
    assert info.value.field == field and text in str(info.value)


def test_beta_quarter_has_no_step_limit() -> None:
    spec = with_run_overrides(load_preset("gnilka-1a"), beta=0.25, time_step=5e-6, degrees=30.0)
    assert simulate(spec).success


def diverging_run():  # noqa: ANN201
    doc = free_mechanism_doc(beta=1 / 6)
    doc["run"].update(degrees=400.0)
    spec = spec_from(doc)
    mechanism = assemble(spec)
    omega_max = mechanism.layer({"rocker"}).modes.omega.max()
    dt = 1.2 * stability_limit(1 / 6, 0.5, omega_max)
    return mechanism, NewmarkOptions(dt, enforce_stability_limit=False)


def test_divergence_stops_with_time_and_configuration() -> None:
    mechanism, options = diverging_run()
    with pytest.raises(RunError) as info:
        NewmarkBackend().simulate(mechanism, options)
    message = str(info.value)
    assert message.startswith("diverged at t = ") and "in configuration III (rocker)" in message


def test_restitution_bounces_end_in_resting_contact() -> None:
    """A bouncing contact (e = 0.8) makes a finite, decaying sequence of impacts, then rests."""
    doc = sdof_doc(amplitude=0.01, seat=0.005, restitution=0.8, time_step=1e-6, beta=0.25, degrees=3e-4)
    trace = simulate(spec_from(doc), every_step=True)
    impacts = [e for e in trace.events if e.clearance == "seat" and e.kind == "closed"]
    speeds = [-e.relative_velocity for e in impacts]
    assert 3 < len(impacts) < 200
    assert all(later < earlier for earlier, later in zip(speeds, speeds[1:], strict=False))
    assert trace.configuration[-1] == 1  # resting on the seat


def test_chattering_is_stopped_by_sticking_when_resting_is_disabled() -> None:
    doc = sdof_doc(amplitude=0.01, seat=0.005, restitution=0.8, time_step=1e-6, beta=0.25, degrees=3e-4)
    mechanism = assemble(spec_from(doc))
    options = NewmarkOptions(1e-6, beta=0.25, rest_velocity=1e-300, zeno_stick=10, zeno_stop=10_000,
                             every_step=True)
    trace = NewmarkBackend().simulate(mechanism, options)
    assert trace.configuration[-1] == 1 and len(trace.events) < 300
    too_strict = NewmarkOptions(1e-6, beta=0.25, rest_velocity=1e-300, zeno_stick=10_000, zeno_stop=30)
    with pytest.raises(RunError, match="chattering contact"):
        NewmarkBackend().simulate(mechanism, too_strict)


def test_an_every_step_run_reports_progress_and_can_be_cancelled() -> None:
    """Every-step output fills the row buffer before a chunk ends: the chunk must still end (progress, cancel)."""
    from vtool.solvers.run import simulate

    spec = load_preset("gnilka-1a")
    seen: list[float] = []
    simulate(spec, every_step=True, progress=seen.append)
    assert len(seen) >= 3 and seen[-1] == 1.0
    with pytest.raises(RunError, match="cancelled"):
        simulate(spec, every_step=True, cancel=lambda: True)


def test_a_run_told_of_its_progress_gives_the_bits_of_one_that_is_not() -> None:
    """With nobody told of the progress, the kernel goes on past each chunk's end by itself
    (``layout.FP_CHUNK``); told, it returns to Python there and is called again. The two give the same
    bits: rows, forces, events and peaks (1A; 1A under the momentum law; a compliant Hertz cam)."""
    from tests.test_compliant import hertz_doc
    from vtool.solvers.studies.compare import with_model

    for spec in (load_preset("gnilka-1a"), with_model(load_preset("gnilka-1a"), "momentum"), spec_from(hertz_doc())):
        backend, mechanism = NewmarkBackend(), assemble(spec)
        options = backend.options_from_run(spec.run)
        seen: list[float] = []
        told = backend.simulate(mechanism, options, progress=seen.append)
        untold = backend.simulate(mechanism, options)
        assert len(seen) >= 3, "the run did not return at its chunks' ends"
        for name in ("time", "q", "qd", "qdd", "contact_force", "configuration", "peak_force"):
            assert getattr(told, name).tobytes() == getattr(untold, name).tobytes(), name
        assert told.events == untold.events


def test_events_taken_whole_from_the_buffers_equal_events_made_one_by_one() -> None:
    """``TraceBuilder.add_events`` makes each Event without its dataclass __init__ (for speed): the events
    equal, and hash as, those :meth:`add_event` makes through Event(...), and stay frozen."""
    import dataclasses

    from vtool.solvers.trace import EVENT_KINDS, Event, TraceBuilder

    spec = load_preset("gnilka-1a")
    problem = ContactProblem(assemble(spec))
    trace = simulate(spec)
    whole = TraceBuilder(spec, problem.source_numbers, problem.omega)
    one_by_one = TraceBuilder(spec, problem.source_numbers, problem.omega)
    floats = np.array([[e.time, e.relative_velocity] for e in trace.events])
    codes = {kind: code for code, kind in EVENT_KINDS.items()}
    names = [c.name for c in spec.clearances]
    ints = np.array([[names.index(e.clearance), codes[e.kind], e.before, e.after] for e in trace.events])
    whole.add_events(floats, ints)
    for e in trace.events:
        one_by_one.add_event(e.time, names.index(e.clearance), e.kind, e.relative_velocity, e.before, e.after)
    assert len(whole.events) == len(trace.events) > 50
    assert whole.events == one_by_one.events == list(trace.events)
    assert [hash(e) for e in whole.events] == [hash(e) for e in one_by_one.events]
    assert all(type(e) is Event and vars(e) == vars(o) for e, o in zip(whole.events, one_by_one.events, strict=True))
    with pytest.raises(dataclasses.FrozenInstanceError):
        whole.events[0].time = 0.0  # type: ignore[misc]


def test_a_kept_mechanism_serves_equal_specs_whatever_their_run_settings() -> None:
    """run._assemble keeps the last mechanisms by the spec's fields but its run settings: an equal spec
    (another object, another speed) shares the kept layers; another member or a clearance does not."""
    import dataclasses

    from vtool.solvers import run

    spec = load_preset("gnilka-1a")
    first = run._assemble(spec)
    assert first.spec is spec
    again = run._assemble(load_preset("gnilka-1a"))
    faster = run._assemble(dataclasses.replace(spec, run=dataclasses.replace(spec.run, rpm=2 * spec.run.rpm)))
    assert again._layers is first._layers and faster._layers is first._layers
    assert faster.spec.run.rpm == 2 * spec.run.rpm
    member = dataclasses.replace(spec.members[0], length=spec.members[0].length * 1.01)
    other = run._assemble(dataclasses.replace(spec, members=(member, *spec.members[1:])))
    assert other._layers is not first._layers
    assert not np.array_equal(other.K, first.K)
    clearance = dataclasses.replace(spec.clearances[0], restitution=0.5)
    assert run._assemble(dataclasses.replace(spec, clearances=(clearance, *spec.clearances[1:])))._layers \
        is not first._layers


@pytest.mark.parametrize("name", ["q", "qd", "qdd", "contact_force"])
def test_a_non_finite_value_anywhere_in_a_trace_is_a_run_error_naming_it(name: str) -> None:
    """run._check_finite: huge finite values (two 1e308s) are no error, a nan or an inf in any place is,
    at its row's time and cam angle."""
    import dataclasses

    from vtool.solvers import run

    trace = simulate(load_preset("gnilka-1a"))
    huge = getattr(trace, name).copy()
    huge[:2, 0] = 1e308
    run._check_finite(dataclasses.replace(trace, **{name: huge}))
    for bad in (np.nan, np.inf, -np.inf):
        values = getattr(trace, name).copy()
        values[7, -1] = bad
        with pytest.raises(RunError, match=rf"^the run diverged: non-finite {name} at t = "
                                           rf"{trace.time[7]:.6g} s \(cam angle {trace.cam_angle[7]:.4g} deg\)"):
            run._check_finite(dataclasses.replace(trace, **{name: values}))


def twenty_clearance_spec():  # noqa: ANN201
    """:func:`chain_doc` with 21 masses: 21 clearances (2^21 configurations; the preset loader's limit
    of 8 is passed by setting the clearances on the loaded spec)."""
    import dataclasses

    doc = chain_doc(21)
    doc["cam"]["amplitude"], doc["run"]["degrees"] = 0.2, 60.0
    every = doc["clearances"]
    doc["clearances"] = every[:8]
    spec = spec_from(doc)
    template = spec.clearances[1]
    return dataclasses.replace(spec, clearances=spec.clearances[:1] + tuple(
        dataclasses.replace(template, name=c["name"], ahead=c["ahead"], behind=c["behind"]) for c in every[1:]))


def test_twenty_clearances_allocate_only_the_configurations_a_run_visits() -> None:
    """The configuration tables grow with the configurations a run visits (a mask -> slot map), not
    with the 2^21 it could reach (dense tables: 2^21 rows of the step operators, some 100 GB)."""
    spec = twenty_clearance_spec()
    mechanism = assemble(spec)
    backend = NewmarkBackend()
    trace = backend.simulate(mechanism, backend.options_from_run(spec.run))
    tables = ContactProblem.for_run(mechanism).tables  # (the mechanism's shared tables)
    built = len(trace.statistics.configurations_built)
    assert len(spec.clearances) == 21 and trace.events and built >= 3
    assert set(tables.slots) == set(tables.layers) == set(trace.statistics.configurations_built)
    assert tables.ci.shape[0] == tables.cp.shape[0] <= 2 * max(built, 4)  # doubled when full
    index = tables.index  # every built configuration found by the kernel's probe, no other
    assert sorted(int(m) for m in index[index[:, 0] >= 0, 0]) == sorted(tables.slots)
