"""Memoized call typing in numba: each operator or builtin call with given argument types is resolved once.

What numba does. To type a call such as ``a[i]`` (``operator.getitem`` on an
array and an integer), numba's function type
(``numba.core.types.functions.BaseFunction.get_call_type``) tries every
template registered for that function, in order, until one accepts the
argument types: for ``getitem`` that is dozens of templates (arrays, tuples,
lists, dicts, strings, records, each ``@overload`` in numba and its
extensions), most of them Python functions that look at the types and say
no. It keeps no memory of the answer. Type inference asks again each time a
constraint is revisited, and lowering asks once more for every call it
lowers. For the Newmark kernel's first compile that was 4,823 resolutions of
which 4,629 repeated one already made, a few milliseconds per array index
(``python3 benchmarks/bench_compile_ab.py 6b6ad5c`` measures the two-process
compile against the commit before this module).

What :func:`install` changes. ``get_call_type`` keeps its answers, keyed by
the function type, the typing context, the target (numba's
``get_local_target``), the argument types and the keyword types. A repeated
question gets the remembered signature, and numba's one side effect of an
answer is repeated too: the function type's implementation key for those
argument types (``_impl_keys[sig.args]``, which lowering reads to find the
implementation) is set again to the template that answered. Failures are not
remembered: a call that does not type raises as before, every time.

Why it is the same answer. A function type's templates are fixed when it is
made (``templates`` is a tuple; a new ``@overload`` makes a new function
type, so a new key), numba's types are immutable values, and the templates'
answers depend only on the types they are given and the typing context.
Templates that compile an implementation (``@overload``) do it on their first
answer and keep it themselves; the memo skips only their later re-answers.
The kernel compiled with the memo is the same LLVM module (compared after
numba's per-compile symbol counters are normalized: only duplicate copies of
numba's ``min``, ``max`` and ``int`` overloads, which it had compiled twice
or three times, are gone), and its runs are equal to the last bit
(``tests/test_numba_typing.py`` compiles a small function both ways).

Guard: it installs only on a numba whose ``BaseFunction`` has the shape it was
written for (``get_call_type(context, args, kws)`` and an ``_impl_keys``
dict; written and checked on numba 0.68); elsewhere numba runs as shipped,
and ``tests/test_numba_typing.py`` fails so that the change is seen.
``VTOOL_TYPING_MEMO=0`` leaves numba as shipped (for comparisons).
"""

from __future__ import annotations

import inspect
import os
from typing import Any

_installed: list[bool] = []
#: (function type, context, target, argument types, keyword types) -> (signature, implementation key)
_memo: dict[tuple[Any, ...], tuple[Any, Any]] = {}
#: [memo hits, resolutions numba made]
counts = [0, 0]


def installed() -> bool:
    """True when :func:`install` has patched this process's numba."""
    return bool(_installed)


def enabled() -> bool:
    """False under ``VTOOL_TYPING_MEMO=0``: numba resolves every call as shipped."""
    return os.environ.get("VTOOL_TYPING_MEMO", "").strip() != "0"


def install() -> bool:
    """Patch numba (once per process) as the module docstring says; returns whether it is patched."""
    if _installed:
        return True
    if not enabled():
        return False
    try:
        from numba.core.target_extension import get_local_target
        from numba.core.types import functions

        base = functions.BaseFunction
        resolve = base.get_call_type
        parameters = list(inspect.signature(resolve).parameters)
        if parameters != ["self", "context", "args", "kws"] or "_impl_keys" not in inspect.getsource(base.__init__):
            return False
    except (ImportError, AttributeError, OSError, TypeError, ValueError):
        return False

    def get_call_type(self: Any, context: Any, args: Any, kws: Any) -> Any:
        try:
            key = (self, context, get_local_target(context), tuple(args), tuple(sorted(kws.items())))
            found = _memo.get(key)
        except TypeError:  # an unhashable type: ask numba
            return resolve(self, context, args, kws)
        if found is not None:
            counts[0] += 1
            signature, impl_key = found
            self._impl_keys[signature.args] = impl_key
            return signature
        counts[1] += 1
        signature = resolve(self, context, args, kws)
        if signature is not None:
            _memo[key] = (signature, self._impl_keys[signature.args])
        return signature

    base.get_call_type = get_call_type  # type: ignore[method-assign]
    _installed.append(True)
    return True
