"""Which DEM runs a measurement meets: the runs of its specimen, never another's.

A measurement may name its specimen (the ``specimen`` of a saved analysis: a specimen file's
``name``) and, where it was analysed with that file, the file's hash (``specimen_sha256``:
:func:`pidcore.specimen.measured_specimen_sha256`); a stored DEM run states ``specimen_name``
and ``specimen_sha256``. A named measurement meets only the runs of that name, and of its file
where it recorded the hash (two files of one name are two specimens; a record without the hash,
saved by an earlier pidcore or with a name only, is matched by name); an unnamed one meets the
runs of its material and direction when they all come from one specimen, the paper's coupon's
among several (the default of ``pidcore report``: a calibration's store holds its design runs,
files named ``paper_coupon`` with other values, beside the coupon's own), and none when they
come from several others (they are not pooled: which specimen was tested is the user's to say).
A measurement named ``x`` with no run of that name meets the runs of ``x_calibrated``, the file
``pidcore calibrate`` wrote from it (a model of the specimen tested); for the paper's coupon
only such a file of its cell and spheres (another file named ``paper_coupon`` calibrates to the
same name; the file written since ``[provenance]`` existed says which it was made from, and its
runs meet the tests of that file, ``"paper_coupon [45d792]"``, and never the paper's coupon's).
A measurement named ``paper_coupon`` meets the paper's coupon's runs, not another file of that
name; a test of such a file is named ``"paper_coupon [45d792]"``, as its runs are
(:func:`pidcore.specimen.measured_specimen_name`). Which specimen is the paper's coupon is
:func:`pidcore.specimen.is_paper_coupon`'s to say. Runs stored before specimens existed (no
hash) and runs of the paper's coupon with either table material are the paper's coupon, as in
:func:`pidcore.dem.persist.runs_of_specimen`.

Both the app's Compare tab and the report table choose their runs here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import PidcoreError


@dataclass(frozen=True)
class SpecimenRuns:
    """The DEM runs one measurement meets.

    Attributes
    ----------
    runs : pandas.DataFrame or None
        The runs to compare with (None: none).
    specimen : str
        The runs' specimen, e.g. ``"steel_6mm_b [3e945a]"``; empty where no run is met.
    note : str
        Why runs were left out (empty where none was); ``refused`` says whether the note asks
        the user to name the specimen.
    refused : bool
        True where the runs of several specimens would have been pooled: none is met.
    calibrated_from : str
        The measurement's specimen ``x`` where the runs met are those of ``x_calibrated`` (no
        run of ``x`` itself); "" otherwise.
    """

    runs: pd.DataFrame | None
    specimen: str = ""
    note: str = ""
    refused: bool = False
    calibrated_from: str = ""


def specimen_label(name: str, sha256: str) -> str:
    """A specimen as the pages name it: ``"name [hash6]"``; the paper's coupon (either table
    material, or no hash: a run stored before specimens existed) is ``"paper_coupon"``."""
    from ..specimen import PAPER_SPECIMEN_NAME, hashed_name, is_paper_coupon

    # a run without a hash predates specimens: it was the paper's coupon, whatever it names
    if not sha256 or is_paper_coupon(name, sha256):
        return PAPER_SPECIMEN_NAME
    return hashed_name(name, sha256)


NOT_PAPER_SPECIMEN_NOTE = ("specimen {name} is not the paper's coupon: the paper's Table 3 is "
                           "not compared")


def run_specimen_labels(runs: pd.DataFrame) -> pd.Series:
    """One :func:`specimen_label` per run (the paper's coupon is one specimen)."""

    def column(name: str) -> pd.Series:
        if name not in runs.columns:
            return pd.Series([""] * len(runs), index=runs.index)
        return runs[name].map(lambda v: v if isinstance(v, str) else "")

    return pd.Series([specimen_label(n, h) for n, h in zip(
        column("specimen_name"), column("specimen_sha256"), strict=True)],
        index=runs.index, dtype=object)


@dataclass(frozen=True)
class CalibrationVariant:
    """A stored DEM run's specimen as a calibration made it: the file ``of_name``
    [``of_sha256``] with the design point's ``values`` (fitted DEM parameters by the names
    ``--fit`` takes), stored under the variant's own text and hash
    (:data:`pidcore.compare.align.CALIBRATION_VARIANT_FIELD`)."""

    of_name: str
    of_sha256: str
    values: tuple[tuple[str, float], ...]

    def text(self) -> str:
        """``"calibration variant of mycoupon [072027] (static_friction 0.4537,
        rolling_friction 0.0213)"``: 4 significant digits tell a design's points apart (its
        own hash, beside it in every label, names it in full)."""
        values = ", ".join(f"{name} {value:.4g}" for name, value in self.values)
        return (f"calibration variant of {specimen_label(self.of_name, self.of_sha256)}"
                + (f" ({values})" if values else ""))


#: :func:`run_origin` of a run of the specimen file as given (``pidcore dem run``, a sweep,
#: the app, a calibration's run of its start file).
AS_GIVEN = "as given"
#: :func:`run_origin` of a run that does not say (stored before pidcore recorded it, or a
#: damaged statement): a file as given or a calibration's variant of one.
UNSTATED = "unstated"


def run_origin(parameters_json: object) -> CalibrationVariant | str:
    """Where a stored run's specimen came from, by what the run stored
    (:data:`pidcore.compare.align.CALIBRATION_VARIANT_FIELD`): its
    :class:`CalibrationVariant`, :data:`AS_GIVEN` or :data:`UNSTATED`."""
    from .align import CALIBRATION_VARIANT_FIELD, stored_parameters

    params = stored_parameters(parameters_json)
    if params is None or CALIBRATION_VARIANT_FIELD not in params:
        return UNSTATED
    stated = params[CALIBRATION_VARIANT_FIELD]
    if stated is None:
        return AS_GIVEN
    try:
        values = tuple((str(name), float(value)) for name, value in stated["values"])
        return CalibrationVariant(str(stated["of_name"]), str(stated["of_sha256"]), values)
    except (AttributeError, KeyError, TypeError, ValueError):
        return UNSTATED  # a damaged statement says nothing


def run_origins(runs: pd.DataFrame) -> pd.Series:
    """:func:`run_origin` per run of a listing (:data:`UNSTATED` for every run where the
    listing has no ``parameters_json``)."""
    if "parameters_json" not in runs.columns:
        return pd.Series([UNSTATED] * len(runs), index=runs.index, dtype=object)
    return pd.Series([run_origin(p) for p in runs["parameters_json"]], index=runs.index,
                     dtype=object)


def are_calibration_variants(runs: pd.DataFrame) -> pd.Series:
    """Per run of a listing, whether it says it is a calibration's variant of a file
    (:func:`run_origin` a :class:`CalibrationVariant`)."""
    return run_origins(runs).map(lambda origin: isinstance(origin, CalibrationVariant))


def run_specimen_descriptions(runs: pd.DataFrame) -> pd.Series:
    """Per run, its specimen as lists of runs name it: its :func:`specimen_label`, and for a
    calibration's variant of a file what it is (``"mycoupon [7167f7]: calibration variant of
    mycoupon [072027] (static_friction 0.4537, rolling_friction 0.0213)"``: its label alone
    read as another file of the name, as if the user had edited theirs). One description per
    label: a run that does not say (stored before pidcore recorded it) is described as the
    other runs of its specimen say."""
    labels = run_specimen_labels(runs)
    known: dict[str, str] = {}
    for label, variant in zip(labels, run_origins(runs), strict=True):
        if isinstance(variant, CalibrationVariant):
            known.setdefault(label, f"{label}: {variant.text()}")
    return labels.map(lambda label: known.get(label, label))


def runs_per_specimen_text(runs: pd.DataFrame) -> str:
    """How many of ``runs`` are of each specimen, by :func:`run_specimen_descriptions`, in
    the order first met: ``"3 of a [1b8b5d], 1 of paper_coupon"``."""
    counts = run_specimen_descriptions(runs).value_counts(sort=False)
    return ", ".join(f"{n} of {label}" for label, n in counts.items())


def _names(runs: pd.DataFrame, labels: pd.Series) -> pd.Series:
    """The specimen name of each run (the paper's coupon for every paper run)."""
    from ..specimen import PAPER_SPECIMEN_NAME

    if "specimen_name" not in runs.columns:
        return pd.Series([PAPER_SPECIMEN_NAME] * len(runs), index=runs.index, dtype=object)
    return pd.Series([PAPER_SPECIMEN_NAME if label == PAPER_SPECIMEN_NAME else str(name)
                      for label, name in zip(labels, runs["specimen_name"], strict=True)],
                     index=runs.index, dtype=object)


def _model_the_papers_coupon(runs: pd.DataFrame) -> np.ndarray:
    """Per run: whether the specimen file it stored (``parameters_json``'s ``specimen_text``)
    models the paper's coupon (:func:`pidcore.specimen.models_paper_coupon`: its cell,
    spheres and coupon mass). A run that stored no text (runs of the paper's coupon's name
    before specimen files were stored) is taken as its name says, as before; one whose text
    no longer reads is not."""
    from ..specimen import Specimen, models_paper_coupon
    from .align import stored_parameters

    if "parameters_json" not in runs.columns:
        return np.ones(len(runs), dtype=bool)
    keep = []
    for params in runs["parameters_json"]:
        text = (stored_parameters(params) or {}).get("specimen_text")
        if not isinstance(text, str) or not text:
            keep.append(True)
            continue
        try:
            keep.append(models_paper_coupon(Specimen.from_text(text, source="stored DEM run")))
        except PidcoreError:
            keep.append(False)
    return np.array(keep, dtype=bool)


def _provenance_test_names(runs: pd.DataFrame) -> pd.Series:
    """Per run: the name of the tests of the file its calibrated specimen was made from, where
    that file's ``[provenance]`` (in the text the run stored) tells a user's own
    ``paper_coupon.toml`` from the paper's coupon (:func:`pidcore.specimen.
    provenance_test_name`: ``"paper_coupon [45d792]"``); "" for every other run (no stored
    text, no provenance, or one the name already says)."""
    from ..specimen import Specimen, provenance_test_name
    from .align import stored_parameters

    if "parameters_json" not in runs.columns:
        return pd.Series([""] * len(runs), index=runs.index, dtype=object)
    out = []
    for params in runs["parameters_json"]:
        text = (stored_parameters(params) or {}).get("specimen_text")
        routed = ""
        if isinstance(text, str) and "[provenance]" in text:  # parsing costs; no table, none
            try:
                routed = provenance_test_name(Specimen.from_text(text, source="stored DEM run"))
            except PidcoreError:
                routed = ""
        out.append(routed)
    return pd.Series(out, index=runs.index, dtype=object)


def _tested_hashes(runs: pd.DataFrame) -> pd.Series:
    """Per run: the sha256 of the file whose tests it models: the file it was calibrated from
    where the text it stored records one (``[provenance]``), else its own ``specimen_sha256``
    ("" where it has none), as a measurement saves it
    (:func:`pidcore.specimen.measured_specimen_sha256`)."""
    from ..specimen import Specimen
    from .align import stored_parameters

    own = (runs["specimen_sha256"] if "specimen_sha256" in runs.columns
           else pd.Series([""] * len(runs), index=runs.index))
    params = (runs["parameters_json"] if "parameters_json" in runs.columns
              else pd.Series([None] * len(runs), index=runs.index))
    out = []
    for sha, stored in zip(own, params, strict=True):
        tested = sha if isinstance(sha, str) else ""
        text = (stored_parameters(stored) or {}).get("specimen_text")
        if isinstance(text, str) and "[provenance]" in text:  # parsing costs; no table, none
            try:
                source = Specimen.from_text(text, source="stored DEM run").provenance
            except PidcoreError:
                source = None
            if source is not None:
                tested = source.calibrated_from_sha256
        out.append(tested)
    return pd.Series(out, index=runs.index, dtype=object)


def _listed(runs: pd.DataFrame) -> str:
    """``"a [1b8b5d] (3 run(s)), ..."``: the specimens of ``runs`` as
    :func:`run_specimen_descriptions` names them, a calibration's variants as such."""
    counts = run_specimen_descriptions(runs).value_counts(sort=False)
    return ", ".join(f"{label} ({n} run(s))" for label, n in counts.items())


def _other_files_words(runs: pd.DataFrame, specimen: str, own_file: str) -> str:
    """Why runs named ``specimen`` (``runs``: those not of the test's file ``own_file``) are
    not the test's: "" where each is a calibration's variant (their description in the list
    says so); for runs of another file as given, another file of that name; for runs that
    do not say (stored before pidcore recorded it), either."""
    if are_calibration_variants(runs).all():
        return ""
    if (run_origins(runs) == UNSTATED).any():
        return (f"runs named {specimen} hold other content than the test's file (its "
                f"sha256 starts {own_file[:6]}): another file of that name, or a "
                "calibration's variants of one, stored before pidcore recorded which")
    return (f"runs named {specimen} are of another file of that name than the test's "
            f"(its specimen's sha256 starts {own_file[:6]})")


def runs_for_measurement(runs: pd.DataFrame | None, specimen: str, material: str,
                         direction: str, sha256: object = "") -> SpecimenRuns:
    """The DEM runs a measurement of ``specimen`` (may be empty: not named) at ``material``
    and ``direction`` meets (see the module's docstring). ``sha256``: the hash of the
    specimen file the measurement recorded (``specimen_sha256``; "" or NaN: none, an older
    record): runs of its name whose file is another (:func:`_tested_hashes`) are not its
    own. Without it, the name decides, as before the hash was saved."""
    if runs is None or runs.empty:
        return SpecimenRuns(None)
    same = runs
    if "material" in runs.columns and "direction" in runs.columns:
        same = runs[(runs["material"] == material) & (runs["direction"] == direction)]
    if same.empty:
        return SpecimenRuns(None)
    from ..specimen import CALIBRATED_SUFFIX, PAPER_SPECIMEN_NAME, is_paper_coupon

    labels = run_specimen_labels(same)
    specimen = (specimen or "").strip()
    paper = (labels == PAPER_SPECIMEN_NAME).to_numpy(bool)
    # a test naming paper_coupon_aluminium is of the paper's coupon too (is_paper_coupon); one
    # naming paper_coupon_calibrated meets its calibrated file's runs first, as any x_calibrated
    if specimen and is_paper_coupon(specimen) and not specimen.endswith(CALIBRATED_SUFFIX) \
            and paper.any():
        # the paper's coupon is the paper's file (its hash), not every file that kept its
        # name: a calibration's design runs (the coupon with another rolling friction ...)
        # are named paper_coupon too, and were pooled with it or refused it
        return _paper_runs(same, labels, paper)
    if specimen:
        names = _names(same, labels)
        # runs of a file calibrated from a user's paper_coupon.toml are named
        # paper_coupon_calibrated as the paper coupon's calibrated file's are: its
        # [provenance] names its tests, "paper_coupon [45d792]", and no other
        routed = _provenance_test_names(same)
        # a measurement that recorded its file's hash meets the runs of that file only (or
        # of one calibrated from it): two files of one name are two specimens. One recorded
        # before the hash was saved meets them by name (runs of two files of that name are
        # refused below, not pooled)
        from ..specimen import deciding_sha256

        own_file = deciding_sha256(sha256)
        of_file = (_tested_hashes(same) == own_file).to_numpy(bool) if own_file \
            else np.ones(len(same), dtype=bool)
        by_name = (names == specimen) & (routed == "")
        # a test of a file named like the paper's coupon with other content names it by its
        # label, "paper_coupon [45d792]" (pidcore.specimen.measured_specimen_name), as its runs
        mine = (by_name | (labels == specimen)).to_numpy(bool) & of_file
        of_paper = is_paper_coupon(specimen)
        if of_paper and not specimen.endswith(CALIBRATED_SUFFIX):
            # no run of the paper's coupon: the runs of another file of its name are met (with
            # their hash) only where they model the coupon (a calibration's design point); a
            # file of another cell was compared with the coupon's test
            mine = mine & _model_the_papers_coupon(same)
        calibrated_from = ""
        if not mine.any():
            # a file `pidcore calibrate` wrote from this specimen ("x_calibrated") models the
            # specimen tested, as its calibration's bands speak for the tests of "x": a test of
            # x met no run of `report --specimen x_calibrated.toml` (no_dem_runs on every row)
            from ..specimen import uncalibrated_name

            mine = np.array([n.endswith(CALIBRATED_SUFFIX)
                             and uncalibrated_name(r or n) == specimen
                             for n, r in zip(names, routed, strict=True)], dtype=bool) & of_file
            if of_paper:
                # a file calibrated from another file named paper_coupon (another cell) is
                # paper_coupon_calibrated too: its runs were compared with the paper
                # coupon's tests. Only a calibrated file of the paper's cell and spheres
                # models them
                mine = mine & _model_the_papers_coupon(same)
            calibrated_from = specimen if mine.any() else ""
        kept, others = labels[mine], labels[~mine]
        left_out = (f"DEM runs of other specimens not compared: {_listed(same[~mine])}"
                    if len(others) else "")
        named_other_file = (names == specimen) & ~pd.Series(of_file, index=same.index)
        if own_file and named_other_file.any():
            # "no DEM runs of specimen x" beside a store of x's runs read as a lost match; a
            # calibration's variants of the test's file are no other file of its name
            why = _other_files_words(same[named_other_file], specimen, own_file)
            if why:
                left_out = ((left_out + "; ") if left_out else "") + why
        if kept.empty:
            return SpecimenRuns(None, "", f"no DEM runs of specimen {specimen} at {material}, "
                                          f"{direction}" + (f"; {left_out}" if left_out else ""))
        if kept.nunique() > 1:  # an edited file keeps its name but is another specimen
            return SpecimenRuns(None, "", f"DEM runs of {kept.nunique()} different specimen "
                                          f"files named {specimen}: {_listed(same[mine])}; not "
                                          "pooled (keep one version's runs, or rename the "
                                          "other)",
                                refused=True)
        return SpecimenRuns(same[mine].reset_index(drop=True), str(kept.iloc[0]), left_out,
                            calibrated_from=calibrated_from)
    if labels.nunique() > 1 and paper.any():
        # as `pidcore report` and the Report tab: the paper's coupon unless another is named
        return _paper_runs(same, labels, paper)
    if labels.nunique() > 1:
        return SpecimenRuns(None, "", f"the DEM runs at {material}, {direction} are of "
                                      f"{labels.nunique()} specimens: {_listed(same)}; not "
                                      "pooled. Name the file's specimen (column `specimen` of "
                                      "the settings table) to compare it with one of them",
                            refused=True)
    return SpecimenRuns(same.reset_index(drop=True), str(labels.iloc[0]))


def _paper_runs(runs: pd.DataFrame, labels: pd.Series, paper) -> SpecimenRuns:
    """The paper's coupon's runs of ``runs`` (``paper``: which), with a note naming the
    other specimens' runs left out and how to compare one of them."""
    from ..specimen import PAPER_SPECIMEN_NAME

    others = labels[~paper]
    note = ""
    if len(others):
        # a calibration's variant of the coupon is described as such in the list
        not_variant = ~are_calibration_variants(runs)
        same_name = ((_names(runs, labels) == PAPER_SPECIMEN_NAME) & not_variant)[~paper].any()
        note = (f"DEM runs of other specimens not compared: {_listed(runs[~paper])} (the paper's "
                f"coupon is compared, as in pidcore report"
                + ("; a run named paper_coupon with a hash is another file of that name, "
                   "e.g. a calibration's design point" if same_name else "")
                + "); to compare another, name its specimen in the file's `specimen` column "
                  "(the settings table) or keep its runs in a store of their own")
    return SpecimenRuns(runs[paper].reset_index(drop=True), PAPER_SPECIMEN_NAME, note)


def run_specimens(runs: pd.DataFrame | None) -> dict[str, object]:
    """The specimens other than the paper's coupon whose DEM runs ``runs`` holds, by
    :func:`specimen_label` (``"my_steel [3e945a]"``), each rebuilt from the specimen file text
    its first run stored (``parameters_json``): what a report of their runs compares
    (``pidcore report --specimen FILE``; the app's Report tab offers them). Runs that do not
    store their specimen's text are left out (they cannot name it)."""
    from ..specimen import PAPER_SPECIMEN_NAME, Specimen
    from .align import stored_parameters

    out: dict[str, object] = {}
    if runs is None or runs.empty or "parameters_json" not in runs.columns:
        return out
    for label, params, key in zip(run_specimen_labels(runs), runs["parameters_json"],
                                  runs["case_key"], strict=True):
        if label == PAPER_SPECIMEN_NAME or label in out:
            continue
        text = (stored_parameters(params) or {}).get("specimen_text")
        if text:
            out[label] = Specimen.from_text(text, source=f"stored DEM run {key}")
    return out
