"""Signals sent to a handler for the length of a block: the one mechanism the commands and the runner install theirs with."""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, Union

Handler = Union[Callable[[int, Any], Any], int, signal.Handlers]


@contextmanager
def handling(handler: Handler, signals: Sequence[int] = (signal.SIGINT,)) -> Iterator[None]:
    """Inside the block ``signals`` go to ``handler`` (``signal.SIG_IGN``: ignored); their handlers are restored after.

    Outside the main thread, where Python has no signal handlers, nothing changes.
    """
    try:
        previous = {sig: signal.signal(sig, handler) for sig in signals}
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


@contextmanager
def noting_ctrl_c() -> Iterator[list[int]]:
    """Inside the block, SIGINT raises KeyboardInterrupt as Python's own handler does, and is noted in the list yielded.

    Only where SIGINT has Python's own handler: ignored (a job started in the
    background) or handled otherwise, it stays so, and nothing is noted;
    nor outside the main thread (no signal handlers there). A KeyboardInterrupt
    raised in a finaliser is not printed as "Exception ignored" with its
    traceback: it is noted (the caller ends as interrupted).
    """
    noted: list[int] = []
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        yield noted
        return

    def handler(signum: int, frame: Any) -> None:
        noted.append(signum)
        signal.default_int_handler(signum, frame)

    printing_unraisable = sys.unraisablehook

    def unraisable(report: Any) -> None:
        if not (noted and report.exc_type is KeyboardInterrupt):
            printing_unraisable(report)

    sys.unraisablehook = unraisable
    try:
        with handling(handler):
            yield noted
    finally:
        sys.unraisablehook = printing_unraisable
