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
    the bar prints nothing and starts no thread.

    Args:
        total: the number of steps.
        desc: the bar's label.
        enabled: draw the bar (False: a silent bar with the same methods).

    Yields:
        The tqdm bar (``update``, ``set_postfix_str``).
    """
    import threading

    from tqdm import tqdm

    bar = tqdm(
        total=total, desc=desc, unit="step", file=sys.stderr, disable=not enabled, leave=False,
        dynamic_ncols=True, bar_format="{desc}: {n_fmt}/{total_fmt} |{bar:20}| {elapsed}{postfix}",
    )
    stop = threading.Event()

    def tick() -> None:
        while not stop.wait(1.0):
            bar.refresh()

    ticker = threading.Thread(target=tick, daemon=True) if enabled else None
    if ticker is not None:
        ticker.start()
    try:
        yield bar
    finally:
        stop.set()
        if ticker is not None:
            ticker.join()
        bar.close()
