"""Presets: TOML files describing one study, and the loaders that turn them into specs.

Every preset has a top-level ``kind`` that picks its loader:

=============  ===============================  ==================================
kind           loader module                    spec it returns
=============  ===============================  ==================================
valvetrain     :mod:`vtool.presets.valvetrain`  :class:`vtool.solvers.spec.MechanismSpec`
boom_wall      :mod:`vtool.presets.boom`        sonic-boom wall assessment
boom_floor     :mod:`vtool.presets.boom`        sonic-boom floor assessment
plate          :mod:`vtool.presets.plate`       condensed-plate study
=============  ===============================  ==================================

A preset is found by path, or by the name of a shipped file in this folder
(``gnilka-1a`` finds ``gnilka-1a.toml``).
"""

from __future__ import annotations

import importlib
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vtool.errors import InputError
from vtool.files import write_atomic

PRESET_DIR = Path(__file__).resolve().parent

#: kind -> module whose ``load(doc: dict) -> spec`` and ``dump(spec) -> dict`` handle it.
LOADERS: dict[str, str] = {
    "valvetrain": "vtool.presets.valvetrain",
    "boom_wall": "vtool.presets.boom",
    "boom_floor": "vtool.presets.boom",
    "plate": "vtool.presets.plate",
}


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
    if candidate.is_file():
        return candidate
    shipped = PRESET_DIR / f"{Path(str(name_or_path)).stem}.toml"
    if candidate.suffix in ("", ".toml") and shipped.is_file() and candidate.parent == Path("."):
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
            return tomllib.load(handle)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(str(path), "invalid TOML", f"valid TOML ({exc})") from None
    except OSError as exc:
        raise InputError("preset", str(path), f"a readable file ({exc.strerror})") from None


def kind_of(doc: dict[str, Any]) -> str:
    kind = doc.get("kind")
    if kind not in LOADERS:
        raise InputError("kind", kind, f"one of: {', '.join(LOADERS)}")
    return kind


def loader_for(kind: str) -> Any:
    return importlib.import_module(LOADERS[kind])


def load_document(doc: dict[str, Any]) -> Any:
    """Validate a parsed preset document and return its frozen spec."""
    return loader_for(kind_of(doc)).load(doc)


def load_preset(name_or_path: str | os.PathLike[str]) -> Any:
    """Find, parse and validate a preset; returns the spec for its kind."""
    path = find_preset(name_or_path)
    doc = read_document(path)
    if kind_of(doc) == "valvetrain":  # resolves a cam lift_table file against the preset's folder
        return loader_for("valvetrain").load(doc, folder=path.parent)
    return load_document(doc)


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
