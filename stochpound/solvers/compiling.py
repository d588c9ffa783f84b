"""How the event engine is compiled: two numba settings beyond its public options.

The engine (:mod:`stochpound.solvers.engine`) is one jitted entry point,
``run_engine``, and about fifty jitted helpers without Python wrappers that
only it calls. numba compiles it on a process's first call unless its cache
(``cache=True``) holds it; :func:`engine_compile` is the block that first
call runs in. Inside it:

* **LLVM optimisation level** :data:`OPTIMISATION_LEVEL` (numba's default,
  ``NUMBA_OPT``, is 3): the engine's hot loops are vectorised at either
  level and the passes level 3 adds find nothing more to gain in it, so it
  compiles faster and runs as fast (docs/benchmarks.md, "First call").
* **No machine code for the helpers.** numba finalises every function it
  compiles, wrapper or not: it optimises the function's module and
  generates its machine code, although a helper without a Python wrapper is
  only ever linked, as LLVM IR, into its callers, which optimise and
  generate code for it again (numba pull request 9566 proposes to skip this
  upstream). Inside the block a library whose function has no Python
  wrapper stays unfinalised: it is linked into its callers as its
  function-optimised IR, and only ``run_engine``'s library, with every
  helper linked in, is optimised as a module and turned into machine code.

Neither setting changes a result: LLVM keeps IEEE semantics at every level
(no fast-math), and the same IR is optimised, only once instead of once per
function (the outputs are compared bitwise with numba's default compile in
``tests/test_engine_compile.py``). A ``NUMBA_OPT`` set in the environment turns both
off: the engine then compiles exactly as numba would by default.

Both reach into numba's internals (its compiler lock, configuration, CPU
target context and code libraries), and they fail safe: before the first
compile :func:`internals_mismatch` checks that every internal they touch is
there with the signature they were written against (numba 0.63 to 0.68), and
on any difference the engine compiles as numba does by default (a
debug-level log message, once, names the difference). So does
:data:`NO_RUNTIME`, the engine's ``_nrt=False``.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import logging
import os
from collections.abc import Iterator
from typing import Any

import numba

try:
    import llvmlite.binding as llvm
    from numba import _dynfunc
    from numba.core.codegen import JITCodeLibrary
    from numba.core.compiler_lock import global_compiler_lock
    from numba.core.cpu import CPUTargetOptions
    from numba.core.funcdesc import FunctionDescriptor
    from numba.core.registry import cpu_target
except ImportError as error:  # numba moved its internals: numba's default compile (see internals_mismatch)
    _IMPORT_ERROR: ImportError | None = error
    JITCodeLibrary = object  # the base of _LinkedOnlyLibrary, which is then never used
    CPUTargetOptions = object
else:
    _IMPORT_ERROR = None

_LOG = logging.getLogger(__name__)

OPTIMISATION_LEVEL = 1
"""LLVM optimisation level of the engine's compile (numba's default, ``NUMBA_OPT``, is 3)."""
NO_RUNTIME = {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}
"""The jit option that compiles without numba's runtime (reference counting), where numba offers it.

``_nrt`` is a target option of numba's CPU target (``numba.core.cpu.CPUTargetOptions``)
without a public spelling. The engine allocates nothing, so the runtime only
adds reference counting (half of its unoptimised IR); without the option
it compiles slower, with the same results.
"""


def numba_default_requested() -> bool:
    """True when the engine must compile as numba does by default.

    The environment asks for numba's own compile settings (``NUMBA_OPT``
    set) or for no compile (``NUMBA_DISABLE_JIT``), or numba's internals
    differ from those :func:`engine_compile` was written against
    (:func:`internals_mismatch`).
    """
    return "NUMBA_OPT" in os.environ or bool(numba.config.DISABLE_JIT) or internals_mismatch() is not None


_SIGNATURES = {
    "JITCodeLibrary.add_linking_library": ["self", "library"],
    "JITCodeLibrary._get_module_for_linking": ["self"],
    "JITCodeLibrary._ensure_finalized": ["self"],
    "CPUContext.get_executable": ["self", "library", "fndesc", "env"],
}
"""The numba methods :func:`engine_compile` overrides or calls, with the parameters it was written against."""
_LIBRARY_ATTRIBUTES = ("_linking_libraries", "_shared_module", "_final_module", "_reload_init", "_finalized")
"""The attributes of a numba code library :class:`_LinkedOnlyLibrary` reads and sets."""


@functools.cache
def internals_mismatch() -> str | None:
    """How numba's internals differ from those :func:`engine_compile` touches (None: they are as expected).

    Checks that every module, class, method and attribute it uses exists, and
    the parameters of the methods it overrides or calls. On a difference it
    logs it once, at debug level, and the engine compiles as numba does by
    default.
    """
    reason = _mismatch()
    if reason is not None:
        _LOG.debug("compiling the engine as numba does by default: %s", reason)
    return reason


def _mismatch() -> str | None:
    if _IMPORT_ERROR is not None:
        return f"numba's internals cannot be imported ({_IMPORT_ERROR})"
    context = cpu_target.target_context
    codegen = context.codegen()
    owners = {"JITCodeLibrary": JITCodeLibrary, "CPUContext": type(context)}
    for name, expected in _SIGNATURES.items():
        owner, method = name.split(".")
        function = getattr(owners[owner], method, None)
        try:
            parameters = list(inspect.signature(function).parameters) if callable(function) else None
        except (TypeError, ValueError):
            parameters = None
        if parameters != expected:
            return f"{name} takes {parameters}, expected {expected}"
    missing = [name for owner, name in ((numba.config, "OPT"), (_dynfunc, "make_function"), (llvm, "Linkage"), (FunctionDescriptor, "lookup_module"),
                                        (FunctionDescriptor, "llvm_cpython_wrapper_name"), (type(codegen), "_library_class"))
               if not hasattr(owner, name)]
    if missing:
        return f"numba has no {', '.join(missing)}"
    if not (isinstance(type(codegen)._library_class, type) and issubclass(type(codegen)._library_class, JITCodeLibrary)):
        return f"numba's code libraries are {type(codegen)._library_class!r}, not JITCodeLibrary"
    with global_compiler_lock:
        library = codegen.create_library("stochpound.solvers.compiling probe")
    missing = [name for name in _LIBRARY_ATTRIBUTES if not hasattr(library, name)]
    return f"numba's code libraries have no {', '.join(missing)}" if missing else None


@contextlib.contextmanager
def engine_compile() -> Iterator[None]:
    """The block in which the engine is compiled: :data:`OPTIMISATION_LEVEL` and no machine code for wrapper-less helpers.

    numba's compiler lock is held throughout (both settings take it), so no
    other thread compiles under them; everything is restored on leaving the
    block, also when it raises. When numba's internals differ from those
    the settings touch (:func:`internals_mismatch`), the block changes nothing.
    """
    if internals_mismatch() is not None:  # numba's default compile (logged once)
        yield
        return
    with optimisation_level(OPTIMISATION_LEVEL), _helpers_without_machine_code():
        yield


@contextlib.contextmanager
def optimisation_level(level: int) -> Iterator[None]:
    """numba's LLVM optimisation passes at ``level`` inside the block (numba's compiler lock held).

    Parameters
    ----------
    level : int
        LLVM optimisation level, 0 to 3 (numba's ``NUMBA_OPT``).

    Notes
    -----
    numba reads ``numba.config.OPT`` whenever it builds a pass pipeline. The
    code generator, which reads it once per process, is created first at the
    default level so that it stays there for every later compile.
    """
    with global_compiler_lock:
        cpu_target.target_context  # noqa: B018 (creates the code generator)
        default = numba.config.OPT
        numba.config.OPT = type(default)(level)
        try:
            yield
        finally:
            numba.config.OPT = default


class _LinkedOnlyLibrary(JITCodeLibrary):
    """A code library that links wrapper-less functions into its callers unfinalised (see the module docstring).

    A library is marked ``linked_only`` by :func:`_executable` when its
    function has no Python wrapper. Such a library is never finalised while
    it is only linked: its callers link its function-optimised module with
    its own callees' linked in (as numba's finalised module would hold them).
    Anything else (inspection, a caller compiled outside the block) finalises
    it as numba always does.
    """

    linked_only = False

    def add_linking_library(self, library: Any) -> None:
        """Link ``library`` into this one when this one is finalised (a linked-only library stays unfinalised until then)."""
        if not getattr(library, "linked_only", False):
            library._ensure_finalized()
        self._linking_libraries.append(library)

    def _get_module_for_linking(self) -> Any:
        """The module its callers link: the function-optimised IR with its callees', functions made ``linkonce_odr`` (as numba's)."""
        if not self.linked_only or self._finalized:
            return super()._get_module_for_linking()
        if self._shared_module is None:
            module = self._final_module.clone()
            for library in dict.fromkeys(self._linking_libraries):
                self._reload_init.update(library._reload_init)
                module.link_in(library._get_module_for_linking(), preserve=True)
            for function in module.functions:
                if not function.is_declaration and function.linkage == llvm.Linkage.external:
                    function.linkage = "linkonce_odr"
            self._shared_module = module
        return self._shared_module


def _executable(context: Any, library: Any, fndesc: Any, env: Any) -> Any:
    """``CPUContext.get_executable`` that leaves a wrapper-less function's library unfinalised (no machine code).

    numba's own asks the finalised library for the Python wrapper's address,
    which is null for such a function anyway; the function object it makes
    from that null address is what callers look the function up by.
    """
    if not isinstance(library, _LinkedOnlyLibrary) or library._finalized or _defines(library, fndesc.llvm_cpython_wrapper_name):
        return type(context).get_executable(context, library, fndesc, env)  # loaded from numba's cache, or wrapped
    library.linked_only = True
    name = fndesc.qualname.split(".")[-1]
    return _dynfunc.make_function(fndesc.lookup_module(), name, f"compiled wrapper for {fndesc.qualname!r}", 0, env, (library,))


def _defines(library: Any, name: str) -> bool:
    """True if the unfinalised ``library`` defines a function named ``name``."""
    return any(function.name == name and not function.is_declaration for function in library._final_module.functions)


@contextlib.contextmanager
def _helpers_without_machine_code() -> Iterator[None]:
    """Inside the block, libraries are :class:`_LinkedOnlyLibrary` and wrapper-less functions get no machine code (numba's compiler lock held)."""
    with global_compiler_lock:
        context = cpu_target.target_context
        codegen = context.codegen()
        codegen._library_class = _LinkedOnlyLibrary
        context.get_executable = _executable.__get__(context)
        try:
            yield
        finally:
            del codegen._library_class
            del context.get_executable
