"""Measured SDCs to calibrate against: a table (CSV) or the store's analysed measurements.

Table columns (one row per load case): ``frequency_hz``, ``acceleration_g``, ``fill_percent``,
``sdc`` and optionally ``sdc_stderr``, ``sdc_stderr_dof`` (its degrees of freedom: ``n_blocks - 1``
of a pidcore analysis, 7 by default; empty or absent: unknown, taken as normal),
``energy_per_cycle_j``, ``material``, ``specimen``.

A measured point carries its particle material and specimen label: measurements of acrylic and
steel particles (or of two specimens) at one load case are different points, never averaged;
:func:`pidcore.calibrate.calibrate.base_specimen` refuses points that are not of the calibrated
specimen.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .. import defaults
from ..compare.align import stored_stderr_dof
from ..compare.plausibility import (
    SDC_UPPER_BOUND,
    UNKNOWN_SPECIMEN_BOUND,
    SdcBound,
    stored_findings,
    stored_record_name,
)
from ..errors import InputFileError, ParameterError, as_given, real_number
from ..io import display_path, file_sha256
from ..loadcase import normalize_material

if TYPE_CHECKING:  # pragma: no cover
    from ..specimen import Specimen

REQUIRED_COLUMNS = ("frequency_hz", "acceleration_g", "fill_percent", "sdc")
OPTIONAL_COLUMNS = ("sdc_stderr", "sdc_stderr_dof", "energy_per_cycle_j", "material",
                    "specimen")
#: The drive direction of every DEM run a calibration makes (the paper's, :class:`LoadCase`'s
#: default): tests driven along another axis are not its load cases.
CALIBRATION_DIRECTION = "z"


def other_direction(value: object) -> str:
    """The direction a table cell or a record states where it is not the calibration's
    (``"x"``), else "" (``"z"``, empty or absent)."""
    text = _text_cell(value, CALIBRATION_DIRECTION).strip().lower()
    return "" if text == CALIBRATION_DIRECTION else text


#: Material of a measurement that states none (the paper's particles).
DEFAULT_MATERIAL = defaults.COMPARE_DEFAULT_MATERIAL


@dataclass(frozen=True)
class MeasuredPoint:
    """One measured load case: SDC (Eq. 11) and its standard error (0: not given), with the
    particle material and the specimen label ("": none named) it was measured on.
    ``sdc_stderr_dof``: the degrees of freedom of the standard error (a mean of 8 block
    estimates: 7), which make its 95 % band Student's t's; NaN where unknown (normal)."""

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    sdc: float
    sdc_stderr: float = 0.0
    material: str = DEFAULT_MATERIAL
    specimen: str = ""
    # how far the stderr can be trusted, not which point it is (and NaN, unknown, would
    # make a point unequal to its own copy)
    sdc_stderr_dof: float = field(default=math.nan, compare=False)
    # where the point was read (a table and its line, or a store), for messages naming it; not
    # part of the point's identity
    source: str = field(default="", compare=False)
    row: int | None = field(default=None, compare=False)
    # what the calibration was fitted to, so that it leads back to its tests
    # (:func:`measured_provenance`): the sha256 of a table's file, the keys of a store's
    # analyses pooled into the point
    source_sha256: str = field(default="", compare=False)
    analyses: tuple[str, ...] = field(default=(), compare=False)
    # the sha256 of the specimen file its tests recorded (a store's ``specimen_sha256``): two
    # files of one name are two specimens; "" where only the name is known (a table, an older
    # record), or the paper's coupon's (pidcore.specimen.deciding_sha256)
    specimen_sha256: str = ""
    # the SDC above which the point is refused (pidcore.compare.plausibility.sdc_bound of the
    # specimen it was measured on at its fill; 2 pi where that is not known): a property of
    # its specimen, not of the point
    sdc_bound: SdcBound = field(default=UNKNOWN_SPECIMEN_BOUND, compare=False)
    # a record without its file's hash whose name several files' tests carry
    # (pidcore.specimen.match_hashless_records): no file of that name may take it
    specimen_ambiguous: bool = field(default=False, compare=False)

    def __post_init__(self) -> None:
        # the rule of a table row, for a script's point too: a script's sdc=nan, a negative
        # standard error or a fill of 0 % was fitted (a NaN likelihood, a calibration saved)
        for name in ("frequency_hz", "acceleration_g", "fill_percent", "sdc", "sdc_stderr"):
            value = real_number(name, getattr(self, name))
            if not math.isfinite(value):
                raise ParameterError(f"{name} {value}: expected a finite number")
            object.__setattr__(self, name, value)
        for name in ("frequency_hz", "acceleration_g"):
            if getattr(self, name) <= 0:
                raise ParameterError(f"{name} {as_given(getattr(self, name))}: expected > 0")
        if not 0 < self.fill_percent <= 100:
            raise ParameterError(f"fill_percent {as_given(self.fill_percent)}: expected a fill "
                                 "in (0, 100] %")
        if self.sdc_stderr < 0:
            raise ParameterError(f"sdc_stderr {as_given(self.sdc_stderr)}: expected >= 0")
        dof = real_number("sdc_stderr_dof", self.sdc_stderr_dof)
        if not (math.isnan(dof) or (math.isfinite(dof) and dof > 0)):
            raise ParameterError(f"sdc_stderr_dof {as_given(dof)}: expected the degrees of "
                                 "freedom of sdc_stderr (> 0, e.g. n_blocks - 1), or NaN where "
                                 "unknown")
        object.__setattr__(self, "sdc_stderr_dof", dof)
        # a negative sdc is a draw of noise around a small one, which a synthetic study
        # (docs/calibration_audit) fits as it is; a measured table refuses one beyond its
        # noise (_check_not_negative_beyond_noise)
        bound = self.sdc_bound
        if self.sdc > bound.sdc:
            # a fit to it runs to the end and only says its posterior piles at a bound
            basis = ("2 pi, a loss factor of 1: more dissipated per radian than the coupon "
                     "stores" if bound.sdc <= SDC_UPPER_BOUND else bound.basis())
            raise ParameterError(
                f"sdc {as_given(self.sdc)} is above {bound.sdc:.4g} ({basis}; Table 3's "
                "largest is 0.88); expected the SDC as a ratio; was it %?")

    def label(self) -> str:
        """E.g. ``'500 Hz, 1 g, 50 %, steel, specimen steel_6mm_b'``: material and specimen
        named, since points differing only in them are different points."""
        from ..specimen import tested_label

        specimen = (f", specimen {tested_label(self.specimen, self.specimen_sha256)}"
                    if self.specimen else "")
        return (f"{self.frequency_hz:g} Hz, {self.acceleration_g:g} g, {self.fill_percent:g} %, "
                f"{self.material}{specimen}")


def _text_cell(value, default: str) -> str:
    """A table or store cell as text; empty, NaN or missing cells give ``default``."""
    if not isinstance(value, str) or not value.strip():
        return default
    return value.strip()


def read_measured_table(path: str | os.PathLike, *,
                        default_material: str = DEFAULT_MATERIAL,
                        specimen: Specimen | None = None) -> list[MeasuredPoint]:
    """Read a measured-SDC table; one-line errors for missing columns or bad values.

    A row without a ``material`` takes ``default_material`` (the calibrated specimen's when
    one is given, as a measurement compared with a specimen does; else the paper's acrylic).
    An SDC above its specimen's bound is refused (:func:`_point_sdc_bound`: ``specimen``,
    the file calibrated, or the paper's coupon), and one below 0 beyond its noise
    (:func:`_check_not_negative_beyond_noise`, the rule of :func:`measured_from_store`).
    """
    from ..tables import line_where, read_text_table_file

    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"{path}: no such file")
    # the reader of the sidecar tables: ',' / ';' / tab with a decimal comma, UTF-8 or
    # Latin-1, '#' lines are comments, rows named by their line in the file
    frame = read_text_table_file(path, numeric=(*REQUIRED_COLUMNS, *OPTIONAL_COLUMNS),
                                 example=",".join(REQUIRED_COLUMNS), row="load case")
    # of the bytes read, as a store keeps a measurement's file: the calibration names the
    # table it was fitted to by it (measured_provenance)
    sha256 = file_sha256(path)
    missing = [c for c in REQUIRED_COLUMNS if c not in frame.columns]
    if missing:
        raise InputFileError(f"{path}: missing column(s) {', '.join(missing)}; expected "
                             f"{', '.join(REQUIRED_COLUMNS)} (optional: "
                             f"{', '.join(OPTIONAL_COLUMNS)})")
    points = []
    for line, row in frame.iterrows():
        where = line_where(str(path), int(line))
        values = {}
        for column in REQUIRED_COLUMNS + ("sdc_stderr",):
            raw = row.get(column, "")
            if column == "sdc_stderr" and raw == "":
                raw = "0"
            if raw == "":
                raise InputFileError(f"{where}: {column} is empty")
            try:
                values[column] = float(raw)
            except (TypeError, ValueError):
                raise InputFileError(f"{where}: {column} {raw!r} is not a number") from None
        raw_dof = row.get("sdc_stderr_dof", "")
        raw_dof = "" if raw_dof is None or (isinstance(raw_dof, float) and math.isnan(raw_dof)) \
            else raw_dof
        try:  # empty or absent: unknown, the normal's quantile as before the column existed
            values["sdc_stderr_dof"] = math.nan if raw_dof == "" else float(raw_dof)
        except (TypeError, ValueError):
            raise InputFileError(f"{where}: sdc_stderr_dof {raw_dof!r} is not a number") from None
        other = other_direction(row.get("direction"))
        if other:
            # an x-drive test was fitted against z-drive DEM runs without a word
            raise InputFileError(f"{where}: direction {other!r}: the calibration's DEM runs "
                                 f"drive along {CALIBRATION_DIRECTION} (the paper's axis); "
                                 f"expected {CALIBRATION_DIRECTION} or no direction")
        try:
            # as the sidecar reads it: 'Acrylic', 'PMMA' or 'Tungsten_Carbide' typed in a
            # spreadsheet are the canonical names, which a point was compared with verbatim
            # (refused as "another material" than the specimen's tungsten_carbide)
            material = normalize_material(_text_cell(row.get("material"), default_material),
                                          "material", known=None)
            named = _text_cell(row.get("specimen"), "")
            point = MeasuredPoint(material=material, specimen=named, source=display_path(path),
                                  row=int(line), source_sha256=sha256, **values,
                                  sdc_bound=_point_sdc_bound(values["fill_percent"], material,
                                                             named, "", specimen)[0])
            # the store's rule (its records refused beyond their noise are left out): zero
            # damping measured with noise is kept, energy created beyond it is not
            _check_not_negative_beyond_noise(point)
            points.append(point)
        except ParameterError as exc:  # the row's values, named by their columns
            raise InputFileError(f"{where}: {exc}") from None
    if not points:
        raise InputFileError(f"{path}: no rows")
    seen: dict[tuple, int | None] = {}
    for p in points:
        key = (p.frequency_hz, p.acceleration_g, p.fill_percent, p.material, p.specimen)
        if key in seen:
            # rows counted as load cases of their own would pass the count of load cases a
            # fit needs, and weigh one case several times
            raise InputFileError(f"{path}: lines {seen[key]} and {p.row} state the same load "
                                 f"case ({p.label()}); give one row per load case (the mean "
                                 "SDC of repeated tests and its standard error)")
        seen[key] = p.row
    return points


def _check_not_negative_beyond_noise(point: MeasuredPoint) -> None:
    """Refuse a measured SDC below 0 beyond its noise (:func:`pidcore.compare.plausibility.
    lowest_kept_sdc` of its standard error: -3 ``sdc_stderr``, 0 without one), the rule that
    leaves a stored record out of ``calibrate --store`` (:func:`measured_from_store`): more
    energy out of the coupon than in, which no passive damper gives. One within it is zero
    damping measured with noise, fitted as it is (-0.057 +- 0.13 was refused from a table
    and fitted from the store)."""
    from ..compare.plausibility import NEGATIVE_WITHIN_STDERRS, lowest_kept_sdc

    lowest = lowest_kept_sdc(point.sdc_stderr)
    if point.sdc >= lowest:
        return
    if lowest == 0.0:
        raise ParameterError(
            f"sdc {as_given(point.sdc)}: expected >= 0 without an sdc_stderr (a negative SDC "
            f"within {NEGATIVE_WITHIN_STDERRS:g} standard errors of 0 is zero damping measured "
            "with noise: give its sdc_stderr)")
    raise ParameterError(
        f"sdc {as_given(point.sdc)}: below 0 beyond its noise ({NEGATIVE_WITHIN_STDERRS:g} x "
        f"sdc_stderr {as_given(point.sdc_stderr)} = {-lowest:.4g}): more energy out than in, "
        f"impossible for a passive damper; expected >= {lowest:.4g}")


def _point_sdc_bound(fill_percent: float, material: str, specimen_name: str,
                     specimen_sha256: str, given: Specimen | None,
                     record: Mapping[str, Any] | None = None) -> tuple[SdcBound, str]:
    """``(bound, note)``: the SDC bound of a measured point
    (:func:`pidcore.compare.plausibility.sdc_bound`):
    one naming no specimen is a test of ``given`` where its particles are ``given``'s (as
    :func:`points_for_specimen` takes it), else of the paper's coupon; one naming a specimen
    is judged as :func:`~pidcore.compare.plausibility.tested_sdc_bound` does, and, where its
    file is not at hand, against the bound saved with its stored ``record``
    (:func:`~pidcore.compare.plausibility.recorded_sdc_bound`) where it has one; ``note``
    says where a stored bound was ignored ("" otherwise)."""
    from ..compare.plausibility import measured_sdc_bound, sdc_bound

    if given is not None and not specimen_name and material == given.particles.material:
        return sdc_bound(fill_percent=fill_percent, material=material, specimen=given), ""
    return measured_sdc_bound(fill_percent=fill_percent, material=material,
                              specimen_name=specimen_name, specimen_sha256=specimen_sha256,
                              given=given, record=record)


def _before_baseline(frame: pd.DataFrame, notes: list[str] | None) -> pd.DataFrame:
    """Each record's Eq. 11 SDC before the empty coupon's damping was taken off it.

    The observation model adds the baseline (fitted, or the specimen's) to the DEM's SDC
    (:func:`pidcore.calibrate.surrogate.predicted_sdc`), so a record analysed with
    ``baseline_loss_factor`` (``analyze --baseline-loss-factor``, as ``report`` advises for
    the raw DEM's comparison) lost it twice: the fitted baseline went to about 0, or a fixed
    one over-predicted every point by 2 pi eta_0 m_s / m_c. The stored complex power is that
    before the subtraction (:class:`pidcore.signal.PowerAnalysis`), so 2 pi Re/Im is that SDC;
    its standard error is the record's (the subtraction is of the drive's own amplitude).
    """
    from ..signal.power import baseline_sdc_taken_off

    if "parameters_json" not in frame.columns or frame.empty:
        return frame
    taken = pd.Series([baseline_sdc_taken_off(row) for _, row in frame.iterrows()],
                      index=frame.index, dtype=float)
    raw = pd.to_numeric(frame["sdc"], errors="coerce") + taken
    undo = (taken != 0) & np.isfinite(raw)
    if notes is not None:
        for _, row in frame[~np.isfinite(raw) & frame["sdc"].notna()].iterrows():
            notes.append(f"{stored_record_name(row)}: analysed with the empty coupon's "
                         "damping taken off, and no complex power stored to undo it: "
                         "calibrated at its SDC after the subtraction, which the calibration "
                         "adds again")
    if not undo.any():
        return frame
    if notes is not None:
        for (_, row), value, off in zip(frame[undo].iterrows(), raw[undo], taken[undo],
                                        strict=True):
            notes.append(f"{stored_record_name(row)}: analysed with the empty coupon's "
                         f"damping (baseline_loss_factor, SDC {off:.3g}) taken off; its SDC "
                         "before that, "
                         f"{value:.4g} (not {float(row['sdc']):.4g}), is calibrated, since "
                         "the calibration adds the baseline to its prediction")
    return frame.assign(sdc=frame["sdc"].where(~undo, raw))


def measured_from_store(store_path: str | os.PathLike, *,
                        left_out: list[str] | None = None,
                        specimen: Specimen | None = None) -> list[MeasuredPoint]:
    """Analysed measurements of a store, grouped per load case, particle material and specimen
    label (mean SDC, standard error), of the newest analysis of each measurement.

    Records of other materials or specimens at one load case are kept apart (averaging acrylic
    and steel particles would fit neither); a record without a material is the paper's acrylic,
    one without a specimen label has none (""). A load case measured several times gives the
    mean and the standard error of the mean (or the analysis's own standard error when
    measured once). The standard error's degrees of freedom go with it: repeats - 1, or the
    analysis's ``sdc_stderr_dof`` (n_blocks - 1; NaN in a record
    without it, of an older pidcore). Measured frequency and
    acceleration are rounded to 3 and 2 significant digits to find the load case; the
    analyses must carry ``fill_percent`` (from a sidecar). Records the plausibility checks
    refuse (saved with ``--accept-implausible``: a negative SDC beyond its noise, one above
    its specimen's bound, :func:`_point_sdc_bound` with ``specimen`` the file calibrated, or
    2 pi where not known) are left out; ``left_out``, where given, gains a line naming each.

    A record of a specimen name saved without its file's hash (an older pidcore) is pooled
    with the tests of the one file of that name the store's other records name, or kept apart
    where they (or ``specimen``, the file calibrated) name two files
    (:func:`pidcore.specimen.match_hashless_records`); ``left_out`` gains the note. The store
    is only read.
    """
    from ..specimen import MEASURED_SHA256_FIELD, match_hashless_records
    from ..store import Store
    from ..store.listing import checked_analyses, latest_per_measurement

    frame = checked_analyses(Store(store_path).list_analyses(), store_path)
    need = {"frequency_hz", "sdc"}
    if frame.empty or not need <= set(frame.columns):
        raise InputFileError(f"{store_path}: no analysed measurements with frequency_hz and sdc")
    for column in ("acceleration_g", "fill_percent"):
        if column not in frame.columns:
            raise InputFileError(f"{store_path}: analyses carry no {column}; calibrate from a "
                                 "table (read_measured_table) instead")
    frame = frame.dropna(subset=["frequency_hz", "acceleration_g", "fill_percent", "sdc"])
    # a file analysed again (other settings) is one measurement, not a repeated test: its two
    # analyses were averaged, with a standard error from their difference
    frame = latest_per_measurement(frame)
    # a result no passive coupon gives, kept as asked for the record, fits no parameter: an
    # SDC of -1.26 and one of 9.4 were averaged into the load case (in-sample RMS 2.7)
    judged = [_point_sdc_bound(
        float(row["fill_percent"]), _text_cell(row.get("material"), DEFAULT_MATERIAL),
        _text_cell(row.get("specimen"), ""), _text_cell(row.get(MEASURED_SHA256_FIELD), ""),
        specimen, row) for _, row in frame.iterrows()]
    bounds = [bound for bound, _ in judged]
    frame = frame.assign(sdc_bound=bounds)
    implausible = [stored_findings(row, bound=bound)[0]
                   for (_, row), bound in zip(frame.iterrows(), bounds, strict=True)]
    if left_out is not None:
        names = [stored_record_name(row) for _, row in frame.iterrows()]
        # a stored bound that is not one is judged at 2 pi: said, as report --store says it
        # (the record was judged right, and a user saw no word of why)
        left_out.extend(f"{name}: {note}" for name, (_, note) in zip(names, judged, strict=True)
                        if note)
        left_out.extend(f"{name}: left out, implausible (saved as accepted): "
                        f"{found[0].message}"
                        for name, found in zip(names, implausible, strict=True) if found)
    frame = frame[[not found for found in implausible]]
    # tests driven along x or y are no load case of the calibration's z-drive DEM runs: they
    # were averaged with the z tests of their case as repeats (report keeps them apart)
    other = [other_direction(v) for v in frame.get(
        "direction", pd.Series([None] * len(frame), index=frame.index))]
    if left_out is not None:
        left_out.extend(f"{stored_record_name(row)}: left out, driven along {axis}: the "
                        f"calibration's DEM runs drive along {CALIBRATION_DIRECTION}"
                        for (_, row), axis in zip(frame.iterrows(), other, strict=True)
                        if axis)
    # a boolean Series: a list, empty where every record was left out above, picks columns
    frame = frame[pd.Series([not axis for axis in other], index=frame.index, dtype=bool)]
    frame = _before_baseline(frame, left_out)
    # measured frequency and acceleration scatter about the nominal ones: a load case is the
    # frequency to 3 significant digits, the acceleration to 2 (e.g. 50.02 Hz, 4.97 g -> 50, 5)
    frame = frame.assign(
        frequency_hz=frame["frequency_hz"].map(lambda v: float(f"{v:.3g}")),
        acceleration_g=frame["acceleration_g"].map(lambda v: float(f"{v:.2g}")),
        material=[_text_cell(v, DEFAULT_MATERIAL) for v in frame.get(
            "material", pd.Series([None] * len(frame), index=frame.index))],
        specimen=[_text_cell(v, "") for v in frame.get(
            "specimen", pd.Series([None] * len(frame), index=frame.index))])
    # tests of two files of one name are not averaged into one point; a record saved before
    # the hash was joins the tests of its name's one file, or stays apart where the name
    # means two (the paper's coupon's hash is "": by name, as before)
    given = {}
    if specimen is not None:
        from ..specimen import measured_specimen_name
        from .prediction import tested_sha256

        given = {measured_specimen_name(specimen): tested_sha256(specimen) or ""}
    matched = match_hashless_records(list(frame["specimen"]), list(frame.get(
        MEASURED_SHA256_FIELD, pd.Series([None] * len(frame), index=frame.index))), given=given)
    frame = frame.assign(specimen_sha256=list(matched.sha256),
                         specimen_ambiguous=list(matched.ambiguous))
    if left_out is not None:
        left_out.extend(note for note in dict.fromkeys(matched.notes) if note)
    points = []
    keys = ["frequency_hz", "acceleration_g", "fill_percent", "material", "specimen",
            "specimen_sha256", "specimen_ambiguous"]
    groups, pooled = _pool_same_simulations(list(frame.groupby(keys)), specimen)
    if left_out is not None:
        left_out.extend(pooled)
    for (f, a, p, material, named, sha256, ambiguous), group in groups:
        sdc = group["sdc"].to_numpy(float)
        if len(sdc) > 1:
            se = float(np.std(sdc, ddof=1) / math.sqrt(len(sdc)))
            dof = float(len(sdc) - 1)
        else:
            se = float(group.get("sdc_stderr", pd.Series([0.0])).fillna(0.0).iloc[0])
            dof = stored_stderr_dof(group.get("sdc_stderr_dof", pd.Series([math.nan])).iloc[0]) \
                if se > 0 else math.nan
        points.append(MeasuredPoint(float(f), float(a), float(p), float(sdc.mean()), se,
                                    str(material), str(named), sdc_stderr_dof=dof,
                                    source=display_path(store_path), specimen_sha256=str(sha256),
                                    analyses=tuple(sorted(map(str, group.get(
                                        "key", pd.Series([], dtype=object))))),
                                    specimen_ambiguous=bool(ambiguous),
                                    # one specimen and fill: one bound
                                    sdc_bound=group["sdc_bound"].iloc[0]))
    if not points:
        # with why its bound is 2 pi where the stored one was ignored: the error is all the
        # command prints then, and "above the physical bound 6.28" of a record analyze kept
        # below its particles' 38.3 read as a contradiction
        dropped = [found[0].message + (f"; {note}" if note else "")
                   for found, (_, note) in zip(implausible, judged, strict=True) if found]
        if dropped:
            # they have a complete load case: "no analysed measurement has a complete load
            # case" sent the user to fills and sidecars, not to the records left out
            raise InputFileError(
                f"{store_path}: no analysed measurement to calibrate against: "
                f"{len(dropped)} record(s) with a complete load case, all implausible and "
                f"saved as accepted (first: {dropped[0]}); a fit takes none of them")
        raise InputFileError(f"{store_path}: no analysed measurement has a complete load case")
    return points


def _pool_same_simulations(groups: list[tuple[tuple, pd.DataFrame]],
                           given: Specimen | None) -> tuple[list[tuple[tuple, pd.DataFrame]],
                                                            list[str]]:
    """(groups, notes): a store's records grouped per load case (keys: frequency,
    acceleration, fill, material, specimen label, sha256, ambiguous), with the groups whose
    fills are the same particles per cell of the specimen they are calibrated with
    (:func:`pidcore.specimen.same_particles_per_cell`) pooled into one, as repeated tests of
    one load case at the fill most of its records state (the lowest of a tie); a note says
    each pool. Tests labelled 50 % and 50.4 % of 10 of 20 particles were two load cases, one
    DEM simulation (calibrate refuses such points: :func:`~pidcore.calibrate.calibrate.
    check_repeated_simulations`); a table states its repeats as one row, a store cannot."""
    from ..dem.simulate import particles_per_cell
    from ..specimen import same_particles_per_cell

    pools: list[tuple[tuple, list[pd.DataFrame], Specimen | None]] = []
    for keys, group in groups:
        counting = _counting_specimen(keys, given)
        for pool_keys, members, pool_counting in pools:
            if counting is not None and pool_counting is not None \
                    and pool_counting.hash == counting.hash \
                    and pool_keys[:2] + pool_keys[3:] == keys[:2] + keys[3:] \
                    and same_particles_per_cell(keys[2], pool_keys[2], counting):
                members.append(group)
                break
        else:
            pools.append((keys, [group], counting))
    out, notes = [], []
    for keys, members, counting in pools:
        if len(members) == 1:
            out.append((keys, members[0]))
            continue
        stated = {float(m["fill_percent"].iloc[0]): len(m) for m in members}
        fill = max(sorted(stated), key=stated.__getitem__)
        count, full = particles_per_cell(fill, specimen=counting)
        out.append(((*keys[:2], fill, *keys[3:]),
                    pd.concat(members).assign(fill_percent=fill)))
        label = MeasuredPoint(keys[0], keys[1], fill, 0.0, material=keys[3],
                              specimen=keys[4], specimen_sha256=keys[5]).label()
        notes.append(f"{label}: tests stated at fills "
                     + ", ".join(f"{f:g} % ({n})" for f, n in sorted(stated.items()))
                     + f" are all {count} of {full} particles per cell of specimen "
                     f"{counting.name}, one DEM simulation: pooled as repeated tests of one "
                     f"load case at {fill:g} %")
    return out, notes


def _counting_specimen(keys: tuple, given: Specimen | None) -> Specimen | None:
    """The specimen whose particles per cell a store's group of tests (``keys`` as
    :func:`_pool_same_simulations` takes them) is counted in: ``given`` where
    :func:`points_for_specimen` keeps its tests, the paper's coupon of their particles where
    no specimen is given and :func:`points_for_paper` keeps them; None where neither (they
    are left out of the fit, or their particles are not in the materials table)."""
    from ..specimen import paper_specimen

    probe = MeasuredPoint(keys[0], keys[1], keys[2], 0.0, material=keys[3], specimen=keys[4],
                          specimen_sha256=keys[5], specimen_ambiguous=bool(keys[6]))
    if given is not None:
        return given if points_for_specimen([probe], given)[0] else None
    if not points_for_paper([probe])[0]:
        return None
    try:
        return paper_specimen(keys[3])
    except ParameterError:
        return None


def measured_provenance(points: Sequence[MeasuredPoint]) -> list[dict[str, Any]]:
    """What a calibration was fitted to, one entry per source in the order read
    (calibration.json's ``settings.measured``): a table by its path and the sha256 of its
    bytes (``kind`` ``table``), a store by its path and the keys of the analyses pooled
    (``store``), points made in code (no source) by their number alone (``points``)."""
    out: dict[tuple[str, str], dict[str, Any]] = {}
    for p in points:
        kind = "table" if p.row is not None else "store" if p.source else "points"
        entry = out.setdefault((kind, p.source), {"kind": kind, "source": p.source,
                                                  "points": 0})
        entry["points"] += 1
        if kind == "table":
            entry["sha256"] = p.source_sha256
        elif kind == "store":
            entry.setdefault("analyses", []).extend(p.analyses)
    return list(out.values())


def measured_words(measured: Sequence[Mapping[str, Any]]) -> str:
    """:func:`measured_provenance` in words, the summary's and the calibrated file's line:
    ``"Measured: 6 load cases of table m.csv (sha256 9a19...)."``."""
    said = []
    for entry in measured:
        n = f"{entry.get('points', 0)} load case(s)"
        if entry.get("kind") == "table":
            said.append(f"{n} of table {entry.get('source')} (sha256 "
                        f"{entry.get('sha256') or 'unknown'})")
        elif entry.get("kind") == "store":
            keys = entry.get("analyses") or []
            said.append(f"{n} of store {entry.get('source')} ({len(keys)} analyses"
                        + (f": {', '.join(keys)}" if keys else "") + ")")
        else:
            said.append(f"{n} given in code")
    return "Measured: " + "; ".join(said) + "." if said else ""


def points_for_specimen(points: Sequence[MeasuredPoint], specimen) -> tuple[list, str]:
    """(points, note): the measured points a specimen file is calibrated against, those of its
    particle material measured on it (their specimen label is its name, or the name it was
    calibrated from) or on no named specimen; ``note`` says what is left out and why ("" if
    nothing)."""
    from ..specimen import (
        hashed_name,
        measured_specimen_name,
        same_tested_file,
        tested_label,
        uncalibrated_name,
    )
    from .prediction import tested_sha256

    material = specimen.particles.material
    # a calibrated file (as pidcore calibrate names it) is the specimen its measurements
    # were made on, as base_specimen reads a point's name: "x", "x_calibrated" and an older
    # "x_calibrated_calibrated" are all x. A file named paper_coupon with another cell is
    # "paper_coupon [45d792]", as its tests are saved: the paper coupon's tests are not its
    # a point that recorded its specimen file's hash is matched by it where the file
    # calibrated knows which file was tested (tested_sha256): two files named x are two
    # specimens. One without (a table, an older record) by name, as before
    tested = uncalibrated_name(measured_specimen_name(specimen))
    tested_file = tested_sha256(specimen) or ""
    kept, other_material, other_specimen = [], {}, {}
    for p in points:
        if str(p.material) != material:
            other_material[str(p.material)] = other_material.get(str(p.material), 0) + 1
        elif str(p.specimen) and uncalibrated_name(str(p.specimen)) != tested:
            other_specimen[str(p.specimen)] = other_specimen.get(str(p.specimen), 0) + 1
        elif str(p.specimen) and same_tested_file(p.specimen_sha256, tested_file) is False:
            label = f"{hashed_name(p.specimen, p.specimen_sha256)} (another file of that name)"
            other_specimen[label] = other_specimen.get(label, 0) + 1
        elif p.specimen_ambiguous:
            # by name it is this file's, and just as much another's: fitted beside this
            # file's own tests it was a second point of one load case
            label = (f"{p.specimen} saved without its specimen's sha256 (the name means several "
                     "files)")
            other_specimen[label] = other_specimen.get(label, 0) + 1
        else:
            kept.append(p)
    reasons = [f"{n} measured load case(s) of specimen {name}"
               for name, n in other_specimen.items()]
    reasons += [f"{n} measured load case(s) of {name} particles"
                for name, n in other_material.items()]
    shown = measured_specimen_name(specimen)
    if any("another file of that name" in name for name in other_specimen):
        shown = tested_label(shown, tested_file)
    note = (f"Not used for {shown} ({material} particles): "
            + "; ".join(reasons)
            + ".") if reasons else ""
    return kept, note


def points_for_paper(points: Sequence[MeasuredPoint], *, hint: str = "") -> tuple[list, str]:
    """(points, note): the measured points the paper's coupon is calibrated against, those
    naming no specimen or the paper's coupon (the library refuses others:
    :func:`pidcore.calibrate.calibrate.check_point_specimens`); ``note`` says what is left out
    ("" if nothing), with ``hint``, the caller's way to calibrate them, in brackets.
    Which names are the paper's coupon is :func:`pidcore.specimen.is_paper_coupon`'s to say
    (``paper_coupon_aluminium`` is; its tests were left out here and accepted by the
    library)."""
    from ..specimen import is_paper_coupon

    kept, others = [], {}
    for p in points:
        # by name, even where the point has its file's hash: another file of the coupon's
        # name is saved as "paper_coupon [45d792]", and a calibrated file of the coupon
        # (another hash) models the coupon its tests were made on
        name = str(p.specimen)
        if not is_paper_coupon(name):
            others[name] = others.get(name, 0) + 1
        else:
            kept.append(p)
    note = ("Not used for the paper's coupon: " + "; ".join(
        f"{n} measured load case(s) of specimen {name}" for name, n in others.items())
        + (f" ({hint})" if hint else "") + ".") if others else ""
    return kept, note


def check_enough_points(points: list[MeasuredPoint], names: Sequence[str], *,
                        leave_one_out: bool = False) -> None:
    """Refuse fewer measured load cases than fitted parameters (``names``); the message lists
    them, since one (the model discrepancy) is fitted unless fixed. ``leave_one_out``: every
    fold is fitted on all cases but one, so one more case is needed (said as such: "2 load
    cases cannot determine 3 parameters" read wrong to a user who gave 3)."""
    n_parameters = len(names)
    need = n_parameters + (1 if leave_one_out else 0)
    if len(points) < need:
        listed = f": {', '.join(names)}"
        fixed = " (fix model_discrepancy with discrepancy=TAU)" \
            if "model_discrepancy" in names else ""
        if leave_one_out:
            raise ParameterError(
                f"cross_validate=loo: leave-one-out fits each fold on {len(points) - 1} of the "
                f"{len(points)} measured load case(s), which cannot determine {n_parameters} "
                f"fitted parameter(s){listed}; it needs at least {need} load cases (parameters "
                f"+ 1): give more, fit fewer parameters{fixed}, or leave out cross_validate")
        raise ParameterError(f"{len(points)} measured load case(s) cannot determine "
                             f"{n_parameters} fitted parameter(s){listed}; give at least "
                             f"{n_parameters} load cases or fit fewer parameters{fixed}")
