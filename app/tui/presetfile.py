"""Saving a form back into its preset file without losing the file's comments and layout.

The form edits the document that the preset loader dumps (``loaded``); the
user's file has comments, provenance notes and an order of its own. Saving
therefore edits the file's own TOML tree (tomlkit, a round-trip parser) at
the paths whose values changed between ``loaded`` and ``edited``, and marks
each changed value with a trailing ``# was <old value>`` note (kept after the
value's own comment, replaced on the next save). Keys the form removed are
removed; keys it added are appended to their table.

A key that points at another file (``[cam] lift_table``: a path resolved
against the preset's folder) is replaced by the values the loader read from
it, written inline (``angles``, ``lifts``), so the saved preset does not
depend on the folder it is saved in; the inline values carry a note naming
the file they came from.

The text written is checked: the preset loader must read it back to the
same document as ``edited``. When it does not (a file laid out in a way the
path walk cannot follow), the caller writes the plain dump instead and says
so; a saved preset is never wrong, only less pretty.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import tomlkit
from tomlkit.items import AoT, Item, Table

_WAS = re.compile(r"\s*;?\s*was [^;#]*$")


def _note(item: Any, old: Any) -> None:
    """Append ``was <old>`` to the value's trailing comment (replacing an earlier note)."""
    if not isinstance(item, Item) or isinstance(item, Table | AoT):
        return
    comment = item.trivia.comment.lstrip("#").strip()
    comment = _WAS.sub("", comment).strip()
    shown = tomlkit.item(old).as_string() if old is not None else "unset"
    item.comment(f"{comment}; was {shown}" if comment else f"was {shown}")


def _merge(node: Any, old: Any, new: Any) -> None:
    """Write into the tomlkit container ``node`` what changed from ``old`` to ``new`` (dicts)."""
    for key, value in new.items():
        before = old.get(key) if isinstance(old, dict) else None
        present = key in node
        if present and isinstance(value, dict) and isinstance(before, dict) \
                and isinstance(node[key], dict):
            _merge(node[key], before, value)
        elif present and isinstance(value, list) and isinstance(before, list) \
                and len(value) == len(before) == len(node[key]) \
                and all(isinstance(v, dict) for v in value) \
                and all(isinstance(v, dict) for v in before):
            for child, b, v in zip(node[key], before, value, strict=True):
                _merge(child, b, v)
        elif before != value or (not present and key not in old):
            node[key] = value
            if before is not None:
                _note(node[key], before)
    for key in list(old) if isinstance(old, dict) else []:
        if key not in new and key in node:
            del node[key]


#: (table, key naming a file, the keys of ``edited`` that hold its values inline)
FileReference = tuple[tuple[str, ...], str, tuple[str, ...]]


def _inline(doc: Any, edited: dict[str, Any], references: Sequence[FileReference]) -> None:
    """Replace each file reference of ``doc`` (tomlkit) by the inline values of ``edited``."""
    for table, key, inline_keys in references:
        node: Any = doc
        values: Any = edited
        for name in table:
            node = node.get(name) if isinstance(node, dict) else None
            values = values.get(name) if isinstance(values, dict) else None
        if not isinstance(node, dict) or key not in node or not isinstance(values, dict):
            continue
        source = node[key]
        del node[key]
        for name in inline_keys:
            if name in values:
                node[name] = values[name]
        if inline_keys and inline_keys[0] in node:
            node[inline_keys[0]].comment(f"inline copy of {key} = {tomlkit.item(source).as_string()}")


def round_trip_text(original: str, loaded: dict[str, Any], edited: dict[str, Any],
                    references: Sequence[FileReference] = ()) -> str:
    """``original`` (TOML text) with the changes from ``loaded`` to ``edited`` written in, and its
    file ``references`` written inline."""
    doc = tomlkit.parse(original)
    _merge(doc, loaded, edited)
    _inline(doc, edited, references)
    return tomlkit.dumps(doc)


def save_text(source: Path | None, loaded: dict[str, Any], edited: dict[str, Any],
              normalize: Callable[[dict[str, Any]], Any], plain: Callable[[], str],
              references: Sequence[FileReference] = ()) -> tuple[str, bool]:
    """The text to save and whether the source file's comments and layout were kept.

    ``normalize`` turns a document into something comparable (the loader's
    load-then-dump); ``plain`` gives the plain dump used when the round trip
    cannot be trusted (no source file, a parse error, or a mismatch).
    """
    if source is not None and source.is_file():
        try:
            text = round_trip_text(source.read_text(encoding="utf-8"), loaded, edited, references)
            if normalize(tomllib.loads(text)) == normalize(edited):
                return text, True
        except (OSError, ValueError, TypeError, KeyError, IndexError, tomlkit.exceptions.TOMLKitError):
            pass  # fall back to the plain dump below (the caller says so)
    return plain(), False
