"""The back-end contract is enough to write a back end (issue 36): tests/rk4_backend.py, fixed-step RK4
between located events written against vtool.solvers.backends and the contact problem's Python-level
methods alone, runs gnilka-1a and lands on the exact back end's events; the contract's equations and
monitors agree with the exact back end's own state-space solution."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from tests.rk4_backend import RK4Backend, RK4Options
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.run import simulate
from vtool.solvers.trace import Trace

#: the RK4 step of the comparison (s): h * omega_max = 0.69 for 1A (RK4 is stable to 2.8); at 1e-6 s the
#: worst event lands 0.061 deg from the exact one (RK4's error, fourth order), at 5e-7 s 0.002 deg
STEP = 5e-7
CONTRACT = {"vtool.errors", "vtool.solvers.backends", "vtool.solvers.model.contact", "vtool.solvers.model.mechanism",
            "vtool.solvers.model.spec", "vtool.solvers.trace", "numpy", "dataclasses", "__future__"}


@pytest.fixture(scope="module")
def exact() -> Trace:
    return simulate(with_run_overrides(load_preset("gnilka-1a"), backend="exact"))


def test_the_test_back_end_imports_only_the_contract() -> None:
    source = Path(__file__).with_name("rk4_backend.py").read_text(encoding="utf-8")
    imported = {node.module for node in ast.walk(ast.parse(source)) if isinstance(node, ast.ImportFrom)}
    imported |= {alias.name for node in ast.walk(ast.parse(source)) if isinstance(node, ast.Import)
                 for alias in node.names}
    assert imported <= CONTRACT, imported - CONTRACT
    assert len(source.splitlines()) <= 160


@pytest.mark.slow
def test_rk4_through_the_contract_lands_on_the_exact_events_of_1a(exact: Trace) -> None:
    spec = load_preset("gnilka-1a")
    trace = RK4Backend().simulate(assemble(spec), RK4Options(STEP))
    seconds = spec.run.degrees / (6.0 * spec.run.rpm)  # 6 rpm = deg/s
    assert trace.statistics.backend == "rk4-test" and trace.statistics.steps >= seconds / STEP
    assert len(exact.events) == 59  # the thesis preset's events (docs/valvetrain.md)
    assert [(e.clearance, e.kind, e.before, e.after) for e in trace.events] == \
        [(e.clearance, e.kind, e.before, e.after) for e in exact.events]
    worst = max(abs(a.cam_angle - b.cam_angle) for a, b in zip(trace.events, exact.events, strict=True))
    assert worst <= 0.05, worst
    assert np.allclose(trace.peak_force, exact.peak_force, rtol=0.02)


def test_the_contract_equations_and_monitors_agree_with_the_exact_solution(exact: Trace) -> None:
    """At output rows of the exact run: accelerations() gives its z̈, monitors() its closed contacts'
    forces (positive) and open gaps (positive), contact_forces() its forces."""
    mechanism = assemble(load_preset("gnilka-1a"))
    problem = ContactProblem.for_run(mechanism)
    n = problem.n
    rows = np.linspace(5, len(exact.time) - 5, 25).astype(int)
    for row in rows:
        t, mask = float(exact.time[row]), int(exact.configuration[row])
        x, v, a = exact.q[row, :n], exact.qd[row, :n], exact.qdd[row, :n]
        scale = np.abs(exact.qdd[:, :n]).max()
        assert np.allclose(problem.accelerations(mask, t, x, v), a, atol=1e-7 * scale)
        forces = problem.contact_forces(mask, t, x, v, a)
        assert np.allclose(forces, exact.contact_force[row], atol=1e-6 * np.abs(exact.contact_force).max())
        values = problem.monitors(mask, t, x, v, a)
        assert (values[problem.monitored] >= -1e-6 * np.abs(exact.contact_force).max()).all()
