"""Screenshots of the app: SVG from Textual, and the same screen as plain text.

``python -m vtool.app.tui.screenshots OUTDIR`` renders every screen (after
a run of its default preset, at 80 x 24 and wider) into ``OUTDIR/*.svg`` and
``OUTDIR/*.txt``; given ``docs/tui`` it also rewrites the screen captures
quoted in README.md and docs/tui.md (generated blocks). The snapshot tests
read the text the same way.
"""

from __future__ import annotations

import asyncio
import html
import re
import sys
from pathlib import Path

_TEXT = re.compile(r'<text class="[^"]*-r\d+" x="([\d.]+)" y="[\d.]+" textLength="([\d.]+)" '
                   r'clip-path="url\(#[^)]*-line-(\d+)\)">([^<]*)</text>')


def svg_text(svg: str, width: int = 80) -> str:
    """The characters of a Textual SVG screenshot, one line per terminal row."""
    matches = list(_TEXT.finditer(svg))
    if not matches:
        return ""
    cell = min(float(m[2]) / max(len(html.unescape(m[4])), 1) for m in matches)
    rows: dict[int, list[str]] = {}
    for m in matches:
        line = int(m[3])
        text = html.unescape(m[4]).replace("\xa0", " ")
        col = round(float(m[1]) / cell)
        row = rows.setdefault(line, [" "] * width)
        for k, ch in enumerate(text):
            if 0 <= col + k < width:
                row[col + k] = ch
    height = max(rows) + 1
    return "\n".join("".join(rows.get(i, [" "] * width)).rstrip() for i in range(height))


async def _capture(mode: str, preset: str, size: tuple[int, int], keys: tuple[str, ...]) -> tuple[str, str]:
    from vtool.app.tui.app import create_app

    app = create_app(preset, remember=False)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.pause()
        for key in keys:
            await pilot.press(key)
            await pilot.pause()
        await pilot.pause(0.2)
        svg = app.export_screenshot(title=f"vtool tui: {mode}")
    return svg, svg_text(svg, size[0])


SHOTS = (
    # below 120 columns a finished run hides the form (ctrl+f shows it)
    ("valvetrain-forces", "valvetrain", "gnilka-1a", (80, 24), ()),
    ("valvetrain-form", "valvetrain", "gnilka-1a", (120, 40), ()),
    ("valvetrain-quantities", "valvetrain", "gnilka-1a", (120, 40), ("ctrl+t",)),
    ("valvetrain-configuration-wide", "valvetrain", "gnilka-1a", (170, 40), ("ctrl+t", "ctrl+t")),
    ("valvetrain-animation", "valvetrain", "gnilka-1a", (80, 24), ("ctrl+t",) * 5),
    ("boom-limits", "boom", "boom-brick-wall", (80, 24), ()),
    ("boom-form", "boom", "boom-brick-wall", (120, 40), ()),
    ("boom-daf", "boom", "boom-brick-wall", (80, 24), ("ctrl+t",)),
    ("plate-transient", "plate", "plate-table2", (120, 32), ("ctrl+t",)),
    ("camshaft-torque", "camshaft", "four-cylinder-intake", (120, 40), ()),
)

#: screens quoted in the docs, as generated blocks (file relative to the repository, block name)
DOC_BLOCKS = {
    "valvetrain-form": (("README.md", "tui-valvetrain"), ("docs/tui.md", "tui-valvetrain")),
    "valvetrain-animation": (("docs/tui.md", "tui-animation"),),
    "boom-limits": (("docs/tui.md", "tui-boom"),),
    "plate-transient": (("docs/tui.md", "tui-plate"),),
    "camshaft-torque": (("docs/tui.md", "tui-camshaft"),),
}


def main(outdir: str) -> None:
    """Write every shot into ``outdir``; when it is a repository's docs/tui, update the docs' blocks."""
    from vtool.markdown import replace_block

    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    root = out.resolve().parent.parent
    for name, mode, preset, size, keys in SHOTS:
        svg, text = asyncio.run(_capture(mode, preset, size, keys))
        (out / f"{name}.svg").write_text(svg, encoding="utf-8")
        (out / f"{name}.txt").write_text(text + "\n", encoding="utf-8")
        print(f"wrote {out / name}.svg and .txt")
        for doc, block in DOC_BLOCKS.get(name, ()):
            if (root / doc).is_file():
                replace_block(root / doc, block, f"```\n{text}\n```")
                print(f"updated {doc} block {block}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/tui")
