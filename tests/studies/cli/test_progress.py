"""The terminal progress bar of the CLI (studies.cli.progress)."""
from __future__ import annotations

import io

from studies.cli.progress import TerminalProgress


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bars_are_drawn_on_a_terminal():
    out = _Tty()
    with TerminalProgress(stream=out, delay=0.0, mininterval=0.0) as p:
        for k in range(1, 5):
            p("projecting", k, 4)
        p("describing", 1, 1)
    text = out.getvalue()
    assert "projecting" in text and "100%" in text and "describing" in text


def test_nothing_is_drawn_when_not_a_terminal():
    out = io.StringIO()
    with TerminalProgress(stream=out, delay=0.0) as p:
        p("projecting", 1, 2)
    assert out.getvalue() == ""


def test_nothing_is_drawn_for_a_short_stage():
    out = _Tty()
    with TerminalProgress(stream=out, delay=60.0) as p:
        p("projecting", 1, 2)
        p("projecting", 2, 2)
    assert out.getvalue() == ""
