"""pidcore.signal: complex power, loss factor and SDC of shaker records (paper Sect. 5.1).

Public API
----------
analyze_power
    Array-level analysis of force and velocity (or acceleration) samples.
analyze_channels
    The same on :class:`~pidcore.records.Channel` records, after validation.
PowerAnalysis
    Frozen result (phasors, complex power, loss factor, SDC, damping ratio, uncertainty).
baseline_sdc_taken_off
    The part of an analysis's SDC (fresh or stored) taken off as the empty coupon's damping.
estimate_drive_frequency
    Drive frequency of the motion channel (FFT peak + Gauss-Newton phase refinement).
synthesize_shaker_record, SyntheticRecord
    Synthetic records with an analytic answer, and the record they return.
"""

# _numba_cache first: it sets up Numba's cache (where it lives, saves that fail) at its import,
# and Numba chooses a function's cache place when the modules below decorate it
from .. import _numba_cache, interrupt  # noqa: F401
from .frequency import estimate_drive_frequency
from .power import PowerAnalysis, analyze_channels, analyze_power, baseline_sdc_taken_off
from .synthetic import SyntheticRecord, synthesize_shaker_record

interrupt.defer_while_compiling()

__all__ = ["PowerAnalysis", "SyntheticRecord", "analyze_channels", "analyze_power",
           "baseline_sdc_taken_off", "estimate_drive_frequency", "synthesize_shaker_record"]
