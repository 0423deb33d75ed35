"""Link-only numba libraries (vtool.numba_link): the same results, through numba's cache too."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

from vtool import numba_link

MODULE = '''
from numba import njit

from vtool import numba_link

INSTALLED = numba_link.install()
inner = njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")


@inner
def scale(a, s):
    for i in range(a.shape[0]):
        a[i] *= s
    return a.sum()


@inner
def checked(x):
    if x < 0.0:
        raise ValueError("negative input:", x)  # a dynamic message: it needs checked's environment
    return 2.0 * x


@njit(cache=True)
def entry(a, s, x):
    return scale(a, s) + checked(x)  # (no array made: numba's np.zeros would add a second to each compile)
'''

RUN = '''
import sys
import numpy as np
sys.path.insert(0, {folder!r})
import toy
from vtool import numba_link
x = {x!r}
value = toy.entry(np.arange(4.0), 2.0, x)
try:
    toy.entry(np.arange(4.0), 2.0, -x)
except ValueError as error:
    raised = str(error)
kinds = [getattr(function.overloads[signature].library, numba_link.LINK_ONLY, False)
         for function in (toy.scale, toy.entry) for signature in function.signatures]
print(toy.INSTALLED, value, raised, kinds, toy.scale.stats.cache_hits.total())
'''


def run(folder: Path, env: dict[str, str], x: float | int) -> str:
    out = subprocess.run([sys.executable, "-c", RUN.format(folder=str(folder), x=x)], capture_output=True,
                         text=True, env=env, cwd=folder, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.strip()


def test_link_only_is_installed_on_this_numba() -> None:
    """The kernel module installs it on import; a numba whose internals changed shape makes this fail (the
    compile then runs as numba ships it: slower, still right)."""
    import vtool.solvers.newmark_kernel  # noqa: F401

    assert numba_link.installed()


def test_a_callee_is_link_only_and_gives_the_same_results_fresh_cached_and_linked_from_the_cache(
        tmp_path: Path) -> None:
    """A callee with no wrapper is link-only, and its caller's results equal numba's own
    (``VTOOL_LINK_ONLY=0``, another cache). A second process loads the caller from the cache; a third
    compiles the caller for new argument types, linking the callee from the cache (a link-only library
    there). A dynamic exception message, which reads the callee's numba environment, comes out right
    every time."""
    (tmp_path / "toy.py").write_text(textwrap.dedent(MODULE))
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    fresh = "True 15.0 ('negative input:', -1.5) [True, False] 0"  # scale(0..3, 2) = 12, checked(1.5) = 3
    assert run(tmp_path, env, 1.5) == fresh
    stock = run(tmp_path, dict(env, NUMBA_CACHE_DIR=str(tmp_path / "stock"), VTOOL_LINK_ONLY="0"), 1.5)
    assert stock == fresh.replace("[True, False]", "[False, False]")
    assert run(tmp_path, env, 1.5) == "True 15.0 ('negative input:', -1.5) [False] 0"  # entry from the cache
    # entry for an integer x: a new compile, which finds scale's link-only library in the cache
    assert run(tmp_path, env, 3) == "True 18.0 ('negative input:', -3) [True, False] 1"
