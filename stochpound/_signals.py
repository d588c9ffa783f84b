"""Signals sent to a handler for the length of a block: the one mechanism the commands and the runner install theirs with."""

from __future__ import annotations

import signal
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
