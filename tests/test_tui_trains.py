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
        assert "train.spring.rate" in names and "train.follower.base_radius" in names
        assert not any(name.startswith("members.") for name in names)
        assert screen.form.row("train.spring.rate").field.unit == "N/mm"
        await put(pilot, screen, "run.degrees", "60")
        await put(pilot, screen, "train.spring.preload", "260")
        assert screen.problem is None
        await run_and_wait(pilot, app)
        doc = valvetrain.dump(load_preset(preset))
        assert "train" in doc
        doc["run"]["degrees"] = 60
        doc["train"]["spring"]["preload"] = 260
        spec = valvetrain.load(doc)
        assert screen.trace.spec == spec and spec.initial.spring_preload == 260
        expected = simulate(spec)
        np.testing.assert_array_equal(screen.trace.q, expected.q)
        from vtool.app.tui.widgets import TextPanel

        summary = screen.query_one("#summary", TextPanel).text
        assert "cam contact (Hertz line contact" in summary and "checks ([checks] limits)" in summary


async def test_a_bad_train_value_shows_the_loader_message() -> None:
    app = create_app("ohc-finger-follower", remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "train.finger.valve_arm", "10")
        assert screen.problem is not None and screen.problem.field == "train.finger.valve_arm"
