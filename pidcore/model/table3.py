"""The paper's Table 3 (SDC from DEM and experiment) as packaged data.

The CSV ``pidcore/data/paper_table3.csv`` is a verbatim copy of the shared transcription with a
leading comment block holding the transcription notes (the missing DEM value at 1000 Hz, 1 g,
90 %; the re-attributed 0.4756; experiment only at 50 % fill).
"""

from __future__ import annotations

from importlib import resources

import pandas as pd

from ..errors import InputFileError

#: Columns of :func:`load_paper_table3`, in order.
TABLE3_COLUMNS: tuple[str, ...] = (
    "frequency_hz", "acceleration_g", "fill_percent", "sdc_dem", "sdc_experimental",
)
_RESOURCE = "paper_table3.csv"


def load_paper_table3() -> pd.DataFrame:
    """Return the paper's Table 3 as a DataFrame.

    Returns
    -------
    pandas.DataFrame
        48 rows with columns ``frequency_hz`` [Hz], ``acceleration_g`` [g], ``fill_percent`` [%],
        ``sdc_dem`` [-] and ``sdc_experimental`` [-], all float; ``NaN`` where the paper prints
        nothing (one DEM value, 36 experimental values).

    Examples
    --------
    >>> t = load_paper_table3()
    >>> len(t), int(t["sdc_experimental"].notna().sum())
    (48, 12)
    """
    path = resources.files("pidcore.data").joinpath(_RESOURCE)
    with resources.as_file(path) as p:
        table = pd.read_csv(p, comment="#", skip_blank_lines=True)
    missing = [c for c in TABLE3_COLUMNS if c not in table.columns]
    if missing:
        raise InputFileError(f"{_RESOURCE}: missing columns {missing}; "
                             f"expected {list(TABLE3_COLUMNS)}")
    return table.loc[:, list(TABLE3_COLUMNS)].astype(float).reset_index(drop=True)
