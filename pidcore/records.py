"""Domain records that flow from the readers to analysis, store and reports.

Readers produce :class:`Measurement` objects whose channels are already in SI units. Nothing
downstream of a reader knows about file formats.

Public API
----------
Measurement, Channel
    A file's channels (SI samples, rate, start, unit as written); ``Measurement.to_pandas()``
    and ``plot()``.
measurement_key, measurement_key_and_basis
    The key a store keeps a measurement under (its file's bytes, or its contents).
json_safe
    A value as JSON takes it (numpy scalars, NaN as null).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .constants import SI_UNITS
from .errors import ChannelError, StoreError, listed

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd


def json_safe(value: object) -> object:
    """``value`` as JSON takes it: numpy scalars as Python numbers and booleans, non-finite
    numbers as ``None`` (JSON has no NaN), through dicts, lists and tuples."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, np.generic):
        return json_safe(value.item())
    return value

@dataclass(frozen=True)
class Channel:
    """One evenly sampled time record in SI units.

    Attributes
    ----------
    name : str
        Channel name from the file (id line, column header, variable name).
    quantity : str
        Physical quantity (see :data:`pidcore.constants.Quantity`).
    data : numpy.ndarray
        Samples in SI units (float64, 1-D).
    sample_rate_hz : float
        Samples per second, Hz.
    source_unit : str
        Unit as written in the file, before conversion.
    start_time_s : float
        Time of the first sample, s.
    """

    name: str
    quantity: str
    data: np.ndarray
    sample_rate_hz: float
    source_unit: str = ""
    start_time_s: float = 0.0

    @property
    def unit(self) -> str:
        """SI unit of :attr:`data`."""
        return SI_UNITS.get(self.quantity, "1")

    @property
    def n_samples(self) -> int:
        return int(self.data.shape[0])

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.sample_rate_hz


@dataclass(frozen=True)
class Measurement:
    """All channels read from one source file.

    Attributes
    ----------
    source : str
        File name (or path) the channels came from.
    channels : tuple of Channel
    sha256 : str
        SHA-256 of the file's bytes; identifies the file in the store.
    file_format : str
        One of :data:`pidcore.constants.FileFormat`.
    metadata : mapping
        Free-form scalar metadata (dates, ids, nominal frequency hints, load-case labels).
    """

    source: str
    channels: tuple[Channel, ...]
    sha256: str = ""
    file_format: str = ""
    metadata: Mapping[str, str | float | int] = field(default_factory=dict)

    def channel(self, name: str) -> Channel:
        """The channel called ``name``; :class:`ChannelError` lists the names there are."""
        for ch in self.channels:
            if ch.name == name:
                return ch
        raise ChannelError(f"{self.source}: no channel named {name!r}; channels are "
                           f"{listed(c.name for c in self.channels)}")

    @property
    def channel_names(self) -> list[str]:
        """Names of the channels, in file order."""
        return [c.name for c in self.channels]

    def to_pandas(self) -> pd.DataFrame:
        """The channels side by side, one row per sample (SI units, each column naming its
        unit): ``time [s]`` (from the first channel's start) and ``<name> [<unit>]`` per
        channel; a shorter channel ends in NaN. ``attrs`` hold ``source`` and
        ``sample_rate_hz``.

        Raises
        ------
        ChannelError
            The channels have different sample rates or start times (no common time axis;
            :func:`pidcore.measure.analyze_measurement` aligns them for an analysis).
        """
        import pandas as pd  # here: records is imported by every reader, pandas is slow

        if not self.channels:
            raise ChannelError(f"{self.source}: no channels to tabulate")
        first = self.channels[0]
        for ch in self.channels[1:]:
            if not (math.isclose(ch.sample_rate_hz, first.sample_rate_hz, rel_tol=1e-9)
                    and math.isclose(ch.start_time_s, first.start_time_s, rel_tol=0.0,
                                     abs_tol=1e-3 / first.sample_rate_hz)):
                raise ChannelError(
                    f"{self.source}: channel {ch.name!r} ({ch.sample_rate_hz:g} Hz from "
                    f"{ch.start_time_s:g} s) and {first.name!r} ({first.sample_rate_hz:g} Hz "
                    f"from {first.start_time_s:g} s) share no time axis; tabulate them apart")
        n = max(ch.n_samples for ch in self.channels)
        columns: dict[str, np.ndarray] = {
            "time [s]": first.start_time_s + np.arange(n) / first.sample_rate_hz}
        for ch in self.channels:
            values = np.full(n, np.nan)
            values[:ch.n_samples] = ch.data
            columns[f"{ch.name} [{ch.unit}]"] = values
        frame = pd.DataFrame(columns)
        frame.attrs.update(source=self.source, sample_rate_hz=first.sample_rate_hz)
        return frame

    def plot(self, ax: Any = None) -> Any:
        """Each channel against time, one axes per channel
        (:func:`pidcore.report.figures_results.plot_measurement`); returns the axes."""
        from .report.figures_results import plot_measurement  # lazy: drawing is optional

        return plot_measurement(self.to_pandas(), ax=ax)


def measurement_key_and_basis(measurement: Measurement) -> tuple[str, str]:
    """``(key, basis)``: the file's SHA-256 when known, else a hash of the channel contents."""
    sha = measurement.sha256.strip().lower()
    if sha:
        if len(sha) < 16 or any(c not in "0123456789abcdef" for c in sha):
            raise StoreError(f"{measurement.source}: sha256 {measurement.sha256!r} is not a hex "
                             "digest of at least 16 digits")
        return sha[:16], "file_sha256"
    # Measurements built in memory (simulations, tests) have no file; hash what defines them so
    # that storing the same one twice still deduplicates.
    digest = hashlib.sha256()
    digest.update(measurement.source.encode("utf-8"))
    for ch in measurement.channels:
        header = f"\0{ch.name}\0{ch.quantity}\0{ch.sample_rate_hz!r}\0{ch.start_time_s!r}\0"
        digest.update(header.encode("utf-8"))
        digest.update(np.ascontiguousarray(ch.data, dtype=np.float64).tobytes())
    return digest.hexdigest()[:16], "content_sha256"


def measurement_key(measurement: Measurement) -> str:
    """The key a store keeps ``measurement`` under (:meth:`pidcore.store.Store.add_measurement`):
    byte-identical files (under any name) share it, so it is also what says two records hold
    the same data (here, below the store, so that the comparison layer can ask it too)."""
    return measurement_key_and_basis(measurement)[0]


__all__ = ["Channel", "Measurement", "json_safe", "measurement_key", "measurement_key_and_basis"]
