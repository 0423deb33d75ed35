"""Memoized call typing in numba (vtool.numba_typing): the same signatures and results, each resolved once."""

from __future__ import annotations

import operator
import os
import subprocess
import sys

import numpy as np
import pytest

from vtool import numba_typing

RUN = '''
import numpy as np
from numba import njit
from vtool import numba_typing

INSTALLED = numba_typing.install()


@njit(error_model="numpy")
def inner(a, b, i):
    return a[i] * b[i, 1] + max(a[i], 0.5) + int(b[i, 0])


@njit(error_model="numpy")
def entry(a, b):
    total = 0.0
    for i in range(a.shape[0]):
        a[i] += 1.0
        total += inner(a, b, i) + a[i] - b[i, 0]
    return total, a[1:].sum()


a = np.linspace(-1.0, 2.0, 7)
b = np.arange(14.0).reshape(7, 2) / 3.0
print(INSTALLED, repr(entry(a, b)), a.tobytes().hex(), numba_typing.counts[0] > 0)
'''


def run(env: dict[str, str]) -> str:
    out = subprocess.run([sys.executable, "-c", RUN], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.strip()


def test_memo_is_installed_on_this_numba() -> None:
    """The kernel module installs it on import; a numba whose ``BaseFunction.get_call_type`` changed
    shape makes this fail (the compile then runs as numba ships it: slower, still right)."""
    import vtool.solvers.newmark.kernel  # noqa: F401

    assert numba_typing.installed()


def test_a_compile_with_the_memo_gives_numbas_own_results() -> None:
    """Array indexing, slices, builtins with overloads (max, int) and a callee: the same values to the
    last bit with the memo and without it (``VTOOL_TYPING_MEMO=0``, numba as shipped), and the memo
    answered repeated questions."""
    env = {key: value for key, value in os.environ.items() if key != "VTOOL_TYPING_MEMO"}
    memo = run(env)
    stock = run(dict(env, VTOOL_TYPING_MEMO="0"))
    assert memo.startswith("True ") and memo.endswith(" True"), memo
    assert stock.startswith("False ") and stock.endswith(" False"), stock
    assert memo.split(" ", 1)[1].rsplit(" ", 1)[0] == stock.split(" ", 1)[1].rsplit(" ", 1)[0]


def test_a_remembered_answer_sets_the_implementation_key_again() -> None:
    """numba's one side effect of an answer, the implementation key lowering reads, is repeated on a
    memo hit, and the hit returns the very signature numba gave."""
    from numba import typeof
    from numba.core import types
    from numba.core.registry import cpu_target

    assert numba_typing.install()
    context = cpu_target.typing_context
    context.refresh()
    function = context.resolve_value_type(operator.getitem)
    args = (typeof(np.zeros(3)), types.int64)
    first = function.get_call_type(context, args, {})
    key = function.get_impl_key(first)
    function._impl_keys.clear()
    hits = numba_typing.counts[0]
    again = function.get_call_type(context, args, {})
    assert again is first
    assert numba_typing.counts[0] == hits + 1
    assert function.get_impl_key(again) == key


def test_a_call_that_does_not_type_fails_every_time() -> None:
    """Failures are not remembered: each attempt raises numba's typing error."""
    from numba import njit
    from numba.core.errors import TypingError

    assert numba_typing.install()

    @njit
    def bad(x):  # noqa: ANN001, ANN202
        return x["no such key"]

    for _ in range(2):
        with pytest.raises(TypingError):
            bad(1.0)
