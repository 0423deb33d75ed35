"""Where the first compile of the Newmark kernel goes: each compiled function, by phase.

Run: ``python3 benchmarks/bench_compile_phases.py [PRESET]`` (default ``gnilka-1a``; about 30 s
on two cores). Prints figures, asserts nothing.

In one process with an empty numba cache (a temporary folder), the functions
``kernel_build.compile_kernel`` splits between its two processes (the helper's share, then
its own share) are compiled one after the other, then ``run_chunk`` itself, each timed as a
whole and split into numba's phases, each phase's time without the phases inside it:

* ``typing``: numba's type inference (``BaseTypeInference``);
* ``lowering``: numba IR to LLVM IR (``NativeLowering``, Python);
* ``fpasses``: LLVM function passes, per function, as each module is added;
* ``mpasses``: LLVM module passes over the library's final module, the linked callees included;
* ``codegen``: machine code for that module (MCJIT);
* ``other``: the rest (bytecode to numba IR, the untyped passes, the inlining of ``@tiny``
  helpers, nested overloads such as ``np.zeros``, caching).

Python's garbage collector is paused around each function's compile, as the solver pauses it
(``kernel_build.collector_paused``); the pass that follows each one is in no phase.

From these it estimates the two-process compile's wall time (the larger share, then
``run_chunk``), which ``bench_newmark.py`` measures. The phases are read by wrapping numba
internals (``numba.core.typed_passes``, ``numba.core.codegen``; numba 0.6x): a numba without
them stops this script with a message, and leaves the solver untouched.
"""

from __future__ import annotations

import collections
import os
import sys
import tempfile
import time
from typing import Any

os.environ["VTOOL_KERNEL"] = "plain"  # the argument types are read from a plain run: nothing compiled yet

PHASES = ("typing", "lowering", "fpasses", "mpasses", "codegen", "other")


def signature(preset: str) -> tuple[Any, ...]:
    """numba's types of ``run_chunk``'s arguments for ``preset`` (from a plain run's KernelRun)."""
    from vtool.presets import load_preset
    from vtool.solvers.newmark import backend as newmark
    from vtool.solvers.run import simulate

    seen: list[tuple[Any, ...]] = []
    execute = newmark.KernelRun.execute

    def noting(self, progress, cancel):  # noqa: ANN001, ANN202
        seen.append(self.signature)
        return execute(self, progress, cancel)

    newmark.KernelRun.execute = noting  # type: ignore[method-assign]
    try:
        simulate(load_preset(preset))
    finally:
        newmark.KernelRun.execute = execute  # type: ignore[method-assign]
    return seen[0]


def instrument(spent: dict[str, float]) -> None:
    """Wrap numba's phase functions so that each adds its own time (its inner phases' left out) to
    ``spent``."""
    from numba.core import codegen, dispatcher, typed_passes

    stack: list[list[Any]] = []

    def wrap(owner: Any, method: str, label: str) -> None:
        original = getattr(owner, method)

        def timed(*args: Any, **kwargs: Any) -> Any:
            started = time.perf_counter()
            stack.append([label, 0.0])
            try:
                return original(*args, **kwargs)
            finally:
                _, inner = stack.pop()
                seconds = time.perf_counter() - started
                spent[label] += seconds - inner
                if stack:
                    stack[-1][1] += seconds

        setattr(owner, method, timed)

    try:
        wrap(dispatcher._FunctionCompiler, "_compile_core", "other")
        wrap(typed_passes.BaseTypeInference, "run_pass", "typing")
        wrap(typed_passes.NativeLowering, "run_pass", "lowering")
        wrap(codegen.CPUCodeLibrary, "_optimize_functions", "fpasses")
        wrap(codegen.CPUCodeLibrary, "_optimize_final_module", "mpasses")
        wrap(codegen.JITCodeLibrary, "_finalize_specific", "codegen")
    except AttributeError as exc:
        raise SystemExit(f"this numba has no {exc.name}: the phases cannot be read") from None


def main(argv: list[str]) -> None:
    preset = argv[0] if argv else "gnilka-1a"
    with tempfile.TemporaryDirectory() as cache:
        os.environ["NUMBA_CACHE_DIR"] = cache  # before numba is imported (the plain run imports it): empty
        types = signature(preset)
        from vtool.solvers.newmark import build as kernel_build

        kernel = kernel_build.kernel()
        spent: dict[str, float] = collections.defaultdict(float)
        instrument(spent)
        helper, own = kernel_build.kernel_split(types)
        print(f"first compile of {preset}'s kernel, one function after another, in one process (s)")
        print(f"  {'share':8s} {'function':14s} {'whole':>6s} " + " ".join(f"{p:>8s}" for p in PHASES))
        shares: dict[str, float] = collections.defaultdict(float)
        totals: dict[str, float] = collections.defaultdict(float)
        for share, jobs in (("helper", helper), ("own", own), ("last", [("run_chunk", types)])):
            for name, arg_types in jobs:
                spent.clear()
                started = time.perf_counter()
                with kernel_build.collector_paused():  # as compile_kernel and its helper compile
                    getattr(kernel, name).compile(arg_types)
                whole = time.perf_counter() - started
                shares[share] += whole
                for phase in PHASES:
                    totals[phase] += spent[phase]
                print(f"  {share:8s} {name:14s} {whole:6.2f} " + " ".join(f"{spent[p]:8.2f}" for p in PHASES),
                      flush=True)
    total = sum(shares.values())
    print(f"  {'all':8s} {'':14s} {total:6.2f} " + " ".join(f"{totals[p]:8.2f}" for p in PHASES))
    wall = max(shares["helper"], shares["own"]) + shares["last"]
    print(f"on two processes (compile_kernel): the larger share {max(shares['helper'], shares['own']):.1f} s, "
          f"then run_chunk {shares['last']:.1f} s: about {wall:.1f} s of compile (ratio to the 10 s target "
          f"{wall / 10.0:.2f}); {total:.1f} s of work in all, {total / 2:.1f} s on two cores at best")


if __name__ == "__main__":
    main(sys.argv[1:])
