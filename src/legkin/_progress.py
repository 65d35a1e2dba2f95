"""The progress bar of ``legkin check`` and ``legkin bench`` (tqdm, on stderr)."""

from __future__ import annotations

import contextlib
import sys
from typing import Any, Iterator

__all__ = ["progress_bar"]


@contextlib.contextmanager
def progress_bar(total: int, desc: str, enabled: bool = True) -> Iterator[Any]:
    """A tqdm bar on stderr (steps done, elapsed time, what runs now in its postfix), redrawn every second.

    A step can take several seconds: a thread redraws the bar so that its clock keeps running. Disabled,
    the bar prints nothing, starts no thread and is no tqdm: a tqdm bar creates tqdm's multiprocessing lock, a
    named semaphore that a killed process (``legkin check``'s workers after Ctrl-C or SIGTERM) leaves to the
    resource tracker, which then warns of a "leaked semaphore".

    Args:
        total: the number of steps.
        desc: the bar's label.
        enabled: draw the bar (False: a silent bar with the same methods).

    Yields:
        The tqdm bar (``update``, ``set_postfix_str``).
    """
    if not enabled:
        yield _SilentBar()
        return
    import threading

    from tqdm import tqdm

    bar = tqdm(
        total=total, desc=desc, unit="step", file=sys.stderr, leave=False,
        dynamic_ncols=True, bar_format="{desc}: {n_fmt}/{total_fmt} |{bar:20}| {elapsed}{postfix}",
    )
    stop = threading.Event()

    def tick() -> None:
        while not stop.wait(1.0):
            bar.refresh()

    ticker = threading.Thread(target=tick, daemon=True)
    ticker.start()
    try:
        yield bar
    finally:
        stop.set()
        ticker.join()
        bar.close()


class _SilentBar:
    """A disabled bar: tqdm's methods that legkin calls, doing nothing."""

    def update(self, n: int = 1) -> None:
        """Nothing (a step done)."""

    def set_postfix_str(self, s: str = "") -> None:
        """Nothing (what runs now)."""
