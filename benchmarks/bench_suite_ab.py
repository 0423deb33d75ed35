"""The whole test suite, ``python3 -m pytest -q``: this checkout's last commit against an earlier one.

Run: ``python3 benchmarks/bench_suite_ab.py REF [--pairs N] [-k EXPRESSION]`` (N = 2; a run takes
4-5 min on the 2-core machine, so the default is about 20 min). Prints figures, asserts nothing.

The suites of two commits need not hold the same tests (tests are added, moved and deleted between
them), so besides the wall times the script sums pytest's own per-test durations (``--junitxml``)
over the tests both suites hold, matched by test name with its parameters and class but not its file
(a restructuring moves tests between files): the ratio of those sums says whether the same tests got
slower, which the wall times alone cannot when one suite is larger.

Each run is the suite of one commit (REF, then HEAD, alternating, so that a drift of the machine's
speed slows both alike) in a fresh ``git archive`` of it, laid out as ``bench_compile_ab.py`` does
and first on ``PYTHONPATH``: numba's cache and mypy's cache start
empty, as in CI's fresh clone. Both run under the pytest and the libraries installed here (CI's
fresh install may pick other versions: pyproject pins pytest below 9.2 for that reason). ``-k``
passes a selection to pytest (to try the script on a few tests).

``--top N`` prints the N tests that got slowest (12). ``--save FILE`` writes each suite's wall seconds, last line and per-test durations to FILE (JSON);
``--old FILE`` takes REF's runs from such a file instead of running REF's suite again (while one
works on the suite's speed: REF does not change, and a run of it takes 1.5-2 min). The figures are
fair only when FILE was written on the same machine under the same load: quote a run without
``--old`` (one invocation, alternating) as the result. A test that HEAD skips (one moved behind an
environment variable) is not among the common tests; the script names those with REF's seconds.

``--same`` then runs the common tests alone in both trees (each tree's own node ids, the same pytest
options and workers, alternating, ``--pairs`` times) and compares the wall times: the same suite
measured as a suite, with what a run costs besides its tests (collection, the workers' start, the
kernels compiled into the empty cache) that the summed durations leave out or spread over the tests.
A saved REF run must hold the node ids (a file this version wrote).

The tests run with ``PYTHONSAFEPATH=1`` and ``.`` after the tree's package on ``PYTHONPATH``: every
process then finds the complete ``vtool`` first, and its own current folder after it (a test's child
``python -m module`` in its folder, ``-p tests.conftest`` in the tree). One test still fails in such a
tree only: tests/test_outputs.py's helper-process test asserts that a plain child has ``''`` on its
path, which PYTHONSAFEPATH removes.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path

from bench_compile_ab import ROOT, layout

#: Where each package a run imports comes from (run in the tree, as pytest and the tests' own processes are):
#: all must be the tree's.
PROBE = "import vtool.app, vtool.assessments, vtool.presets, vtool.solvers as s, vtool.errors as e; " \
        "print(*(m.__file__ for m in (vtool.app, vtool.assessments, vtool.presets, s, e)))"


#: pytest-xdist's ``--dist loadgroup`` suffix of a grouped test's name (``test_x[id]@group``): not the test's
#: identity (a test put into a group is the same test) and not part of its node id on the command line
GROUP = re.compile(r"@[^@\[\]]*$")


def test_name(case: ET.Element) -> str:
    return GROUP.sub("", str(case.get("name")))


def durations(report: Path, skipped: bool = False) -> dict[str, list[float]]:
    """Seconds of each passed test in a junit XML report, by test name with its class (not its file); with
    ``skipped``, of each skipped test instead."""
    seconds: dict[str, list[float]] = defaultdict(list)
    for case in ET.parse(report).getroot().iter("testcase"):
        tags = {child.tag for child in case}
        if tags & {"failure", "error"} or ("skipped" in tags) != skipped:
            continue
        owner = case.get("classname", "").rsplit(".", 1)[-1]
        key = f"{owner}::{test_name(case)}" if owner[:1].isupper() else test_name(case)
        seconds[key].append(float(case.get("time", "0")))
    return seconds


def node_ids(report: Path) -> dict[str, list[str]]:
    """pytest's node ids of the passed tests in a junit XML report, by the key of :func:`durations`."""
    ids: dict[str, list[str]] = defaultdict(list)
    for case in ET.parse(report).getroot().iter("testcase"):
        if {child.tag for child in case} & {"failure", "error", "skipped"}:
            continue
        parts = case.get("classname", "").split(".")
        owner = parts[-1] if parts[-1][:1].isupper() else ""
        module = parts[:-1] if owner else parts
        key = f"{owner}::{test_name(case)}" if owner else test_name(case)
        ids[key].append("::".join(["/".join(module) + ".py", *([owner] if owner else []), test_name(case)]))
    return ids


def run_suite(ref: str, select: str | None, only: list[str] | None = None
              ) -> tuple[float, str, dict[str, list[float]], list[str], dict[str, list[str]]]:
    """Wall seconds of ``python3 -m pytest -q`` in a fresh tree of ``ref``, pytest's last line, the
    per-test durations, the skipped tests' names and the passed tests' node ids; ``only``: just these
    node ids (the tree's own)."""
    with tempfile.TemporaryDirectory() as folder:
        entry = layout(ref, Path(folder))
        env = dict(os.environ)
        # "." after the tree's package: every process's own current folder, resolved when it starts (site
        # makes sys.path absolute), as Python's '' would be without PYTHONSAFEPATH (below) but behind the
        # complete package: `-p tests.conftest` in the tree and `python -m module` in a test's folder import
        env["PYTHONPATH"] = os.pathsep.join([str(entry), ".", env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        env.pop("NUMBA_CACHE_DIR", None)  # numba's cache beside the tree's sources: empty
        # the tree's own folder never first on sys.path (PYTHONSAFEPATH for pytest and every process a test
        # starts in the tree; pytest appends it, for tests/): its vtool/ holds the core alone, and its
        # subpackages would then come from the package installed here, whose editable finder maps them
        # to this checkout, so that the suite of REF would run this checkout's solvers
        env["PYTHONSAFEPATH"] = "1"
        where = subprocess.run([sys.executable, "-c", PROBE], cwd=Path(folder) / "tree", env=env, capture_output=True,
                               text=True)
        files = where.stdout.split()
        if where.returncode != 0 or len(files) != 5 or not all(Path(f).resolve().is_relative_to(
                Path(folder).resolve()) for f in files):
            raise SystemExit(f"the tree of {ref} does not import its own packages: {where.stdout}{where.stderr[-500:]}")
        command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--import-mode=append",
                   f"--junitxml={Path(folder) / 'report.xml'}"]
        if select:
            command += ["-k", select]
        if only is not None:
            command += only
        started = time.perf_counter()
        out = subprocess.run(command, cwd=Path(folder) / "tree", env=env, capture_output=True, text=True)
        seconds = time.perf_counter() - started
        report = Path(folder) / "report.xml"
        each = durations(report) if report.exists() else {}
        skipped = sorted(durations(report, skipped=True)) if report.exists() else []
        ids = node_ids(report) if report.exists() else {}
    last = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else out.stderr[-300:]
    if not each:
        raise SystemExit(f"the suite of {ref} did not run ({last}):\n{out.stdout[-3000:]}")
    if out.returncode != 0:  # a failed test is left out of the durations; its name is printed
        failed = [line for line in out.stdout.splitlines() if line.startswith(("FAILED", "ERROR"))]
        print(f"  {ref}: " + "\n  ".join(failed), flush=True)
    return seconds, last, each, skipped, ids


def main(argv: list[str]) -> None:
    if not argv or argv[0].startswith("-"):
        raise SystemExit("usage: REF [--pairs N] [-k EXPRESSION] [--top N] [--save FILE] [--old FILE] [--same]")
    ref = argv[0]
    pairs = int(argv[argv.index("--pairs") + 1]) if "--pairs" in argv else 2
    select = argv[argv.index("-k") + 1] if "-k" in argv else None
    top = int(argv[argv.index("--top") + 1]) if "--top" in argv else 12
    save = Path(argv[argv.index("--save") + 1]) if "--save" in argv else None
    saved = json.loads(Path(argv[argv.index("--old") + 1]).read_text()) if "--old" in argv else None
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()
    old: list[float] = []
    new: list[float] = []
    old_each: list[dict[str, list[float]]] = []
    new_each: list[dict[str, list[float]]] = []
    runs: dict[str, list[dict[str, object]]] = {ref: [], head: []}
    for number in range(pairs):
        for label, commit, times, each in ((ref, ref, old, old_each), (f"HEAD {head}", head, new, new_each)):
            if saved is not None and commit == ref:
                if saved["ref"] != ref or number >= len(saved["runs"][ref]):
                    raise SystemExit(f"--old: the file holds {len(saved['runs'].get(ref, []))} run(s) of "
                                     f"{saved['ref']}, not run {number + 1} of {ref}")
                kept = saved["runs"][ref][number]
                seconds, last, tests, skipped, ids = (kept["seconds"], kept["last"] + " (saved)", kept["each"],
                                                      kept.get("skipped", []), kept.get("ids", {}))
            else:
                seconds, last, tests, skipped, ids = run_suite(commit, select)
            runs[commit].append({"seconds": seconds, "last": last, "each": tests, "skipped": skipped, "ids": ids})
            times.append(seconds)
            each.append(tests)
            print(f"  {label}: {seconds:.1f} s ({last})", flush=True)
    if save is not None:
        save.write_text(json.dumps({"ref": ref, "head": head, "runs": runs}))
    print(f"the suite, {pairs} alternating pair(s): {ref} {min(old):.1f}-{max(old):.1f} s, HEAD {head} "
          f"{min(new):.1f}-{max(new):.1f} s; ratio of the sums {sum(new) / sum(old):.2f}")
    common = [key for key in old_each[0] if key in new_each[0] and len(old_each[0][key]) == len(new_each[0][key])]
    summed_old = sum(sum(run[key]) for run in old_each for key in common)
    summed_new = sum(sum(run[key]) for run in new_each for key in common)
    print(f"the {len(common)} test names both suites hold (of {len(old_each[0])} in {ref}, {len(new_each[0])} in HEAD): "
          f"summed test durations {summed_old / pairs:.1f} s in {ref}, {summed_new / pairs:.1f} s in HEAD; "
          f"ratio {summed_new / summed_old:.2f}")
    change = sorted(((sum(sum(run[key]) for run in new_each) - sum(sum(run[key]) for run in old_each)) / pairs, key)
                    for key in common)
    print("the common tests that changed most (seconds a run, HEAD minus REF):")
    for seconds, key in change[::-1][:top] + change[:3]:
        print(f"  {seconds:+8.2f}  {key}")
    # a test HEAD skips (moved behind an environment variable) is not a common test: name it with REF's time
    skipped_now = [key for key in runs[head][0]["skipped"] if key in old_each[0]]
    if skipped_now:
        print(f"left out: {len(skipped_now)} test(s) {ref} ran and HEAD skips (seconds a run in {ref}):")
        for key in skipped_now:
            print(f"  {sum(sum(run[key]) for run in old_each) / pairs:8.2f}  {key}")
    if "--same" in argv:
        same_suite(ref, head, runs, common, pairs)


def same_suite(ref: str, head: str, runs: dict[str, list[dict[str, object]]], common: list[str],
               pairs: int) -> None:
    """The wall time of the same suite in both trees: only the common tests, by each tree's own node ids
    (a test moved between files keeps its name), under the same pytest options, alternating."""
    ids = {commit: runs[commit][0]["ids"] for commit in (ref, head)}
    if not all(ids.values()):
        raise SystemExit("--same: the saved REF run holds no node ids (save it again with this script)")
    only = {commit: sorted(node for key in common for node in ids[commit][key]) for commit in (ref, head)}  # type: ignore[index]
    wall: dict[str, list[float]] = {ref: [], head: []}
    for _ in range(pairs):
        for commit in (ref, head):
            seconds, last, _each, _skipped, _ids = run_suite(commit, None, only[commit])
            wall[commit].append(seconds)
            print(f"  the {len(common)} common tests alone, {commit}: {seconds:.1f} s ({last})", flush=True)
    print(f"the same {len(common)} tests in both trees, {pairs} alternating pair(s): {ref} "
          f"{min(wall[ref]):.1f}-{max(wall[ref]):.1f} s, HEAD {head} {min(wall[head]):.1f}-{max(wall[head]):.1f} s; "
          f"wall ratio {sum(wall[head]) / sum(wall[ref]):.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
