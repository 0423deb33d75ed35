"""Presets: TOML files describing one study, and the loaders that turn them into specs.

Every preset has a top-level ``kind`` that picks its loader from the one
kinds table, :data:`vtool.presets.kinds.KINDS` (kind -> spec type, loader,
solve function, TUI screen).

Reading a file is guarded: a file over :data:`MAX_PRESET_BYTES`, invalid
UTF-8, invalid TOML and tables or arrays nested too deep for the parser are
each one :class:`vtool.errors.InputError` line.

A preset is found by path, or by the name of a shipped file in this folder
(``gnilka-1a`` finds ``gnilka-1a.toml``).
"""

from __future__ import annotations

import importlib
import os
import re
import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vtool.errors import InputError, one_line
from vtool.files import is_file, write_atomic
from vtool.presets.kinds import KINDS, kind_named

PRESET_DIR = Path(__file__).resolve().parent

#: kind -> module whose ``load(doc: dict) -> spec`` and ``dump(spec) -> dict`` handle it.
LOADERS: dict[str, str] = {name: kind.loader for name, kind in KINDS.items()}

#: Largest preset file read (bytes); the shipped ones are below 10 kB.
MAX_PRESET_BYTES = 1_000_000


@dataclass(frozen=True)
class PresetInfo:
    name: str
    kind: str
    title: str
    path: Path


def shipped_names() -> list[str]:
    return sorted(p.stem for p in PRESET_DIR.glob("*.toml"))


def find_preset(name_or_path: str | os.PathLike[str]) -> Path:
    """Resolve a preset given as a path or a shipped name."""
    candidate = Path(name_or_path)
    if is_file(candidate):  # a name the system cannot look up (too long, a NUL) is no file
        return candidate
    shipped = PRESET_DIR / f"{Path(str(name_or_path)).stem}.toml"
    if candidate.suffix in ("", ".toml") and is_file(shipped) and candidate.parent == Path("."):
        return shipped
    raise InputError(
        "preset", str(name_or_path),
        f"an existing .toml file or a shipped name ({', '.join(shipped_names())})",
    )


def read_document(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Parse a preset file; a TOML syntax error becomes a one-line InputError."""
    path = Path(path)
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_PRESET_BYTES + 1)
    except OSError as exc:
        raise InputError("preset", str(path), f"a readable file ({exc.strerror})") from None
    if len(data) > MAX_PRESET_BYTES:
        raise InputError("preset", str(path), f"a file of at most {MAX_PRESET_BYTES:,} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(str(path), f"byte 0x{data[exc.start]:02x} on line {line}",
                         "UTF-8 text (TOML files are UTF-8)") from None
    return parse_text(text, str(path))


#: Most parts of one dotted key or table header (``a.b.c`` has 3); the presets use at most 4.
MAX_KEY_PARTS = 100
_QUOTED = re.compile(r'"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'')
_STRUCTURE = re.compile(r"[=,\[\]{}]")


def check_key_depth(text: str, where: str = "<preset>") -> None:
    """Refuse a dotted key or table header of more than :data:`MAX_KEY_PARTS` parts, in one line.

    tomllib takes time quadratic in a dotted key's parts: 20,000 parts took 33 s and a 400 kB
    header ran for minutes, inside the 1 MB file limit. This scan is linear: per line, quoted
    strings are dropped, the rest is cut at ``= , [ ] { }``, and no piece may hold more than
    ``MAX_KEY_PARTS - 1`` dots (a number has one). A line of more dots inside a multi-line string
    is refused too (the message says where).
    """
    for number, line in enumerate(text.splitlines(), start=1):
        if line.count(".") < MAX_KEY_PARTS:
            continue
        for piece in _STRUCTURE.split(_QUOTED.sub("q", line)):
            if piece.count(".") >= MAX_KEY_PARTS:
                raise InputError(where, f"a dotted key of {piece.count('.') + 1:,} parts on line {number}",
                                 f"keys and table headers of at most {MAX_KEY_PARTS} parts")


def parse_text(text: str, where: str = "<preset>") -> dict[str, Any]:
    """Parse preset TOML text; syntax errors, too-deep nesting and too-long dotted keys
    (:func:`check_key_depth`) are one-line InputErrors."""
    check_key_depth(text, where)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(where, "invalid TOML", f"valid TOML ({one_line(str(exc), 200)})") from None
    except RecursionError:
        raise InputError(where, "arrays or tables nested too deep",
                         "valid TOML nested a few levels deep") from None


def kind_of(doc: dict[str, Any]) -> str:
    return kind_named(doc.get("kind")).name


def loader_for(kind: str) -> Any:
    return importlib.import_module(kind_named(kind).loader)


@dataclass(frozen=True)
class Override:
    """A value for a preset field given outside the file (``vtool solve --rpm``: ``run.rpm``, named
    ``--rpm`` in an error). The loader reads it like the file's own value: checked once, there."""

    path: str
    value: Any
    source: str = ""


def load_document(doc: dict[str, Any], folder: str | os.PathLike[str] | None = None,
                  overrides: tuple[Override, ...] = ()) -> Any:
    """Validate a parsed preset document and return its frozen spec.

    ``folder`` is the preset file's folder: a file the preset names (a cam
    lift table, a boom pulse CSV) resolves against it, for every kind and
    every command (None: the working folder, for a document with no file).
    ``overrides`` are set into the document first (the loader's
    ``with_overrides``) and checked with it; an error on one names its source.
    """
    if not isinstance(doc, dict):
        raise InputError("<preset>", type(doc).__name__, "a TOML document (a table)")
    kind = kind_named(kind_of(doc))
    loader = importlib.import_module(kind.loader)
    if overrides:
        taken = {path for _, path in kind.overrides}  # the fields this kind takes from outside the file
        for o in overrides:
            if o.path not in taken:
                raise InputError(o.source or o.path, o.value, f"no {o.source or o.path} for a {kind.name} preset")
        doc = loader.with_overrides(doc, {o.path: o.value for o in overrides})
    try:
        return loader.load(doc, None if folder is None else Path(folder))
    except RecursionError:
        raise InputError("<preset>", "values nested too deep", "the fields of a preset") from None
    except InputError as exc:
        source = next((o.source for o in overrides if o.path == exc.field and o.source), None)
        if source is None:
            raise
        raise InputError(source, exc.value, exc.expected, exc.unit) from None


def load_preset(name_or_path: str | os.PathLike[str], overrides: tuple[Override, ...] = ()) -> Any:
    """Find, parse and validate a preset (with ``overrides`` of some of its fields); returns the spec
    for its kind."""
    path = find_preset(name_or_path)
    return load_document(read_document(path), path.parent, overrides)


_LIFT_TABLE_LINE = re.compile(r"^[ \t]*lift_table[ \t]*=.*$", re.MULTILINE)


def self_contained_text(path: Path) -> tuple[str, str | None]:
    """The preset's text with the files it names written in, and a note saying what was, or None.

    A copy (``vtool presets copy``) must load from any folder: a cam
    ``lift_table = "file.csv"`` (relative to the preset's folder) becomes the
    inline ``angles``/``lifts`` arrays in place of that line, the rest of the
    text (comments included) unchanged. The new text is checked to load to
    the same spec.
    """
    text = path.read_text(encoding="utf-8")
    doc = parse_text(text, str(path))
    cam = doc.get("cam")  # (a [cam] table: a valve-train preset's; any other kind's loader refuses one)
    name = cam.get("lift_table") if isinstance(cam, dict) else None
    if not isinstance(name, str) or not name or Path(name).is_absolute():
        return text, None
    lines = _LIFT_TABLE_LINE.findall(text)
    if len(lines) != 1:  # written some other way (an inline table): keep it, the copy says where it points
        return text, None
    from vtool.presets.lift_table import read_lift_table

    units = str(doc.get("units", ""))
    angles, lifts = read_lift_table("cam.lift_table", name, path.parent, units)
    inline = (f"angles = [{', '.join(repr(a) for a in angles)}] # deg, from {name} (inlined by the copy)\n"
              f"lifts = [{', '.join(repr(x) for x in lifts)}] # follower lift, preset length unit")
    copied = text.replace(lines[0], inline, 1)
    with warnings.catch_warnings():  # loading warned once already, where the preset was read
        warnings.simplefilter("ignore")
        same = load_document(parse_text(copied, str(path))) == load_document(doc, path.parent)
    if not same:
        raise InputError("cam.lift_table", name, "a table that can be written inline")  # not expected
    return copied, f"the lift table {name} written inline"


def preset_info(path: Path) -> PresetInfo:
    doc = read_document(path)
    return PresetInfo(path.stem, str(doc.get("kind", "?")), str(doc.get("title", "")), path)


def list_presets() -> list[PresetInfo]:
    return [preset_info(PRESET_DIR / f"{name}.toml") for name in shipped_names()]


def save_spec(spec: Any, path: str | os.PathLike[str]) -> None:
    """Save a spec as a preset TOML (tomli-w), atomically."""
    import tomli_w

    kind = spec.kind
    write_atomic(path, tomli_w.dumps(loader_for(kind).dump(spec)))
