"""BLAS pools during a computation: each entry point runs with one thread (vtool.threads.limited, issue 12)
and leaves the pools as it found them. The plate study ran on the libraries' default threads until
2026-11-26 (``benchmarks/bench_threads.py`` measures both; docs/plate.md)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import pytest
import threadpoolctl

from vtool.assessments.plate import model as plate_model
from vtool.assessments.plate import study as plate_study
from vtool.assessments.plate import vibration
from vtool.presets import load_preset


def blas_threads() -> list[int]:
    return [p["num_threads"] for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas"]


@contextmanager
def two_threads() -> Iterator[None]:
    """The BLAS pools at two threads (the libraries' default on the 2-core machine), whatever this process had."""
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        if not blas_threads() or set(blas_threads()) != {2}:
            pytest.skip("no BLAS pool that takes two threads")
        yield


def watching(monkeypatch: pytest.MonkeyPatch, owner: Any, name: str) -> list[list[int]]:
    """Record the BLAS threads at each call of ``owner.name`` (a callee of the entry point)."""
    seen: list[list[int]] = []
    inner: Callable[..., Any] = getattr(owner, name)

    def spy(*args: Any, **kwargs: Any) -> Any:
        seen.append(blas_threads())
        return inner(*args, **kwargs)

    monkeypatch.setattr(owner, name, spy)
    return seen


def test_the_plate_entry_points_run_on_one_blas_thread_and_restore_the_pools(
        monkeypatch: pytest.MonkeyPatch) -> None:
    spec = load_preset("plate-table2")
    case = spec.study.cases[0]
    plate = spec.study.plate
    reductions = watching(monkeypatch, plate_model, "reduce")
    frequencies = watching(monkeypatch, vibration, "natural_frequencies")
    rk4 = watching(monkeypatch, plate_study, "run_rk4")
    with two_threads():
        model = plate_model.build_model(plate, case)
        vibration.free_vibration(plate, model, 3)
        plate_study.run_case(plate, case, "uniform", "rk4", 2.0, 1.0, 50)
        assert set(blas_threads()) == {2}  # restored after each
    assert reductions and frequencies and rk4
    assert all(set(threads) == {1} for threads in reductions + frequencies + rk4)


def test_a_whole_plate_study_runs_on_one_blas_thread(monkeypatch: pytest.MonkeyPatch) -> None:
    study = load_preset("plate-table2").study
    seen = watching(monkeypatch, vibration, "natural_frequencies")
    with two_threads():
        plate_study.run_study(study, transient=False)
        assert set(blas_threads()) == {2}
    assert seen and all(set(threads) == {1} for threads in seen)


def test_a_valve_train_run_runs_on_one_blas_thread(monkeypatch: pytest.MonkeyPatch) -> None:
    """The run, and the assembly of a mechanism no run has kept yet (and its modes) before it."""
    import dataclasses

    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers import run
    from vtool.solvers.model import contact

    spec = with_run_overrides(load_preset("gnilka-1a"), degrees=5.0)
    member = dataclasses.replace(spec.members[0], length=spec.members[0].length * 1.000123)  # a new mechanism
    spec = dataclasses.replace(spec, members=(member, *spec.members[1:]))
    assembled = watching(monkeypatch, run, "assemble")
    problems = watching(monkeypatch, contact.ContactProblem, "for_run")
    with two_threads():
        run.simulate(spec)
        assert set(blas_threads()) == {2}
    assert assembled and problems and all(set(threads) == {1} for threads in assembled + problems)
