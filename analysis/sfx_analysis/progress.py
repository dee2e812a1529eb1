"""The report's steps, for the progress bar of `sfx report`: when SFX_PROGRESS_FD names a
file descriptor, one line "DONE TOTAL LABEL" is written to it as each step starts (and
"TOTAL TOTAL done" at the end); sfx draws them with the progress display all its long commands
share (app/progress.h). Without SFX_PROGRESS_FD, nothing is written."""

from __future__ import annotations

import os
from typing import Optional, TextIO


class Steps:
    def __init__(self, total: int = 0):
        self.total = total
        self.done = 0
        self._out: Optional[TextIO] = None
        fd = os.environ.get("SFX_PROGRESS_FD", "")
        if fd.isdigit():
            try:
                self._out = os.fdopen(int(fd), "w", buffering=1, encoding="utf-8")
            except OSError:
                self._out = None

    def _write(self, label: str) -> None:
        if self._out is None:
            return
        try:
            self._out.write(f"{self.done} {max(self.total, self.done)} {label}\n")
        except OSError:  # the reader went away: the report goes on without a bar
            self._out = None

    def start(self, label: str) -> None:
        """The next step begins; the previous one is done."""
        self._write(label)
        self.done += 1

    def finish(self) -> None:
        self.total = self.done
        self._write("done")
        if self._out is not None:
            try:
                self._out.close()
            except OSError:
                pass
            self._out = None
