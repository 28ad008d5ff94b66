"""Report files built outside Streamlit's script runs (the Report page's *Build report files*).

Writing the report (tables, figures, HTML, LaTeX and a PDF) takes seconds of CPU: inside the
script run the page was blocked meanwhile, and a click on any widget stopped the run, and the
build with it. Here the build runs in a thread of its own; the page only starts it and shows
its state (a :class:`ReportBuild` kept in the browser session), as the DEM and Calibrate pages
do with theirs.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field

from ..constants import BackgroundState


@dataclass
class ReportBuild:
    """One build of the report files (mutated by its thread only, read by the page).

    Attributes
    ----------
    of : hashable
        What the files are of (the store's state and the page's choices): files of another
        state are not offered.
    state : str
        One of :data:`pidcore.constants.BACKGROUND_STATES`.
    files : dict
        The built files by format, ``{format: (file name, bytes, MIME type)}`` once done.
    message : str
        Why it failed ("" otherwise).
    """

    of: Hashable
    state: BackgroundState = "running"
    started: float = field(default_factory=time.time)
    finished: float | None = None
    files: dict = field(default_factory=dict)
    message: str = ""

    def elapsed_s(self) -> float:
        """Seconds since the start (to the end once finished)."""
        return (self.finished or time.time()) - self.started


def start_report_build(of: Hashable, build: Callable[[], dict],
                       current: ReportBuild | None = None) -> ReportBuild:
    """Run ``build()`` (returning the files by format) in a background thread; returns its
    :class:`ReportBuild` at once. ``current``: the session's build so far: while it is still
    running for the same ``of`` it is returned as is (a second click builds nothing twice).

    A :class:`pidcore.errors.PidcoreError` of the build is its one line; anything else keeps
    its class name (``KeyError: 'x'`` says nothing without it).
    """
    if current is not None and current.state == "running" and current.of == of:
        return current
    job = ReportBuild(of)

    def run() -> None:
        from ..errors import PidcoreError

        try:
            files, state, message = build(), "done", ""
        except PidcoreError as exc:
            files, state, message = {}, "failed", str(exc)
        except Exception as exc:  # noqa: BLE001 - shown on the page as the build's error
            files, state, message = {}, "failed", f"{type(exc).__name__}: {exc}"
        job.files, job.message, job.finished = files, message, time.time()
        job.state = state  # last: a reader that sees "done" finds the files

    threading.Thread(target=run, name="pidcore-report-build", daemon=True).start()
    return job
