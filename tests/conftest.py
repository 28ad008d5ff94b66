"""Fixtures shared by several test modules."""

import pandas as pd
import pytest

from pidcore.model import SdcModel, load_paper_table3


@pytest.fixture(scope="session")
def paper_table() -> pd.DataFrame:
    """The paper's Table 3 as bundled with pidcore."""
    return load_paper_table3()


@pytest.fixture(scope="session")
def paper_model(paper_table) -> SdcModel:
    """The pchip SDC model over the paper's Table 3 DEM values."""
    return SdcModel.from_table(paper_table)
