"""Progress of long computations on the terminal: :class:`TerminalProgress` turns the
``progress(stage, done, total)`` callbacks of ``kin`` (which never prints) into tqdm bars on
stderr — shown only when stderr is a terminal and only for a stage that lasts over a second."""
from __future__ import annotations

import sys

from tqdm import tqdm


class TerminalProgress:
    """A ``progress(stage, done, total)`` callback drawing one bar per stage; use it as a context
    manager so the last bar is closed."""

    def __init__(self, stream=None, delay: float = 1.0, mininterval: float = 0.1):
        self.stream = stream if stream is not None else sys.stderr
        self.delay = delay
        self.mininterval = mininterval
        self.stage: str | None = None
        self.bar: tqdm | None = None

    def __call__(self, stage: str, done: float, total: float) -> None:
        if stage != self.stage:
            self.close()
            self.stage = stage
            self.bar = tqdm(total=total, desc=stage, delay=self.delay, mininterval=self.mininterval, file=self.stream,
                            disable=None, leave=False,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}")
        if self.bar is not None:
            self.bar.update(max(done - self.bar.n, 0))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        self.bar = None
        self.stage = None

    def __enter__(self) -> "TerminalProgress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
