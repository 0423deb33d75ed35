"""Saving a form into its preset file: comments and layout kept, the edit exact (property test)."""

from __future__ import annotations

import copy
import tomllib

from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.app.tui.form import first_line, get_path, set_path
from vtool.app.tui.presetfile import round_trip_text, save_text
from vtool.presets import find_preset, valvetrain

SOURCE = find_preset("gnilka-1a")
TEXT = SOURCE.read_text(encoding="utf-8")
LOADED = valvetrain.dump(valvetrain.load(tomllib.loads(TEXT)))
EDITABLE = (("run", "rpm"), ("run", "degrees"), ("members", "pushrod", "length"),
            ("members", "valve_spring", "stiffness"), ("clearances", 1, "restitution"),
            ("seat", "position"), ("gravity",), ("damping", "factor"))


def normalize(doc):  # type: ignore[no-untyped-def]
    return valvetrain.dump(valvetrain.load(doc))


@settings(max_examples=25, deadline=None)
@given(st.dictionaries(st.sampled_from(EDITABLE), st.floats(0.01, 1.0), min_size=1))
def test_saved_text_loads_to_the_edit_and_keeps_every_comment(scales) -> None:  # type: ignore[no-untyped-def]
    edited = copy.deepcopy(LOADED)
    for path, scale in scales.items():
        set_path(edited, path, get_path(LOADED, path) * scale if get_path(LOADED, path) else scale)
    text = round_trip_text(TEXT, LOADED, edited)
    assert normalize(tomllib.loads(text)) == normalize(edited)
    lines = text.splitlines()
    for line in TEXT.splitlines():
        if line.lstrip().startswith("#"):
            assert line in lines  # provenance and notes survive
    changed = [p for p in scales if get_path(edited, p) != get_path(LOADED, p)]
    assert sum("was " in line.split("#", 1)[-1] for line in lines if "#" in line) >= len(changed)


def test_unchanged_save_is_the_file_itself_and_no_source_falls_back_to_the_dump() -> None:
    text, kept = save_text(SOURCE, LOADED, LOADED, normalize, lambda: "plain")
    assert kept and text == TEXT
    assert save_text(None, LOADED, LOADED, normalize, lambda: "plain") == ("plain", False)


def test_a_second_save_replaces_the_was_note() -> None:
    once = copy.deepcopy(LOADED)
    once["run"]["rpm"] = 9000
    first = round_trip_text(TEXT, LOADED, once)
    twice = copy.deepcopy(once)
    twice["run"]["rpm"] = 8000
    second = round_trip_text(first, once, twice)
    assert "rpm = 8000 # was 9000" in second and "11000" not in second.split("[run]")[1].split("\n")[1]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.text("abcdefghij.^/", min_size=1, max_size=22), min_size=1, max_size=5), st.integers(4, 20))
def test_a_rows_label_line_is_the_first_line_rich_wraps_it_to(words: list[str], width: int) -> None:
    """FieldRow draws its label's first line (form.first_line): the first line Rich gives the label at that
    width, as the Label widget it replaced showed it in a one-line cell (words wrapped, a long word cut)."""
    from rich.console import Console
    from rich.text import Text

    label = " ".join(words)
    lines = Text(label).wrap(Console(width=200), width)
    assert first_line(label, width) == lines[0].plain.rstrip()
