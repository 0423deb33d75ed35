"""`vtool modes` and `vtool presets` through click's CliRunner."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from click.testing import CliRunner

from tests import thesis_data as thesis
from vtool.app.cli.main import cli


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


def test_modes_prints_frequencies_and_static_start() -> None:
    result = run("modes", "gnilka-1a")
    assert result.exit_code == 0, result.output
    assert "XZERO   = 0.88245022 in" in result.output
    assert "FZERO = 501.85073 lbf" in result.output
    assert "Layer closed: none  (8 coordinates)" in result.output
    assert "Layer closed: rocker  (7 coordinates)" in result.output
    assert "Hz" in result.output and "rad/s" in result.output


def test_modes_json_has_the_thesis_frequencies() -> None:
    result = run("modes", "gnilka-1a", "--json")
    assert result.exit_code == 0
    report = json.loads(result.stdout)
    open_layer, contact_layer = report["layers"]
    np.testing.assert_allclose(open_layer["omega_rad_s"][1:], thesis.FIG_6_1_OMEGA[1:], rtol=0.002)
    np.testing.assert_allclose(contact_layer["omega_rad_s"], thesis.FIG_6_2_OMEGA, rtol=0.002)
    assert abs(report["cam_offset_XZERO"]["value"] - thesis.XZERO) < 5e-9
    assert report["follower_force_FZERO"]["unit"] == "lbf"
    assert np.array(contact_layer["mode_shapes_columns"]).shape == (7, 7)


def test_presets_list_show_copy(tmp_path: Path) -> None:
    listing = run("presets", "list")
    assert listing.exit_code == 0 and "gnilka-1a" in listing.output and "valvetrain" in listing.output
    shown = run("presets", "show", "gnilka-2")
    assert shown.exit_code == 0 and "rpm = 9000.0" in shown.output
    copied = run("presets", "copy", "gnilka-1a", str(tmp_path))
    assert copied.exit_code == 0
    target = tmp_path / "gnilka-1a.toml"
    assert target.read_text() == run("presets", "show", "gnilka-1a").output
    again = run("presets", "copy", "gnilka-1a", str(target))
    assert again.exit_code == 2 and "--force" in again.output
    by_path = run("modes", str(target))
    assert by_path.exit_code == 0
