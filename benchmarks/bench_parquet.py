"""Peak memory of a sweep written to Parquet: 10^5 points against 10^4 and 2*10^5 against 10^5, in one run.

Each case runs in a fresh process (``--case``) and reports its peak resident
memory (``ru_maxrss``) above the process's size just before the work starts,
after a warm-up of the same work on two points, so that imports, the compiled
kernel and the Parquet writer's one-off setup (its code pages and pyarrow's
memory pool, measured and shown as ``setup``) do not count as growth. Two cases:

``writer``
    The Parquet sink alone (:class:`vtool.solvers.parquet.SweepParquet` through
    :func:`vtool.files.open_atomic_binary`), fed N synthetic points with the
    metric columns of gnilka-1d: what ``--format parquet`` adds.
``sweep``
    ``vtool sweep gnilka-1d --set run.rpm=START:STOP:0.05 --set run.degrees=0.5
    --workers 1 --out f.parquet`` in one process: real points, the cheapest a
    sweep allows (half a cam degree each, about 1.4 ms a point on an idle
    development machine), planned and run: the range is kept as (start, step,
    count) and each point's spec made when it runs (presets/paths.py), the
    finished points go to the file in row groups (solvers/parquet.py).

Bounded: the ratios near 1 (10 for 10^5/10^4, 2 for 2*10^5/10^5: growing in
proportion to the points). Run: ``python3 benchmarks/bench_parquet.py``
(about 8 minutes on an idle 2-core machine, nearly all of it the 3.1*10^5 real
points; ``--sizes 1000,10000,20000`` for a quick look). ``--write`` puts the
table into docs/sweep.md between its ``parquet`` markers.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "sweep.md"
BEGIN, END = "<!-- generated:parquet (python3 benchmarks/bench_parquet.py --write) -->", "<!-- /generated:parquet -->"


def peak_kb() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def write_points(n: int, out: Path) -> int:
    """``n`` synthetic gnilka-1d points through the Parquet sink into ``out``; the row group's rows."""
    import math

    from vtool.files import open_atomic_binary
    from vtool.presets import load_preset
    from vtool.solvers.parquet import SweepParquet
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import PointResult

    spec = load_preset("gnilka-1d")
    names = [name for name, _ in metric_columns(spec)]
    with open_atomic_binary(out, "bench") as handle:
        sink = SweepParquet(handle, (("run.rpm", "rev/min"),), spec)
        for i in range(n):
            metrics = {name: math.sin(i + k) for k, name in enumerate(names)}
            sink.append(PointResult(i, (("run.rpm", 1000.0 + 0.05 * i),), metrics))
        sink.finish()
    return sink.size


def run_writer(n: int, out: Path) -> dict:
    import pyarrow.parquet  # noqa: F401 - imported before the baseline: its libraries are not the output's

    start = peak_kb()
    write_points(2, out)  # the one-off setup: the writer's code paged in, pyarrow's pool started
    before = peak_kb()
    started = time.perf_counter()
    rows = write_points(n, out)
    return {"setup_kb": before - start, "before_kb": before, "peak_kb": peak_kb(),
            "seconds": time.perf_counter() - started, "bytes": out.stat().st_size, "group_rows": rows}


def run_sweep(n: int, out: Path) -> dict:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    def sweep(count: int) -> Any:
        stop = f"{1000 + 0.05 * (count - 1):.12g}"
        result = CliRunner().invoke(cli, ["sweep", "gnilka-1d", "--set", f"run.rpm=1000:{stop}:0.05", "--set",
                                          "run.degrees=0.5", "--workers", "1", "--out", str(out)])
        if result.exit_code != 0:
            raise SystemExit(result.output)
        return result

    start = peak_kb()
    sweep(2)  # warm-up: the imports, the compiled kernel and the Parquet writer's setup are in the baseline
    before = peak_kb()
    started = time.perf_counter()
    sweep(n)
    return {"setup_kb": before - start, "before_kb": before, "peak_kb": peak_kb(),
            "seconds": time.perf_counter() - started, "bytes": out.stat().st_size}


def case(kind: str, n: int) -> dict:
    """One case in a fresh process; its peak memory above its start."""
    with tempfile.TemporaryDirectory() as folder:
        code = (f"import json, sys; sys.path.insert(0, {str(ROOT / 'benchmarks')!r}); import bench_parquet as b; "
                f"from pathlib import Path; print(json.dumps(b.run_{kind}({n}, Path({folder!r}) / 'out.parquet')))")
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                              env=dict(os.environ, PYTHONWARNINGS="ignore"))
    data = json.loads(done.stdout.strip().splitlines()[-1])
    data["growth_mb"] = (data["peak_kb"] - data["before_kb"]) / 1024.0
    data["setup_mb"] = data["setup_kb"] / 1024.0
    return data


def table(sizes: list[int]) -> str:
    lines = ["| case | points | peak memory added (MB) | time (s) | file (MB) |", "|---|---|---|---|---|"]
    ratios = []
    notes = []
    for kind in ("writer", "sweep"):
        results = [case(kind, n) for n in sizes]
        for n, r in zip(sizes, results, strict=True):
            lines.append(f"| {kind} | {n:,} | {r['growth_mb']:.1f} | {r['seconds']:.1f} | {r['bytes'] / 1e6:.2f} |")
        pairs = [f"{b:,}/{a:,}: {rb['growth_mb'] / max(ra['growth_mb'], 0.1):.2f}"
                 for (a, ra), (b, rb) in itertools.pairwise(zip(sizes, results, strict=True))]
        ratios.append(f"{kind} {', '.join(pairs)}")
        setups = [r["setup_mb"] for r in results]
        notes.append(f"{kind} {min(setups):.1f}-{max(setups):.1f} MB")
        if kind == "writer":
            notes[-1] += f" (row groups of {results[0]['group_rows']:,} points)"
    lines.append("")
    lines.append(f"Peak memory ratios (1 = bounded, the ratio of the point counts = growing with them): "
                 f"{'; '.join(ratios)}.")
    lines.append("")
    lines.append(f"One-off setup before the measured work (the two-point warm-up, not counted above): "
                 f"{'; '.join(notes)}.")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10000,100000,200000", help="point counts, smallest first")
    parser.add_argument("--write", action="store_true", help="put the table into docs/sweep.md")
    args = parser.parse_args()
    sizes = [int(v) for v in args.sizes.split(",")]
    text = table(sizes)
    print(text)
    if args.write:
        doc = DOC.read_text()
        block = f"{BEGIN}\n{text}\n{END}"
        if BEGIN in doc:
            doc = doc[:doc.index(BEGIN)] + block + doc[doc.index(END) + len(END):]
        else:
            doc = doc.rstrip() + "\n\n" + block + "\n"
        DOC.write_text(doc)
        print(f"wrote {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
