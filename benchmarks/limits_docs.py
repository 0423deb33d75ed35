"""Regenerate docs/limits.md's measured figures: the nominal 1A runs and the cost guard's example line.

Run: ``python3 benchmarks/limits_docs.py`` (a few seconds; ``--check`` compares
instead of writing and exits 1 on a difference). It writes the generated
blocks

* ``limits-nominal``: example 1A as shipped (the thesis' start, the local
  impact law) and from the quasi-static start the extremes table's variants
  use (tests/test_extremes.py ``variant()``): throw-off, first seating and its
  bounce, peak forces, largest valve coordinate, events;
* ``limits-cost-guard``: what ``vtool solve gnilka-1a --rpm 1.5`` prints.

Everything here is deterministic (no wall times); tests/test_limits_docs.py
regenerates the blocks and compares them with the committed page.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

from vtool.markdown import read_block, replace_block
from vtool.presets import PRESET_DIR, load_document, read_document
from vtool.solvers.run import simulate
from vtool.solvers.trace import CLOSED, OPENED, RELEASED, Trace

DOC = Path(__file__).resolve().parent.parent / "docs" / "limits.md"
VALVE = 7  # the valve coordinate of the thesis' mechanism


def _doc(velocities: str | None) -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    if velocities is not None:
        doc["initial"]["velocities"] = velocities
    return doc


def describe(trace: Trace) -> str:
    """One sentence of a run's figures (cam angles in deg, the preset's units)."""
    units = trace.spec.unit_system
    cam = [e for e in trace.events if e.clearance == "cam" and e.kind in (OPENED, RELEASED)]
    throw = next((e.cam_angle for e in cam if e.cam_angle % 360.0 < 180.0), None)
    seat = [e for e in trace.events if e.clearance == "seat" and e.kind == CLOSED]
    first_rev = [e for e in seat if e.cam_angle < 360.0]
    seating = (f"valve seats at {seat[0].cam_angle:.1f}° at {-seat[0].relative_velocity:.4g} {units.velocity}"
               if seat else "the valve never seats")
    if len(first_rev) > 1:
        bounces = ", ".join(f"{e.cam_angle:.1f}° at {-e.relative_velocity:.4g} {units.velocity}"
                            for e in first_rev[1:])
        seating += f" and re-seats {len(first_rev) - 1} time(s) in the first revolution ({bounces})"
    peaks = " / ".join(f"{p:,.0f}" for p in trace.peak_force)
    labels = "/".join(trace.force_label(k) for k in range(len(trace.spec.clearances)))
    throw_text = f"follower thrown off the cam at {throw:.1f}°" if throw is not None else "no throw-off"
    return (f"{throw_text}, {seating}, peak forces {labels} = {peaks} {units.force}, largest valve "
            f"coordinate q{VALVE} {trace.coordinate(VALVE).max():.4g} {units.length}, "
            f"{len(trace.events)} events over {trace.spec.run.degrees:g}°")


def nominal_block() -> str:
    shipped = simulate(load_document(_doc(None)))
    quasi = simulate(load_document(_doc("quasi-static")))
    return (f"The nominal 1A run as shipped (the thesis' start, the local impact law): {describe(shipped)}.\n"
            f"From the quasi-static start, which every variant below uses (so that the first revolution "
            f"shows the extreme's own physics, not the start shock): {describe(quasi)}.\n")


def cost_guard_block() -> str:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    result = CliRunner().invoke(cli, ["solve", "gnilka-1a", "--rpm", "1.5"])
    if result.exit_code != 2:
        raise RuntimeError(f"vtool solve gnilka-1a --rpm 1.5 exited {result.exit_code}: {result.output}")
    return f"```\n$ vtool solve gnilka-1a --rpm 1.5\n{result.output.rstrip()}\n```\n"


BLOCKS = {"limits-nominal": nominal_block, "limits-cost-guard": cost_guard_block}


def main(argv: list[str]) -> int:
    check = "--check" in argv
    status = 0
    for name, make in BLOCKS.items():
        text = make()
        if check:
            same = read_block(DOC, name) == text
            print(f"docs/limits.md {name}: {'current' if same else 'differs'}")
            status |= not same
        else:
            print(f"docs/limits.md {name}: {'rewritten' if replace_block(DOC, name, text) else 'unchanged'}")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
