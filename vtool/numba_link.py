"""Link-only numba libraries: a function that only compiled code calls gets no machine code of its own.

How numba compiles a call chain. Each jitted function is lowered into its own
code library. Finalizing a library links its callees' finished modules into
it, runs LLVM's module passes (``-O3``, inlining) over the whole and makes
machine code of it. numba finalizes every library as soon as its function is
compiled, also for a function that only other compiled code calls (no CPython
and no C wrapper: the kernels' ``@inner`` helpers, and numba's own overloads
such as ``np.zeros``'s). So a callee at depth d of the call tree is optimized
and made into machine code d + 1 times: for itself, inside its caller, inside
its caller's caller, ... and only the copy in the entry point's library is
ever run. For the Newmark kernel's first compile that was about a quarter of
the compile's work (``benchmarks/bench_compile_phases.py``: module passes and
code generation outside ``run_chunk``).

What :func:`install` changes. The library of a function compiled with neither
wrapper is *link-only*:

* finalizing it links its callees' modules in and stops there (no module
  passes, no machine code); its functions have had LLVM's function passes, as
  numba runs them when it adds each module;
* a library with a wrapper (an entry point) that links it in is finalized as
  numba does it: its module passes see all the linked code at once, and its
  machine code is the only one made;
* numba's cache keeps a link-only library as its bitcode (kind ``"link"``),
  which is all a caller needs, instead of machine code plus bitcode; loading
  one gives a link-only library again;
* an environment (numba's per-function object that dynamic exception messages
  use) is set only where its symbol has machine code, and the entry point's
  library sets those of the link-only callees in it after its code is made.

Same results: the entry point's code is made from the same functions by the
same passes. The Newmark kernel's runs (1A, 2, 3, the ramped cam, a Hertz
drop) were equal to the last bit with and without it (q, forces and event
times, ``array_equal``, also with the callees loaded from the cache), and its
kernel as fast (135.6 against 138.9 ns/step on 1A, one process each, warm);
``tests/test_numba_link.py`` holds a small call chain to numba's own results,
fresh, from the cache and linked from the cache.

Bundles: the callees' machine code made in another process. An entry
point's library makes machine code for everything linked into it, after its
own function is lowered: for the Newmark kernel's ``run_chunk`` that last
stage was half the compile's wall time, on one core. :func:`build_bundle`
(run by the helper process of :func:`vtool.solvers.newmark.build.compile_kernel`)
links some compiled functions' libraries into one module, with each of them
exported under a new name (``<symbol>.<tag>``, a tag per bundle, so that two
bundles never define the same symbol) and everything else internal, runs the
module passes numba runs on an entry point and makes machine code of it.
Inside :func:`expecting_bundle`, the entry point's library takes it
(:func:`take_bundle`): its calls to those functions are renamed to the
exported names, their libraries are not linked in, and the bundle's machine
code is added to numba's JIT beside its own, where the calls resolve. So the
bundle's machine code is made while the entry point is typed and lowered. The
machine code comes from the same IR by the same passes, so the results are
the same; LLVM only no longer inlines a bundled callee into the entry point.
numba's cache keeps such an entry point as its object code, its bitcode for
linking and the bundle (kind ``"bundled"``); loading it adds the bundle to
the JIT first.

Made for size: LLVM's ``optsize`` (and ``minsize``) function attributes
make its passes inline and unroll less inside a function and its code
generator make less code of it. :func:`build_bundle` gives them to the
bundled functions named in ``for_size`` (both), and :func:`expecting_bundle`
to the entry point's own function with ``entry_for_size`` (``optsize``
alone): code that runs rarely, such as a solver's event handling, compiles
faster and runs a little slower. The hot functions keep LLVM's full
optimization.

Guard: it installs only on a numba whose internals have the shape it was
written for (``CPUCodeLibrary.finalize``, ``serialize_using_object_code``,
``_unserialize``, ``CPUContext.get_executable``, ``JITCPUCodegen.set_env`` and
the library methods they call; written and checked on numba 0.68 with
llvmlite 0.50); elsewhere numba runs as shipped, and
``tests/test_numba_link.py`` fails so that the change is seen.
``VTOOL_LINK_ONLY=0`` makes no new library link-only (for comparisons);
loading a cached one stays possible.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable, Iterator
from typing import Any

#: Set on a library that is link-only (finalized without module passes or machine code).
LINK_ONLY = "_vtool_link_only"
#: numba's cache kind of a link-only library: its module's bitcode.
KIND = "link"
#: Set on an entry point's library that took a bundle (the bundle: see :func:`build_bundle`).
BUNDLE = "_vtool_bundle"
#: numba's cache kind of such a library: numba's object code and bitcode, and the bundle.
BUNDLED = "bundled"
_installed: list[bool] = []
#: Per thread (numba finalizes a library in the thread that compiles it): ``stack``, the (library name, a
#: callable that returns the bundle or None) pairs of the :func:`expecting_bundle` blocks it is in.
_expecting = threading.local()


@contextlib.contextmanager
def expecting_bundle(name: str, fetch: Callable[[], dict[str, Any] | None],
                     entry_for_size: bool = False) -> Iterator[None]:
    """Inside: the next JIT library named ``name`` to be finalized takes the bundle ``fetch()`` returns
    (called then; None: no bundle, the library is finalized as numba does it). Only the compiles of
    this thread: another thread's compile of a library of that name goes on as numba does it. With
    ``entry_for_size``, the library's own functions (the entry point and its wrapper) are optimized for
    size when it takes a bundle (see "Made for size" in the module doc)."""
    stack = _expected()
    entry = (name, fetch, entry_for_size)
    stack.append(entry)
    try:
        yield
    finally:
        stack.remove(entry)


def _expected() -> list[tuple[str, Callable[[], dict[str, Any] | None], bool]]:
    """This thread's :func:`expecting_bundle` blocks, innermost last."""
    if not hasattr(_expecting, "stack"):
        _expecting.stack = []
    return _expecting.stack  # type: ignore[no-any-return]


#: The function attributes of a bundled function made for size, and of an entry point made for size.
SIZE_ATTRIBUTES = ("optsize", "minsize")
ENTRY_SIZE_ATTRIBUTES = ("optsize",)


def _for_size(function: Any, attributes: tuple[str, ...]) -> None:
    for attribute in attributes:
        function.add_function_attribute(attribute)


def build_bundle(functions: list[tuple[str, Any]], tag: str, for_size: tuple[str, ...] = ()) -> dict[str, Any]:
    """One module of these compiled functions, ``(name, numba's CompileResult)``, made into machine code;
    those whose name is in ``for_size`` optimized for size (see "Made for size" in the module doc).

    Returns the bundle: ``object`` (the machine code), ``exports`` (each
    function's symbol -> (its name in the bundle, ``name``)) and ``envs``
    (the numba environments its code refers to).
    """
    module = None
    for _, compiled in functions:
        part = compiled.library._get_module_for_linking().clone()
        # external before linking: LLVM links a linkonce definition in only where something uses it
        part.get_function(compiled.fndesc.mangled_name).linkage = "external"
        if module is None:
            module = part
        else:
            module.link_in(part)
    assert module is not None
    exports: dict[str, tuple[str, str]] = {}
    for name, compiled in functions:
        symbol = compiled.fndesc.mangled_name
        exports[symbol] = (f"{symbol}.{tag}", name)
        function = module.get_function(symbol)
        function.name = exports[symbol][0]
        if name in for_size:
            _for_size(function, SIZE_ATTRIBUTES)
    exported = {new for new, _ in exports.values()}
    for function in module.functions:
        if not function.is_declaration and function.name.startswith("_ZN") and function.name not in exported:
            # the bundle's own: internal (LLVM may change its arguments) and renamed, since the JIT's linker
            # resolves another module's call by name to a local function too
            function.linkage = "internal"
            function.name = f"{function.name}.{tag}"
    codegen_ = functions[0][1].library.codegen
    library = codegen_.create_library(f"bundle.{tag}")
    library._final_module = module
    library._optimize_final_module()  # numba's module passes for an entry point, as in finalize
    return {"object": codegen_._tm.emit_object(library._final_module), "exports": exports,
            "envs": [variable.name for variable in library._final_module.global_variables
                     if variable.name.startswith("_ZN08NumbaEnv")]}


def take_bundle(library: Any, bundle: dict[str, Any]) -> None:
    """``library`` (not finalized yet) calls the bundle's functions: see "Bundles" in the module doc."""
    from llvmlite import binding

    exports = bundle["exports"]
    for symbol, (new, _) in exports.items():
        try:
            function = library._final_module.get_function(symbol)
        except NameError:
            continue
        if function.is_declaration:
            function.name = new
    kept = []
    for linked in library._linking_libraries:
        defined = {function.name for function in linked._final_module.functions if not function.is_declaration}
        if any(symbol in defined and linked.name == name for symbol, (_, name) in exports.items()):
            library._reload_init.update(linked._reload_init)  # (as numba's finalize does for what it links)
            continue  # a bundled function's own library
        kept.append(linked)
    library._linking_libraries[:] = kept
    library._codegen._engine._ee.add_object_file(binding.ObjectFileRef.from_data(bundle["object"]))
    setattr(library, BUNDLE, bundle)


def installed() -> bool:
    """True when :func:`install` has patched this process's numba."""
    return bool(_installed)


def enabled() -> bool:
    """False under ``VTOOL_LINK_ONLY=0``: new libraries are finalized as numba does."""
    return os.environ.get("VTOOL_LINK_ONLY", "").strip() != "0"


def install() -> bool:
    """Patch numba (once per process) as the module docstring says; returns whether it is patched."""
    if _installed:
        return True
    try:
        from numba import _dynfunc
        from numba.core import codegen, cpu
        from numba.core.environment import lookup_environment

        library_class = codegen.CPUCodeLibrary
        jit_library = codegen.JITCodeLibrary
        finalize = library_class.finalize
        serialize = library_class.serialize_using_object_code
        unserialize = library_class.__dict__["_unserialize"].__func__
        finalize_specific = jit_library._finalize_specific
        get_executable = cpu.CPUContext.get_executable
        set_env = codegen.JITCPUCodegen.set_env
        for needed in ("_finalize_dynamic_globals", "_verify_declare_only_symbols", "_get_module_for_linking",
                       "_ensure_finalized", "_raise_if_finalized", "_optimize_final_module"):
            getattr(library_class, needed)
    except (ImportError, AttributeError, KeyError):
        return False

    def is_link_only(library: Any) -> bool:
        return bool(getattr(library, LINK_ONLY, False))

    def link_only_finalize(self: Any) -> None:
        if not is_link_only(self):
            expected = _expected()
            if expected and isinstance(self, jit_library) and self.name == expected[-1][0]:
                _, fetch, entry_for_size = expected[-1]
                bundle = fetch()
                if bundle is not None:
                    take_bundle(self, bundle)
                    if entry_for_size:
                        for function in self._final_module.functions:
                            if not function.is_declaration:
                                _for_size(function, ENTRY_SIZE_ATTRIBUTES)
            return finalize(self)
        self._raise_if_finalized()
        seen = set()
        for library in self._linking_libraries:
            if library not in seen:
                self._reload_init.update(library._reload_init)
                seen.add(library)
                self._final_module.link_in(library._get_module_for_linking(), preserve=True)
        self._final_module.verify()
        self._finalize_dynamic_globals()
        self._verify_declare_only_symbols()
        self._finalized = True
        return None

    def has_wrapper(library: Any, fndesc: Any) -> bool:
        for name in (fndesc.llvm_cpython_wrapper_name, fndesc.llvm_cfunc_wrapper_name):
            try:
                library._final_module.get_function(name)
            except NameError:
                continue
            return True
        return False

    def link_only_executable(self: Any, library: Any, fndesc: Any, env: Any) -> Any:
        fresh = not library._finalized and enabled() and not has_wrapper(library, fndesc)
        if fresh:
            setattr(library, LINK_ONLY, True)
        if not (fresh or is_link_only(library)):
            return get_executable(self, library, fndesc, env)
        # as numba's, with no function pointer (there is no wrapper to point at) and no machine code
        return _dynfunc.make_function(fndesc.lookup_module(), fndesc.qualname.split(".")[-1],
                                      f"compiled, link-only: {fndesc.qualname!r}", 0, env, (library,))

    def link_only_serialize(self: Any) -> Any:
        if not is_link_only(self):
            name, kind, data = serialize(self)
            bundle = getattr(self, BUNDLE, None)
            return (name, kind, data) if bundle is None else (name, BUNDLED, (*data, bundle))
        self._ensure_finalized()
        return (self.name, KIND, self._final_module.as_bitcode())

    def link_only_unserialize(cls: Any, codegen_: Any, state: Any) -> Any:
        name, kind, data = state
        if kind == BUNDLED:
            from llvmlite import binding

            object_code, bitcode, bundle = data
            codegen_._engine._ee.add_object_file(binding.ObjectFileRef.from_data(bundle["object"]))
            library = unserialize(cls, codegen_, (name, "object", (object_code, bitcode)))
            setattr(library, BUNDLE, bundle)
            set_envs(codegen_, bundle["envs"])
            return library
        if kind != KIND:
            return unserialize(cls, codegen_, state)
        from llvmlite import binding

        self = codegen_.create_library(name)
        self._final_module = binding.parse_bitcode(data)
        self._finalize_dynamic_globals()
        setattr(self, LINK_ONLY, True)
        self._finalized = True
        return self

    def guarded_set_env(self: Any, env_name: str, env: Any) -> None:
        if self._engine.get_global_value_address(env_name):  # no machine code for a link-only symbol
            set_env(self, env_name, env)

    def set_envs(codegen_: Any, names: list[str]) -> None:
        for name in names:
            env = lookup_environment(name)
            if env is not None:
                guarded_set_env(codegen_, name, env)

    def finalize_and_set_envs(self: Any) -> None:
        finalize_specific(self)
        # the link-only callees' environments, now that their code is in this library's (or its bundle's)
        set_envs(self._codegen, [variable.name for variable in self._final_module.global_variables
                                 if variable.name.startswith("_ZN08NumbaEnv")])
        set_envs(self._codegen, getattr(self, BUNDLE, {}).get("envs", []))

    library_class.finalize = link_only_finalize  # type: ignore[method-assign]
    library_class.serialize_using_object_code = link_only_serialize  # type: ignore[method-assign]
    library_class._unserialize = classmethod(link_only_unserialize)  # type: ignore[assignment]
    jit_library._finalize_specific = finalize_and_set_envs  # type: ignore[method-assign]
    cpu.CPUContext.get_executable = link_only_executable  # type: ignore[method-assign]
    codegen.JITCPUCodegen.set_env = guarded_set_env  # type: ignore[method-assign]
    _installed.append(True)
    return True
