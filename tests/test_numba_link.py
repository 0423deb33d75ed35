"""Link-only numba libraries (vtool.numba_link): the same results, through numba's cache too."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from vtool import numba_link

# one worker, early (see conftest.py): seven child processes that compile, 18 s
pytestmark = pytest.mark.xdist_group("numba_link")

HEADER = '''
from numba import njit

import pytest

from vtool import numba_link

INSTALLED = numba_link.install()
inner = njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")


@inner
def scale(a, s):
    for i in range(a.shape[0]):
        a[i] *= s
    return a.sum()
'''

MODULE = HEADER + '''

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
import pytest

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
    import vtool.solvers.newmark.kernel  # noqa: F401

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


BUNDLE_MODULE = HEADER + '''

@inner
def twice(a, s):
    return scale(a, s) + scale(a, 2.0)  # (scale is this bundle's own, and the entry calls it too)


@njit(cache=True)
def entry(a, s):
    return twice(a, s) - scale(a, 0.25)
'''

BUNDLE_RUN = '''
import sys
import numpy as np
from numba import types
sys.path.insert(0, {folder!r})
import toy2
import pytest

from vtool import numba_link
vec = types.Array(types.float64, 1, "C")
sized = {sized!r}
if {make!r}:
    toy2.twice.compile((vec, types.float64))
    bundle = numba_link.build_bundle([("twice", toy2.twice.overloads[(vec, types.float64)])], "t0",
                                     for_size=("twice",) if sized else ())
    with numba_link.expecting_bundle("entry", lambda: bundle, entry_for_size=sized):
        value = toy2.entry(np.arange(5.0), 3.0)
    library = toy2.entry.overloads[toy2.entry.signatures[0]].library
    entry_sized = "optsize" in str(library._final_module)
else:
    value = toy2.entry(np.arange(5.0), 3.0)
    entry_sized = sized  # (not read back from the cache)
library = toy2.entry.overloads[toy2.entry.signatures[0]].library
assert entry_sized == sized, entry_sized
print(repr(value), getattr(library, numba_link.BUNDLE, None) is not None, toy2.entry.stats.cache_hits.total())
'''


@pytest.mark.parametrize("sized", [False, True])
def test_an_entry_point_calls_its_callees_in_a_bundle_fresh_and_from_the_cache(tmp_path: Path, sized: bool) -> None:
    """A bundle (the callees' machine code made apart, vtool.numba_link.build_bundle) gives the entry point
    numba's own result; numba's cache keeps the entry point with its bundle, and a second process loads
    both and gets the same result again. So too with the bundled callee and the entry point made for
    size (their IR then carries LLVM's optsize attribute; the entry's is checked)."""
    (tmp_path / "toy2.py").write_text(textwrap.dedent(BUNDLE_MODULE))

    def bundle_run(env: dict[str, str], make: bool) -> str:
        code = BUNDLE_RUN.format(folder=str(tmp_path), make=make, sized=sized)
        out = subprocess.run([sys.executable, "-c", code],
                             capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
        assert out.returncode == 0, out.stderr[-3000:]
        return out.stdout.strip()

    stock = bundle_run(dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "stock")), make=False)
    value = stock.split()[0]
    assert float(value) == 3.0 * 10.0 + 6.0 * 10.0 - 1.5 * 10.0  # a scaled by 3, 2 and 0.25; sum(0..4) = 10
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    assert bundle_run(env, make=True) == f"{value} True 0"
    assert bundle_run(env, make=False) == f"{value} True 1"  # from the cache, bundle and all
