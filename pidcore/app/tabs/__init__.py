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


#: The choice of the paper's coupon in :func:`specimen_choice`.
PAPER_CHOICE = "paper coupon (default)"


def specimen_choice(key: str):
    """(specimen, error): the specimen chosen on a page (None: the paper's coupon), a file of
    ``defaults.APP_SPECIMEN_FOLDERS`` or an uploaded TOML (parsed by
    :func:`pidcore.specimen.Specimen.from_text`, never executed); ``error`` is why the chosen
    file is refused (None when it is not). Widget keys ``{key}_specimen`` and
    ``{key}_specimen_file``."""
    from pidcore import defaults
    from pidcore.app import jobs
    from pidcore.app.uploads import specimen_files
    from pidcore.errors import PidcoreError
    from pidcore.specimen import load_specimen

    files = sorted(specimen_files(defaults.APP_SPECIMEN_FOLDERS))
    c1, c2 = st.columns(2)
    upload = c2.file_uploader("or a specimen file (TOML)", type=["toml"],
                              key=f"{key}_specimen_file")
    choice = c1.selectbox("specimen", [PAPER_CHOICE, *map(str, files)], key=f"{key}_specimen",
                          disabled=upload is not None)
    try:
        if upload is not None:
            return jobs.specimen_from_upload(upload.name, upload.getvalue()), None
        return (None if choice == PAPER_CHOICE else load_specimen(choice)), None
    except (PidcoreError, OSError, ValueError) as exc:
        name = upload.name if upload is not None else choice
        message = str(exc) if str(exc).startswith(name) else f"{name}: {exc}"
        st.error(message)
        return None, message
