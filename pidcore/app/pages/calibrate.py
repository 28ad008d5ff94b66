"""Calibration page: fit the DEM to saved measurements (:mod:`pidcore.calibrate`)."""

from __future__ import annotations

import streamlit as st

from pidcore.app.calibration import calibration_api


def render(stores) -> None:
    """The page (a clear "not available" state while the calibration library is missing)."""
    st.subheader("Calibrate the DEM against measurements")
    api, reason = calibration_api()
    if api is None:
        st.info(f"Calibration is not available: {reason}.")
        return
    st.info("pidcore.calibrate is installed; run `pidcore calibrate --store "
            f"{stores.path}` for the posterior and the calibrated specimen (the page's own "
            "controls are not built yet).")
