"""Valve lash as an alternative to the seat position (solvers/model/lash.py).

Sources: the thesis' printed start for example 1A, XZERO = 0.88245022 in with
A = 0.5 in, so the base circle puts the follower at XZERO - A; the rocker arms
(1.0 in pushrod side, 1.5 in valve side) make the follower move 1/1.5 of the
valve's travel, up to the members' small compliance.
"""

from __future__ import annotations

import copy

import pytest

from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, load_preset, read_document
from vtool.presets.valvetrain import dump, load
from vtool.solvers.model.lash import base_and_ratio, lash_of

XZERO, A, CLEAR = 0.88245022, 0.5, 0.7


def doc_1a(**seat: object) -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    doc["seat"] = {"coordinate": 10, **seat}
    return doc


def test_base_circle_and_lever_ratio_of_the_thesis_mechanism() -> None:
    base, ratio = base_and_ratio(load_preset("gnilka-1a"))
    assert base == pytest.approx(XZERO - A, abs=1e-8)
    assert ratio == pytest.approx(1.0 / 1.5, rel=1e-3)


def test_lash_and_seat_position_are_two_ways_to_say_the_same() -> None:
    thesis = load_preset("gnilka-1a")
    lash = lash_of(thesis)
    assert lash == pytest.approx(CLEAR / 1.5 - (XZERO - A), rel=1e-2)
    spec = load_document(doc_1a(lash=lash))
    assert spec.seat.position == pytest.approx(CLEAR, rel=1e-12)
    assert spec.seat.lash == lash and lash_of(spec) == pytest.approx(lash, rel=1e-12)
    assert dump(spec)["seat"] == {"coordinate": 10, "name": "seat", "lash": lash}
    assert load(dump(spec)) == spec


def test_larger_lash_seats_the_valve_higher() -> None:
    low = load_document(doc_1a(lash=0.01)).seat.position
    high = load_document(doc_1a(lash=0.02)).seat.position
    assert high - low == pytest.approx(0.01 / base_and_ratio(load_preset("gnilka-1a"))[1], rel=1e-12)


@pytest.mark.parametrize("seat", [{"lash": 0.01, "position": 0.7}, {}])
def test_position_or_lash_not_both(seat: dict) -> None:
    with pytest.raises(InputError, match="either position or lash"):
        load_document(doc_1a(**seat))


def test_ramped_preset_is_set_by_lash() -> None:
    spec = load_preset("ramped-cam")
    assert spec.seat.lash == 0.008 and lash_of(spec) == pytest.approx(0.008, rel=1e-12)


@pytest.mark.asyncio
async def test_tui_edits_the_lash_and_the_fit_of_a_table_cam() -> None:
    from tests.tui_helpers import put
    from vtool.app.tui.app import create_app

    app = create_app("ramped-cam", remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert screen.form.value("seat.lash") == "0.008" and screen.form.value("cam.tolerance") == "0.0001"
        assert not screen.form.has_field("cam.amplitude") and not screen.form.has_field("seat.position")
        await put(pilot, screen, "seat.lash", "0.01")
        await put(pilot, screen, "cam.tolerance", "0.001")
        spec = screen.validate()
        assert spec.seat.lash == 0.01 and lash_of(spec) == pytest.approx(0.01, rel=1e-12)
        assert spec.cam.tolerance == 0.001 and len(spec.cam.angles) == 360
