"""Progress of long calls (``progress=``): a tqdm bar when tqdm is
installed, else lines on stderr like those of the ``errp`` program in a
log. The compiled core calls the reporter with ``(stage, done, total)``
from the thread that waits for the work, at most every 50 ms and only
when something changed; ``total`` is 0 when it is not known beforehand
(the steps of a targeting search)."""

from __future__ import annotations

import contextlib
import sys
import time
from typing import Iterator, Optional

#: What one step of each stage is, for the bar's rate.
_UNITS = {"calibrating": "step", "episodes": "episode", "runs": "run"}


def enabled(progress) -> bool:
    """Whether to show progress: ``progress`` itself when a bool, else
    (``None``) whether stderr is a terminal."""
    if progress is None:
        stream = sys.stderr
        return bool(stream is not None and hasattr(stream, "isatty") and stream.isatty())
    if isinstance(progress, bool):
        return progress
    raise TypeError(
        f"progress must be True, False or None (on when stderr is a terminal), "
        f"not {type(progress).__name__} {progress!r}"
    )


class Reporter:
    """Shows ``(stage, done, total)`` as the core reports them; one bar or
    run of lines per stage."""

    def __init__(self, what: str):
        self.what = what
        self.stage: Optional[str] = None
        self.bar = None
        self.started = time.monotonic()
        self.tenth = -1
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
        self.tqdm = tqdm

    def __call__(self, stage: str, done: int, total: int) -> None:
        if stage != self.stage:
            # The work moved on: the stage before is done.
            if self.bar is not None and self.bar.total:
                self.bar.update(self.bar.total - self.bar.n)
            self.close()
            self.stage, self.tenth = stage, -1
            if self.tqdm is not None:
                self.bar = self.tqdm(
                    total=total or None,
                    desc=f"{self.what}: {stage}",
                    unit=_UNITS.get(stage, "step"),
                    file=sys.stderr,
                    dynamic_ncols=True,
                )
        if self.bar is not None:
            if total and self.bar.total != total:
                self.bar.total = total
            self.bar.update(done - self.bar.n)
            return
        self._line(stage, done, total)

    def _line(self, stage: str, done: int, total: int) -> None:
        secs = time.monotonic() - self.started
        if total:
            tenth = 10 * done // total
            if tenth == self.tenth:
                return
            self.tenth = tenth
            text = f"{self.what}: {stage} {done}/{total} [{secs:.1f} s]"
        else:
            text = f"{self.what}: {stage}, step {done} [{secs:.1f} s]"
        print(text, file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


@contextlib.contextmanager
def shown(progress, what: str) -> Iterator[Optional[Reporter]]:
    """The reporter to hand the core (``None`` when progress is off),
    closed when the call ends, however it ends."""
    if not enabled(progress):
        yield None
        return
    reporter = Reporter(what)
    try:
        yield reporter
    finally:
        reporter.close()
