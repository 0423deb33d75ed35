"""`vtool solve` through click's CliRunner: summary, CSV, JSON, plots, errors, other preset kinds."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


@pytest.mark.parametrize("name", ["gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-1d", "gnilka-2", "gnilka-3"])
def test_every_thesis_preset_solves_and_writes_csv(tmp_path: Path, name: str) -> None:
    out = tmp_path / f"{name}.csv"
    result = run("solve", name, "--csv", str(out))
    assert result.exit_code == 0, result.output
    assert "peak force (lbf)" in result.output and "wrote 851 rows" in result.output
    rows = list(csv.reader(out.open()))
    header = rows[0]
    assert header[:3] == ["time (s)", "cam_angle (deg)", "q1 (in)"]
    assert "q3 (rad)" in header and "F2 (lbf)" in header and "q1-q9 (in)" in header
    assert header[-2:] == ["configuration", "closed"]
    assert len(rows) == 852 and rows[1][-2:] == ["7", "cam+rocker"]
    assert float(rows[-1][1]) == pytest.approx(850.0)


def test_every_step_csv_has_a_row_per_step(tmp_path: Path) -> None:
    out = tmp_path / "steps.csv"
    result = run("solve", "gnilka-1d", "--degrees", "100", "--every-step", "--csv", str(out))
    assert result.exit_code == 0, result.output
    rows = out.read_text().splitlines()
    assert len(rows) > 1500  # about 1,515 steps of 1 µs for 100 degrees at 11,000 RPM


def test_json_summary_has_events_and_statistics() -> None:
    result = run("solve", "gnilka-1a", "--degrees", "200", "--json")
    assert result.exit_code == 0
    summary = json.loads(result.stdout)
    assert summary["backend"] == "newmark" and summary["steps"] > 3000
    assert summary["events_list"][0]["clearance"] == "cam"
    assert {c["clearance"] for c in summary["clearances"]} == {"cam", "rocker", "seat"}


def test_plot_draws_force_displacement_and_configuration_charts() -> None:
    result = run("solve", "gnilka-1b", "--degrees", "120", "--plot")
    assert result.exit_code == 0
    for title in ("contact forces (lbf)", "displacements", "configuration"):
        assert title in result.output


def test_overrides_change_the_run() -> None:
    result = run("solve", "gnilka-1a", "--rpm", "9000", "--degrees", "90", "--dt", "2e-6", "--json")
    settings = json.loads(result.stdout)["settings"]
    assert settings == {"time_step_s": 2e-6, "beta": 1 / 6, "gamma": 0.5, "refine_after_events": 10,
                        "rpm": 9000.0, "degrees": 90.0, "impact": ["local"], "rocker_scale": 1.0,
                        "start_velocities": "thesis"}


def test_impact_law_and_start_overrides_are_in_the_settings_and_the_events() -> None:
    """`--impact` and `--start` change the model; `--events --json` carries every event's angle,
    clearance, kind, relative velocity and the configurations before and after, and the law."""
    result = run("solve", "gnilka-1a", "--degrees", "400", "--impact", "momentum", "--start", "quasi-static",
                 "--events", "--json")
    summary = json.loads(result.stdout)
    assert summary["settings"]["impact"] == ["momentum"]
    assert summary["settings"]["start_velocities"] == "quasi-static"
    assert {c["impact_law"] for c in summary["clearances"]} == {"momentum"}
    event = summary["events_list"][0]
    assert set(event) >= {"cam_angle_deg", "clearance", "kind", "relative_velocity", "before", "after"}
    bad = run("solve", "gnilka-1a", "--impact", "elastic")
    assert bad.exit_code == 2 and "--impact: got 'elastic', expected one of: local, thesis, momentum" in bad.output


@pytest.mark.parametrize(
    "args, text",
    [
        (["--dt", "0"], "--dt: got 0.0, expected >= 1e-12 and <= 0.1 s"),
        (["--dt", "1e-5"], "stability limit"),
        (["--rpm", "-1"], "--rpm: got -1.0, expected >= 0.001 and <= 1e+06 rev/min"),
        (["--degrees", "0"], "--degrees: got 0.0, expected >= 1e-06 and <= 3.6e+06 deg"),
        (["--backend", "euler"], "'euler' is not one of 'exact', 'newmark', 'scipy'"),
    ],
)
def test_bad_settings_exit_2_with_one_line_and_write_nothing(tmp_path: Path, args: list[str], text: str) -> None:
    out = tmp_path / "never.csv"
    result = run("solve", "gnilka-1a", "--csv", str(out), *args)
    assert result.exit_code == 2
    assert result.output.strip().count("\n") == 0 and text in result.output
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


def test_a_failed_run_exits_1_and_leaves_an_existing_file_untouched(tmp_path: Path, monkeypatch) -> None:
    """A diverging run (step 1.2x the stability limit, the limit check switched off) writes nothing."""
    import tomli_w

    from tests.test_newmark import free_mechanism_doc
    from vtool.solvers.newmark import backend as newmark

    doc = free_mechanism_doc(beta=1 / 6)
    doc["run"]["degrees"] = 400.0
    preset = tmp_path / "unstable.toml"
    preset.write_text(tomli_w.dumps(doc))
    from tests.test_newmark import diverging_run

    _, options = diverging_run()

    def unstable(run, every_step=False):  # noqa: ANN001, ANN202
        return options

    monkeypatch.setattr(newmark.NewmarkBackend, "options_from_run", staticmethod(unstable))
    out = tmp_path / "old.csv"
    out.write_text("previous results\n")
    result = run("solve", str(preset), "--csv", str(out))
    errors = [line for line in result.output.splitlines() if not line.startswith("warning: ")]  # undamped: warns
    assert result.exit_code == 1 and len(errors) == 1 and errors[0].startswith("run failed: diverged at t = ")
    assert "in configuration III (rocker)" in result.output and "Traceback" not in result.output
    assert out.read_text() == "previous results\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.csv", "unstable.toml"]


def test_solve_dispatches_boom_and_plate_presets() -> None:
    boom = run("solve", "boom-brick-wall")
    assert boom.exit_code == 0, boom.output
    plate = run("solve", "plate-irs")
    assert plate.exit_code == 0, plate.output
    refused = run("solve", "boom-brick-wall", "--dt", "1e-6")
    assert refused.exit_code == 2 and "(--dt applies to valvetrain presets)" in refused.output
    assert refused.output.count("\n") == 1


@pytest.mark.parametrize("name", ["gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-1d", "gnilka-2", "gnilka-3",
                                  "ramped-cam"])
def test_compare_runs_for_every_valvetrain_preset(tmp_path: Path, name: str) -> None:
    """`vtool compare` (every law, both starts) runs on every shipped valve-train preset; JSON and CSV agree."""
    out = tmp_path / "compare.csv"
    result = run("compare", name, "--degrees", "120", "--start", "thesis,quasi-static", "--json", "--csv", str(out))
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)["rows"]  # a preset warning goes to stderr
    assert [(r["impact"], r["start"]) for r in rows] == [(law, start) for law in ("local", "thesis", "momentum")
                                                         for start in ("thesis", "quasi-static")]
    assert len(out.read_text().splitlines()) == 1 + len(rows)


@pytest.mark.parametrize("command", [["size", "--rpm-max", "12000"], ["compare"], ["cam", "show"], ["accuracy"]])
def test_valvetrain_only_commands_refuse_another_kind_in_one_line(command: list[str]) -> None:
    result = run(*command, "plate-table2")
    assert result.exit_code == 2
    assert result.output.strip().count("\n") == 0
    assert "expected a valvetrain preset" in result.output
