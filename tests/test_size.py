"""The model sized to the question (solvers/studies/size.py, `vtool size`) and the docs' generated blocks.

Sources: Newmark's stability limit for γ = 1/2, β < 1/4 is Ω = ω Δt <
1/sqrt(γ/2 - β) (2 sqrt 3 for β = 1/6; Newmark 1959); the fixed-free bar's
ω_1 = (π/2) sqrt(k/m).
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

import pytest
import scipy.linalg
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.markdown import read_block, table_differences
from vtool.presets import load_preset
from vtool.solvers.model.assembly import unsplit_members
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.studies.size import (
    relative_change,
    size_study,
    stable_time_step,
    study_rows,
    with_elements,
)

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_size  # noqa: E402


def short(name: str = "gnilka-1a", degrees: float = 120.0):  # type: ignore[no-untyped-def]
    spec = load_preset(name)
    return replace(spec, run=replace(spec.run, degrees=degrees))


def test_relative_change() -> None:
    assert relative_change({"a": 110.0, "b": 0.0}, {"a": 100.0, "b": 0.0}) == pytest.approx(10 / 110)
    assert relative_change({"a": -2.0}, {"a": 2.0}) == pytest.approx(2.0)


def test_time_step_is_cut_to_the_stability_limit() -> None:
    spec = with_elements(load_preset("gnilka-1a"), "left_rocker", 8)
    dt = stable_time_step(spec)
    M, K = assemble(spec).M, assemble(spec).K
    omega_max = math.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True).max())  # no configuration is stiffer
    assert dt < spec.run.time_step
    assert omega_max * dt == pytest.approx(0.9 * 2 * math.sqrt(3), rel=1e-12)
    assert stable_time_step(load_preset("gnilka-1a")) == 1e-6  # the thesis model is inside the limit


def test_with_elements_refines_one_member_from_one_element_each() -> None:
    spec = with_elements(with_elements(load_preset("gnilka-1a"), "pushrod", 4), "valve", 2)
    assert [m.elements for m in spec.members] == [1, 1, 1, 1, 2]
    assert spec.n_coordinates == 9 and spec.cam.coordinate == 10
    assert unsplit_members(with_elements(spec, "", 1)) == load_preset("gnilka-1a")


def test_study_rows_and_recommendation() -> None:
    study = size_study(short(), 12000.0, tolerance=0.5, max_elements=2)
    assert [(r.knob, r.value) for r in study.runs] == [("baseline", 1)] + [
        (m.name, 2) for m in load_preset("gnilka-1a").members]
    assert study.runs[0].coordinates == 8 and study.runs[0].steps > 0
    assert all(r.wall_time > 0 for r in study.runs)
    for name, (n, converged) in study.elements.items():
        change = next(r.change for r in study.runs if r.knob == name)
        assert (n, converged) == ((1, True) if change < 0.5 else (2, False))
    assert study.cam_harmonic == 1 and study.harmonics is None
    header, rows = study_rows(study, with_costs=False)
    assert header[-1] == "steps" and "max seating velocity (in/s)" in header


def test_size_command_prints_its_table_and_refuses_bad_input() -> None:
    result = CliRunner().invoke(cli, ["size", "gnilka-1d", "--rpm-max", "9000", "--max-elements", "2"])
    assert result.exit_code == 0, result.output
    assert "| one element each | 1 | 8 |" in result.output and "cost ratio" in result.output
    assert "elements: pushrod" in result.output
    bad = CliRunner().invoke(cli, ["size", "gnilka-1a", "--rpm-max", "-5"])
    assert bad.exit_code == 2 and "--rpm-max" in bad.output
    assert CliRunner().invoke(cli, ["size", "plate-table2", "--rpm-max", "100"]).exit_code == 2


def rows_text(rows: list[list[str]]) -> str:
    """Rows from :func:`deterministic` as Markdown table lines again."""
    return "\n".join(" | ".join(row) + ("" if row[-1].endswith("|") else " |") for row in rows) + "\n"


def deterministic(block: str) -> list[list[str]]:
    """Table rows without the wall-time columns."""
    rows = [line.split(" | ") for line in block.splitlines() if line.startswith("| ")]
    return [row[:-2] if "wall (s)" in rows[0][-2] else row for row in rows]


def test_generated_surge_and_cam_blocks_are_current() -> None:
    from vtool.markdown import table

    assert read_block(bench_size.DOCS, "surge-convergence") == table(*bench_size.surge_rows())
    assert read_block(bench_size.DOCS, "cam-ramped") == table(*bench_size.cam_rows("ramped-cam"))


@pytest.mark.slow
def test_generated_size_block_for_the_thesis_mechanism_is_current() -> None:
    name, rpm = bench_size.SIZE_CASES["size-1a"]
    fresh = bench_size.size_block(bench_size.size_study_for(name, rpm))
    committed = read_block(bench_size.DOCS, "size-1a")
    # numbers to 1e-3 relative: a refined run's step count follows its event times, whose last bits follow
    # LAPACK's (the modes), which differ between CPUs (114074 steps on one, 114076 on another)
    assert table_differences(rows_text(deterministic(committed.split("\n\n")[0])),
                             rows_text(deterministic(fresh.split("\n\n")[0])), 1e-3) == []
    assert committed.splitlines()[-3:] == fresh.splitlines()[-3:]


@pytest.mark.slow
def test_generated_table_versus_harmonic_block_is_current() -> None:
    from vtool.markdown import table

    fresh = bench_size.table_vs_harmonic_rows()
    committed = read_block(bench_size.DOCS, "table-vs-harmonic")
    # the bounds to a decade: scipy's and Newmark's worst differences sit near a power of ten, and their
    # last bits follow the CPU's BLAS kernels
    assert table_differences(committed, table(*fresh), 0.0, decades=1) == []
    assert all(row[2] == "yes" and float(row[3].lstrip("< ")) <= 1e-5 for row in fresh[1])
