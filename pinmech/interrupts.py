"""Signals as exceptions while a command runs: SIGINT (Ctrl-C), SIGTERM and SIGHUP (the
terminal closed) raise `Interrupted`, a KeyboardInterrupt, so outputs are finished as
partial, servers stop, and the CLI prints one line and exits 128 + the signal's number.
Inside `SIGNALS.held()` a signal waits until the block is done (one row goes to every
output or to none).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

from pinmech.exceptions import Interrupted


class Signals:
    """SIGINT, SIGTERM and SIGHUP raised as `Interrupted` (a KeyboardInterrupt) while a
    command runs, so outputs are finished as partial and servers stop; inside `held()`
    the signal waits until the block is done."""

    def __init__(self) -> None:
        self.holding = False
        self.pending: int | None = None

    def _handle(self, signum: int, frame: object) -> None:
        if self.holding:
            self.pending = signum
            return
        raise Interrupted(signum)

    @contextlib.contextmanager
    def installed(self) -> Iterator[None]:
        """The handlers, for the duration of the block (main thread only: elsewhere, none)."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        names = [n for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)]
        saved = {n: signal.signal(getattr(signal, n), self._handle) for n in names}
        try:
            yield
        finally:
            for n, handler in saved.items():
                signal.signal(getattr(signal, n), handler)
            self.holding, self.pending = False, None

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        self.holding = True
        try:
            yield
        finally:
            self.holding = False
            pending, self.pending = self.pending, None
            if pending is not None:
                raise Interrupted(pending)


SIGNALS = Signals()
