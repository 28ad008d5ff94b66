"""Analyse page: upload exports, per-file settings (load case, specimen, corrections, channels),
results with plausibility warnings, Save."""

from __future__ import annotations

import hashlib

import pandas as pd
import streamlit as st

from pidcore import defaults
from pidcore.app import state, uploads
from pidcore.app.vocabulary import page_terms
from pidcore.constants import DRIVE_DIRECTIONS
from pidcore.loadcase import parse_optional_rate
from pidcore.units import display_number


def _size(n: int) -> str:
    return (f"{n / 2**20:.1f} MB" if n >= 2**20 else f"{n / 1024:.0f} kB" if n >= 1024
            else f"{n} bytes")


def _settings_editor(measurements, tables: dict[str, pd.DataFrame], channel_names: list[str],
                     materials: tuple[str, ...], specimen_material: str | None = None):
    """The editable per-file settings table; returns the edited frame. ``specimen_material``:
    the particles of the specimen file uploaded with the exports, the material of a file that
    states none."""
    from pidcore.compare.case import PROPOSED_FILL_PERCENT, stated_case

    names = [u.name for u in measurements]
    sig = (tuple((u.name, state.upload_sha256(u)) for u in measurements), tuple(sorted(tables)),
           specimen_material)
    ss = st.session_state
    if ss.get("settings_sig") != sig:
        applied = ss.get("settings_tables_applied", set())
        earlier = [t for sha, t in tables.items() if sha in applied]
        new = [t for sha, t in tables.items() if sha not in applied]
        stated = [stated_case(n, materials=materials, specimen_material=specimen_material)
                  for n in names]
        before = ss.get("settings_specimen_material")
        previous = uploads.restate_default_material(
            ss.get("settings_current"),
            {n: stated_case(n, materials=materials, specimen_material=before).material
             for n in names},
            {n: s.material for n, s in zip(names, stated, strict=True)},
            {n: uploads.columns_given(list(tables.values()), n) for n in names})
        ss["settings_base"] = uploads.merge_settings(names, stated, previous, new,
                                                     earlier_tables=earlier)
        ss["settings_tables_applied"] = set(tables)
        ss["settings_sig"] = sig
        ss["settings_specimen_material"] = specimen_material
    channels = [uploads.AUTO_CHANNEL, uploads.NO_CHANNEL, *channel_names]
    key = "settings_" + hashlib.sha256(repr(sig).encode()).hexdigest()[:12]
    # the numbers are edited as text, checked by pidcore (uploads.TEXT_EDITED_NUMBERS): the
    # grid's number editor turned "1,5" into 15 and "1e-3" into -13 without a word
    edited = st.data_editor(
        uploads.editor_settings(ss["settings_base"]), key=key, hide_index=True,
        num_rows="fixed", width="stretch", disabled=["file"],
        column_config={
            "fill [%]": st.column_config.TextColumn(
                help=f"packing ratio, 0 < fill <= 100 (the paper's tests: "
                     f"{PROPOSED_FILL_PERCENT:g}); empty: not stated, the file is saved "
                     "without a load case"),
            "material": st.column_config.SelectboxColumn(
                options=list(materials), required=True,
                help="the table's materials, those of the specimen files and of the store's "
                     "DEM runs (own specimens)"),
            "specimen": st.column_config.TextColumn(
                help="a specimen file's name (or 'name [3e945a]' where two files share it), "
                     "as the DEM tab offers them: saved with the specimen's sha256; another name "
                     "is saved by name only"),
            "direction": st.column_config.SelectboxColumn(options=list(DRIVE_DIRECTIONS),
                                                          required=True),
            "vibrometer delay [µs]": st.column_config.TextColumn(
                help="output delay of the laser vibrometer, removed from velocity"),
            "mass below gauge [g]": st.column_config.TextColumn(
                help="mass between force gauge and coupon"),
            "baseline loss factor [-]": st.column_config.TextColumn(
                help="loss factor of the empty coupon, subtracted"),
            "structure mass [g]": st.column_config.TextColumn(
                help="mass of the empty structure above the gauge (coupon and fixture)"),
            **{f"{role} channel": st.column_config.SelectboxColumn(options=channels)
               for role in ("force", "velocity", "acceleration")},
            "inverted channels": st.column_config.TextColumn(
                help="channels whose sign is flipped, separated by ';' (e.g. Force)"),
            "time base unit": st.column_config.TextColumn(
                help=uploads.TIME_UNIT_COLUMN_HELP),
        })
    ss["settings_current"] = edited
    st.download_button("Download these settings as a CSV template", uploads.settings_template(
        edited), file_name="pidcore_file_settings.csv", mime="text/csv",
        key="settings_template")
    return edited


#: The "Options for every file" specimen choice that leaves each file's row to name one.
ROW_SPECIMEN_CHOICE = "(as the settings table names it)"


def _known_specimens(stores) -> list:
    """The specimen files the DEM tab offers: bundled, in the specimen folders, and those
    uploaded on the DEM or Calibrate tab (their widgets keep them for the session; after a
    reload, the files their page address names)."""
    from pidcore.app.tabs import uploaded_specimens

    return uploads.known_specimens(defaults.APP_SPECIMEN_FOLDERS,
                                   uploaded_specimens(stores.path))


def _card(upload, row, sample_rate_hz, time_unit, materials, given=(), known=(),
          every_file="", said_specimens=None, specimen=None):
    """Results of one file; returns an AnalysedFile or None. ``known``: the specimen files a
    typed specimen name may mean; ``every_file``: the specimen of a row naming none;
    ``said_specimens``: the specimen notes earlier cards showed (added to), each shown once;
    ``specimen``: the specimen file uploaded with the exports (``--specimen``)."""
    from pidcore.compare.case import load_case_of, stated_case
    from pidcore.compare.plausibility import implausible_findings, tested_sdc_bound
    from pidcore.errors import PidcoreError

    name = upload.name
    with st.container(border=True):
        st.markdown(f"**{name}** · {_size(upload.size)}")
        sha = state.upload_sha256(upload)
        try:  # the row's own time base unit reads the file (a batch of exports in s and ms)
            file_time_unit = uploads.file_time_unit(row, time_unit)
        except PidcoreError as exc:
            st.error(str(exc))
            return None
        found = state.parsed(sha, name, sample_rate_hz, file_time_unit, upload)
        if found.error is not None:  # no numbers: nothing assumed for them to say
            st.error(found.error)
            return None
        assumed = uploads.assumed_note(stated_case(
            name, materials=materials,
            specimen_material=specimen.particles.material if specimen else None), row, given)
        if assumed:  # a default the user has not confirmed: say so next to the numbers
            st.info(f"{assumed} (set it in the settings table)")
        try:
            options = uploads.options_of(row, sample_rate_hz=sample_rate_hz,
                                         time_unit=time_unit)
        except PidcoreError as exc:
            st.error(str(exc))
            return None
        outcome = state.analysed(sha, name, sample_rate_hz, file_time_unit,
                                 uploads.options_to_json(options), upload)
        st.caption(uploads.channels_caption(found.channels.names, outcome, options))
        if outcome.error is not None:
            st.error(outcome.error)
            return None
        record = uploads.row_time_unit_notes(outcome.record, row, time_unit)
        delay = uploads.delay_note(row, given, velocity_used="velocity" in record.channels_used)
        if delay:
            st.info(f"{delay} (set it in the settings table)")
        try:
            fill = uploads.fill_of(row)
        except PidcoreError as exc:  # names the file and the column itself
            st.error(f"{exc}; set it in the settings table")
            return None
        try:  # no fill stated: no load case, as `pidcore analyze` saves such a file
            case = None if fill is None else load_case_of(
                record, fill_percent=fill, material=str(row["material"]),
                direction=str(row["direction"]))
        except (PidcoreError, ValueError, TypeError) as exc:
            st.error(f"{name}: no valid load case ({exc}); set it in the settings table")
            return None
        material = case.material if case is not None else str(row["material"])
        named = uploads.file_specimen(str(row.get("specimen", "") or ""), material, known,
                                      given=specimen, every_file=every_file)
        tested = uploads.tested_specimen(named, (specimen, *known))
        try:  # before its numbers, as `pidcore analyze` refuses it before any
            uploads.check_specimen_fill(name, fill, material, named, tested)
        except PidcoreError as exc:
            st.error(f"{exc}; set it in the settings table")
            return None
        if case is None:
            st.info(uploads.no_fill_note(name))
        a = record.analysis
        m1, m2, m3, m4 = st.columns([1, 1, 1, 1.6])  # the SDC ± stderr needs the room
        m1.metric("frequency [Hz]", f"{a.frequency_hz:.3f}")
        m2.metric("acceleration [g]", display_number(a.acceleration_g))
        m3.metric("loss factor [-]", display_number(a.loss_factor))
        m4.metric("SDC ± stderr [-]", uploads.format_sdc(a.sdc, a.sdc_stderr))
        # as the CLI: a negative SDC within its noise is zero damping (a note), not a
        # warning to confirm
        # judged against the bound of the specimen tested (its particles' mass on its coupon
        # at this fill), as `pidcore analyze` judges it; 2 pi where its file is not at hand
        bound = tested_sdc_bound(fill_percent=fill, material=case.material if case else None,
                                 specimen_name=named.name, specimen_sha256=named.sha256,
                                 given=tested or specimen)
        warnings, zero_notes = implausible_findings(a, bound=bound)
        for w in warnings:
            # in the page's words: the library's keywords (specimen=FILE) showed as written
            st.warning(f"**Implausible:** {page_terms(w.message)}. *Likely cause:* "
                       f"{page_terms(w.likely_cause)}.", icon="⚠️")
        for note in (*record.notes, *zero_notes):
            st.caption(f"note: {note}")
        # a name alone meets another file's DEM runs of that name; said on the first card
        # naming it (three files of one unknown name showed the same note three times)
        if named.note and (said_specimens is None or named.note not in said_specimens):
            st.info(named.note)
            if said_specimens is not None:
                said_specimens.add(named.note)
        return uploads.AnalysedFile(record, case, options, named.name, warnings,
                                    specimen_sha256=named.sha256, sdc_bound=bound)


def render(stores) -> list:
    """The page; returns this session's analysed files (for the Compare page)."""
    from pidcore.errors import PidcoreError
    from pidcore.specimen import hashed_name

    st.subheader("Upload & analyse")
    st.caption(f"UFF58 (ASCII or binary), CSV/TXT, MAT and HDF5 exports; several at once. "
               f"Upload limit: {defaults.APP_MAX_UPLOAD_MB} MB per file. Files are parsed, "
               "never executed; nothing is stored until you press Save. A CSV table with a "
               "`file` column and settings columns (e.g. `fill_percent`, `velocity_delay_us`, "
               "as in the template below) is read as per-file settings, under any name and at "
               "any time. A specimen file (`.toml`, as `pidcore analyze --specimen FILE`) is "
               "the specimen of the files of its particles whose row names none: its name and "
               "sha256 are saved with them.")
    files = st.file_uploader("shaker-test exports, settings tables and a specimen file (TOML)",
                             accept_multiple_files=True, key="uploads",
                             max_upload_size=defaults.APP_MAX_UPLOAD_MB)
    specimen_uploads = [u for u in files or [] if uploads.is_specimen_file(u.name)]
    files = [u for u in files or [] if not uploads.is_specimen_file(u.name)]
    try:
        specimen = uploads.analysis_specimen([(u.name, u.getvalue()) for u in specimen_uploads])
    except PidcoreError as exc:
        # nothing analysed: saved without it, the files would be the paper's coupon's tests
        st.error(str(exc))
        st.info("Nothing is analysed until the specimen file is fixed or removed.")
        return []
    if specimen is not None:
        st.info(f"specimen {specimen.name} ({specimen.source}, {specimen.particles.material} "
                "particles): the material of the files that state none, and the specimen, "
                "saved with its sha256, of the files of its particles whose row names none")
    with st.expander("Options for every file", expanded=False):
        # text read by pidcore: the browser's number box made a typed "25,6" 256 Hz
        rate = st.text_input("sample rate if no time column [Hz]", "0", key="sample_rate",
                             help="only for CSV/TXT files without a time column; 0 = none")
        try:
            sample_rate_hz = parse_optional_rate(rate, name="sample rate if no time column "
                                                            "[Hz]")
        except PidcoreError as exc:
            st.error(f"{exc}; files are read without a sample rate")
            sample_rate_hz = None
        typed_unit = st.text_input(
            uploads.TIME_UNIT_FIELD, "", key="time_unit",
            help="s, ms, us: the unit of a UFF abscissa whose label pidcore does not read, of "
                 "a CSV time column or MATLAB time vector that states none (otherwise "
                 "seconds, noted); overrides a file's own (noted); blank = each file's own")
        try:
            time_unit = uploads.page_time_unit(typed_unit)
        except PidcoreError as exc:
            st.error(f"{exc}; files are read with the time units they state")
            time_unit = None
        known = _known_specimens(stores)
        if specimen is not None:
            known = [*known, specimen]
        every_file = st.selectbox(
            "specimen of every file", [ROW_SPECIMEN_CHOICE, *dict.fromkeys(
                hashed_name(s.name, s.hash) for s in known)], key="every_file_specimen",
            disabled=specimen is not None,
            help=f"off while the specimen file {specimen.source} is uploaded with the files"
            if specimen is not None else
            "a specimen file the DEM tab offers, saved with its sha256, for the files whose "
            "settings row names no specimen")
        every_file = "" if every_file == ROW_SPECIMEN_CHOICE else every_file
    measurements, tables, accepted = [], {}, []
    refused: list[uploads.RefusedTable] = []
    try:
        runs = state.store_listing("dem_runs", stores.stamp(), stores)
    except PidcoreError as exc:  # the uploads work without it: only the table's materials
        st.warning(f"DEM runs not read ({exc}): only the table's particle materials offered")
        runs = None
    materials = uploads.measurement_materials(
        [*(runs["material"] if "material" in getattr(runs, "columns", ()) else ()),
         *uploads.specimen_materials(defaults.APP_SPECIMEN_FOLDERS),
         *([specimen.particles.material] if specimen is not None else [])])
    for upload in files or []:
        try:
            uploads.check_upload_size(upload.name, upload.size)
        except PidcoreError as exc:
            st.error(str(exc))
            continue
        data = upload.getvalue()
        if uploads.is_settings_table(data):
            try:
                table = uploads.read_settings_table(upload.name, data, materials)
            except PidcoreError as exc:
                st.error(str(exc))
                # the files it names wait for it: analysed without it, they showed and saved
                # a result with settings the user did not give (e.g. no vibrometer delay)
                refused.append(uploads.refused_table(upload.name, data, str(exc)))
                continue
            accepted.append((upload, data, table))  # by name: two tables may be byte-equal
        else:
            measurements.append(upload)
    kept_tables = []
    for upload, data, table in accepted:
        try:  # rows matched as `pidcore analyze` matches them: an ambiguous one is refused
            uploads.check_table_rows(upload.name, table, [u.name for u in measurements])
        except PidcoreError as exc:
            st.error(str(exc))
            refused.append(uploads.refused_table(upload.name, data, str(exc)))
            continue
        tables[state.upload_sha256(upload)] = table
        kept_tables.append((upload.name, table))
    accepted = kept_tables
    for name, table in accepted:
        info, unmatched = uploads.table_match_note(name, table, [u.name for u in measurements])
        st.info(info)
        if unmatched:
            st.warning(unmatched)
    if not measurements:
        return []
    kept, notes = uploads.distinct_uploads([(u.name, state.upload_sha256(u))
                                            for u in measurements])
    measurements = [measurements[i] for i in kept]
    for note in [*notes, *uploads.identical_uploads([(u.name, state.upload_sha256(u))
                                                     for u in measurements])]:
        st.warning(note)
    channel_names = []
    for upload in measurements:
        found = state.parsed(state.upload_sha256(upload), upload.name, sample_rate_hz,
                             time_unit, upload)
        if found.channels is not None:
            channel_names += [n for n in found.channels.names if n not in channel_names]
    st.markdown("**Per-file settings** (edit the cells; each file is analysed with its own row)")
    settings = _settings_editor(measurements, tables, channel_names, materials,
                                specimen.particles.material if specimen is not None else None)
    analysed, said_specimens = [], set()
    for upload, (_, row) in zip(measurements, settings.iterrows(), strict=True):
        held = uploads.refusal_of(upload.name, refused)
        if held:  # no numbers, no "none given" notes: its settings were given, and refused
            with st.container(border=True):
                st.markdown(f"**{upload.name}** · {_size(upload.size)}")
                st.error(held)
            continue
        result = _card(upload, row, sample_rate_hz, time_unit, materials,
                       uploads.columns_given(list(tables.values()), upload.name), known,
                       every_file, said_specimens, specimen)
        if result is not None:
            analysed.append(result)
    if analysed:
        st.markdown("**Results**")
        st.dataframe(uploads.results_table(analysed), hide_index=True, key="results_table",
                     width="stretch", placeholder="")
    flagged = [f for f in analysed if f.warnings]
    confirm = False
    if flagged:
        confirm = st.checkbox(f"Save the {len(flagged)} implausible record(s) anyway (their "
                              "warnings are saved with them)", key="confirm_implausible")
    if refused:  # one save of what the user uploaded, not of the part its settings allow
        conflict = uploads.refused_tables_text(refused)
    else:
        conflict = uploads.load_case_conflict(analysed)
    if conflict:  # said before Save, which would refuse it
        st.error(f"cannot save: {conflict}")
    if st.button(f"Save {uploads.saved_count(analysed)} record(s) to the store",
                 disabled=not analysed or bool(conflict),
                 type="primary", key="save"):
        try:
            saved = uploads.save_records(stores.path, analysed, confirm_implausible=confirm)
        except PidcoreError as exc:
            st.error(f"not saved: {exc}")
        else:
            st.success(f"saved {len(saved.keys)} analysis record(s) to {stores.path}"
                       + (f" ({saved.breakdown})" if saved.breakdown else ""))
            for note in saved.notes:
                st.warning(note)
    return analysed
