"""The valve-train screen on a train-type preset: the form edits the type's parameters (presets/trains.py)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.tui_helpers import put, run_and_wait
from vtool.app.tui.app import create_app
from vtool.presets import load_preset, valvetrain
from vtool.solvers.run import simulate

pytestmark = pytest.mark.asyncio


@pytest.mark.parametrize("preset", ["ohc-finger-follower", "direct-acting-bucket"])
async def test_train_form_edits_the_type_parameters_and_runs_what_the_library_runs(preset: str) -> None:
    app = create_app(preset, remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        names = [f.name for f in screen.form.fields]
        assert "train.spring.wire_diameter" in names and "train.follower.base_radius" in names
        assert not any(name.startswith("members.") for name in names)
        assert screen.form.row("train.spring.installed_length").field.unit == "mm"
        await put(pilot, screen, "run.degrees", "60")
        await put(pilot, screen, "train.spring.installed_length", "37")
        assert screen.problem is None
        await run_and_wait(pilot, app)
        doc = valvetrain.dump(load_preset(preset))
        assert "train" in doc
        doc["run"]["degrees"] = 60
        doc["train"]["spring"]["installed_length"] = 37
        spec = valvetrain.load(doc)
        # the data sheet's preload at 37 mm: the bucket's 35 N/mm over 8 mm, the finger's table 200 + 30 N
        preload = {"direct-acting-bucket": 79300.0 * 256.0 / (8.0 * 13824.0 * 5.25) * 8.0,
                   "ohc-finger-follower": 230.0}[preset]
        assert screen.trace.spec == spec and spec.initial.spring_preload == pytest.approx(preload, rel=1e-12)
        expected = simulate(spec)
        np.testing.assert_array_equal(screen.trace.q, expected.q)
        from vtool.app.tui.widgets import TextPanel

        summary = screen.query_one("#summary", TextPanel).text
        assert "cam contact (Hertz line contact" in summary and "checks ([checks] limits)" in summary
        assert "valve springs (data sheet" in summary and "coil-bind margin" in summary


async def test_a_bad_train_value_shows_the_loader_message() -> None:
    app = create_app("ohc-finger-follower", remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "train.finger.valve_arm", "10")
        assert screen.problem is not None and screen.problem.field == "train.finger.valve_arm"


async def test_the_clashing_spring_preset_shows_its_coil_clash_in_the_summary() -> None:
    app = create_app("nested-spring-clash", remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        await run_and_wait(pilot, app)
        from vtool.app.tui.widgets import TextPanel

        summary = app.screen.query_one("#summary", TextPanel).text
        assert "first coil clash at" in summary and "COIL BIND" in summary
        assert "peak coil contact force" in summary and "not to be trusted" not in summary
        assert "FAIL  valve spring coil-bind margin" in summary
