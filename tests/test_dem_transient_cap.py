"""The transient skipped before measuring is capped in cycles and in simulated time."""

import pytest

from pidcore.dem import DemConfig, LoadCase, simulate_load_case
from pidcore.errors import ParameterError


def test_cap_is_the_smaller_of_cycles_and_time():
    config = DemConfig(max_transient_cycles=100, max_transient_s=0.5)
    assert config.transient_cap_cycles(50.0) == 25     # 0.5 s at 50 Hz (explicit cap)
    assert config.transient_cap_cycles(1000.0) == 100  # the cycle cap binds at high frequency
    with pytest.raises(ParameterError, match="max_transient_s"):
        DemConfig(max_transient_s=-1.0)


def test_resting_bed_is_measured_after_the_time_cap_and_flagged():
    # a loose bed at 1 g keeps compacting (walls' work well below the dissipation), never
    # passes the balance test within 0.1 s -> measured after the cap, and flagged
    result = simulate_load_case(LoadCase(50.0, 1.0, 25.0),
                                DemConfig(cells=1, steady_cycles=5, max_transient_s=0.1,
                                          block_cycles=5, start_packing="loose"))
    assert not result.steady_detected
    assert result.steady_start_cycle == 5  # 0.1 s x 50 Hz, on a block boundary
    assert result.steady_cycles >= 5
