"""How the engine is compiled (stochpound.solvers.compiling): settings that change no result, and leave numba as they found it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest
from numba.core.registry import cpu_target

from stochpound.solvers import compiling, engine

PROBE = """
import hashlib, json, os

if os.environ.get("PROBE_CHANGE_NUMBA_INTERNALS"):  # numba still works; one method it has is not the one compiling.py was written against
    from numba.core.cpu import CPUContext

    numbas_own = CPUContext.get_executable
    CPUContext.get_executable = lambda self, *arguments: numbas_own(self, *arguments)

import numba
import numpy as np
from numba.core import event
from numba.core.registry import CPUDispatcher

import stochpound
from stochpound.solvers import compiling, engine
from stochpound.solvers.exact import compile_engine
from tests.helpers import free_masses
from tests.helpers import HARD_CASES
from tests.helpers import random_scene

levels = []


class EngineCompileLevel(event.Listener):
    def on_start(self, compile_event):
        if compile_event.data["dispatcher"] is engine.run_engine:
            levels.append(int(numba.config.OPT))

    def on_end(self, compile_event):
        pass


def digest(run):
    h = hashlib.sha256()
    for name in sorted(run.variables):
        values = np.ascontiguousarray(run[name].values)
        h.update(name.encode() + str(values.dtype).encode() + values.tobytes())
    h.update(json.dumps({k: v for k, v in run.attrs.items() if k.startswith("events_")}, sort_keys=True).encode())
    return h.hexdigest()


event.register("numba:compile", EngineCompileLevel())
compile_engine()
after = int(numba.config.OPT)
runs = {name: stochpound.simulate(stochpound.scene_from_dict(scene), demands=True) for name, scene in HARD_CASES.items()}
runs.update({f"seed {seed}": stochpound.simulate(stochpound.scene_from_dict(random_scene(seed))) for seed in range(12)})
runs["hard case 1, ivp"] = stochpound.simulate(stochpound.scene_from_dict(next(iter(HARD_CASES.values()))), method="ivp")
runs["hertz_damp, ivp"] = stochpound.simulate(stochpound.scene_from_dict(free_masses("hertz_damp", 0.6)), method="ivp")
print(json.dumps({"levels": levels, "after": after, "specialisations": len(engine.run_engine.signatures), "mismatch": compiling.internals_mismatch(),
                  "signatures": {name: len(f.signatures) for name, f in vars(engine).items() if isinstance(f, CPUDispatcher)},
                  "digests": {name: digest(run) for name, run in runs.items()}}))
"""


@pytest.fixture(scope="module")
def numbas_default(tmp_path_factory) -> dict:
    """:data:`PROBE`'s output with the engine compiled as numba compiles by default: in a numba whose internals differ
    from those compiling.py touches, so that it changes nothing (one cold compile serves both tests that need it; the
    level is asserted to be numba's default, 3, by the test of that case)."""
    return _probe(tmp_path_factory.mktemp("default"), PROBE_CHANGE_NUMBA_INTERNALS="1")


def _probe(cache: Path, **environment: str) -> dict:
    """What :data:`PROBE` prints in a fresh process compiling the engine into the empty numba cache ``cache``."""
    env = {name: value for name, value in os.environ.items() if name not in ("NUMBA_OPT", "NUMBA_DISABLE_JIT", "NUMBA_BOUNDSCHECK")}
    env.update(NUMBA_CACHE_DIR=str(cache), **environment)
    result = subprocess.run([sys.executable, "-c", PROBE], cwd=Path(__file__).parents[1], env=env, capture_output=True, text=True,
                            timeout=900, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    return json.loads(result.stdout.splitlines()[-1])


@pytest.mark.slow
def test_engine_stays_in_bounds_and_its_compile_settings_change_no_result(tmp_path, numbas_default):
    """The engine compiled as stochpound compiles it, with numba's bounds checking on, and as numba does by default (level 3).

    Compiled code reads and writes unchecked otherwise: an index past an
    array's end would go unnoticed as long as the values read are
    overwritten; with bounds checking it raises. Both processes compile into
    an empty cache and run hard cases with demand read-outs, random scenes
    and two ivp runs (one with a nonlinear law): every variable of every
    result dataset and the event counters must be bitwise the same. Each
    process first runs ``compile_engine`` (the experiment runner's warm-up),
    which must compile the one specialisation every later run uses, and
    every jitted function of the engine once (twice for ``_copy``: float and
    int arrays): a compile-time constant passed to a helper, or arrays of
    another layout, would compile it again. The cache is empty, so every
    function the runs reach is compiled in the probe and counted.
    """
    ours, default = _probe(tmp_path / "ours", NUMBA_BOUNDSCHECK="1"), numbas_default
    assert ours["mismatch"] is None
    assert ours["levels"] == [compiling.OPTIMISATION_LEVEL] and ours["after"] == 3  # numba's default level restored afterwards
    assert default["levels"] == [3]
    assert ours["specialisations"] == default["specialisations"] == 1
    for probe in (ours, default):
        assert probe["signatures"]["run_engine"] == 1 and sum(count > 0 for count in probe["signatures"].values()) > 20
        assert {name: count for name, count in probe["signatures"].items() if count > (2 if name == "_copy" else 1)} == {}
    assert len(ours["digests"]) == 19
    assert ours["digests"] == default["digests"]


@pytest.mark.slow
def test_engine_compiles_as_numba_does_by_default_when_numbas_internals_differ(numbas_default):
    """A numba whose internals differ from those compiling.py touches: the engine still compiles, at numba's default level,
    once; its results are those of the engine compiled as stochpound compiles it (the test above compares the digests)."""
    changed = numbas_default
    assert changed["mismatch"] == "CPUContext.get_executable takes ['self', 'arguments'], expected ['self', 'library', 'fndesc', 'env']"
    assert changed["levels"] == [3] and changed["specialisations"] == 1


@pytest.mark.parametrize("change", ["missing attribute", "other parameters", "no library class"])
def test_a_difference_in_numbas_internals_is_detected_and_leaves_the_compile_to_numba(monkeypatch, change):
    """internals_mismatch names the difference; engine_compile then changes nothing (numba's optimisation level, no library class of ours)."""
    from numba.core.codegen import JITCodeLibrary

    context = cpu_target.target_context
    if change == "missing attribute":
        monkeypatch.delattr(compiling.FunctionDescriptor, "lookup_module")
        expected = "numba has no lookup_module"
    elif change == "other parameters":
        monkeypatch.setattr(JITCodeLibrary, "add_linking_library", lambda self, library, extra=None: None)
        expected = "JITCodeLibrary.add_linking_library takes ['self', 'library', 'extra'], expected ['self', 'library']"
    else:
        monkeypatch.setattr(type(context.codegen()), "_library_class", object)
        expected = "numba's code libraries are <class 'object'>, not JITCodeLibrary"
    compiling.internals_mismatch.cache_clear()
    try:
        assert compiling.internals_mismatch() == expected and compiling.numba_default_requested()
        default = numba.config.OPT
        with compiling.engine_compile():
            assert numba.config.OPT is default and "_library_class" not in vars(context.codegen())
    finally:
        monkeypatch.undo()
        compiling.internals_mismatch.cache_clear()
    assert compiling.internals_mismatch() is None


def test_optimisation_level_is_set_inside_the_block_only():
    """numba's optimisation level (its own type kept) inside the block, restored after it, also when the block raises."""
    default = numba.config.OPT
    with pytest.raises(RuntimeError), compiling.optimisation_level(1):
        assert numba.config.OPT == 1 and type(numba.config.OPT) is type(default)
        raise RuntimeError
    assert numba.config.OPT is default


def test_wrapperless_helpers_get_no_machine_code_inside_the_block():
    """Inside engine_compile a helper without a Python wrapper is linked into its caller unfinalised; numba's own behaviour after the block."""
    context = cpu_target.target_context
    codegen = context.codegen()

    def make():
        @numba.njit(**engine.INTERNAL)
        def scaled(values, factor):
            total = 0.0
            for value in values:
                total += factor * value
            return total

        @numba.njit(_nrt=False)
        def caller(values):
            return scaled(values, 2.0) + 1.0

        return scaled, caller

    values = np.arange(5.0)
    with pytest.raises(RuntimeError), compiling.engine_compile():
        scaled, caller = make()
        assert caller(values) == 21.0
        (helper,) = scaled.overloads.values()
        assert helper.library.linked_only and not helper.library._finalized  # no machine code of its own
        assert caller.overloads[caller.signatures[0]].library._finalized
        raise RuntimeError
    assert "_library_class" not in vars(codegen) and "get_executable" not in vars(context)  # numba's own again
    scaled, caller = make()
    assert caller(values) == 21.0
    (helper,) = scaled.overloads.values()
    assert helper.library._finalized and not getattr(helper.library, "linked_only", False)
