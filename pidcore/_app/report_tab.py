"""Report tab: the Table 3-style table of the store and its downloads."""

from __future__ import annotations

import streamlit as st

from pidcore import app_support


def render(stores) -> None:
    from pidcore.errors import PidcoreError

    st.subheader("Report (Table 3 style)")
    try:
        from pidcore._app.ui import store_listing

        table = store_listing("report_table", stores.stamp(), stores)
    except PidcoreError as exc:
        st.error(f"cannot read the store: {exc}")
        return
    if table.empty:
        st.info(f"{stores.path} holds no saved analyses with a load case and no DEM runs yet: "
                "save analysed files (tab Analyse) or run DEM cases (tab DEM).")
        return
    st.dataframe(table, hide_index=True, key="report_table")
    for note in table.attrs.get("notes", []):
        st.caption(f"note: {note}")
    if st.button("Build report files (CSV, HTML, LaTeX, PDF)", key="build_report"):
        try:
            with st.spinner("Writing the report ..."):
                st.session_state["report_files"] = (stores.stamp(), app_support.report_files(
                    stores.path, stores.dem_reference))
        except PidcoreError as exc:
            st.error(f"no report: {exc}")
    stamp, files = st.session_state.get("report_files") or (None, None)
    if files and stamp == stores.stamp():  # files of an older store state are not offered
        cols = st.columns(len(files))
        for col, (fmt, (name, data, mime)) in zip(cols, files.items(), strict=True):
            col.download_button(f"{fmt.upper()}", data, file_name=name, mime=mime,
                                key=f"download_{fmt}")
