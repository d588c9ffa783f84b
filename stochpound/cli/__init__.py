"""The ``stochpound`` command-line interface (one module per command group).

A Ctrl-C at any moment ends a command with exit status 130 and one line,
``interrupted``, on stderr, never a traceback: while the modules load (caught
here; ``import stochpound`` itself loads almost nothing), and while a command
runs (:class:`~stochpound.cli._group.HelpGroup`), both through
:func:`interruptible`.
"""

import os
import sys
from collections.abc import Callable
from typing import Any, NoReturn, TypeVar

INTERRUPTED = 130
"""Exit status of a command stopped by Ctrl-C (128 + SIGINT), as shells report it."""
T = TypeVar("T")


def interrupted(loading: bool = False) -> NoReturn:
    """End the command as stopped by Ctrl-C: one line on stderr, exit status :data:`INTERRUPTED`.

    ``loading``: the modules were still loading, nothing is written yet; the
    process ends at once (``os._exit``), because a Ctrl-C that landed in code
    an extension ran through the interpreter's own runner leaves a flag that
    turns any later exit into death by SIGINT (status -2), caught or not.
    """
    sys.stderr.write("interrupted\n")
    if loading:
        sys.stderr.flush()
        os._exit(INTERRUPTED)
    raise SystemExit(INTERRUPTED)


def interruptible(work: Callable[[], T], loading: bool = False) -> T:
    """``work()``; a Ctrl-C meanwhile ends the command as :func:`interrupted` (``loading`` passed on), whatever ``work`` did then.

    Also when a library turned the Ctrl-C's KeyboardInterrupt into an error
    of its own (an HDF5 or netCDF read cut short fails with its message; an
    extension module's import with ``ImportError: initialization failed``):
    an error raised after a Ctrl-C is the Ctrl-C. One raised inside a
    finaliser (``__del__``, a weakref callback), where Python would print it
    as "Exception ignored" and go on, is raised again in ``work`` at once
    (``stochpound._signals.noting_ctrl_c``). One a library caught never
    reaches ``work``: ``work`` then returns and the command ends as
    interrupted. A Ctrl-C noted by an enclosing block before ``work`` starts
    ends it before it starts.
    """
    from stochpound._signals import noting_ctrl_c

    with noting_ctrl_c() as ctrl_c:
        try:
            if ctrl_c:
                raise KeyboardInterrupt
            result = work()
        except KeyboardInterrupt:
            interrupted(loading)
        except Exception:
            if ctrl_c:
                interrupted(loading)
            raise
        if ctrl_c:
            interrupted(loading)
        return result


def _build() -> Any:
    """The ``stochpound`` command group with its commands (this loads click and the command modules)."""
    import click

    from stochpound import __version__
    from stochpound.cli._group import HelpGroup

    @click.group(cls=HelpGroup, context_settings={"help_option_names": ["-h", "--help"]})
    @click.version_option(__version__, prog_name="stochpound")
    def main() -> None:
        """Stochastic analysis of earthquake pounding between adjacent buildings."""

    from stochpound.cli._simulate import simulate
    main.add_command(simulate)
    from stochpound.cli._records import records
    main.add_command(records)
    from stochpound.cli._experiment import experiment
    main.add_command(experiment)
    from stochpound.cli._report import report
    main.add_command(report)
    from stochpound.cli._risk import risk
    main.add_command(risk)
    from stochpound.cli._site import site
    main.add_command(site)
    return main


def _load() -> Any:
    """:func:`_build`, ended as interrupted by a Ctrl-C meanwhile (:func:`interruptible`)."""
    try:
        return interruptible(_build, loading=True)
    except KeyboardInterrupt:  # before the Ctrl-C could be noted
        interrupted(loading=True)


main = _load()
"""The ``stochpound`` command (``python -m stochpound``, the ``stochpound`` script)."""
