"""Three TUI actions, this checkout against an earlier commit, alternating processes.

Run: ``python3 benchmarks/bench_tui_actions.py REF [--pairs N]`` (N = 3). Prints figures, asserts
nothing. The earlier commit is laid out as ``bench_compile_ab.py`` does.

In Textual's headless test driver at 120 x 40 cells, on the valve-train screen:

1. opening another preset of the same form (``gnilka-1b`` and ``gnilka-1a`` in turn, as a menu or
   the open dialog does: ``app.open_preset``), until the screen is idle again;
2. a run's start and end as the screen shows them, without the run: the progress bar shown and
   hidden (``show_progress(True)``, then ``False``), until the screen is idle again;
3. the app's start: ``create_app("gnilka-1a")`` to the first idle screen (``vtool tui gnilka-1a``
   without the terminal; each TUI test starts the app at least once).

Each is the best of 8 in a process (the start: of 4); the figure to quote is the best of each version over the
pairs, and their ratio.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_compile_ab import ROOT, arguments, layout

TIMING = """
import asyncio, time
import vtool.app.tui.app as module
assert module.__file__.startswith({prefix!r}), module.__file__
from vtool.app.tui.app import create_app

async def main():
    starting = float("inf")
    for _ in range(4):
        started = time.perf_counter()
        app = create_app("gnilka-1a", remember=False, chart_color=False)
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause()
            starting = min(starting, time.perf_counter() - started)
    app = create_app("gnilka-1a", remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        opening = showing = float("inf")
        for name in ("gnilka-1b", "gnilka-1a") * 4:
            started = time.perf_counter()
            await app.open_preset(name)
            await pilot.pause()
            opening = min(opening, time.perf_counter() - started)
        for _ in range(8):
            started = time.perf_counter()
            screen.show_progress(True)
            await pilot.pause()
            screen.show_progress(False)
            await pilot.pause()
            showing = min(showing, time.perf_counter() - started)
        print(opening, showing, starting)

asyncio.run(main())
"""


def timings(path_entry: Path | None, prefix: str) -> tuple[float, float, float]:
    env = dict(os.environ)
    if path_entry is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(path_entry), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    out = subprocess.run([sys.executable, "-c", TIMING.format(prefix=prefix)], capture_output=True, text=True,
                         env=env, cwd=tempfile.gettempdir())
    if out.returncode != 0:
        raise SystemExit(f"timing run failed:\n{out.stderr[-2000:]}")
    opening, showing, starting = out.stdout.split()[-3:]
    return float(opening), float(showing), float(starting)


def main(argv: list[str]) -> None:
    ref, pairs = arguments(argv, 3)
    old, new = [], []
    with tempfile.TemporaryDirectory() as folder:
        entry = layout(ref, Path(folder))
        for _ in range(pairs):
            old.append(timings(entry, str(entry)))
            new.append(timings(None, str(ROOT)))
            print(f"  {ref}: open {old[-1][0] * 1e3:.0f} ms, progress shown and hidden {old[-1][1] * 1e3:.0f} ms, "
                  f"start {old[-1][2] * 1e3:.0f} ms   this checkout: {new[-1][0] * 1e3:.0f} ms, "
                  f"{new[-1][1] * 1e3:.0f} ms, {new[-1][2] * 1e3:.0f} ms", flush=True)
    for index, what in enumerate(("opening another preset of the same form", "a run's progress bar shown and hidden",
                                  "the app's start to its first idle screen")):
        a, b = min(t[index] for t in old), min(t[index] for t in new)
        print(f"{what}, best of {pairs} alternating processes: {ref} {a * 1e3:.0f} ms, this checkout "
              f"{b * 1e3:.0f} ms; ratio {b / a:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
