"""Writes the example output in README.md (``vtool solve gnilka-1a``), so it is never typed.

Run: ``python3 benchmarks/readme_examples.py``. The summary is produced by the same
code as the command (``Trace.summary_text``); ``tests/test_readme_examples.py``
regenerates it and compares every line but the wall time.
"""

from __future__ import annotations

from pathlib import Path

from vtool.markdown import replace_block
from vtool.presets import load_preset
from vtool.solvers.run import simulate

README = Path(__file__).resolve().parent.parent / "README.md"


def solve_1a() -> str:
    """What ``vtool solve gnilka-1a`` prints: the summary, then the evaluation lines (window, criteria, the
    window's metrics, the start-up shock)."""
    from vtool.solvers.studies.metrics import evaluation_summary

    trace = simulate(load_preset("gnilka-1a"))
    return "```\n" + trace.summary_text() + "\n\n" + "\n".join(evaluation_summary(trace)["lines"]) + "\n```\n"


def main() -> None:
    replace_block(README, "solve-1a", solve_1a())
    print(f"wrote the solve-1a block of {README.name}")


if __name__ == "__main__":
    main()
