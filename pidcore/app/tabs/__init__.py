"""One module per tab of the app, each with ``render(stores, ...)``; and what they share."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import streamlit as st

#: How the DEM and Calibrate forms keep their values over a page reload: each field is bound
#: to the page address (Streamlit's own binding; the widget's key names the parameter, a
#: default value is left out of the address). The address is the browser tab's own, so it
#: survives a reload, two tabs keep their own settings, and nothing is written to the store
#: (a store write per keystroke would change its stamp and re-read every listing). Text fields
#: come back as text and are read, or refused naming the field, at Run as typed text is.
ADDRESS_BINDING = "query-params"

#: Session-state key of the choices the page address held that a field does not offer.
_ADDRESS_REFUSALS = "_address_refusals"


def draw_polling(body: Callable[..., None], *args, polling: bool, every_s: float) -> None:
    """Draw ``body(*args, polling)`` as a fragment that reruns every ``every_s`` seconds while
    ``polling`` (a background job is queued or running), and only with the page otherwise.

    An idle page then costs the server and the browser nothing between clicks (a fragment that
    always polled kept both busy, ~0.16 core per open page). ``body`` receives ``polling`` and
    calls ``st.rerun(scope="app")`` once its job is over, so the page is drawn again without
    the timer.
    """
    st.fragment(run_every=every_s if polling else None)(body)(*args, polling)


#: A checkbox's value as the page address writes it.
FLAG_WORDS = {True: "true", False: "false"}


def refuse_address_flag(key: str, label: str, default: bool = False) -> None:
    """:func:`refuse_address_choices` of a checkbox: anything but true or false (Streamlit
    reads it as the default without a word)."""
    refuse_address_choices(key, label, list(FLAG_WORDS.values()), FLAG_WORDS[default])


def refuse_address_choices(key: str, label: str, options: Sequence[str],
                            default: Sequence[str] | str) -> None:
    """Say, in the one-line style of a refused typed value, where the page address holds a
    choice of the field ``key`` (``label``) that is not among ``options``: Streamlit drops it
    without a word and shows ``default`` (a changed vocabulary, or an edited address, would
    otherwise run something else than the address says). Call before the field is drawn; the
    error stays until the field is changed."""
    refusals = st.session_state.setdefault(_ADDRESS_REFUSALS, {})
    # an empty value is a cleared field (a multiple choice with nothing chosen), not a choice;
    # a checkbox's word is read in any case (Streamlit reads "TRUE" as true)
    stated = [v.lower() if list(options) == list(FLAG_WORDS.values()) else v
              for v in st.query_params.get_all(key) if v != ""]
    unknown = [v for v in stated if v not in options]
    if unknown and key not in st.session_state:  # a fresh session reading its address
        # a multiple choice keeps the address's known values (Streamlit's filter), else the
        # default
        fallback = default if isinstance(default, str) else (
            [v for v in stated if v in options] or list(default))
        shown = fallback if isinstance(fallback, str) else ", ".join(fallback) or "none"
        quoted = ", ".join(f"'{v}'" for v in unknown)
        offered = (f"one of {', '.join(options)}" if options
                   else "offered (there is nothing to choose yet)")
        refusals[key] = (f"{label}: {quoted} (from the page address) is not {offered}; "
                         f"{shown} is chosen instead", fallback)
    refused = refusals.get(key)
    if refused is None:
        return
    message, fallback = refused
    current = st.session_state.get(key, fallback)
    if isinstance(current, bool):  # a checkbox: its address words
        current = FLAG_WORDS[current]
    if current == fallback:
        st.error(message)
    else:  # the user chose: the address's value is no longer the question
        del refusals[key]


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
    choices = [PAPER_CHOICE, *map(str, files)]
    with c1:
        refuse_address_choices(f"{key}_specimen", "specimen", choices, PAPER_CHOICE)
    choice = c1.selectbox("specimen", choices, key=f"{key}_specimen",
                          disabled=upload is not None, bind=ADDRESS_BINDING)
    try:
        if upload is not None:
            return jobs.specimen_from_upload(upload.name, upload.getvalue()), None
        return (None if choice == PAPER_CHOICE else load_specimen(choice)), None
    except (PidcoreError, OSError, ValueError) as exc:
        name = upload.name if upload is not None else choice
        message = str(exc) if str(exc).startswith(name) else f"{name}: {exc}"
        st.error(message)
        return None, message
