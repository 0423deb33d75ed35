"""First compile of the Newmark kernel: this checkout against an earlier commit, interleaved.

Run: ``python3 benchmarks/bench_compile_ab.py [REF] [--pairs N]`` (default REF ``5077ed9``, the
kernel before issue 35's stock-numba rewrite; N = 3 pairs). An old REF is run with
``VTOOL_KERNEL=compiled VTOOL_NATIVE=0`` (its switches then: the compile in the run's own process,
on its two processes and patched numba; this checkout ignores them). Each process compiles ``gnilka-1a``'s kernel with an empty numba cache, as
``bench_newmark.py`` does; the two versions alternate, so that a machine whose speed drifts
(this project's 2-core VMs drift by ±20 % within minutes) slows both alike, and the ratio of
the medians is the figure to quote.

The earlier commit is read with ``git archive`` into a temporary folder laid out as the
installed package (``vtool/`` with ``app``, ``assessments``, ``presets`` and ``solvers``
inside) and put first on ``PYTHONPATH``, ahead of the editable install's finder.
"""

from __future__ import annotations

import io
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SUBPACKAGES = ("app", "assessments", "presets", "solvers")  # folders the installed package maps into vtool
COMPILE = """
from vtool.presets import load_preset
from vtool.solvers.run import simulate
import vtool.solvers.newmark.kernel as kernel
trace = simulate(load_preset("gnilka-1a"))
assert kernel.__file__.startswith({prefix!r}), kernel.__file__
print(trace.statistics.compile_time)
"""


def layout(ref: str, folder: Path) -> Path:
    """``ref``'s sources as an importable ``vtool`` package under ``folder``; returns the path entry."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", ref], capture_output=True, check=True).stdout
    tree = folder / "tree"
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(tree, filter="data")
    package = folder / "path" / "vtool"
    package.mkdir(parents=True)
    for entry in (tree / "vtool").iterdir():
        (package / entry.name).symlink_to(entry)
    for name in SUBPACKAGES:
        (package / name).symlink_to(tree / name)
    metadata(tree, folder / "path")
    return folder / "path"


def metadata(tree: Path, entry: Path) -> None:
    """A ``vtool`` distribution's metadata on ``entry`` holding the tree's own entry points (its back ends),
    found before the installed checkout's: importlib.metadata takes the first distribution of a name."""
    import tomllib
    project = tomllib.loads((tree / "pyproject.toml").read_text())["project"]
    info = entry / "vtool-0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: vtool\nVersion: 0\n")
    lines = []
    for group, points in project.get("entry-points", {}).items():
        lines.append(f"[{group}]")
        lines += [f"{name} = {target}" for name, target in points.items()]
    (info / "entry_points.txt").write_text("\n".join(lines) + "\n")


def environment(path_entry: Path | None, cache: str) -> dict[str, str]:
    """A child process's environment: numba's cache in ``cache``, and ``path_entry`` (from :func:`layout`)
    first on its path when not None. An old REF runs numba's kernel in the process, as this checkout does
    (``VTOOL_KERNEL=compiled VTOOL_NATIVE=0``: its own switches then)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, VTOOL_KERNEL="compiled", VTOOL_NATIVE="0")
    if path_entry is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(path_entry), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def compile_seconds(path_entry: Path | None, prefix: str) -> float:
    with tempfile.TemporaryDirectory() as cache:
        env = environment(path_entry, cache)
        out = subprocess.run([sys.executable, "-c", COMPILE.format(prefix=prefix)], capture_output=True,
                             text=True, env=env, cwd=tempfile.gettempdir())
    if out.returncode != 0:
        raise SystemExit(f"compile run failed:\n{out.stderr[-2000:]}")
    return float(out.stdout.split()[-1])


def arguments(argv: list[str], pairs: int, ref: str | None = None) -> tuple[str, int]:
    """(REF, N) from ``[REF] [--pairs N]``, with these defaults (no default REF: it must be given)."""
    if "--pairs" in argv:
        pairs = int(argv[argv.index("--pairs") + 1])
    refs = [a for i, a in enumerate(argv) if not a.startswith("--") and (i == 0 or argv[i - 1] != "--pairs")]
    if not refs and ref is None:
        raise SystemExit("usage: REF [--pairs N]")
    return (refs[0] if refs else str(ref)), pairs


def main(argv: list[str]) -> None:
    ref, pairs = arguments(argv, 3, "5077ed9")
    old, new = [], []
    with tempfile.TemporaryDirectory() as folder:
        entry = layout(ref, Path(folder))
        for _ in range(pairs):
            old.append(compile_seconds(entry, str(entry)))
            new.append(compile_seconds(None, str(ROOT)))
            print(f"  {ref}: {old[-1]:.1f} s   this checkout: {new[-1]:.1f} s", flush=True)
    a, b = statistics.median(old), statistics.median(new)
    print(f"first compile of gnilka-1a's kernel, empty cache, median of {pairs} interleaved: {ref} {a:.1f} s, "
          f"this checkout {b:.1f} s; ratio {b / a:.2f} (target 15 s: ratio {b / 15.0:.2f})")


if __name__ == "__main__":
    main(sys.argv[1:])
