"""Valve-train presets: shipped presets load and round-trip; bad ones fail with one clear line."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
import tomli_w
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, load_preset, read_document, save_spec

FIXTURES = Path(__file__).parent / "fixtures" / "valvetrain"
VALVETRAIN_PRESETS = sorted(p.stem for p in PRESET_DIR.glob("gnilka-*.toml"))
BAD_PRESETS = sorted(FIXTURES.glob("*.toml"))


def expected_message(path: Path) -> str:
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first.startswith("# expect: ")
    return first.removeprefix("# expect: ")


def test_six_thesis_presets_are_shipped() -> None:
    assert VALVETRAIN_PRESETS == ["gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-1d", "gnilka-2", "gnilka-3"]


@pytest.mark.parametrize("name", VALVETRAIN_PRESETS)
def test_preset_round_trips_through_tomli_w(name: str) -> None:
    spec = load_preset(name)
    text = tomli_w.dumps(__import__("vtool.presets.valvetrain", fromlist=["dump"]).dump(spec))
    assert load_document(tomllib.loads(text)) == spec


def test_save_spec_writes_a_loadable_file(tmp_path: Path) -> None:
    spec = load_preset("gnilka-1c")
    target = tmp_path / "mine.toml"
    save_spec(spec, target)
    assert load_preset(target) == spec
    assert list(tmp_path.iterdir()) == [target]  # no temporary left behind


@pytest.mark.parametrize("name", VALVETRAIN_PRESETS)
def test_thesis_runs_are_850_degrees_at_one_microsecond(name: str) -> None:
    run = load_preset(name).run
    assert (run.degrees, run.time_step, run.beta, run.gamma) == (850.0, 1e-6, 1 / 6, 0.5)


def test_preset_variants_differ_as_the_thesis_examples() -> None:
    states = {n: {c.name: c.state for c in load_preset(n).clearances} for n in VALVETRAIN_PRESETS}
    rpm = {n: load_preset(n).run.rpm for n in VALVETRAIN_PRESETS}
    assert states["gnilka-1a"] == {"cam": "enabled", "rocker": "enabled", "seat": "enabled"}
    assert states["gnilka-1b"]["seat"] == "removed"
    assert states["gnilka-1c"]["rocker"] == "pinned" and states["gnilka-1c"]["seat"] == "enabled"
    assert states["gnilka-1d"] == {"cam": "enabled", "rocker": "pinned", "seat": "removed"}
    assert rpm == {"gnilka-1a": 11000, "gnilka-1b": 11000, "gnilka-1c": 11000, "gnilka-1d": 11000,
                   "gnilka-2": 9000, "gnilka-3": 10000}


@pytest.mark.parametrize("path", BAD_PRESETS, ids=lambda p: p.stem)
def test_bad_preset_raises_input_error_naming_the_field(path: Path) -> None:
    with pytest.raises(InputError) as info:
        load_document(read_document(path))
    assert expected_message(path) in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("path", BAD_PRESETS, ids=lambda p: p.stem)
def test_bad_preset_on_the_cli_exits_2_with_one_line(path: Path) -> None:
    result = CliRunner().invoke(cli, ["modes", str(path)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert expected_message(path) in lines[0]
    assert "Traceback" not in result.output


def test_unknown_preset_name_lists_the_shipped_ones() -> None:
    result = CliRunner().invoke(cli, ["modes", "gnilka-9z"])
    assert result.exit_code == 2
    assert "gnilka-1a" in result.output and "Traceback" not in result.output
