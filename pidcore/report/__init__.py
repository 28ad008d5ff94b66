"""pidcore.report: the comparison table, figures, provenance and the report files.

* :func:`build_report_table` (:mod:`.table`) - Table 3-style comparison of our DEM, our
  measurements and the paper.
* :func:`write_report` (:mod:`.render`) - CSV, Markdown, self-contained HTML, LaTeX (booktabs,
  longtable) and PDF, figures as PNG and SVG, written atomically.
* :func:`collect_provenance` (:mod:`.provenance`) - versions, parameters, seeds, hashes.
* :func:`make_report` (:mod:`.pipeline`) - everything ``pidcore report`` does.
* Figures: :mod:`.figures` (model families, paper Figs. 8-14) and :mod:`.comparison_figures`.

Public API
----------
make_report, ReportResult
    Everything ``pidcore report`` does, as a function; what it wrote.
analyze_files, MeasuredResult
    Files analysed with their load cases (the first step of a report).
build_report_table, REPORT_COLUMNS, ALIGNMENT_COLUMN
    The Table 3-style comparison (a pandas frame whose columns name their units).
REPORT_COLUMNS_RENAMED
    Old column name -> new, for a report.csv of an earlier pidcore.
write_report, parse_formats, RENDERERS, REPORT_MARKER
    The report files (CSV, Markdown, HTML, LaTeX, PDF).
collect_provenance, Provenance
    Versions, parameters, seeds and hashes behind a report (the hashes:
    :func:`pidcore.io.file_sha256`).
open_verified_store
    A store opened and verified (one-line error if corrupt).
"""

from .pipeline import MeasuredResult, ReportResult, analyze_files, make_report, open_verified_store
from .provenance import Provenance, collect_provenance
from .render import RENDERERS, REPORT_MARKER, parse_formats, write_report
from .table import ALIGNMENT_COLUMN, REPORT_COLUMNS, REPORT_COLUMNS_RENAMED, build_report_table

__all__ = [
    "ALIGNMENT_COLUMN", "RENDERERS", "REPORT_COLUMNS", "REPORT_COLUMNS_RENAMED", "REPORT_MARKER",
    "MeasuredResult",
    "Provenance", "ReportResult", "analyze_files", "build_report_table", "collect_provenance",
    "make_report", "open_verified_store", "parse_formats", "write_report",
]
