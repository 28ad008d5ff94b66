"""Multivariate pchip model of the specific damping capacity (paper Sect. 5.1 and 8).

The paper interpolates its Table 3 with a "pchip" interpolant in fill fraction, acceleration
amplitude and drive frequency. :class:`SdcModel` is that interpolant: a tensor-product of
one-dimensional piecewise cubic Hermite interpolants with Fritsch-Carlson (pchip) slopes,
evaluated axis after axis.

Why not ``scipy.interpolate.RegularGridInterpolator(method="pchip")``: it demands at least four
points per axis and Table 3 has three accelerations (1, 5, 10 g). The slopes and Hermite
coefficients still come from :class:`scipy.interpolate.PchipInterpolator`; only the per-point
selection of the interval is done here.

Properties that follow from the construction (and are tested):

* every grid point is reproduced (up to round-off);
* pchip is monotone on every interval, so each one-dimensional pass stays between its two
  neighbouring values and the result stays within the min/max of the 2^3 surrounding grid
  values: no overshoot, SDC stays in [0, 1] when the data do;
* along a grid line (two coordinates on grid values) the model is monotone wherever the data are.

The passes run in the fixed order frequency, fill, acceleration. pchip is nonlinear in the data,
so the order matters between grid lines (not on them); acceleration goes last so that, at a fixed
fill and frequency, the model is exactly one 1-D pchip in acceleration
(:meth:`SdcModel.acceleration_section`), which the harmonic-response solver uses.

Holes (a grid combination with no value, such as the paper's DEM value at 1000 Hz, 1 g, 90 %) are
filled before the grid is built, along the fill axis at the same frequency and acceleration:

* between two known fills: 1-D pchip through the known fills of that line;
* beyond the last (or before the first) known fill: the nearest known value is held constant.

Holding is chosen over pchip or linear extrapolation because extrapolating a cubic is unbounded
and the paper's hole sits where SDC is already 0.81 at 75 %: linear extrapolation from 50-75 %
gives 0.92, the ratio from the 500 Hz line gives 1.06 (beyond the physical limit 1). At every
other (frequency, acceleration) of Table 3 SDC rises from 75 % to 90 %, so holding the 75 %
value is a lower bound: it under-predicts damping there, the conservative side for a response
prediction. Filled points are flagged (:attr:`SdcModel.filled`, :meth:`SdcModel.filled_points`)
so reports can say so, and so is every value resting on one (:meth:`SdcModel.filled_dependence`:
a pchip slope at a grid point takes its neighbours, so a hole reaches beyond its own cell).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator

from ..errors import ParameterError, as_given, instance_of

#: Names of the model's axes, in the order of :attr:`SdcModel.axes` and of ``__call__``.
AXIS_NAMES: tuple[str, str, str] = ("fill_percent", "acceleration_g", "frequency_hz")
_AXIS_UNITS = {"fill_percent": "%", "acceleration_g": "g", "frequency_hz": "Hz"}
#: Relative slack on the grid bounds in :meth:`SdcModel.contains` (float noise from unit
#: conversions such as g -> m/s^2 -> g must not push a grid-edge point outside).
_BOUND_RTOL = 1e-9
#: Which way an SDC held at the model's edge errs (:attr:`HeldEdge.error`): the model's own
#: trend at the edge, continued beyond it, lies below the held value ("overstated"), above
#: it ("understated"), or the trend is flat there or the axes held disagree ("unknown").
HELD_ERRORS: tuple[str, str, str] = ("overstated", "understated", "unknown")
#: Step of the one-sided difference that takes the model's slope at an edge, relative to the
#: axis span: the model is a C1 piecewise cubic, so the step's own error (its curvature x
#: step) is 1e-8 of the SDC's change over the axis, and round-off (1e-16 / 1e-8) as small.
_EDGE_STEP = 1e-8
#: A slope whose change over the axis span is below this share of the model's largest SDC is
#: flat: pchip sets an edge slope to exactly 0 where the data turn, and the difference then
#: holds only the curvature x step (about 1e-8 of it).
_FLAT_SLOPE = 1e-5
#: Step of the one-sided differences of :meth:`SdcModel.filled_dependence`, relative to the
#: model's largest |SDC| (at least 1): on either side of the turns of pchip's slopes the value
#: is smooth in a grid value (Hermite cubics of harmonic-mean slopes), so a difference's error
#: is its curvature x step (~1e-6) and round-off 1e-16 / 1e-6 = 1e-10, below the 3 digits a
#: note prints.
_FILLED_STEP = 1e-6
#: Values a filled grid value is set to, evenly over the SDC's range [0, 1] (widened to the
#: data's) and once its width beyond either end, besides +-:data:`_FILLED_STEP` about it, to
#: tell whether a value moves with it at all (:meth:`SdcModel.filled_dependence`): a value
#: still for all of them is taken not to rest on it (Table 3 has values that move only for a
#: hole above 1.06; a dependence only within a 3/127 gap between them would be missed).
_FILLED_PROBES = 128


@dataclass(frozen=True)
class HeldEdge:
    """One axis on which a point lies beyond the model's grid, its SDC held at the edge.

    Attributes
    ----------
    axis : str
        One of :data:`AXIS_NAMES`.
    below : bool
        The point lies below the axis's first value (else above its last).
    edge : float
        The edge value held, in the axis's unit (%, g or Hz).
    slope : float
        The model's slope there, d SDC / d axis [1 / unit], taken inward at the held point.
    error : str
        Which way the held SDC errs if the model's trend at the edge continues beyond it
        (:data:`HELD_ERRORS`): below a rising edge (or above a falling one) the held value
        is "overstated"; "unknown" where the slope is flat.
    """

    axis: str
    below: bool
    edge: float
    slope: float
    error: str


def held_error(edges: Sequence[HeldEdge]) -> str:
    """The one direction of :func:`SdcModel.held_edges`' edges ("" for none; "unknown" where
    they disagree: the model does not tell which trend wins beyond two edges)."""
    errors = {e.error for e in edges}
    if not errors:
        return ""
    return errors.pop() if len(errors) == 1 else "unknown"


@dataclass(frozen=True)
class FilledDependence:
    """Which filled holes of a model's grid the SDC at some points rests on
    (:meth:`SdcModel.filled_dependence`).

    Attributes
    ----------
    points : pandas.DataFrame
        The filled grid points (:meth:`SdcModel.filled_points`), one row per filled value.
    depends : ndarray of bool
        Shape ``(*points' shape, len(points))``: the SDC at the point rests on that value.
    slope_rising, slope_falling : ndarray
        Same shape: d SDC / d (that filled value) [-] as the value rises above / falls below
        the one filled in (they differ where pchip's slope turns there, as at a value held
        equal to its neighbour); exactly 0 where ``depends`` is False.
    """

    points: pd.DataFrame
    depends: np.ndarray
    slope_rising: np.ndarray
    slope_falling: np.ndarray

    @property
    def any(self) -> np.ndarray:
        """Per point: the SDC rests on at least one filled value."""
        return self.depends.any(axis=-1)

    def summary(self) -> str:
        """One line: per filled value, how many of the points rest on it and how far their SDC
        moves per unit it rises and falls (ranges over those points); "" where none does,
        e.g. ``"2 point(s) rest on the filled grid value at 1000 Hz, 1 g, 90 % (0.8078, no
        data: filled along fill): their SDC moves +0.67 .. +0.941 per unit it rises, +0.67 ..
        +0.941 per unit it falls"``."""
        if self.points.empty or not self.depends.any():
            return ""
        depends = self.depends.reshape(-1, len(self.points))
        rising = self.slope_rising.reshape(depends.shape)
        falling = self.slope_falling.reshape(depends.shape)
        parts = []
        for h, row in enumerate(self.points.itertuples(index=False)):
            at = depends[:, h]
            if not at.any():
                continue
            up, down = (_span(slope[at, h]) for slope in (rising, falling))
            moves = f"{up} per unit of it" if up == down else \
                f"{up} per unit it rises, {down} per unit it falls"
            parts.append(f"{int(at.sum())} point(s) rest on {filled_label(row)}: their SDC "
                         f"moves {moves}")
        return "; ".join(parts)


def _span(values: np.ndarray) -> str:
    low, high = (format(float(v), "+.3g") for v in (np.min(values), np.max(values)))
    return low if low == high else f"{low} .. {high}"


def filled_label(row: tuple) -> str:
    """``"the filled grid value at 1000 Hz, 1 g, 90 % (0.8078, no data: filled along
    fill)"`` of a row of :meth:`SdcModel.filled_points`."""
    value = row[-1]
    return (f"the filled grid value at {row.frequency_hz:g} Hz, {row.acceleration_g:g} g, "
            f"{row.fill_percent:g} % ({value:.4g}, no data: filled along fill)")


def _pchip_select(x: np.ndarray, y: np.ndarray, xq: np.ndarray, *,
                  shared: bool = False) -> np.ndarray:
    """pchip along axis 0 of ``y``, each query point on its own column.

    Not shared: ``y`` has shape ``(len(x), ..., N)`` and column ``n`` (last axis) is evaluated at
    ``xq[n]`` only. Shared: ``y`` has shape ``(len(x), ...)`` and every query uses all of it.
    Returns shape ``(..., N)``. This is the per-point 1-D pass of the tensor-product interpolant
    without the N x N cost of evaluating every column at every query.
    """
    # c[k, i, ...] multiplies (xq - x[i])**(3 - k) on interval i
    c = PchipInterpolator(x, y, axis=0, extrapolate=False).c
    interval = np.clip(np.searchsorted(x, xq, side="right") - 1, 0, len(x) - 2)
    dx = xq - x[interval]
    if shared:
        coeffs = c[:, interval]  # (4, N, ...)
        coeffs = np.moveaxis(coeffs, 1, -1)  # (4, ..., N)
    else:
        coeffs = c[:, interval, ..., np.arange(xq.size)]  # advanced indices first: (N, 4, ...)
        coeffs = np.moveaxis(coeffs, 0, -1)  # (4, ..., N)
    out = coeffs[0]
    for k in range(1, coeffs.shape[0]):
        out = out * dx + coeffs[k]
    # the last node is the end of the last interval, its cubic evaluated at dx = its width:
    # its own value up to round-off of its neighbours', which made a grid point (90 %, 10 g,
    # 1000 Hz) move by 1e-16 with the hole at 1 g; taken as given, as every other node is
    # (dx = 0 leaves the constant coefficient, the value itself, exactly)
    at_end = xq == x[-1]
    if np.any(at_end):
        last = y[-1][..., np.newaxis] if shared else y[-1]
        out[..., at_end] = np.broadcast_to(last, out.shape)[..., at_end]
    return out


def _support_select(x: np.ndarray, depends: np.ndarray, xq: np.ndarray, *,
                    shared: bool = False) -> np.ndarray:
    """Which results of :func:`_pchip_select` (same arguments, ``depends`` a bool array of
    ``y``'s shape) depend on a node value flagged in ``depends``.

    pchip's cubic on interval k takes the values and slopes at its two ends; the slope at a
    node takes that node's two neighbours (at an end, its two inward ones), so interval k
    rests on the values k-1 .. k+2 and on no other. A query on a node is that node's value
    alone (:func:`_pchip_select` returns it as given). The rule is the interpolant's own
    stencil, so a value not flagged is bit for bit the same whatever the flagged values are.
    """
    n = len(x)
    stencil = np.stack([depends[max(k - 1, 0):min(k + 3, n)].any(axis=0)
                        for k in range(n - 1)])
    interval = np.clip(np.searchsorted(x, xq, side="right") - 1, 0, n - 2)
    node = np.where(xq == x[interval], interval, np.where(xq == x[-1], n - 1, -1))
    if shared:
        inside = np.moveaxis(stencil[interval], 0, -1)
        on_node = np.moveaxis(depends[node], 0, -1)
    else:
        cols = np.arange(xq.size)
        inside = np.moveaxis(stencil[interval, ..., cols], 0, -1)
        on_node = np.moveaxis(depends[node, ..., cols], 0, -1)
    return np.where(node >= 0, on_node, inside)


def _fill_holes_along_fill(values: np.ndarray, axes: tuple[np.ndarray, ...]
                           ) -> tuple[np.ndarray, np.ndarray]:
    """Fill NaNs along the fill axis (axis 0); see the module docstring for the rule.
    ``axes``: fill [%], acceleration [g], frequency [Hz], to name a line without a value."""
    fills = axes[0]
    values = values.copy()
    filled = np.isnan(values)
    for ia in range(values.shape[1]):
        for iz in range(values.shape[2]):
            line = values[:, ia, iz]
            known = ~np.isnan(line)
            if known.all():
                continue
            if not known.any():
                raise ParameterError(
                    f"SDC table: no value at any fill for {axes[1][ia]:g} g, {axes[2][iz]:g} Hz "
                    "(the grid is every combination of the frequencies, accelerations and "
                    "fills given); cannot fill the grid (every frequency/acceleration pair "
                    "needs at least one fill value)")
            xk, yk = fills[known], line[known]
            inner = (~known) & (fills > xk[0]) & (fills < xk[-1])
            if inner.any():
                line[inner] = PchipInterpolator(xk, yk)(fills[inner]) if xk.size > 1 else yk[0]
            line[(~known) & (fills < xk[0])] = yk[0]
            line[(~known) & (fills > xk[-1])] = yk[-1]
    return values, filled


@dataclass(frozen=True, eq=False)
class SdcModel:
    """Tensor-product pchip interpolant of SDC over fill, acceleration and frequency.

    Build it with :meth:`from_table`. Inputs are in the units of the paper's table (fill in %,
    acceleration amplitude in g, frequency in Hz); the output is SDC [-].

    Attributes
    ----------
    axes : tuple of ndarray
        Grid of fill [%], acceleration [g], frequency [Hz], each strictly increasing.
    values : ndarray
        Grid values, shape ``(n_fill, n_acceleration, n_frequency)``, holes filled.
    filled : ndarray of bool
        Same shape; True where the value was filled rather than given.
    value_name : str
        Column the values came from (``"sdc_dem"``, ``"sdc"``...).
    log_frequency : bool
        Interpolate in log10(frequency) instead of frequency.
    source : str
        Where the data came from (for provenance in reports).
    """

    axes: tuple[np.ndarray, np.ndarray, np.ndarray]
    values: np.ndarray
    filled: np.ndarray
    value_name: str = "sdc"
    log_frequency: bool = False
    source: str = ""
    _freq_nodes: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        for name, ax in zip(AXIS_NAMES, self.axes, strict=True):
            if ax.ndim != 1 or ax.size < 2 or not np.all(np.diff(ax) > 0):
                raise ParameterError(f"SdcModel: axis {name} needs at least 2 strictly "
                                     f"increasing values, got {ax.tolist()}")
        shape = tuple(ax.size for ax in self.axes)
        if self.values.shape != shape or self.filled.shape != shape:
            raise ParameterError(f"SdcModel: values shape {self.values.shape} does not match "
                                 f"the axes {shape}")
        if not np.all(np.isfinite(self.values)):
            raise ParameterError("SdcModel: values must be finite after hole filling")
        if self.log_frequency and self.axes[2][0] <= 0:
            raise ParameterError("SdcModel: log_frequency needs positive frequencies")
        nodes = np.log10(self.axes[2]) if self.log_frequency else self.axes[2]
        object.__setattr__(self, "_freq_nodes", nodes)
        for arr in (*self.axes, self.values, self.filled, nodes):
            arr.setflags(write=False)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_table(cls, table: pd.DataFrame, *, value: str = "sdc_dem",
                   log_frequency: bool = False, source: str = "") -> SdcModel:
        """Build the model from a long table of SDC values.

        Parameters
        ----------
        table : pandas.DataFrame
            Columns ``fill_percent`` [%], ``acceleration_g`` [g], ``frequency_hz`` [Hz] and the
            value column. Rows with a NaN value are ignored; duplicate grid points (repeated DEM
            runs) are averaged. Missing grid combinations are holes, filled along the fill axis
            (module docstring) and flagged.
        value : str
            Name of the value column (``"sdc_dem"`` for Table 3, ``"sdc"`` for store runs).
        log_frequency : bool
            Interpolate in log10(frequency) (grid points unchanged, interior values differ).
        source : str
            Free text kept for provenance.

        Examples
        --------
        >>> from pidcore.model import load_paper_table3
        >>> m = SdcModel.from_table(load_paper_table3())
        >>> float(m(50, 5, 100))
        0.1891
        """
        needed = [*AXIS_NAMES, value]
        missing = [c for c in needed if c not in table.columns]
        if missing:
            raise ParameterError(f"SDC table: missing columns {missing}; expected {needed}")
        data = table.loc[:, needed].astype(float)
        data = data[np.isfinite(data[value])]
        if data.empty:
            raise ParameterError(f"SDC table: no finite values in column {value!r}")
        if not np.all(np.isfinite(data[list(AXIS_NAMES)].to_numpy())):
            raise ParameterError(f"SDC table: non-finite coordinates in {list(AXIS_NAMES)}")
        mean = data.groupby(list(AXIS_NAMES))[value].mean()
        # Axes come from every row of the table, including rows whose value is NaN, so that a
        # documented hole (Table 3) stays a grid point.
        coords = table.loc[:, list(AXIS_NAMES)].astype(float)
        coords = coords[np.all(np.isfinite(coords.to_numpy()), axis=1)]
        axes = tuple(np.unique(coords[name].to_numpy()) for name in AXIS_NAMES)
        for name, ax in zip(AXIS_NAMES, axes, strict=True):
            if ax.size < 2:
                # named by its source: `model damper --table store` of a store holding one
                # fill said only "SDC table", not which store's runs fell short
                values = ", ".join(f"{v:g}" for v in ax)
                raise ParameterError(f"{source or 'SDC table'}: column {name} has {ax.size} "
                                     f"distinct value(s) ({values}); the model needs at least "
                                     "2 per axis")
        full = pd.MultiIndex.from_product(axes, names=list(AXIS_NAMES))
        grid = mean.reindex(full).to_numpy().reshape(tuple(a.size for a in axes))
        values, filled = _fill_holes_along_fill(grid, axes)
        return cls(axes=axes, values=values, filled=filled, value_name=value,
                   log_frequency=log_frequency, source=source)

    # ------------------------------------------------------------------ queries
    @property
    def bounds(self) -> dict[str, tuple[float, float]]:
        """Range of each axis, ``{"fill_percent": (25.0, 90.0), ...}``."""
        return {n: (float(a[0]), float(a[-1])) for n, a in zip(AXIS_NAMES, self.axes, strict=True)}

    def contains(self, point: Sequence[float]) -> bool:
        """True if ``point = (fill_percent, acceleration_g, frequency_hz)`` lies in the grid box."""
        if len(point) != 3:
            raise ParameterError(f"SdcModel.contains: point must be (fill_percent, "
                                 f"acceleration_g, frequency_hz), got {point!r}")
        return bool(np.all(self._inside(*(np.asarray(p, dtype=float) for p in point))))

    def _inside(self, *coords: np.ndarray) -> np.ndarray:
        inside = np.ones(np.broadcast_shapes(*(c.shape for c in coords)), dtype=bool)
        for c, ax in zip(coords, self.axes, strict=True):
            slack = _BOUND_RTOL * max(abs(ax[0]), abs(ax[-1]))
            inside &= (c >= ax[0] - slack) & (c <= ax[-1] + slack)
        return inside

    def __call__(self, fill_percent: float | np.ndarray, acceleration_g: float | np.ndarray,
                 frequency_hz: float | np.ndarray) -> np.ndarray:
        """SDC [-] at the given points (broadcast); raises outside the grid (:meth:`evaluate`)."""
        return self.evaluate(fill_percent, acceleration_g, frequency_hz)

    def evaluate(self, fill_percent: float | np.ndarray, acceleration_g: float | np.ndarray,
                 frequency_hz: float | np.ndarray, *, clip_to_range: bool = False) -> np.ndarray:
        """SDC [-] at the given points.

        Parameters
        ----------
        fill_percent, acceleration_g, frequency_hz : array_like
            Coordinates in %, g and Hz; broadcast against each other.
        clip_to_range : bool
            False (default): any point outside the grid box raises :class:`ParameterError`
            (extrapolating a cubic is unsafe). True: each coordinate is clamped to its axis range,
            i.e. SDC is held at the nearest edge of the data.

        Returns
        -------
        numpy.ndarray
            SDC with the broadcast shape of the inputs.
        """
        coords, shape = self._query(fill_percent, acceleration_g, frequency_hz, clip_to_range)
        if coords[0].size == 0:
            return np.zeros(shape)
        return self._passes(self.values, coords, _pchip_select).reshape(shape)

    def _query(self, fill_percent: float | np.ndarray, acceleration_g: float | np.ndarray,
               frequency_hz: float | np.ndarray, clip_to_range: bool
               ) -> tuple[list[np.ndarray], tuple[int, ...]]:
        """The points as :meth:`evaluate` takes them: flat, checked, clamped onto the grid box
        (refused outside it unless ``clip_to_range``); and their broadcast shape."""
        coords = [np.asarray(c, dtype=float) for c in (fill_percent, acceleration_g, frequency_hz)]
        shape = np.broadcast_shapes(*(c.shape for c in coords))
        coords = [np.broadcast_to(c, shape).ravel() for c in coords]
        if not all(np.all(np.isfinite(c)) for c in coords):
            raise ParameterError("SdcModel: fill_percent, acceleration_g and frequency_hz must "
                                 "be finite")
        if not isinstance(clip_to_range, (bool, np.bool_)):  # "no" clipped, being truthy
            raise ParameterError(f"clip_to_range: expected True or False, got {clip_to_range!r}")
        if clip_to_range:
            # the edge holds for a load case beyond the grid, not for none: a fill of 0 or
            # 150 % was given the 25 or 90 % SDC, and a damper table made of it
            possible = (coords[0] > 0) & (coords[0] <= 100) & (coords[1] > 0) & (coords[2] > 0)
            if not np.all(possible):
                i = int(np.argmin(possible))
                bad = ", ".join(f"{n}={as_given(c[i])} {_AXIS_UNITS[n]}"
                                for n, c in zip(AXIS_NAMES, coords, strict=True))
                raise ParameterError(f"SdcModel: point ({bad}) is no load case (expected "
                                     "fill_percent in (0, 100] %, acceleration_g and "
                                     "frequency_hz > 0); clip_to_range=True holds the edge "
                                     "value of load cases beyond the grid only")
            coords = [np.clip(c, ax[0], ax[-1]) for c, ax in zip(coords, self.axes, strict=True)]
        else:
            inside = self._inside(*coords)
            if not np.all(inside):
                i = int(np.argmin(inside))
                bad = ", ".join(f"{n}={as_given(c[i])} {_AXIS_UNITS[n]}"
                                for n, c in zip(AXIS_NAMES, coords, strict=True))
                rng = ", ".join(f"{n} in [{as_given(lo)}, {as_given(hi)}]"
                                for n, (lo, hi) in self.bounds.items())
                raise ParameterError(f"SdcModel: point ({bad}) is outside the model range "
                                     f"({rng}); pass clip_to_range=True to hold edge values")
            coords = [np.clip(c, ax[0], ax[-1]) for c, ax in zip(coords, self.axes, strict=True)]
        return coords, shape

    def _passes(self, grid: np.ndarray, coords: list[np.ndarray], select) -> np.ndarray:
        """The three 1-D passes over ``grid`` (the values, or flags with :func:`_support_select`)
        at flat, clamped points; shape (N,)."""
        fill, acc, freq = coords
        fq = np.log10(freq) if self.log_frequency else freq
        # pass 1: frequency -> (n_fill, n_acc, N)
        v = select(self._freq_nodes, np.moveaxis(grid, 2, 0), fq, shared=True)
        # pass 2: fill -> (n_acc, N)
        v = select(self.axes[0], v, fill)
        # pass 3: acceleration -> (N,)
        return select(self.axes[1], v, acc)

    def filled_dependence(self, fill_percent: float | np.ndarray,
                          acceleration_g: float | np.ndarray, frequency_hz: float | np.ndarray,
                          *, clip_to_range: bool = False) -> FilledDependence:
        """Which filled grid values the SDC at each point rests on, and how much it moves with
        each.

        Points as :meth:`evaluate` takes them. pchip is local: the value at a point takes the
        grid values of a few neighbouring nodes per axis only (:func:`_support_select`), so
        most points do not depend on a filled hole at all, and some away from its grid cell
        do (a slope at a node takes both neighbours). Within those, a value rests on the hole
        where it changes at all, by any amount, when the hole is set to another value
        (:data:`_FILLED_PROBES` of them over [-1, 2], and the held value +- a step); where
        pchip turns (a slope set to 0, an end slope clamped) it may change for none. Where
        the test says no, the value is the same bit for bit for every hole value probed, and
        for any outside the stencil.

        Returns
        -------
        FilledDependence
            Per point and filled value (in the order of :meth:`filled_points`): whether the
            SDC rests on it, and d SDC / d (that value) as it rises and as it falls.
        """
        coords, shape = self._query(fill_percent, acceleration_g, frequency_hz, clip_to_range)
        holes = np.argwhere(self.filled)
        depends = np.zeros((coords[0].size, len(holes)), dtype=bool)
        slopes = np.zeros((2, *depends.shape))
        step = _FILLED_STEP * max(float(np.max(np.abs(self.values))), 1.0)
        low = min(0.0, float(np.min(self.values)))
        high = max(1.0, float(np.max(self.values)))
        low, high = low - (high - low), high + (high - low)
        for h, index in enumerate(map(tuple, holes)):
            flag = np.zeros(self.values.shape, dtype=bool)
            flag[index] = True
            # the stencil: outside it the value is bit for bit the same whatever the hole holds
            stencil = self._passes(flag, coords, _support_select)
            if not stencil.any():
                continue
            points = [c[stencil] for c in coords]

            def at(value: float, index: tuple = index, points: list = points) -> np.ndarray:
                grid = self.values.copy()
                grid[index] = value
                return self._passes(grid, points, _pchip_select)

            held = float(self.values[index])
            base = at(held)
            # inside it a turn of pchip's slopes (set to 0, or an end slope clamped) can leave
            # a value still for every hole value: 1 in 25 of random points of Table 3 never
            # moves. Moved: changed at all (no tolerance: a slope set to 0 is exactly 0)
            rising, falling = at(held + step), at(held - step)
            moved = (rising != base) | (falling != base)
            for value in np.linspace(low, high, _FILLED_PROBES):
                moved |= at(float(value)) != base
            depends[stencil, h] = moved
            slopes[0, stencil, h] = np.where(moved, (rising - base) / step, 0.0)
            slopes[1, stencil, h] = np.where(moved, (base - falling) / step, 0.0)
        full = (*shape, len(holes))
        return FilledDependence(points=self.filled_points(), depends=depends.reshape(full),
                                slope_rising=slopes[0].reshape(full),
                                slope_falling=slopes[1].reshape(full))

    def held_edges(self, fill_percent: float, acceleration_g: float, frequency_hz: float
                   ) -> tuple[HeldEdge, ...]:
        """The axes on which a point lies beyond the grid, each with the model's slope at its
        edge and the way holding the edge SDC errs there (:class:`HeldEdge`); empty inside.

        The slope is taken at the held point (the other coordinates clamped as
        :meth:`evaluate` with ``clip_to_range=True`` clamps them), one-sided into the grid.
        It is the model's own trend, not a bound: beyond the edge no data say how the SDC
        goes on.
        """
        point = [float(v) for v in (fill_percent, acceleration_g, frequency_hz)]
        if not all(np.isfinite(point)):
            raise ParameterError(f"SdcModel.held_edges: point {point} must be finite")
        held = [float(np.clip(v, ax[0], ax[-1])) for v, ax in zip(point, self.axes,
                                                                  strict=True)]
        scale = max(float(np.max(np.abs(self.values))), np.finfo(float).tiny)
        edges = []
        for k, (name, ax) in enumerate(zip(AXIS_NAMES, self.axes, strict=True)):
            slack = _BOUND_RTOL * max(abs(ax[0]), abs(ax[-1]))
            if ax[0] - slack <= point[k] <= ax[-1] + slack:
                continue
            below = bool(point[k] < ax[0])
            span = float(ax[-1] - ax[0])
            step = _EDGE_STEP * span
            inner = list(held)
            inner[k] = held[k] + (step if below else -step)
            at_edge, inside = (float(self.evaluate(*map(np.asarray, q))) for q in (held, inner))
            # + 0.0: a flat edge read -0 per Hz
            slope = (inside - at_edge) / step * (1.0 if below else -1.0) + 0.0
            if abs(slope) * span <= _FLAT_SLOPE * scale:
                error = "unknown"
            else:
                # the edge's own trend continued: lower below a rising edge, higher above it
                error = "overstated" if (slope > 0) == below else "understated"
            edges.append(HeldEdge(axis=name, below=below,
                                  edge=float(ax[0] if below else ax[-1]), slope=slope,
                                  error=error))
        return tuple(edges)

    def acceleration_section(self, fill_percent: float, frequency_hz: float) -> PchipInterpolator:
        """The model along acceleration at a fixed fill and frequency, as a 1-D pchip in g.

        Exactly equal to the model on that line (acceleration is the last pass). Raises
        :class:`ParameterError` if fill or frequency lies outside the grid.
        """
        if not self.contains((fill_percent, self.axes[1][0], frequency_hz)):
            raise ParameterError(f"SdcModel: fill_percent={as_given(fill_percent)} %, "
                                 f"frequency_hz={as_given(frequency_hz)} Hz outside the "
                                 f"model range {self.bounds}")
        f = np.clip(float(fill_percent), self.axes[0][0], self.axes[0][-1])
        z = np.clip(float(frequency_hz), self.axes[2][0], self.axes[2][-1])
        zq = np.log10(z) if self.log_frequency else z
        v = _pchip_select(self._freq_nodes, np.moveaxis(self.values, 2, 0), np.array([zq]),
                          shared=True)
        v = _pchip_select(self.axes[0], v, np.array([f]))[:, 0]
        return PchipInterpolator(self.axes[1], v, extrapolate=False)

    # ------------------------------------------------------------------ views
    def grid_table(self) -> pd.DataFrame:
        """The grid as a long table with a boolean ``filled`` column."""
        idx = pd.MultiIndex.from_product(self.axes, names=list(AXIS_NAMES))
        return pd.DataFrame({self.value_name: self.values.ravel(),
                             "filled": self.filled.ravel()}, index=idx).reset_index()

    def data_points(self) -> pd.DataFrame:
        """Grid points that carry data (not filled), as a long table."""
        t = self.grid_table()
        return t[~t["filled"]].drop(columns="filled").reset_index(drop=True)

    def filled_points(self) -> pd.DataFrame:
        """Grid points whose value was filled, as a long table (empty if none)."""
        t = self.grid_table()
        return t[t["filled"]].drop(columns="filled").reset_index(drop=True)


def complete_grid(table: pd.DataFrame, value: str = "sdc") -> tuple[pd.DataFrame, str]:
    """The rows of ``table`` (``frequency_hz``, ``acceleration_g``, ``value``) on the largest
    frequency x acceleration grid every pair of which has a finite value at some fill, and the
    values left out in words ("" when none is).

    A pchip model needs a value at every (frequency, acceleration) pair (holes along fill are
    filled). The value of either axis that lacks the largest share of its pairs is left out,
    one at a time (of equal shares, the one with the fewest runs): a frequency run at one
    acceleration only goes, the grid around it stays. The rows kept are every row at the
    values kept, those without a finite value too: a run that gave none is a hole of the grid,
    filled and flagged, as it is in a grid that needs nothing left out.
    """
    finite = np.isfinite(pd.to_numeric(table[value], errors="coerce"))
    rows = table[finite]
    left: dict[str, list[float]] = {"frequency_hz": [], "acceleration_g": []}
    while True:
        pairs = set(zip(rows["frequency_hz"], rows["acceleration_g"], strict=True))
        axes = {"frequency_hz": sorted(set(rows["frequency_hz"])),
                "acceleration_g": sorted(set(rows["acceleration_g"]))}
        worst = None
        for name, other in (("frequency_hz", "acceleration_g"),
                            ("acceleration_g", "frequency_hz")):
            for v in axes[name]:
                missing = sum((v, o) not in pairs if name == "frequency_hz"
                              else (o, v) not in pairs for o in axes[other])
                if missing:
                    rank = (missing / len(axes[other]), -int((rows[name] == v).sum()))
                    if worst is None or rank > worst[0]:
                        worst = (rank, name, v)
        if worst is None:
            break
        _, name, v = worst
        left[name].append(v)
        rows = rows[rows[name] != v]
    kept = table[~table["frequency_hz"].isin(left["frequency_hz"])
                 & ~table["acceleration_g"].isin(left["acceleration_g"])]
    words = [f"{', '.join(f'{v:g}' for v in sorted(values))} {unit} (not run at every "
             f"{other})" for values, unit, other in (
                 (left["frequency_hz"], "Hz", "acceleration"),
                 (left["acceleration_g"], "g", "frequency")) if values]
    return kept, "; ".join(words)


def complete_grid_model(table: pd.DataFrame, *, value: str = "sdc", log_frequency: bool = False,
                        source: str = "") -> tuple[SdcModel, pd.DataFrame, str]:
    """(model, rows it is built on, values left out in words: "" where none is) of ``table``
    over its complete frequency x acceleration grid (:func:`complete_grid`): the model of
    every row where they make one (:meth:`SdcModel.from_table`), else that of the complete
    grid, its ``source`` naming what was left out. The one rule of the report's model of
    stored DEM runs and of ``pidcore model damper/figures --table store``: one run off the
    grid (the app's DEM tab runs any case) refused the model of every other.

    Where no complete grid is left to model either, the refusal names ``source`` and the
    frequency x acceleration pairs without a value at any fill.
    """
    try:
        return (SdcModel.from_table(table, value=value, log_frequency=log_frequency,
                                    source=source), table, "")
    except ParameterError as exc:
        kept, left_out = complete_grid(table, value)
        if not left_out:
            raise
        first = exc
    named = f"{source}, the complete grid; left out: {left_out}"
    try:
        return (SdcModel.from_table(kept, value=value, log_frequency=log_frequency,
                                    source=named), kept, left_out)
    except ParameterError as exc:
        why = str(exc).removeprefix(f"{named}: ")
        finite = table[np.isfinite(pd.to_numeric(table[value], errors="coerce"))]
        pairs = set(zip(finite["frequency_hz"], finite["acceleration_g"], strict=True))
        missing = [f"{f:g} Hz, {a:g} g" for f in sorted(set(table["frequency_hz"]))
                   for a in sorted(set(table["acceleration_g"])) if (f, a) not in pairs]
        raise ParameterError(
            f"{source or 'SDC table'}: no value at any fill at {'; '.join(missing)} (a pchip "
            "model needs one at every frequency x acceleration pair), and no complete grid "
            f"is left without {left_out}: {why}") from first


#: Columns of stored DEM runs that define the simulated conditions besides the three axes.
#: Runs differing in any of them are not averaged into one model.
DEM_CONDITION_COLUMNS: tuple[str, ...] = (
    "material", "direction", "normal_damping_mode", "vibrated_mass_convention",
    "start_protocol", "start_packing", "tangential_model", "tangential_stiffness_model",
    "fill_reference",
)


def select_runs(runs: pd.DataFrame, *, where: Mapping[str, str] | None = None) -> pd.DataFrame:
    """Runs matching ``where`` (column -> value, compared as numbers where the stored value and
    the one given both read as one, else as text; a ``*sha256`` column also by its first 6 or
    more digits), checked to be homogeneous.

    Raises :class:`ParameterError` if a column of ``where`` is missing, nothing matches, or the
    remaining runs are of several specimens, differ in a :data:`DEM_CONDITION_COLUMNS`
    column or in their numerical settings (averaging acrylic with aluminium runs, or runs of
    two damping coefficients, would make a model of neither). ``settings_hash`` (6 hex digits,
    as the report's "DEM settings" column shows it) can be selected on like a column; runs of
    one settings hash differ only in their seed.
    """
    from ..compare.align import settings_hash

    # a Store given for its listing failed with AttributeError from inside
    instance_of("runs", runs, pd.DataFrame, hint="e.g. Store(path).list_dem_runs()")
    selected = runs
    if "parameters_json" in runs.columns:
        selected = runs = runs.assign(settings_hash=runs["parameters_json"].map(settings_hash))
    for column, wanted in (where or {}).items():
        if column not in runs.columns:
            raise ParameterError(f"DEM runs: no column {column!r} to select on; columns are "
                                 f"{sorted(runs.columns)}")
        text = selected[column].astype(str)
        # a hash may be given by its first digits, as `specimen check` and labels show it
        hashed = column.endswith("sha256") and len(str(wanted)) >= 6
        selected = selected[text.str.startswith(str(wanted)) if hashed
                            else _matches(text, str(wanted), column)]
    if selected.empty:
        raise ParameterError(f"DEM runs: none match {dict(where or {})}")
    _check_one_specimen(selected)  # first: a specimen fixes the material and more
    for column in DEM_CONDITION_COLUMNS:
        if column in selected.columns:
            distinct = sorted(selected[column].dropna().astype(str).unique())
            if len(distinct) > 1:
                raise ParameterError(
                    f"DEM runs differ in {column} ({', '.join(distinct)}); select one, e.g. "
                    f"where={{{column!r}: {distinct[0]!r}}} (CLI: --where {column}={distinct[0]})")
    if "settings_hash" in selected.columns:
        counts = selected.loc[selected["settings_hash"] != "", "settings_hash"].value_counts()
        if len(counts) > 1:
            raise ParameterError(
                f"DEM runs of {len(counts)} different numerical settings "
                f"({_settings_difference(selected, counts)}); select one, e.g. "
                f"where={{'settings_hash': {counts.index[0]!r}}} (CLI: --where "
                f"settings_hash={counts.index[0]})")
    return selected


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _matches(stored: pd.Series, wanted: str, column: str) -> pd.Series:
    """``stored == wanted`` of :func:`select_runs`: as numbers where both parse as one
    (``fill_percent=50`` matched none of the runs stored at 50.0 %, ``fixture_mass_kg=0`` none
    at 0.0), as text otherwise. Exact: a stored number is the one typed for its run, and
    float() of "50" and of "50.0" are the same. Hashes stay text: a hex digest of digits and
    one "e" reads as a number."""
    if column.endswith(("sha256", "hash")) or (number := _number(wanted)) is None:
        return stored == wanted
    numbers = stored.map(_number)
    return numbers.map(lambda v: v is not None and v == number).astype(bool) | (stored == wanted)


def _settings_difference(runs: pd.DataFrame, counts: pd.Series) -> str:
    """Each settings hash with its run count and the settings in which the hashes differ,
    e.g. ``"settings hash 108aa6 (2 runs): config_damping_coefficient eq3; eb7961 (1 run):
    config_damping_coefficient calibrated"``."""
    import json

    from ..compare.align import run_settings

    params = {digest: run_settings(runs.loc[runs["settings_hash"] == digest,
                                            "parameters_json"].iloc[0])
              for digest in counts.index}
    keys = sorted({k for p in params.values() for k in p})
    differ = [k for k in keys if len({json.dumps(p.get(k), default=str)
                                      for p in params.values()}) > 1]
    parts = []
    for digest, n in counts.items():
        shown = ", ".join(f"{k} {params[digest].get(k)}" for k in differ[:4])
        parts.append(f"{digest} ({n} run{'s' if n != 1 else ''})" + (f": {shown}" if shown
                                                                       else ""))
    return "settings hash " + "; ".join(parts)


def _check_one_specimen(runs: pd.DataFrame) -> None:
    """Refuse runs of several specimens: their SDCs describe different structures.

    The paper's coupon is one specimen (either table material; runs stored before specimens
    had no hash); two files of one name are two specimens.
    """
    from ..compare.specimens import run_specimen_labels

    labels = run_specimen_labels(runs)
    counts = labels.value_counts(sort=False)
    if len(counts) < 2:
        return
    listed = ", ".join(f"{label} ({n} run{'s' if n != 1 else ''})"
                       for label, n in counts.items())
    # a specimen of the user's (the paper's coupon has no hash in its label), by name unless
    # two files share it
    k = next(k for k, label in enumerate(labels) if label.endswith("]"))
    name = str(runs["specimen_name"].iloc[k])
    same_name = sum(label.rsplit(" [", 1)[0] == name for label in counts.index)
    column, value = ("specimen_name", name) if same_name == 1 else \
        ("specimen_sha256", str(runs["specimen_sha256"].iloc[k]))
    raise ParameterError(
        f"DEM runs are of {len(counts)} specimens: {listed}; select one, e.g. "
        f"where={{{column!r}: {value!r}}} (CLI: --where {column}={value})")
