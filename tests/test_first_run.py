"""A new install's first run: it does not wait for the kernel's compile (see newmark's "First run").

The plain-Python copy of the kernel is the same source; a run may start in it
and move to the compiled kernel between chunks, with the results of a run that
was compiled throughout (to the reference tolerances of
test_newmark.py::test_numba_kernel_equals_numpy_reference_on_example_1a).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.newmark import backend as newmark
from vtool.solvers.newmark import build as kernel_build
from vtool.solvers.newmark import kernel
from vtool.solvers.run import simulate

needs_jit = pytest.mark.skipif(not kernel_build.jit_enabled(), reason="NUMBA_DISABLE_JIT: nothing is compiled")


def assert_same_run(a, b) -> None:  # noqa: ANN001 (two Traces)
    assert [(e.clearance, e.kind) for e in a.events] == [(e.clearance, e.kind) for e in b.events]
    np.testing.assert_allclose([e.time for e in a.events], [e.time for e in b.events], rtol=0, atol=1e-11)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.contact_force, b.contact_force, rtol=0, atol=1e-6 * b.peak_force.max())


def wait_until_cached(env: dict, names: tuple[str, ...]) -> None:
    """Poll (in fresh processes, with ``env``'s cache) until the background compile has cached ``names``.

    A probe process imports numba (about a second of CPU, taken from the compile it waits for), so one
    starts only once each name has an index file in ``env``'s cache folder; the probe then decides."""
    probe = ("import sys; from vtool.solvers.newmark import kernel as k; "
             f"sys.exit(0 if k.is_cached({names!r}, None, None) else 1)")
    folder = Path(env["NUMBA_CACHE_DIR"])
    deadline = time.monotonic() + 600
    while True:
        if (all(any(folder.rglob(f"kernel.{name}-*.nbi")) for name in names)
                and subprocess.run([sys.executable, "-c", probe], env=env).returncode == 0):
            return
        assert time.monotonic() < deadline, f"the background compile of {names} did not reach the cache in 600 s"
        time.sleep(0.25)


def test_kernel_mode_comes_from_the_environment(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.delenv("VTOOL_KERNEL", raising=False)
    assert kernel_build.kernel_mode() == "auto"
    for mode in kernel_build.KERNEL_MODES:
        monkeypatch.setenv("VTOOL_KERNEL", mode)
        assert kernel_build.kernel_mode() == mode
    monkeypatch.setenv("VTOOL_KERNEL", "fast")
    with pytest.raises(InputError, match="VTOOL_KERNEL: got 'fast', expected one of auto, compiled, plain"):
        kernel_build.kernel_mode()


def test_a_bad_kernel_mode_is_one_line_and_exit_2(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("VTOOL_KERNEL", "fast")
    result = CliRunner().invoke(cli, ["solve", "gnilka-1a"])
    assert result.exit_code == 2
    assert "VTOOL_KERNEL" in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


@needs_jit
def test_the_plain_kernel_is_the_same_source_without_numba() -> None:
    plain = kernel_build.plain_kernel()
    assert plain is not kernel and plain.PLAIN and not kernel.PLAIN
    assert plain.__file__ == kernel.__file__
    assert not hasattr(plain.run_chunk, "signatures")  # a Python function, not a numba dispatcher
    assert plain.run_chunk.__code__.co_code == kernel.run_chunk.py_func.__code__.co_code
    assert (plain.FINISHED, plain.I_STEPS, plain.CL_MON) == (kernel.FINISHED, kernel.I_STEPS, kernel.CL_MON)


@needs_jit
def test_a_plain_run_equals_the_compiled_run(monkeypatch) -> None:  # noqa: ANN001
    compiled = simulate(load_preset("gnilka-1a"))
    monkeypatch.setenv("VTOOL_KERNEL", "plain")
    plain = simulate(load_preset("gnilka-1a"))
    assert compiled.statistics.plain_steps == 0
    assert plain.statistics.plain_steps == plain.statistics.steps == compiled.statistics.steps
    assert_same_run(plain, compiled)
    assert f"steps {plain.statistics.steps} (all as plain Python)," in plain.summary_text()


@needs_jit
def test_a_run_moves_from_plain_to_compiled_between_chunks(monkeypatch) -> None:  # noqa: ANN001
    """The compile "finishes" after the second chunk: the run goes on compiled from there."""
    compiled = simulate(load_preset("gnilka-1a"))
    started = []
    answers = iter([False, False, False])  # first_kernel's question, then before chunks 1 and 2
    monkeypatch.setenv("VTOOL_KERNEL", "auto")
    monkeypatch.setattr(kernel_build, "start", lambda jobs: started.append(jobs) or True)
    monkeypatch.setattr(kernel_build, "compiling", lambda jobs: True)
    monkeypatch.setattr(newmark.KernelRun, "ready", lambda self: next(answers, True))
    moved = simulate(load_preset("gnilka-1a"))
    assert len(started) == 1
    steps = moved.statistics.steps
    assert steps == compiled.statistics.steps
    assert 0 < moved.statistics.plain_steps < steps  # two chunks of 5000 steps, of 17,034
    assert moved.statistics.plain_steps >= 2 * 5000
    assert_same_run(moved, compiled)
    summary = moved.summary_text()
    assert f"({moved.statistics.plain_steps} of them as plain Python)" in summary


@needs_jit
def test_a_run_compiles_itself_when_the_child_is_gone(monkeypatch) -> None:  # noqa: ANN001
    """The child ended without putting the kernel in the cache: the run compiles it (no endless plain run)."""
    compiled = simulate(load_preset("gnilka-1a"))
    monkeypatch.setenv("VTOOL_KERNEL", "auto")
    monkeypatch.setattr(kernel_build, "start", lambda jobs: True)
    monkeypatch.setattr(kernel_build, "compiling", lambda jobs: False)
    monkeypatch.setattr(newmark.KernelRun, "ready", lambda self: False)
    alone = simulate(load_preset("gnilka-1a"))
    assert alone.statistics.plain_steps == 0  # moved before the first chunk
    assert_same_run(alone, compiled)


@needs_jit
def test_no_compile_is_started_when_the_kernel_is_loaded(monkeypatch) -> None:  # noqa: ANN001
    simulate(load_preset("gnilka-1a"))
    monkeypatch.setenv("VTOOL_KERNEL", "auto")
    monkeypatch.setattr(kernel_build, "start", lambda jobs: pytest.fail("a compile was started"))
    assert simulate(load_preset("gnilka-1a")).statistics.plain_steps == 0


def test_one_lock_per_compile(tmp_path) -> None:  # noqa: ANN001
    lock = tmp_path / "kernel.lock"
    assert kernel_build._take(lock) is True
    assert kernel_build._take(lock) is False  # just made: its process id follows
    lock.write_text(str(os.getpid()))
    assert kernel_build._take(lock) is False  # a live process holds it
    old = time.time() - kernel_build.STALE_S - 1
    os.utime(lock, (old, old))
    assert kernel_build._take(lock) is True  # too old: replaced
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    lock.write_text(gone)
    assert not kernel_build.holder_alive(lock)
    assert kernel_build._take(lock) is True  # its process is gone: replaced
    lock.write_text("not a process id")
    assert not kernel_build.holder_alive(lock)
    assert kernel_build._take(tmp_path / "missing" / "kernel.lock") is None  # no lock to be had


class FakeKernel:
    """Stands in for the kernel module in compile_once's tests: notes the loads of run_chunk."""

    def __init__(self) -> None:
        self.loads: list[tuple] = []
        self.run_chunk = self

    def compile(self, signature: tuple) -> None:
        self.loads.append(signature)


def test_compiled_runs_compile_a_kernel_once_between_processes(tmp_path, monkeypatch) -> None:  # noqa: ANN001
    """compile_once: with no compile under way it holds the lock while it compiles; while another
    process holds it, it waits and loads the result; if that process ends without the kernel, it
    compiles itself."""
    from vtool import numba_cache

    monkeypatch.setattr(numba_cache, "CACHE_ENABLED", True)
    lock = tmp_path / "kernel.lock"
    monkeypatch.setattr(kernel_build, "lock_path", lambda jobs: lock if jobs == [("run_chunk", ("sig",))] else None)
    monkeypatch.setattr(kernel_build, "POLL_S", 0.01)
    fake = FakeKernel()
    monkeypatch.setattr(kernel_build, "kernel", lambda: fake)
    compiled: list[str] = []

    def compile_kernel(signature: tuple) -> None:
        compiled.append(lock.read_text())  # the lock is held, with this process's id, meanwhile
    monkeypatch.setattr(kernel_build, "compile_kernel", compile_kernel)

    kernel_build.compile_once(("sig",), cached=lambda: False)  # nobody else: compiled here
    assert compiled == [str(os.getpid())] and not lock.exists() and fake.loads == []

    compiled.clear()
    lock.write_text(str(os.getpid()))  # another compile of the same kernel holds the lock (a live process)
    threading.Timer(0.5, lock.unlink).start()  # ... and finishes in 0.5 s
    started = time.monotonic()
    kernel_build.compile_once(("sig",), cached=lambda: True)
    assert time.monotonic() - started >= 0.4  # it waited for the other compile ...
    assert compiled == [] and fake.loads == [("sig",)]  # ... and loaded its kernel from the cache

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    lock.write_text(gone)  # the other process died without the kernel
    kernel_build.compile_once(("sig",), cached=lambda: False)
    assert compiled == [str(os.getpid())] and not lock.exists()

    monkeypatch.setattr(numba_cache, "CACHE_ENABLED", False)  # nothing to share: compiled at once
    compiled.clear()
    lock.write_text(str(os.getpid()))
    kernel_build.compile_once(("sig",), cached=lambda: True)
    assert len(compiled) == 1


def test_a_failed_child_leaves_its_error_and_no_lock(tmp_path, monkeypatch) -> None:  # noqa: ANN001
    lock = tmp_path / "kernel.lock"
    lock.write_text("")
    child = subprocess.run([sys.executable, "-m", "vtool.solvers.newmark.build", str(lock)], input=b"not a pickle",
                           capture_output=True)
    assert child.returncode != 0
    assert not lock.exists()
    assert "UnpicklingError" in kernel_build.failed_path(lock).read_text()
    monkeypatch.setattr(kernel_build, "lock_path", lambda jobs: lock)
    monkeypatch.setattr(subprocess, "Popen", lambda *a, **k: pytest.fail("a failed compile was started again"))
    assert kernel_build.start([]) is False  # the caller compiles in its own process, where the error shows


@needs_jit
def test_the_split_compiles_helper_writes_its_jobs_into_the_cache(tmp_path) -> None:  # noqa: ANN001
    """``python -m vtool.solvers.newmark.build --part`` (compile_kernel's helper) compiles the pickled
    jobs into numba's cache and exits 0; another process then finds them there."""
    import pickle

    from numba import types

    vec, mat = types.Array(types.float64, 1, "C"), types.Array(types.float64, 2, "C")
    jobs = [("fill_sources", (types.int64, types.int64, types.float64, vec, mat, mat, types.float64, vec))]
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    helper = subprocess.run([sys.executable, "-m", "vtool.solvers.newmark.build", "--part"], input=pickle.dumps(jobs),
                            env=env, capture_output=True, timeout=600)
    assert helper.returncode == 0, helper.stderr.decode()
    probe = ("import sys; from vtool.solvers.newmark import kernel as k; "
             "sys.exit(0 if k.is_cached(('fill_sources',)) else 1)")
    assert subprocess.run([sys.executable, "-c", probe], env=env, timeout=600).returncode == 0


def test_memoized_types_are_numbas() -> None:
    import numba

    base = np.zeros((4, 6))
    readonly = np.ones(3)
    readonly.flags.writeable = False
    values = (base, base.T, base[:, ::2], base[0], np.zeros(5, dtype=np.int64), readonly, np.zeros((2, 2, 2)),
              base.T.copy(order="F"), 3, 2.5, True, None, np.int64(4), base)
    assert kernel_build.numba_types(values) == tuple(numba.typeof(value) for value in values)
    assert kernel_build.numba_types(values) == tuple(numba.typeof(value) for value in values)  # memoized


@needs_jit
@pytest.mark.parametrize("name", ["gnilka-1a", "gnilka-2"])
def test_the_split_compile_names_the_types_run_chunk_calls_its_callees_with(name: str, monkeypatch) -> None:  # noqa: ANN001
    """kernel_split's types for each callee are those of the one version of it that run_chunk uses: the
    cache holds no other version for the same law switches (a wrong guess, compiled by the split,
    would be a second one beside the version run_chunk compiled for itself)."""
    signatures: list = []
    compile_run = newmark.KernelRun.compile

    def noting(run) -> None:  # noqa: ANN001
        signatures.append(run.signature)
        compile_run(run)

    monkeypatch.setattr(newmark.KernelRun, "compile", noting)
    simulate(load_preset(name))  # run_chunk compiled (or loaded) for this preset, its callees cached
    helper, own = kernel_build.kernel_split(signatures[0])
    assert {job for job, _ in helper} & {job for job, _ in own} == set()
    for job, types in helper + own:
        getattr(kernel, job).compile(types)  # from the cache: the split's versions, if run_chunk's differ
        switches = types[-1:]
        versions = [args for args in kernel.cached_signatures(job) if args[-1:] == switches]
        assert versions == [types], job


@needs_jit
def test_a_piecewise_run_calls_the_rules_as_plain_python_until_they_are_cached(monkeypatch) -> None:  # noqa: ANN001
    """The exact back end before its event rules are cached: the same run, with the plain rules; the types
    they were called with are those of the compiled rules' calls, and their compile is started after."""
    spec = with_run_overrides(load_preset("gnilka-1a"), backend="exact")
    compiled = simulate(spec)
    started: list = []
    monkeypatch.setenv("VTOOL_KERNEL", "auto")
    monkeypatch.setattr(kernel, "is_cached", lambda names, hertz=None, momentum=None: False)
    monkeypatch.setattr(kernel_build, "start", lambda jobs: started.append(jobs) or True)
    plain = simulate(spec)
    assert_same_run(plain, compiled)
    assert len(started) == 1
    jobs = dict(started[0])
    assert set(jobs) == {"fill_sources", "settle", "impact"}
    for name, signature in jobs.items():
        assert signature in getattr(kernel, name).signatures  # what the compiled run compiled
    assert kernel_build.rules(None, None).__class__ is kernel_build.RecordingRules
    monkeypatch.setenv("VTOOL_KERNEL", "compiled")
    assert kernel_build.rules(None, None) is kernel


@needs_jit
@pytest.mark.slow
def test_a_new_install_runs_the_exact_back_end_without_waiting(tmp_path) -> None:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("VTOOL_KERNEL")
    command = [sys.executable, "-m", "vtool", "solve", "gnilka-1a", "--backend", "exact", "--json"]
    first = subprocess.run(command, env=env, capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    assert "compiling" not in first.stderr
    wait_until_cached(env, ("impact", "settle", "fill_sources"))
    second = subprocess.run(command, env=env, capture_output=True, text=True, timeout=600)
    assert second.returncode == 0, second.stderr
    assert json.loads(second.stdout)["events_list"] == json.loads(first.stdout)["events_list"]


def test_the_collector_is_paused_during_a_compile_and_restored_after() -> None:
    """kernel_build.collector_paused: off inside; after it, as it was before (also after an error), with
    what was made inside frozen (the collector's next pass does not go over it)."""
    import gc

    was = gc.isenabled()
    try:
        gc.enable()
        frozen = gc.get_freeze_count()
        with kernel_build.collector_paused():
            assert not gc.isenabled()
            made = [[index] for index in range(1000)]
        assert gc.isenabled()
        assert gc.get_freeze_count() >= frozen + len(made)
        with pytest.raises(RuntimeError), kernel_build.collector_paused():
            raise RuntimeError("a failed compile")
        assert gc.isenabled()
        gc.disable()
        with kernel_build.collector_paused():
            assert not gc.isenabled()
        assert not gc.isenabled()  # off before: left off
    finally:
        (gc.enable if was else gc.disable)()
