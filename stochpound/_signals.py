"""Signals sent to a handler for the length of a block: the one mechanism the commands and the runner install theirs with."""

from __future__ import annotations

import _thread
import signal
import sys
import threading
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


class _NotingCtrlC:
    """SIGINT's handler inside :func:`noting_ctrl_c`: notes each Ctrl-C, and raises KeyboardInterrupt while ``raising``."""

    def __init__(self, raising: bool) -> None:
        self.noted: list[int] = []
        self.raising = raising

    def __call__(self, signum: int, frame: Any) -> None:
        self.noted.append(signum)
        if self.raising:
            signal.default_int_handler(signum, frame)


REPEAT_DELAY = 0.05
"""Seconds after which a Ctrl-C swallowed by a finaliser is raised again (:func:`noting_ctrl_c`): the finaliser has ended."""


def _interrupt_main_soon(handler: _NotingCtrlC) -> None:
    """``handler`` called in the main thread again :data:`REPEAT_DELAY` seconds from now (from a timer thread), if it is still
    SIGINT's handler and raising then (the block may have ended meanwhile: then nothing)."""

    def again() -> None:
        if handler.raising and signal.getsignal(signal.SIGINT) is handler:
            _thread.interrupt_main(signal.SIGINT)

    timer = threading.Timer(REPEAT_DELAY, again)
    timer.daemon = True
    timer.start()


@contextmanager
def noting_ctrl_c(raising: bool = True) -> Iterator[list[int]]:
    """Inside the block, SIGINT is noted in the list yielded and, if ``raising``, raises KeyboardInterrupt as Python's own handler does.

    Only where SIGINT has Python's own handler: ignored (a job started in the
    background) or handled otherwise, it stays so, and nothing is noted;
    nor outside the main thread (no signal handlers there). A block inside
    another shares its list and sets ``raising`` for its length (a command
    raises; the code around it, which would print its own message, only
    notes). A KeyboardInterrupt raised in a finaliser (``__del__``, a weakref
    callback), where Python would print "Exception ignored" with its
    traceback and go on, is not printed: while ``raising`` it is raised
    again in the code the finaliser interrupted (:data:`REPEAT_DELAY` later),
    so the work stops then and not when it would have ended.
    """
    current = signal.getsignal(signal.SIGINT)
    if isinstance(current, _NotingCtrlC):
        before, current.raising = current.raising, raising
        try:
            yield current.noted
        finally:
            current.raising = before
        return
    if current is not signal.default_int_handler:
        yield []
        return
    handler = _NotingCtrlC(raising)
    printing_unraisable = sys.unraisablehook

    def unraisable(report: Any) -> None:
        try:
            if not (handler.noted and report.exc_type is KeyboardInterrupt):
                printing_unraisable(report)
            elif handler.raising:
                _interrupt_main_soon(handler)
        except KeyboardInterrupt:  # a Ctrl-C meanwhile, here: raised again too
            _interrupt_main_soon(handler)

    sys.unraisablehook = unraisable
    try:
        with handling(handler):
            yield handler.noted
    finally:
        sys.unraisablehook = printing_unraisable
