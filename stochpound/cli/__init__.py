"""The ``stochpound`` command-line interface (one module per command group).

A Ctrl-C at any moment ends a command with exit status 130 and one line,
``interrupted``, on stderr, never a traceback: while the modules load (caught
here; ``import stochpound`` itself loads almost nothing), and while a command
runs (:class:`~stochpound.cli._group.HelpGroup`).
"""

import os
import sys
from typing import Any, NoReturn

INTERRUPTED = 130
"""Exit status of a command stopped by Ctrl-C (128 + SIGINT), as shells report it."""


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
    return main


def _load() -> Any:
    """:func:`_build`, ended as interrupted by a Ctrl-C meanwhile: also one a library or a finaliser swallowed, or one
    that an extension module's import turned into an error (``ImportError: initialization failed``)."""
    ctrl_c: list[int] = []
    try:
        from stochpound._signals import noting_ctrl_c

        with noting_ctrl_c() as ctrl_c:
            group = _build()
    except KeyboardInterrupt:
        interrupted(loading=True)
    except Exception:
        if ctrl_c:
            interrupted(loading=True)
        raise
    if ctrl_c:
        interrupted(loading=True)
    return group


main = _load()
"""The ``stochpound`` command (``python -m stochpound``, the ``stochpound`` script)."""
