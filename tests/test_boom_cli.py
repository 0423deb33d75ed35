"""`vtool boom daf|wall|floor`, solve_preset, shipped boom presets and broken fixtures."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from vtool.app.cli.boom import solve_preset
from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_preset, loader_for, read_document

FIXTURES = Path(__file__).parent / "fixtures" / "boom"
BOOM_PRESETS = sorted(p.stem for p in PRESET_DIR.glob("boom-*.toml"))


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


@pytest.mark.parametrize("name", BOOM_PRESETS)
def test_shipped_boom_presets_round_trip_and_run(name, capsys, tmp_path):
    spec = load_preset(name)
    loader = loader_for(spec.kind)
    assert loader.load(loader.dump(spec)) == spec
    doc = read_document(PRESET_DIR / f"{name}.toml")
    assert {"kind", "title", "units"} <= set(doc)
    out_csv = tmp_path / "limits.csv"
    solve_preset(spec, out_csv, plot=False, as_json=False)
    text = capsys.readouterr().out
    assert "DAF source:" in text and "envelope (thesis family) of types" in text
    rows = list(csv.reader(out_csv.open(encoding="utf-8")))
    assert rows[0][2] == "f [Hz]" and any("[psi]" in h for h in rows[0])
    assert len(rows) > 1


def test_solve_preset_json_and_plot(capsys):
    spec = load_preset("boom-brick-wall")
    solve_preset(spec, None, plot=False, as_json=True)
    report = json.loads(capsys.readouterr().out)
    assert report["kind"] == "boom_wall" and report["limits"]
    assert "envelope" in report["daf_source"]
    solve_preset(spec, None, plot=True, as_json=False)
    assert "allowable p+ against frequency" in capsys.readouterr().out


def test_boom_daf_symmetric_n_wave(tmp_path):
    out = tmp_path / "daf.csv"
    result = run("boom", "daf", "--type", "N", "--s", "2", "--r1", "0", "--range", "0:2.5:0.001",
                 "--csv", str(out))
    assert result.exit_code == 0, result.output
    assert "free    max 2.126" in result.output
    assert "at tau/T = 0.436" in result.output or "at tau/T = 0.437" in result.output
    rows = list(csv.reader(out.open(encoding="utf-8")))
    assert rows[0][0] == "tau/T [-]" and len(rows) == 2502


def test_boom_daf_plot_envelope_and_csv_pulse():
    assert "DAF of P(" in run("boom", "daf", "--type", "P", "--r1", "0.2", "--range", "0:2:0.05",
                              "--plot").output
    env = run("boom", "daf", "--envelope", "--range", "0.4:0.6:0.1")
    assert env.exit_code == 0 and "source: velocity DAF, undamped, envelope" in env.output
    tab = run("boom", "daf", "--pulse-csv", str(FIXTURES / "n-like.csv"), "--range", "0.1:1:0.1")
    assert tab.exit_code == 0, tab.output
    assert "tabulated: tau = 0.05 s" in tab.output


def test_boom_wall_and_floor_commands():
    wall = run("boom", "wall", "boom-brick-wall")
    assert wall.exit_code == 0, wall.output
    assert "measured" in wall.output and "plate formula" in wall.output
    floor = run("boom", "floor", "boom-tall-building")
    assert floor.exit_code == 0 and "tentative" in floor.output
    wrong = run("boom", "floor", "boom-brick-wall")
    assert wrong.exit_code == 2 and "boom_floor" in wrong.output


BROKEN = {
    "negative-tau.toml": "boom.positive_durations: got 0.0, expected a non-empty list of values in [0.0001, 10] s",
    "s-below-one.toml": "boom.s: got 0.8, expected >= 1 and <= 100",
    "r1-out-of-range.toml": "boom.r1: got 1.2, expected >= 0 and < 1",
    "negative-mass.toml": "walls[0].surface_weight: got -0.2473, expected >= 1.45e-07 and <= 145 lbf/in^2",
    "negative-frequency.toml": "walls[0].measured_frequency: got -17.5, expected >= 0.01 and <= 1000 Hz",
    "unknown-key.toml": "walls[0].thicknes: got 4.5, expected no such field (unknown key) (did you mean `thickness`?)",
}


@pytest.mark.parametrize(("fixture", "message"), sorted(BROKEN.items()))
def test_broken_presets_give_one_line_errors(fixture, message):
    path = FIXTURES / fixture
    with pytest.raises(InputError) as err:
        load_preset(path)
    assert str(err.value) == message
    result = run("boom", "wall", str(path))
    assert result.exit_code == 2
    assert result.output.strip() == f"error: {message}"


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--s", "0.5"], "s: got 0.5, expected >= 1"),
        (["--type", "P", "--r1", "1.0"], "r1: got 1.0, expected in [0, 1)"),
        (["--type", "P", "--r1", "-0.1"], "r1: got -0.1"),
        (["--range", "-1:2:0.1"], "expected 0 <= start <= stop"),
        (["--range", "0:2"], "expected start:stop:step"),
        (["--damping", "-0.1"], "damping: got -0.1"),
        (["--pulse-csv", str(FIXTURES / "not-monotonic.csv")], "strictly increasing"),
    ],
)
def test_boom_daf_bad_input_exit_code_2(args, needle):
    result = run("boom", "daf", *args)
    assert result.exit_code == 2
    assert needle in result.output
    assert "Traceback" not in result.output
