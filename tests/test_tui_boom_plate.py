"""Pilot tests of the sonic-boom and plate screens, against the library and the CLI."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest
from click.testing import CliRunner

from tests.tui_helpers import put, run_and_wait
from vtool.app.cli.main import cli
from vtool.app.plots import line_chart
from vtool.app.tui.app import create_app
from vtool.app.tui.boom import BoomScreen
from vtool.app.tui.dialogs import ErrorDialog
from vtool.app.tui.plate import PlateScreen, transient_chart
from vtool.assessments.plate.model import build_model
from vtool.assessments.plate.report import frequency_table
from vtool.assessments.plate.transient import exact_histories, peak_errors, run_modal
from vtool.assessments.plate.vibration import free_vibration
from vtool.assessments.sonic_boom.assess import assess, boom_source
from vtool.assessments.sonic_boom.spectra import daf_at
from vtool.errors import InputError
from vtool.presets import boom, load_preset, plate

pytestmark = pytest.mark.asyncio




async def export(pilot, app, path) -> None:  # type: ignore[no-untyped-def]
    await pilot.press("ctrl+e")
    await pilot.pause()
    app.screen.query_one("#path-input").value = str(path)
    await pilot.press("enter")
    await pilot.pause()


@pytest.mark.slow
async def test_boom_screen_limits_daf_and_csv_match_the_library_and_cli(tmp_path) -> None:  # type: ignore[no-untyped-def]
    app = create_app("boom-brick-wall", remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, BoomScreen)
        await run_and_wait(pilot, app)
        spec = load_preset("boom-brick-wall")
        expected = assess(spec)
        assert screen.results.rows == expected.rows
        assert "damage-threshold" in screen.limits_panel.text and expected.source in screen.limits_panel.text
        for r in expected.rows:
            assert f"{r.pressure:.4g}" in screen.limits_panel.text
        screen.tabs.active = "tab-daf"
        await pilot.pause()
        ratio = screen.messages_seen[-1].daf["ratio"]
        daf, _ = daf_at(boom_source(spec.boom), ratio, "velocity", 0.0)
        w, h = screen.daf_chart.chart_size
        assert screen.daf_chart.chart_text == line_chart(ratio, {"velocity DAF": daf}, title="overall DAF",
                                                         xlabel="tau/T", ylabel="DAF", width=w, height=h,
                                                         color=False)
        screen.tabs.active = "tab-design"
        await pilot.pause()
        assert len(screen.design_charts) == 1  # both walls have the same mass: one set of curves
        assert screen.design_charts[0].chart_text.strip()
        await export(pilot, app, tmp_path / "tui.csv")
    result = CliRunner().invoke(cli, ["solve", "boom-brick-wall", "--csv", str(tmp_path / "cli.csv")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "tui.csv").read_text() == (tmp_path / "cli.csv").read_text()


async def test_boom_edits_pulse_switch_and_invalid_damping() -> None:
    app = create_app("boom-brick-wall", remember=False, chart_color=False)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "walls[0].measured_frequency", "20")
        # choosing an idealized pulse shows its parameters instead of the envelope's
        screen.form.row("boom.pulse").editor.value = "N"
        await pilot.pause()
        await pilot.pause()
        assert screen.form.has_field("boom.s") and not screen.form.has_field("boom.envelope.s")
        await put(pilot, screen, "boom.s", "1.8")
        await put(pilot, screen, "boom.damping", "1.5")
        with pytest.raises(InputError) as info:
            boom.load(screen.current_document())
        assert screen.form.row("boom.damping").has_class("-invalid")
        assert str(screen.form.row("boom.damping").query_one(".field-error").render()) == info.value.one_line()
        await pilot.press("ctrl+r")
        await pilot.pause()
        assert screen.worker is None
        await put(pilot, screen, "boom.damping", "0")
        await run_and_wait(pilot, app)
        doc = boom.dump(load_preset("boom-brick-wall"))
        doc["walls"][0]["measured_frequency"] = 20
        doc["boom"] = {"positive_durations": [0.1], "damping": 0, "pulse": "N", "s": 1.8, "r1": 0.0}
        expected = assess(boom.load(doc))
        assert screen.results.rows == expected.rows
        assert "pulse N" in screen.results.source


@pytest.mark.slow
async def test_plate_screen_frequencies_transient_and_csv(tmp_path) -> None:  # type: ignore[no-untyped-def]
    app = create_app("plate-irs", remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, PlateScreen)
        # choose case G9 (w at the 9 interior nodes), point load, exact modal scheme, shorter history
        screen.form.row("_run.case").editor.value = "G9"
        await pilot.pause()
        await pilot.pause()
        assert screen.form.has_field("cases[1].masters")
        screen.form.row("_run.load").editor.value = "point"
        screen.form.row("_run.scheme").editor.value = "modal"
        await put(pilot, screen, "_run.periods", "0.5")
        await put(pilot, screen, "_run.exact_modes", "60")
        await run_and_wait(pilot, app)
        assert app.errors_shown == []
        spec = load_preset("plate-irs")
        study = screen.results.study
        cases = {c.name: c for c in spec.study.cases}
        assert screen.query_one("#frequencies").text == frequency_table(
            study.free, cases, "16-DOF element (bfs16): percentage errors of the lowest natural frequencies",
            masters_last=True)  # the TUI puts the master-set description after the errors (120 columns)
        p = spec.study.plate
        model = build_model(p, cases["G9"])
        free = free_vibration(p, model, spec.study.frequencies)
        np.testing.assert_allclose(screen.results.free.omega, free.omega, rtol=1e-12)
        exact = exact_histories(p, "point", 0.5, 60)
        resp = run_modal(p, model, "point", exact.tau)
        np.testing.assert_allclose(screen.results.response.displacement, resp.displacement, rtol=1e-9, atol=1e-12)
        assert screen.results.errors == pytest.approx(peak_errors(resp, exact), nan_ok=True)
        screen.tabs.active = "tab-transient"
        await pilot.pause()
        chart = screen.chart("displacement")
        w, h = chart.chart_size
        assert chart.chart_text == transient_chart(screen.results, "displacement", w, h, False)
        assert "KS = 9" in screen.query_one("#case-text").text
        await export(pilot, app, tmp_path / "tui.csv")
    result = CliRunner().invoke(cli, ["solve", "plate-irs", "--csv", str(tmp_path / "cli.csv")])
    assert result.exit_code == 0, result.output

    def stable_rows(path):  # type: ignore[no-untyped-def]
        """Rows without measured times (they differ run to run); everything else must be equal."""
        rows = list(csv.reader(io.StringIO(path.read_text())))
        return [r for r in rows if r[5] not in ("eigen_time", "time_loop")]

    assert stable_rows(tmp_path / "tui.csv") == stable_rows(tmp_path / "cli.csv")


async def test_plate_invalid_step_blocks_and_auto_masters_round_trip(tmp_path) -> None:  # type: ignore[no-untyped-def]
    app = create_app("plate-irs", remember=False, chart_color=False)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "_run.omega_max_h", "3")
        row = screen.form.row("_run.omega_max_h")
        assert row.has_class("-invalid") and "RK4 stability limit" in str(row.query_one(".field-error").render())
        await pilot.press("ctrl+r")
        await pilot.pause()
        assert screen.worker is None
        await put(pilot, screen, "_run.omega_max_h", "1")
        # the full model with automatic (Henshell-Ong) masters, then save and reload
        screen.form.row("cases[0].masters").editor.value = "auto (Henshell-Ong)"
        await pilot.pause()
        await pilot.pause()
        await put(pilot, screen, "cases[0].auto", "12")
        await put(pilot, screen, "plate.thickness", "0.2")
        spec = screen.validate()
        assert spec is not None and spec.study.cases[0].masters.auto == 12
        await pilot.press("ctrl+s")
        await pilot.pause()
        app.screen.query_one("#path-input").value = str(tmp_path / "plate.toml")
        await pilot.press("enter")
        await pilot.pause()
        assert load_preset(tmp_path / "plate.toml") == spec
        assert plate.load(plate.dump(spec)) == spec
        # a preset that does not load shows the loader's message in the error dialog
        (tmp_path / "broken.toml").write_text('kind = "plate"\ntitle = "x"\nunits = "furlongs"\n')
        await app.open_preset(str(tmp_path / "broken.toml"))
        await pilot.pause()
        assert isinstance(app.screen, ErrorDialog)
        assert app.errors_shown[-1].startswith("units: got 'furlongs'")


async def test_boom_form_offers_the_envelope_family_and_pseudo_height_rule_of_the_preset() -> None:
    """The form's choices write the preset keys the loader reads; the default stays unwritten."""
    app = create_app("boom-brick-wall", remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        family = screen.form.row("boom.envelope.family")
        rule = screen.form.row("walls[0].pseudo_height_rule")
        assert family.text == "thesis" and rule.text == "whole-unit"  # default / the preset's value
        assert "family" not in screen.current_document()["boom"]["envelope"]  # absent stays absent
        assert not family.has_class("-changed")
        family.editor.value = "equal-rise"
        rule.editor.value = "exact"
        await pilot.pause()
        assert family.has_class("-changed") and rule.has_class("-changed")
        await run_and_wait(pilot, app)
        doc = boom.dump(load_preset("boom-brick-wall"))
        doc["boom"]["envelope"]["family"] = "equal-rise"
        doc["walls"][0]["pseudo_height_rule"] = "exact"
        expected = assess(boom.load(doc))
        assert screen.results.rows == expected.rows
        assert "P r2=r1" in screen.results.source  # the equal-rise family
        left = next(s for s in screen.results.structures if s.name == "left")
        assert left.details["pseudo_height"] == pytest.approx(31565.0 / 207.0)  # 152.49 in, not 152
