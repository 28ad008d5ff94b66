"""The force-displacement loop: one record that results hand over and drawing code reads.

A loop is one drive period of force against displacement, synthesised from the harmonic
phasors of a measurement or of a DEM run's virtual shaker record (the same way for both, so
their areas are comparable energies per cycle). Matplotlib figures
(:mod:`pidcore.report.figures_results`) and the app's charts read the same
:meth:`ForceDisplacementLoop.to_pandas` frame.

Public API
----------
ForceDisplacementLoop
    One period of force against displacement (``to_pandas()``, ``plot()``,
    ``energy_per_cycle_j``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from . import defaults
from .errors import ParameterError


@dataclass(frozen=True)
class ForceDisplacementLoop:
    """One drive period of force against displacement (SI units, see :attr:`UNITS`).

    Attributes
    ----------
    displacement_m : numpy.ndarray
        Displacement at equally spaced phases of one period, m (DC left out).
    force_n : numpy.ndarray
        Force at the same phases, N.
    frequency_hz : float
        Drive frequency, Hz.
    label : str
        What the loop is of (a file name, a DEM run); used as legend text.

    The curve is closed: the point after the last is the first (:meth:`closed` appends it).
    """

    displacement_m: np.ndarray
    force_n: np.ndarray
    frequency_hz: float
    label: str = ""
    #: Unit of each array and scalar.
    UNITS: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"phase_rad": "rad", "displacement_m": "m", "force_n": "N", "frequency_hz": "Hz",
         "energy_per_cycle_j": "J"})

    def __post_init__(self) -> None:
        x = np.asarray(self.displacement_m, dtype=np.float64)
        f = np.asarray(self.force_n, dtype=np.float64)
        if x.ndim != 1 or x.shape != f.shape or x.size < 3:
            raise ParameterError(f"loop {self.label!r}: displacement and force must be 1-D "
                                 f"arrays of equal length >= 3, got {x.shape} and {f.shape}")
        object.__setattr__(self, "displacement_m", x)
        object.__setattr__(self, "force_n", f)
        object.__setattr__(self, "frequency_hz", float(self.frequency_hz))

    @classmethod
    def from_phasors(cls, harmonics: np.ndarray, force_phasors_n: np.ndarray,
                     velocity_phasors_m_s: np.ndarray, frequency_hz: float, *,
                     n_points: int = defaults.LOOP_POINTS,
                     label: str = "") -> ForceDisplacementLoop:
        """Harmonic synthesis of one period from one-sided phasors (``x(t) = Re(X e^{jnwt})``).

        Displacement phasors are ``X_n = V_n / (j n w)``; the loop's area
        (:attr:`energy_per_cycle_j`) is then ``Re(1/2 sum F_n conj(V_n)) / f``, to rounding,
        while the highest harmonic is below ``n_points / 2``.
        """
        if not (np.isfinite(frequency_hz) and frequency_hz > 0):
            raise ParameterError(f"frequency_hz: {frequency_hz!r}, expected a positive number")
        if int(n_points) != n_points or n_points < 3:
            raise ParameterError(f"n_points: {n_points!r}, expected an integer >= 3")
        n = np.asarray(harmonics, dtype=np.float64)
        omega = 2 * np.pi * float(frequency_hz)
        phase = 2 * np.pi * np.arange(int(n_points)) / int(n_points)
        rot = np.exp(1j * np.outer(n, phase))
        disp = np.asarray(velocity_phasors_m_s, dtype=complex) / (1j * n * omega)
        return cls(np.real(disp @ rot), np.real(np.asarray(force_phasors_n, dtype=complex) @ rot),
                   float(frequency_hz), label)

    @property
    def n_points(self) -> int:
        """Points on the loop (without the closing repeat)."""
        return int(self.displacement_m.size)

    @property
    def phase_rad(self) -> np.ndarray:
        """Drive phase of each point, rad (``2 pi k / n_points``)."""
        return 2 * np.pi * np.arange(self.n_points) / self.n_points

    @property
    def energy_per_cycle_j(self) -> float:
        """``oint f dx`` over the period, J: > 0 when the loop dissipates energy.

        The points are equally spaced phases of one period, so ``dx/dphase`` is taken
        spectrally and ``f dx/dphase`` summed over the period: exact for a loop of harmonics
        below ``n_points / 2`` (every loop :meth:`from_phasors` makes). The polygon's area
        was short by ``1 - n/(2 pi) sin(2 pi/n)`` (1e-4 at 256 points), a fourth digit the
        app showed different from the energy per cycle ``pidcore analyze`` prints.
        """
        n = self.n_points
        wavenumber = np.fft.fftfreq(n, d=1.0 / n)
        if n % 2 == 0:
            wavenumber[n // 2] = 0.0  # the Nyquist term has no derivative a real x can carry
        dx_dphase = np.real(np.fft.ifft(1j * wavenumber * np.fft.fft(self.displacement_m)))
        return float(2 * np.pi / n * np.sum(self.force_n * dx_dphase))

    def closed(self) -> tuple[np.ndarray, np.ndarray]:
        """``(displacement_m, force_n)`` with the first point repeated at the end."""
        return (np.append(self.displacement_m, self.displacement_m[:1]),
                np.append(self.force_n, self.force_n[:1]))

    def to_pandas(self) -> pd.DataFrame:
        """One row per point: ``phase [rad]``, ``displacement [m]``, ``force [N]``.

        ``attrs`` hold ``label``, ``frequency_hz`` and ``energy_per_cycle_j``.
        """
        frame = pd.DataFrame({"phase [rad]": self.phase_rad,
                              "displacement [m]": self.displacement_m,
                              "force [N]": self.force_n})
        frame.attrs.update(label=self.label, frequency_hz=self.frequency_hz,
                           energy_per_cycle_j=self.energy_per_cycle_j)
        return frame

    def plot(self, ax: Any = None) -> Any:
        """The closed loop, displacement in µm, its energy per cycle in the legend text
        (:func:`pidcore.report.figures_results.plot_loop`); returns ``ax``."""
        from .report.figures_results import plot_loop  # lazy: drawing is optional

        return plot_loop(self, ax=ax)


__all__ = ["ForceDisplacementLoop"]
