"""`vtool plate modes | transient | study` and solve_preset, through click's CliRunner."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.app.cli.plate import solve_preset
from vtool.presets import PRESET_DIR, load_preset

FIXTURES = Path(__file__).parent / "fixtures" / "plate"
SMALL = """kind = "plate"
title = "small study"
units = "in-lbf-s"

[plate]
a = 40.0
b = 27.0
thickness = 0.1
youngs_modulus = 30.0e6
poisson = 0.3
density = 7.3316e-4

[study]
element = "bfs16"
mesh = [4, 4]
frequencies = 4
convergence_meshes = [2, 4]

[[cases]]
name = "A1"
masters = "all"

[[cases]]
name = "A11"
masters = "centre-w"

[[cases]]
name = "B3"
element = "mason24"
mesh = [2, 2]
masters = "all"

[transient]
cases = ["A1", "A11"]
loads = ["uniform"]
omega_max_h = [1.0]
periods = 0.5
exact_modes = 50
"""


def run(*args: str):
    return CliRunner().invoke(cli, ["plate", *args])


@pytest.fixture()
def small(tmp_path: Path) -> Path:
    path = tmp_path / "plate-small.toml"
    path.write_text(SMALL, encoding="utf-8")
    return path


def test_modes_prints_errors_against_exact(tmp_path: Path) -> None:
    out = tmp_path / "modes.csv"
    result = run("modes", "plate-table2", "--case", "A1", "--csv", str(out))
    assert result.exit_code == 0, result.output
    assert "(1,1)" in result.output and "0.0151" in result.output
    header = out.read_text().splitlines()[0]
    assert "rad_per_s" in header and "error_pct" in header


def test_modes_json_all_cases() -> None:
    result = run("modes", "plate-table3", "--json", "--count", "2")
    assert result.exit_code == 0
    data = json.loads(result.stdout)
    assert [d["KS"] for d in data][:3] == [82, 44, 18]


def test_transient_rk4_with_csv_and_plot(small: Path, tmp_path: Path) -> None:
    out = tmp_path / "resp.csv"
    result = run("transient", str(small), "--case", "A1", "--load", "uniform", "--scheme", "rk4",
                 "--wh", "1.0", "--csv", str(out))
    assert result.exit_code == 0, result.output
    assert "halving h" in result.output and "centre displacement" in result.output
    lines = out.read_text().splitlines()
    assert lines[0].startswith("t_over_T,displacement_w_over_p0_mw2")
    assert len(lines) > 100


def test_transient_modal_point_load_says_acceleration_does_not_converge(small: Path) -> None:
    result = run("transient", str(small), "--case", "A11", "--load", "point", "--scheme", "modal", "--no-plot")
    assert result.exit_code == 0, result.output
    assert "does not converge" in result.output
    assert "n/a" in result.output


@pytest.mark.parametrize("wh", ["3.0", "0", "-1"])
def test_transient_rejects_unstable_step(small: Path, wh: str) -> None:
    result = run("transient", str(small), "--wh", wh)
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "--wh" in lines[0] and "2.8" in lines[0]


@pytest.mark.parametrize("fixture", ["negative-side", "poisson-half", "master-constrained", "master-outside-mesh"])
def test_bad_presets_exit_2_with_one_line(fixture: str) -> None:
    result = run("modes", str(FIXTURES / f"{fixture}.toml"))
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ")


def test_unknown_case_is_an_input_error() -> None:
    result = run("modes", "plate-table2", "--case", "Z1")
    assert result.exit_code == 2 and "A11" in result.output


def test_non_plate_preset_is_rejected() -> None:
    names = sorted(p.stem for p in PRESET_DIR.glob("*.toml") if not p.stem.startswith("plate-"))
    result = run("modes", names[0])
    assert result.exit_code == 2 and "plate preset" in result.output


def test_study_prints_tables(small: Path, tmp_path: Path) -> None:
    out = tmp_path / "study.csv"
    result = run("study", str(small), "--csv", str(out))
    assert result.exit_code == 0, result.output
    for text in ("Table 2", "Table 3", "Table 4", "Table 5", "observed order", "Optimum"):
        assert text in result.output
    assert out.read_text().startswith("table,case,KS,load,omega_max_h,quantity,mode,value,unit")


def test_solve_preset_json_and_csv(small: Path, tmp_path: Path, capsys) -> None:
    spec = load_preset(str(small))
    out = tmp_path / "solve.csv"
    solve_preset(spec, out, False, True)
    data = json.loads(capsys.readouterr().out)
    assert data["title"] == "small study"
    assert [f["KS"] for f in data["frequencies"]] == [64, 1, 18]
    # the uniform-load acceleration's peak moves several % when the modes are halved: not converged
    assert data["exact"]["uniform"]["acceleration_converged"] is (
        data["exact"]["uniform"]["peak_change_pct"]["acceleration"] <= 1.0)
    assert "frequency_error" in out.read_text()


def test_solve_preset_plots(small: Path, capsys) -> None:
    solve_preset(load_preset(str(small)), None, True, False)
    assert "centre acceleration, uniform step load" in capsys.readouterr().out


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(p.stem for p in PRESET_DIR.glob("plate-*.toml")))
def test_every_shipped_plate_preset_runs(name: str) -> None:
    result = run("study", name)
    assert result.exit_code == 0, result.output
    assert "Table 5" in result.output
