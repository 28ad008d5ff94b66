"""One module per tab of the app, each with ``render(stores, ...)``; and what they share."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

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
        offered = (f"one of {', '.join(options)}" if options
                   else "offered (there is nothing to choose yet)")
        refusals[key] = (_address_refusal(label, unknown, offered, shown), fallback)
    _say_address_refusal(key)


def _address_refusal(label: str, unknown: Sequence[str], offered: str, shown: str) -> str:
    """The one line that refuses the page address's ``unknown`` values of a field."""
    quoted = ", ".join(f"'{v}'" for v in unknown)
    return f"{label}: {quoted} (from the page address) is not {offered}; {shown} is chosen instead"


def _say_address_refusal(key: str) -> None:
    """Show the field ``key``'s refusal of its address value while the field holds what was
    chosen instead; forget it once the user chose another."""
    refusals = st.session_state.setdefault(_ADDRESS_REFUSALS, {})
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


def address_choice(key: str, label: str, options: Mapping[str, str],
                   resolve: Callable[[str], str | None], *, offered: str) -> str:
    """A select box ``key`` (``label``) of ``options`` (each option's page-address name ->
    the label shown), kept in the page address under ``key`` by that name: Streamlit's own
    binding (:data:`ADDRESS_BINDING`) writes the label shown, and a label that changes with
    the data (a count of files) made an older address name nothing.

    ``resolve`` finds today's option of a name the address (or the last run) holds, None
    where nothing is that option any more; a fresh session's address naming nothing is
    refused in one line (as :func:`refuse_address_choices`: ``offered`` says what would have
    been taken) and the first option shown. Returns the chosen option's name."""
    names = list(options)
    fresh = key not in st.session_state
    stated = st.query_params.get(key) if fresh else st.session_state[key]
    current = None
    if stated:
        current = stated if stated in options else resolve(stated)
    if current is None:
        current = names[0]
        if stated and fresh:
            refusals = st.session_state.setdefault(_ADDRESS_REFUSALS, {})
            refusals[key] = (_address_refusal(label, [stated], offered, options[current]),
                             current)
    # set before the box is drawn: the box then opens on it (what ``resolve`` found may be
    # spelled otherwise than the address or the last run held it); only when it changes: a
    # value set this way is sent to the browser as a new value, which redraws the box
    if fresh or st.session_state[key] != current:
        st.session_state[key] = current
    _say_address_refusal(key)
    choice = st.selectbox(label, names, format_func=options.__getitem__, key=key)
    if st.query_params.get(key) != choice:
        st.query_params[key] = choice
    return choice


#: The choice of the paper's coupon in :func:`specimen_choice`.
PAPER_CHOICE = "paper coupon (default)"
#: The specimen list's label while an uploaded specimen file (or the page address's, refused)
#: takes its place.
SPECIMEN_REPLACED_LABEL = "specimen (not used: see the specimen file at the right)"


#: The page-address parameter of a form's uploaded specimen file: ``{key}_specimen_upload``
#: holds its sha256 (:mod:`pidcore.app.kept_specimens`), never its text.
SPECIMEN_UPLOAD_PARAMETER = "{key}_specimen_upload"
#: The forms whose specimen uploader the Analyse tab's specimen names may mean.
SPECIMEN_FORMS = ("dem", "calibration")


def _specimen_memory(key: str) -> str:
    return f"_{key}_specimen_upload"


def _forget_specimen_upload(key: str) -> None:
    # button callback: before the script, so this run draws the form without the file
    st.session_state[_specimen_memory(key)] = (None, False)


def specimen_upload(key: str, store_path, upload):
    """The form ``key``'s uploaded specimen file this run (:func:`pidcore.app.kept_specimens.
    specimen_upload`), its hash put in the page address (or taken out of it) so that a
    reload restores the file; a fresh session reads the address's hash."""
    from pidcore.app import kept_specimens

    parameter = SPECIMEN_UPLOAD_PARAMETER.format(key=key)
    memory = _specimen_memory(key)
    if memory not in st.session_state:  # a fresh session: what the address says
        st.session_state[memory] = (st.query_params.get(parameter) or None, False)
    sha256, seen = st.session_state[memory]
    state = kept_specimens.specimen_upload(
        kept_specimens.kept_specimens_folder(store_path),
        upload=None if upload is None else (upload.name, upload.getvalue()),
        sha256=sha256, upload_seen=seen)
    st.session_state[memory] = (state.sha256, state.upload_seen)
    if state.sha256:
        if st.query_params.get(parameter) != state.sha256:
            st.query_params[parameter] = state.sha256
    elif parameter in st.query_params:
        del st.query_params[parameter]
    return state


def uploaded_specimens(store_path) -> list[tuple[str, bytes]]:
    """The specimen files uploaded on the DEM and Calibrate forms (``(name, bytes)``), those
    restored from the page address after a reload included (each form says why one of them
    is refused; here it is left out)."""
    from pidcore.app import kept_specimens
    from pidcore.errors import ParameterError

    found = []
    for key in SPECIMEN_FORMS:
        upload = st.session_state.get(f"{key}_specimen_file")
        if upload is not None:
            found.append((upload.name, upload.getvalue()))
            continue
        sha256, seen = st.session_state.get(_specimen_memory(key), (
            st.query_params.get(SPECIMEN_UPLOAD_PARAMETER.format(key=key)) or None, False))
        if sha256 and not seen:
            try:
                kept = kept_specimens.restore_specimen(
                    kept_specimens.kept_specimens_folder(store_path), sha256)
            except ParameterError:
                continue
            found.append((kept.name, kept.data))
    return found


def specimen_choice(key: str, store_path):
    """(specimen, error): the specimen chosen on a page (None: the paper's coupon), a file of
    ``defaults.APP_SPECIMEN_FOLDERS`` or an uploaded TOML (parsed by
    :func:`pidcore.specimen.Specimen.from_text`, never executed; kept beside the store
    ``store_path`` and restored after a reload: :func:`specimen_upload`); ``error`` is why
    the chosen file is refused (None when it is not). Widget keys ``{key}_specimen`` and
    ``{key}_specimen_file``."""
    from pidcore import defaults
    from pidcore.app.uploads import app_words, specimen_files
    from pidcore.errors import PidcoreError
    from pidcore.specimen import load_specimen

    files = sorted(specimen_files(defaults.APP_SPECIMEN_FOLDERS))
    c1, c2 = st.columns(2)
    upload = c2.file_uploader("or a specimen file (TOML)", type=["toml"],
                              key=f"{key}_specimen_file")
    uploaded = specimen_upload(key, store_path, upload)
    if upload is None and (uploaded.kept is not None or uploaded.error is not None):
        # restored from the address (or refused there): the uploader is empty, so say which
        # file is in use, and let it go without uploading another
        if uploaded.note:
            c2.caption(uploaded.note)
        c2.button("forget this specimen file", key=f"{key}_specimen_forget",
                  on_click=_forget_specimen_upload, args=(key,),
                  help="choose from the list instead")
    elif uploaded.note:  # kept for no reload: the folder cannot be written
        c2.warning(uploaded.note)
    choices = [PAPER_CHOICE, *map(str, files)]
    with c1:
        refuse_address_choices(f"{key}_specimen", "specimen", choices, PAPER_CHOICE)
    replaced = uploaded.kept is not None or uploaded.error is not None
    # the greyed list read "specimen: paper coupon (default)" beside the note that an uploaded
    # file is the one used; its choice is kept (bound to the address) for when the file is
    # forgotten, so only its label says so (a user key keeps the widget's identity over it)
    choice = c1.selectbox(SPECIMEN_REPLACED_LABEL if replaced else "specimen", choices,
                          key=f"{key}_specimen", disabled=replaced, bind=ADDRESS_BINDING)
    if uploaded.error is not None:
        st.error(uploaded.error)
        return None, uploaded.error
    if uploaded.kept is not None:
        return uploaded.kept.specimen, None
    try:
        return (None if choice == PAPER_CHOICE else load_specimen(choice)), None
    except (PidcoreError, OSError, ValueError) as exc:
        # a calibrated specimen file's refusal names the call that writes its folder
        message = app_words(str(exc) if str(exc).startswith(choice) else f"{choice}: {exc}",
                            names=[choice])
        st.error(message)
        return None, message
