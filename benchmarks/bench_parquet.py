"""Peak memory of a sweep written to Parquet: 10^5 points against 10^4 (ratio), measured in one run.

Each case runs in a fresh process (``--case``) and reports its peak resident
memory (``ru_maxrss``) above the process's size just before the work starts,
so imports and the interpreter do not count. Two cases per size:

``writer``
    The Parquet sink alone (:class:`vtool.solvers.parquet.SweepParquet` through
    :func:`vtool.files.open_atomic_binary`), fed N synthetic points with the
    metric columns of gnilka-1d: what ``--format parquet`` adds. Bounded when
    the ratio is near 1.
``sweep``
    ``vtool sweep gnilka-1d --set run.rpm=... --set run.degrees=0.5 --out
    f.parquet`` in one process (``--workers 1``): real points, the cheapest a
    sweep allows (half a cam degree each), planned and run. The plan checks
    the range's ends and keeps the swept values only; each point's spec is
    made when it runs and dropped (presets/paths.py PointGrid), and the sweep
    holds the finished points' indices: bounded when the ratio is near 1.

Run: ``python benchmarks/bench_parquet.py`` (about 25 minutes for the 10^5-point
sweep on the 2-core development machine, most of it the loader making each
point's spec; ``--sizes 1000,10000`` for a quick look).
``--write`` puts the table into docs/sweep.md between its ``parquet`` markers.
"""

from __future__ import annotations

import argparse
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


def run_writer(n: int, out: Path) -> dict:
    import math

    from vtool.files import open_atomic_binary
    from vtool.presets import load_preset
    from vtool.solvers.parquet import SweepParquet
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import PointResult

    spec = load_preset("gnilka-1d")
    names = [name for name, _ in metric_columns(spec)]
    fields = (("run.rpm", "rev/min"),)
    import pyarrow.parquet  # noqa: F401 - imported before the baseline: its libraries are not the output's

    before = peak_kb()
    started = time.perf_counter()
    with open_atomic_binary(out, "bench") as handle:
        sink = SweepParquet(handle, fields, spec)
        for i in range(n):
            metrics = {name: math.sin(i + k) for k, name in enumerate(names)}
            sink.append(PointResult(i, (("run.rpm", 1000.0 + i),), metrics))
        sink.finish()
    return {"before_kb": before, "peak_kb": peak_kb(), "seconds": time.perf_counter() - started,
            "bytes": out.stat().st_size}


def run_sweep(n: int, out: Path) -> dict:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    def sweep(count: int) -> Any:
        return CliRunner().invoke(cli, ["sweep", "gnilka-1d", "--set", f"run.rpm=1000:{1000 + count - 1}:1",
                                        "--set", "run.degrees=0.5", "--workers", "1", "--out", str(out)])

    sweep(2)  # warm-up: the imports, the compiled kernel and pyarrow are in the baseline
    before = peak_kb()
    started = time.perf_counter()
    result = sweep(n)
    if result.exit_code != 0:
        raise SystemExit(result.output)
    return {"before_kb": before, "peak_kb": peak_kb(), "seconds": time.perf_counter() - started,
            "bytes": out.stat().st_size}


def case(kind: str, n: int) -> dict:
    """One case in a fresh process; its peak memory above its start."""
    with tempfile.TemporaryDirectory() as folder:
        code = (f"import json, sys; sys.path.insert(0, {str(ROOT / 'benchmarks')!r}); import bench_parquet as b; "
                f"from pathlib import Path; print(json.dumps(b.run_{kind}({n}, Path({folder!r}) / 'out.parquet')))")
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                              env=dict(os.environ, PYTHONWARNINGS="ignore"))
    data = json.loads(done.stdout.strip().splitlines()[-1])
    data["growth_mb"] = (data["peak_kb"] - data["before_kb"]) / 1024.0
    return data


def table(sizes: list[int]) -> str:
    small, large = sizes
    lines = ["| case | points | peak memory added (MB) | time (s) | file (MB) |", "|---|---|---|---|---|"]
    ratios = []
    for kind in ("writer", "sweep"):
        results = [case(kind, n) for n in sizes]
        for n, r in zip(sizes, results, strict=True):
            lines.append(f"| {kind} | {n:,} | {r['growth_mb']:.1f} | {r['seconds']:.1f} | {r['bytes'] / 1e6:.2f} |")
        ratios.append(f"{kind}: {results[1]['growth_mb'] / max(results[0]['growth_mb'], 0.1):.2f}")
    lines.append("")
    lines.append(f"Peak memory ratio, {large:,} points against {small:,}: {'; '.join(ratios)} "
                 f"(1 = bounded, {large // small} = linear).")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10000,100000", help="two point counts, small,large")
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
