"""Recently used preset files, remembered between sessions (a small JSON list)."""

from __future__ import annotations

import json
import os
from pathlib import Path

from vtool.files import write_atomic

LIMIT = 10


def default_path() -> Path:
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "vtool" / "recent.json"


class RecentFiles:
    """Most recent first; shipped presets by name, user files by absolute path."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self.items: list[str] = []
        if path is not None and path.is_file():
            try:
                data = json.loads(path.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                data = []
            if isinstance(data, list):
                self.items = [str(item) for item in data if isinstance(item, str)][:LIMIT]

    def add(self, item: str) -> None:
        self.items = [item] + [i for i in self.items if i != item]
        del self.items[LIMIT:]
        if self.path is None:
            return
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(self.path, json.dumps(self.items, indent=1) + "\n")
        except OSError:
            pass  # remembering is a convenience; an unwritable config dir must not stop the app
