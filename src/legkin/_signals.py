"""SIGTERM and SIGHUP as exceptions, so that ``finally`` clauses run (``legkin check`` kills its workers, ``legkin
view`` stops its server): Python's default action for both ends the process at once, clean-up skipped."""

from __future__ import annotations

import contextlib
import signal
import threading
from typing import Callable, Iterator


class SignalInterrupt(KeyboardInterrupt):
    """SIGTERM or SIGHUP delivered as a KeyboardInterrupt (``legkin view`` stops as on Ctrl-C), with its number."""

    def __init__(self, signum: int):
        super().__init__(f"signal {signum}")
        self.signum = signum


@contextlib.contextmanager
def signals_raise(make: Callable[[int], BaseException]) -> Iterator[None]:
    """Inside the block, SIGTERM and SIGHUP raise ``make(signum)`` in the main thread.

    Args:
        make: builds the exception from the signal's number.

    Returns:
        A context manager; outside the main thread (where Python delivers no signal) it changes nothing. The
        previous handlers are restored on exit.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise make(signum)

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
