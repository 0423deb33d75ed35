"""The TUI's start: from ``create_app`` to the first screen laid out and drawn, headless.

Run: ``python3 benchmarks/bench_tui_start.py [--rounds N]`` (N = 3). Prints figures, asserts nothing.

Each round starts the app on ``gnilka-1c`` in Textual's headless test driver (100 x 30 cells)
in two processes, one with Python's collector as Python sets it and one as ``vtool tui``
sets it (``vtool.app.cli.tui.tune_collector`` after the imports), in alternating order, and
prints the start's wall time and the collector's time (``gc.callbacks``).
"""

from __future__ import annotations

import subprocess
import sys

ONE = """
import asyncio, gc, sys, time
from vtool.app.tui.app import create_app
if {tuned!r}:
    from vtool.app.cli.tui import tune_collector
    tune_collector()
started, spent = [], [0.0]
def timer(phase, info):
    if phase == "start":
        started.append(time.perf_counter())
    else:
        spent[0] += time.perf_counter() - started.pop()
gc.callbacks.append(timer)
async def start():
    app = create_app("gnilka-1c", remember=False, chart_color=False)
    begin = time.perf_counter()
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        return time.perf_counter() - begin
wall = asyncio.run(start())
print(wall, spent[0])
"""


def one(tuned: bool) -> tuple[float, float]:
    out = subprocess.run([sys.executable, "-c", ONE.format(tuned=tuned)], capture_output=True, text=True,
                         check=True)
    wall, collector = out.stdout.split()[-2:]
    return float(wall), float(collector)


def main(argv: list[str]) -> None:
    rounds = int(argv[argv.index("--rounds") + 1]) if "--rounds" in argv else 3
    best: dict[bool, float] = {}
    print("TUI start on gnilka-1c, headless 100 x 30, one process each")
    for r in range(rounds):
        for tuned in ((False, True) if r % 2 == 0 else (True, False)):
            wall, collector = one(tuned)
            best[tuned] = min(best.get(tuned, wall), wall)
            print(f"  collector {'as vtool tui sets it' if tuned else 'as Python sets it   '}: {wall:.2f} s, "
                  f"of which the collector {collector:.2f} s", flush=True)
    print(f"best: {best[False]:.2f} s as Python sets it, {best[True]:.2f} s as vtool tui does; "
          f"ratio {best[True] / best[False]:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
