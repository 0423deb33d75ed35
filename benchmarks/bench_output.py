"""Big-output benchmark: ``vtool solve gnilka-1a --degrees 36000 --every-step --csv``, ratios in one run.

Run: ``python3 benchmarks/bench_output.py [--write]``. Prints figures, asserts nothing; ``--write``
also writes items 1 and 2 into the ``big-output`` block of docs/valvetrain.md.

1. The whole command in a child process (warm numba cache, the same interpreter): wall time
   and peak resident memory (``os.wait4``'s rusage of that child), and their ratios to the
   targets (under 10 s, under 400 MB); the CSV's rows and size.
2. The same command at a tenth of the length (3,600 degrees): memory is bounded when the
   two peaks are about equal (the rows stream to the file; the trace in memory is thinned).
3. The number formatter alone on 20,000 rows of the run's width: the compiled kernel
   (:mod:`vtool.csvrows`) against Python's ``'%.10g' %`` (the text is identical), per row.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vtool.markdown import replace_block, table

DOC = Path(__file__).resolve().parent.parent / "docs" / "valvetrain.md"


TARGET_WALL_S = 10.0
TARGET_PEAK_MB = 400.0
COMMAND = ["solve", "gnilka-1a", "--every-step"]


def child(degrees: float, csv: Path) -> tuple[float, float, str]:
    """(wall s, peak RSS MB, last output line) of ``vtool solve ... --csv`` in a fresh process."""
    argv = [sys.executable, "-m", "vtool.app.cli.main", *COMMAND, "--degrees", f"{degrees:g}", "--csv", str(csv)]
    started = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - started
    out, err = process.stdout.read(), process.stderr.read()  # type: ignore[union-attr]
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({process.returncode}): {err.strip()[-400:]}")
    peak_mb = usage.ru_maxrss / 1024.0  # KiB on Linux
    return wall, peak_mb, out.strip().splitlines()[-1]


def formatter(rows: int = 20_000, columns: int = 46) -> tuple[float, float]:
    """(kernel µs per row, Python µs per row) on random values of mixed magnitudes."""
    from vtool.csvrows import format_rows, python_row

    rng = np.random.default_rng(12)
    values = rng.normal(size=(rows, columns)) * 10.0 ** rng.integers(-6, 6, (rows, columns))
    labels, which = ["VI,cam+seat"], np.zeros(rows, dtype=np.int64)
    format_rows(values[:2], labels, which[:2], compiled=True)  # load (or compile) the kernel: not timed
    started = time.perf_counter()
    fast = format_rows(values, labels, which)
    kernel = time.perf_counter() - started
    started = time.perf_counter()
    slow = "".join(python_row(values[r], labels[0]) for r in range(rows))
    python = time.perf_counter() - started
    if fast != slow:
        raise SystemExit("the kernel's text differs from Python's")
    return kernel / rows * 1e6, python / rows * 1e6


def main() -> None:
    print("Big output, ratios measured in this run")
    with tempfile.TemporaryDirectory() as folder:
        csv = Path(folder) / "out.csv"
        child(10.0, csv)  # warm the numba cache (kernel and formatter)
        wall, peak, said = child(36000.0, csv)
        size = csv.stat().st_size
        short_wall, short_peak, short_said = child(3600.0, csv)
        short_size = csv.stat().st_size
    print(f"  `vtool {' '.join(COMMAND)} --degrees 36000 --csv`: {wall:.2f} s wall "
          f"(ratio to the {TARGET_WALL_S:.0f} s target {wall / TARGET_WALL_S:.2f}), peak {peak:.0f} MB "
          f"(ratio to the {TARGET_PEAK_MB:.0f} MB target {peak / TARGET_PEAK_MB:.2f}); {said}, "
          f"{size / 1e6:.0f} MB of CSV")
    print(f"  the same at 3600 degrees: {short_wall:.2f} s wall, peak {short_peak:.0f} MB; "
          f"peak at 36000 / peak at 3600 = {peak / short_peak:.2f} "
          "(rows stream to the file; the trace in memory grows like a per-degree run, not per step)")
    if "--write" in sys.argv[1:]:
        def rows(text: str) -> str:
            found = re.search(r"wrote (\d+) rows", text)
            return f"{int(found.group(1)):,}" if found else "?"

        header = [f"`vtool {' '.join(COMMAND)} --csv`", "rows", "CSV (MB)", "wall time (s)",
                  f"wall / {TARGET_WALL_S:.0f} s target", "peak memory (MB)", f"peak / {TARGET_PEAK_MB:.0f} MB target"]
        replace_block(DOC, "big-output", table(header, [
            ["--degrees 36000", rows(said), f"{size / 1e6:.0f}", f"{wall:.2f}", f"{wall / TARGET_WALL_S:.2f}",
             f"{peak:.0f}", f"{peak / TARGET_PEAK_MB:.2f}"],
            ["--degrees 3600", rows(short_said), f"{short_size / 1e6:.0f}", f"{short_wall:.2f}",
             f"{short_wall / TARGET_WALL_S:.2f}", f"{short_peak:.0f}", f"{short_peak / TARGET_PEAK_MB:.2f}"]]))
        print(f"  wrote the big-output block of {DOC.name}")
    kernel, python = formatter()
    print(f"  number formatter, 46 values per row: {kernel:.2f} us/row compiled, {python:.2f} us/row "
          f"Python '%.10g' (ratio {python / kernel:.1f}), identical text")


if __name__ == "__main__":
    sys.exit(main())
