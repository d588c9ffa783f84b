"""The command groups' class: whole first sentences in the command lists, help (exit 0) when called without a command."""

from __future__ import annotations

import sys
from functools import partial
from typing import Any

import click

from stochpound._errors import StochpoundError
from stochpound._signals import noting_ctrl_c


class HelpGroup(click.Group):
    """A click group that lists each command with the whole first sentence of its help.

    click cuts the sentence at the terminal's width (``run     Run the missing
    cases of each EXPERIMENT_FILE into its store,...``); here it is wrapped
    instead. Called without a command, it prints its help and exits with 0
    (click's default is 2, an error).
    """

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        """Print the help and exit 0 if no argument is given."""
        if not args and self.no_args_is_help and not ctx.resilient_parsing:
            click.echo(ctx.get_help(), color=ctx.color)
            ctx.exit(0)
        return super().parse_args(ctx, args)

    def main(self, *args: Any, **kwargs: Any) -> Any:
        """click's ``main``; a Ctrl-C before the command starts or after it ends ends it as interrupted too (:meth:`invoke`).

        Around the command a Ctrl-C is only noted, not raised: click would
        print "Aborted!" and exit with status 1.
        """
        from stochpound.cli import INTERRUPTED, interrupted

        with noting_ctrl_c(raising=False) as ctrl_c:
            try:
                result = super().main(*args, **kwargs)
            except SystemExit as ending:
                if ctrl_c and ending.code != INTERRUPTED:
                    interrupted()
                raise
            if ctrl_c:
                interrupted()
            return result

    def invoke(self, ctx: click.Context) -> object:
        """Run the command; a Ctrl-C anywhere in it ends it with exit status 130 and no traceback (click's is 1, "Aborted!"),
        also one a library swallowed or turned into its own error (:func:`stochpound.cli.interruptible`).

        An error stochpound raises on purpose (:class:`~stochpound.StochpoundError`, whose message names the
        field or file) that a command did not catch ends it with that one line, never a traceback.
        """
        from stochpound.cli import interruptible

        try:
            return interruptible(partial(super().invoke, ctx))
        except StochpoundError as error:
            raise click.ClickException(str(error)) from None

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The ``Commands:`` section, each command's first sentence whole."""
        rows = []
        for name in self.list_commands(ctx):
            command = self.get_command(ctx, name)
            if command is not None and not command.hidden:
                rows.append((name, command.get_short_help_str(limit=sys.maxsize)))
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)
