"""One module per tab of the app, each with ``render(stores, ...)``; and what they share."""

from __future__ import annotations

from collections.abc import Callable

import streamlit as st


def draw_polling(body: Callable[..., None], *args, polling: bool, every_s: float) -> None:
    """Draw ``body(*args, polling)`` as a fragment that reruns every ``every_s`` seconds while
    ``polling`` (a background job is queued or running), and only with the page otherwise.

    An idle page then costs the server and the browser nothing between clicks (a fragment that
    always polled kept both busy, ~0.16 core per open page). ``body`` receives ``polling`` and
    calls ``st.rerun(scope="app")`` once its job is over, so the page is drawn again without
    the timer.
    """
    st.fragment(run_every=every_s if polling else None)(body)(*args, polling)
