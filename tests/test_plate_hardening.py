"""No plate input reaches a traceback, a hang or an unbounded allocation (issue 14 reproducers)."""

from __future__ import annotations

import copy
import time

import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.assessments.plate.assembly import Plate
from vtool.assessments.plate.model import Case, MasterSelection, build_model
from vtool.assessments.plate.study import check_mesh_size
from vtool.assessments.plate.transient import run_rk4
from vtool.errors import InputError, RunError
from vtool.presets import PRESET_DIR, plate, read_document

DOC = read_document(PRESET_DIR / "plate-table2.toml")


def _edit(path: tuple, value: object) -> dict:
    doc = copy.deepcopy(DOC)
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return doc


@pytest.mark.parametrize(("path", "value", "needle"), [
    (("plate", "thickness"), 1e-300, "plate.thickness: got 1e-300"),  # was LinAlgError in guyan_T
    (("plate", "a"), 1e-300, "plate.a: got 1e-300"),  # was ZeroDivisionError in hermite_values
    (("plate", "youngs_modulus"), 1e300, "plate.youngs_modulus: got 1e+300"),
    (("plate", "poisson"), -0.999999, "plate.poisson: got -0.999999"),
    (("study", "mesh"), [64, 64], "study.mesh: got '64x64 bfs16 = 16900 DOF"),  # was ~2 GB per matrix
    (("study", "convergence_meshes"), [2, 4, 32], "study.convergence_meshes: got '32x32 bfs16"),
    (("transient", "omega_max_h"), [1e-300], "transient.omega_max_h: got 1e-300"),
    (("transient", "omega_max_h"), [1.0] * 10**4, "got 'a list of 10000 values'"),
    (("transient", "exact_modes"), 5000, "transient.exact_modes: got 5000"),
    (("transient", "periods"), 20.0, "transient: got '"),  # the exact reference's cost guard
])
def test_loader_refuses_before_any_matrix(path, value, needle) -> None:
    start = time.perf_counter()
    with pytest.raises(InputError) as err:
        plate.load(_edit(path, value))
    assert needle in str(err.value)
    assert len(str(err.value)) < 300
    assert time.perf_counter() - start < 5.0


def test_numerical_failures_become_run_errors() -> None:
    thin = Plate(40.0, 27.0, 1e-300, 30.0e6, 0.3, 7e-4)  # D underflows to 0
    with pytest.raises(RunError, match="case c: "):
        build_model(thin, Case("c", "bfs16", 4, 4, MasterSelection(named="interior-w")))


def test_rk4_step_guards() -> None:
    p = Plate(40.0, 27.0, 0.1, 30.0e6, 0.3, 7e-4)
    model = build_model(p, Case("c", "bfs16", 2, 2, MasterSelection(named="all")))
    with pytest.raises(InputError, match="omega_max_h"):
        run_rk4(p, model, "uniform", 1e-300)  # was OverflowError computing the step count
    with pytest.raises(InputError, match="RK4 steps"):
        run_rk4(p, model, "uniform", 0.01, periods=1e6)


def test_mesh_guard_names_the_estimate() -> None:
    assert check_mesh_size("bfs16", 4, 4) == 100
    with pytest.raises(InputError, match=r"at most 1500 DOF \(a coarser mesh\)"):
        check_mesh_size("mason24", 16, 16)


def test_cli_bad_values_are_one_line() -> None:
    runner = CliRunner()
    result = runner.invoke(cli, ["plate", "transient", "plate-table2", "--wh", "1e-300", "--no-plot"])
    assert result.exit_code == 2 and result.output.startswith("error: --wh: got 1e-300")
    result = runner.invoke(cli, ["plate", "modes", "plate-table2", "--case", "A11", "--csv", "/missing/x.csv"])
    assert result.exit_code == 2 and "error: --csv: got '/missing/x.csv'" in result.output
    assert "Traceback" not in result.output


def test_cancel_stops_a_study() -> None:
    from vtool.assessments.cancel import Cancelled
    from vtool.assessments.plate.study import run_study
    from vtool.presets import load_preset

    study = load_preset("plate-table2").study
    polls = []

    def cancel() -> bool:
        polls.append(1)
        return len(polls) > 2

    start = time.perf_counter()
    with pytest.raises(Cancelled):
        run_study(study, cancel=cancel)
    assert time.perf_counter() - start < 10.0
