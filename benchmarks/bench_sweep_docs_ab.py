"""docs/sweep.md's regeneration at its old scope: this checkout's last commit against an earlier one.

Run: ``python3 benchmarks/bench_sweep_docs_ab.py REF [--pairs N]`` (N = 2; about a minute a pair on
the 2-core machine). Prints figures, asserts nothing.

tests/test_sweep_docs.py regenerates docs/sweep.md's tables. Its name stayed while its work grew: at
5077ed9^ it searched 4 presets' jump and bounce speeds over 7 scanned speeds (4,000-16,000 rev/min)
with one plain run a point, and the 1A spring-rate table; now it searches 8 presets over 16 speeds,
each point run cycle by cycle to steady state, and draws two Campbell maps. So its duration in two
suites (benchmarks/bench_suite_ab.py) compares different work. This script times the old scope's work
(the speeds table and the spring table as 5077ed9^'s benchmarks/sweep_docs.py made them) in a fresh
``git archive`` of each commit (laid out as ``bench_compile_ab.py`` does), in one process per run,
after a first pass that compiles the kernels into an empty numba cache (the compile is issue 35's
figure, not this one): the CPU seconds of the second pass, REF and HEAD alternating. It prints each
search's speed and runs in both trees, which must agree unless a commit between them changed the
solver's numbers or the criteria (between 5077ed9^ and this session they did: the lift event, the
intervals, the gap thresholds), and the CPU time a run when they do not.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_compile_ab import ROOT, arguments, environment, layout

WORK = """
import json, time
from vtool.presets import load_preset
from vtool.presets.paths import plan_sweep
from vtool.presets.valvetrain import with_run_overrides
try:
    from vtool.solvers.studies.metrics import seat_index
    from vtool.solvers.studies.sweep import SerialRunner, find_speed
except ImportError:  # before solvers/ was split by role
    from vtool.solvers.metrics import seat_index
    from vtool.solvers.sweep import SerialRunner, find_speed

PRESETS = ("gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-2")
SCAN = list(range(4000, 16001, 2000))
SPRING = "members.valve_spring.stiffness=150:350:50"


def work():
    runner, found = SerialRunner(), []
    for name in PRESETS:
        spec = load_preset(name)
        for criterion in ("jump-speed", "bounce-speed"):
            if criterion == "bounce-speed" and seat_index(spec) is None:
                continue
            result = find_speed(criterion, lambda rpm, spec=spec: with_run_overrides(spec, rpm=rpm), SCAN, runner)
            found.append((name, criterion, result.speed, len(result.history)))
    for point in plan_sweep("gnilka-1a", [SPRING]).points:
        result = find_speed("jump-speed", lambda rpm, spec=point.spec: with_run_overrides(spec, rpm=rpm), SCAN,
                            runner)
        found.append((dict(point.values)[SPRING.split("=")[0]], "jump-speed", result.speed, len(result.history)))
    return found


work()  # the kernels compiled into the empty cache
cpu, wall = time.process_time(), time.perf_counter()
found = work()
print(json.dumps({"cpu": time.process_time() - cpu, "wall": time.perf_counter() - wall, "found": found}))
"""


def run(ref: str) -> dict:
    """The old scope's second pass in a fresh tree of ``ref``: CPU and wall seconds, and what it found."""
    with tempfile.TemporaryDirectory() as folder:
        entry = layout(ref, Path(folder))
        env = environment(entry, str(Path(folder) / "cache"))
        out = subprocess.run([sys.executable, "-c", WORK], cwd=folder, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"the old scope's regeneration failed in {ref}:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str]) -> None:
    ref, pairs = arguments(argv, 2)
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()
    seconds: dict[str, list[float]] = {ref: [], head: []}
    found: dict[str, list] = {}
    for _ in range(pairs):
        for commit in (ref, head):
            result = run(commit)
            seconds[commit].append(result["cpu"])
            found[commit] = result["found"]
            print(f"  {commit}: {result['cpu']:.2f} s CPU, {result['wall']:.2f} s wall", flush=True)
    print(f"the old scope of docs/sweep.md's regeneration (5077ed9^: 4 presets x 7 speeds, plain runs, and the "
          f"spring table), second pass, {pairs} alternating pair(s): {ref} {min(seconds[ref]):.2f}-"
          f"{max(seconds[ref]):.2f} s CPU, HEAD {head} {min(seconds[head]):.2f}-{max(seconds[head]):.2f} s; "
          f"ratio of the sums {sum(seconds[head]) / sum(seconds[ref]):.2f}")
    runs = {commit: sum(f[3] for f in found[commit]) for commit in (ref, head)}
    print(f"runs a pass: {ref} {runs[ref]}, HEAD {runs[head]} (the searches bisect where each commit's criteria "
          f"change); CPU a run {1e3 * min(seconds[ref]) / runs[ref]:.2f} ms in {ref}, "
          f"{1e3 * min(seconds[head]) / runs[head]:.2f} ms in HEAD (the fastest pass each)")
    for old, new in zip(found[ref], found[head], strict=True):
        same = "" if old == new else "   <- differs"
        print(f"  {old[0]} {old[1]}: {ref} {old[2]} ({old[3]} runs), HEAD {new[2]} ({new[3]} runs){same}")


if __name__ == "__main__":
    main(sys.argv[1:])
