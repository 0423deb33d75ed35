"""Table-cam presets from anywhere: sweep and copy, a base-circle start, the seat preflight, lash bounds.

Sources: ramped-cam.toml (a lash of 0.008 in, the valve seated on the base
circle every revolution: its lift table is 0 over the dwell); a sampled sine
is a trigonometric polynomial of degree 1, with no junction however coarse.
"""

from __future__ import annotations

import copy
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, load_preset, read_document
from vtool.presets.paths import plan_sweep
from vtool.solvers.model.cam import junction_warning
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.preflight import seat_reach_warning


def ramped_doc() -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / "ramped-cam.toml"))
    doc["cam"]["lift_table"] = str(PRESET_DIR / "ramped-cam.csv")
    return doc


def test_a_sweep_of_a_table_preset_finds_its_table_from_any_folder(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # not the presets folder: the table resolves against the preset's
    plan = plan_sweep("ramped-cam", ["run.rpm=3000,3100"])
    assert [p.spec.run.rpm for p in plan.points] == [3000.0, 3100.0]
    assert plan.points[0].spec.cam == load_preset("ramped-cam").cam
    assert dict(plan.fields)["run.rpm"] == "rev/min"


def test_a_copied_table_preset_loads_anywhere_with_the_table_inline(tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "deep" / "x.toml"
    target.parent.mkdir()
    result = CliRunner().invoke(cli, ["presets", "copy", "ramped-cam", str(target)])
    assert result.exit_code == 0, result.output
    assert "ramped-cam.csv written inline" in result.output
    monkeypatch.chdir(tmp_path)
    copied = load_preset(target)
    assert copied == load_preset("ramped-cam")
    text = target.read_text(encoding="utf-8")
    assert "lift_table" not in text and "# A dwell-and-ramps cam" in text  # the comments stay


def test_a_table_starting_on_the_base_circle_is_refused_naming_the_lash() -> None:
    doc = ramped_doc()
    del doc["cam"]["lift_table"]
    angles = np.arange(0.0, 360.0, 2.0)  # a 120-degree lift event centred at 180 deg, base circle at 0
    doc["cam"]["angles"] = angles.tolist()
    bump = 0.1 * (1.0 + np.cos(np.radians(3.0 * (angles - 180.0)))) ** 2  # smooth to its acceleration
    doc["cam"]["lifts"] = np.where(np.abs(angles - 180.0) < 60.0, bump, 0.0).tolist()
    spec = load_document(doc)
    with pytest.raises(InputError, match=r"^seat\.lash: got 0\.008, expected a lash below the cam's lift at "
                                         r"angle 0, .*rotate it"):
        assemble(spec).start  # noqa: B018 (the start is where the seat is checked)


def test_a_lash_preset_that_seats_every_revolution_does_not_warn() -> None:
    assert seat_reach_warning(assemble(load_preset("ramped-cam"))) is None
    doc = ramped_doc()  # a seat far below the valve's whole travel still warns, for a table cam too
    del doc["seat"]["lash"]
    doc["seat"]["position"] = -0.6
    message = seat_reach_warning(assemble(load_document(doc)))
    assert message is not None and message.startswith("seat.position: the valve (q7) moves between")


def test_a_negative_lash_is_refused_in_one_line() -> None:
    doc = ramped_doc()
    doc["seat"]["lash"] = -0.008
    with pytest.raises(InputError) as info:
        load_document(doc)
    assert str(info.value) == "seat.lash: got -0.008, expected >= 0 in"


@pytest.mark.parametrize("points", [7, 9, 17, 19, 21])
def test_a_coarse_smooth_table_gets_no_junction_warning(points: int) -> None:
    angles = np.arange(points) * 360.0 / points
    for lifts in (0.5 + 0.5 * np.sin(np.radians(angles)),
                  (0.5 + 0.5 * np.cos(np.radians(angles))) ** 2,
                  0.3 + 0.2 * np.sin(np.radians(angles)) + 0.1 * np.sin(np.radians(3 * angles))):
        assert junction_warning(angles, np.round(lifts, 6)) is None


def test_loading_a_seven_point_sine_table_does_not_warn() -> None:
    doc = ramped_doc()
    del doc["cam"]["lift_table"], doc["cam"]["tolerance"]
    angles = [i * 360.0 / 7 for i in range(7)]
    doc["cam"].update(angles=angles, lifts=[round(0.2 + 0.2 * math.sin(math.radians(a)), 6) for a in angles], harmonics=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_document(doc)
