"""The README and docs/ stay true to the code in what can be checked without running anything:
every command they show parses with today's CLI, every option they name exists, every link and
anchor resolves, and the tables of sidecar columns and specimen keys name exactly what the
readers take (drift that a reader only finds when a copied command fails)."""

from __future__ import annotations

import argparse
import re
import shlex
import subprocess
from pathlib import Path

import pytest

from pidcore.cli import build_parser
from pidcore.compare.loadcase import (
    ANALYSIS_SETTINGS_COLUMNS,
    FREE_TEXT_COLUMNS,
    SPECIMEN_COLUMN,
)
from pidcore.specimen import PAIR_NAMES, SCHEMA

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def _shipped(paths: list[Path]) -> list[Path]:
    """``paths`` less those git ignores: a study script's output (docs/physics_audit's
    report.md, written by run_all.sh into an ignored folder) is no page of the project, and a
    link it holds to files of its run was checked as one."""
    if not paths or not (ROOT / ".git").exists():
        return paths
    try:
        listed = subprocess.run(["git", "check-ignore", "--stdin"], cwd=ROOT, text=True,
                                capture_output=True, timeout=60,
                                input="\n".join(str(p.relative_to(ROOT)) for p in paths))
    except (OSError, subprocess.SubprocessError):
        return paths  # no git: a clean checkout holds no ignored output anyway
    ignored = {ROOT / line for line in listed.stdout.splitlines() if line}
    return [p for p in paths if p not in ignored]


DOCS = _shipped(sorted((ROOT / "docs").rglob("*.md")))
SAMPLE_NOTES = _shipped(sorted((ROOT / "data_samples").rglob("README.md")))
PAGES = [README, *DOCS, *SAMPLE_NOTES]


def _ids(pages: list[Path]) -> list[str]:
    return [str(p.relative_to(ROOT)) for p in pages]


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _all_parsers(parser: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    out = [parser]
    for sub in _subparsers(parser).values():
        out.extend(_all_parsers(sub))
    return out


def _options(parser: argparse.ArgumentParser) -> set[str]:
    return {o for action in parser._actions for o in action.option_strings}


@pytest.fixture(scope="module")
def parser() -> argparse.ArgumentParser:
    return build_parser()


def _shown_commands(text: str) -> list[str]:
    """``pidcore ...`` command lines of the page's code blocks (continuations joined;
    comments, ``&&``/``;`` chains and output redirections split off); usage synopses
    (``[--x]``, ``(a | b)``) are not commands."""
    commands = []
    for block in re.findall(r"```[a-z]*\n(.*?)```", text, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            line = re.split(r"\s#", line)[0].strip()
            for part in re.split(r"&&|;", line):
                # an output redirection is the shell's, not the command's
                part = re.split(r"\s\d?>>?\s", part)[0].strip()
                if part.startswith("pidcore ") and not re.search(r"[\[\]|]|\(--", part):
                    commands.append(part)
    return commands


@pytest.mark.parametrize("page", PAGES, ids=_ids(PAGES))
def test_every_command_shown_parses_with_the_cli(page, parser):
    # a renamed or removed option, or a value a choice no longer takes, fails here rather
    # than in the hands of a user who copied the command
    refused = []
    for command in _shown_commands(page.read_text(encoding="utf-8")):
        try:
            parser.parse_args(shlex.split(command)[1:])
        except SystemExit:
            refused.append(command)
    assert refused == []


def test_readme_shows_commands_of_every_subcommand():
    # the parse test above is only as good as what it finds: the README's blocks hold
    # analyze, dem run/sweep, specimen check, report and calibrate commands
    shown = {" ".join(c.split()[:2]) for c in _shown_commands(README.read_text("utf-8"))}
    assert {"pidcore analyze", "pidcore dem", "pidcore specimen", "pidcore report",
            "pidcore calibrate", "pidcore app"} <= shown


def _script_options(folder: Path) -> set[str]:
    """Options of the docs' own scripts (``docs/physics_study.py --plot-only``)."""
    return {m for script in folder.rglob("*.py")
            for m in re.findall(r"add_argument\(\s*[\"'](--[a-z][a-z0-9-]*)", script.read_text(
                encoding="utf-8", errors="replace"))}


@pytest.mark.parametrize("page", PAGES, ids=_ids(PAGES))
def test_every_option_named_exists(page, parser):
    known = set().union(*(_options(p) for p in _all_parsers(parser)))
    known |= _script_options(ROOT / "docs")
    text = page.read_text(encoding="utf-8")
    named = set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", text))
    assert sorted(named - known) == []


@pytest.mark.parametrize("page", PAGES, ids=_ids(PAGES))
def test_inline_commands_name_options_of_their_own_subcommand(page, parser):
    # `pidcore report --calibration-key` must be an option of report, not of some other command
    wrong = []
    for span in re.findall(r"`(pidcore [^`]+)`", page.read_text(encoding="utf-8")):
        words = span.split()[1:]
        subs = [parser]
        # `dem run/sweep --x`: the option of each
        while words and all(w in _subparsers(subs[0]) for w in words[0].split("/")):
            subs = [_subparsers(subs[0])[w] for w in words.pop(0).split("/")]
        if subs == [parser]:
            continue
        options = {w.split("=")[0] for w in words if w.startswith("--")}
        wrong += [f"{span}: {o}" for sub in subs for o in sorted(options - _options(sub))]
    assert wrong == []


def _anchors(page: Path) -> set[str]:
    """GitHub's heading anchors of a Markdown page."""
    out, seen = set(), {}
    for line in page.read_text(encoding="utf-8").splitlines():
        m = re.match(r"#+\s+(.*)", line)
        if not m:
            continue
        slug = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


@pytest.mark.parametrize("page", PAGES, ids=_ids(PAGES))
def test_every_link_and_anchor_resolves(page):
    broken = []
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue  # a web address: not checked offline
        path, _, anchor = target.partition("#")
        resolved = (page.parent / path) if path else page
        if not resolved.exists():
            broken.append(target)
        elif anchor and anchor not in _anchors(resolved):
            broken.append(target)
    assert broken == []


@pytest.mark.parametrize("page", PAGES, ids=_ids(PAGES))
def test_every_repository_path_named_exists(page):
    # `tests/test_x.py`, `pidcore/dem/bench_reference.py`, `data_samples/...` in prose
    text = page.read_text(encoding="utf-8")
    missing = []
    for path in re.findall(
            r"`((?:docs|tests|pidcore|data_samples|app|\.ci|\.streamlit)/[^`\s]*)`", text):
        if any(c in path for c in "*…<") or "..." in path:
            continue
        if not (ROOT / path.rstrip("/")).exists():
            missing.append(path)
    assert missing == []


def _table(text: str, header: str) -> list[str]:
    """First cells of the Markdown table starting with ``header``."""
    start = text.index(header)
    rows = text[start:text.index("\n\n", start)].splitlines()[2:]
    return [row.split("|")[1] for row in rows]


def test_readme_sidecar_table_names_exactly_the_columns_read():
    # one more column in the reader, or one the reader no longer takes, shows here
    cells = _table(README.read_text(encoding="utf-8"),
                   "| column | meaning (option it stands for) |")
    documented = {name for cell in cells for name in re.findall(r"`([^`]+)`", cell)}
    assert documented == {*ANALYSIS_SETTINGS_COLUMNS, SPECIMEN_COLUMN, *FREE_TEXT_COLUMNS}


def test_readme_specimen_table_names_no_key_the_reader_refuses():
    # the other direction (every key documented) is test_specimen_runs'
    cells = _table(README.read_text(encoding="utf-8"), "| key | unit | meaning |")
    sections = {"cell", "coupon", "particles", "pairs", "provenance",
                *(f"pairs.{p}" for p in PAIR_NAMES)}
    keys = {k for section in SCHEMA.values() for k in section}
    stale = []
    for cell in cells:
        for span in re.findall(r"`([^`]+)`", cell):
            for word in re.sub(r"\[([^\]]+)\]", r" \1 ", span).split():
                if word not in keys | sections:
                    stale.append(word)
    assert stale == []


DOC_SCRIPTS = sorted((ROOT / "docs").rglob("*.py"))


@pytest.mark.parametrize("script", DOC_SCRIPTS, ids=_ids(DOC_SCRIPTS))
def test_docs_scripts_import_what_exists(script):
    # docs/physics_audit/dem2.py imported _Incline from a test module that had moved it to
    # tests/_incline.py: run_all.sh, which the audit's README says repeats everything, stopped
    # there. Only pidcore's and the tests' modules are checked (the docs' own are scripts).
    import ast
    import importlib

    tests_dir = Path(__file__).resolve().parent
    missing = []
    for node in ast.walk(ast.parse(script.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            module, names = node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            module, names = None, [a.name for a in node.names]
        else:
            continue
        for target, name in ([(module, n) for n in names] if module else
                             [(n, None) for n in names]):
            top = target.split(".")[0]
            if top != "pidcore" and not (tests_dir / f"{top}.py").exists():
                continue
            try:
                found = importlib.import_module(target)
            except ImportError:
                missing.append(target)
                continue
            if name is not None and not hasattr(found, name):
                try:
                    importlib.import_module(f"{target}.{name}")
                except ImportError:
                    missing.append(f"{target}.{name}")
    assert missing == []


AUDIT = ROOT / "docs" / "physics_audit"


@pytest.mark.parametrize("name", ["paper", "steel", "wc", "pom", "wc_tiny", "wc_full"])
def test_physics_audit_reference_agrees_with_specimen_check(name):
    # docs/physics_audit/README.md: ref.py's first-principles numbers differ from `specimen
    # check` by at most 3e-16; its overlap was of a 0.3 m/s impact under the name of specimen
    # check's hardest-impact overlap and read +229 %. 1e-12 leaves round-off of a few
    # operations (the README's 3e-16) and catches any change of a formula or its inputs.
    import importlib.util

    from pidcore.specimen import describe, load_specimen

    spec = importlib.util.spec_from_file_location("physics_audit_ref", AUDIT / "ref.py")
    ref = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ref)
    mine, _ = ref.ref(str(AUDIT / f"{name}.toml"))
    described = describe(load_specimen(AUDIT / f"{name}.toml"))
    compared = {k: (described[k], v) for k, v in mine.items() if k in described}
    assert len(compared) >= 12  # masses, stiffnesses, overlaps, speeds, times, gaps
    off = {k: (p, r) for k, (p, r) in compared.items() if p != pytest.approx(r, rel=1e-12)}
    assert off == {}


def test_every_cli_option_is_named_in_the_docs(parser):
    # `pidcore app --print-command`, `model figures --log-frequency`, `samples make
    # --skip-sweep` and the bench sizes were in --help only: a user reading the README did not
    # learn they exist. The other direction (every option named exists) is tested above.
    named = set()
    for page in PAGES:
        named |= set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", page.read_text("utf-8")))
    unnamed = sorted(o for p in _all_parsers(parser) for o in _options(p)
                     if o.startswith("--") and o not in {"--help", "--version"}
                     and o not in named)
    assert unnamed == []


def test_readme_quotes_the_main_jobs_measured_sdcs_and_calibrated_bands():
    # README's first paragraph: the bundled exports' SDCs and the calibrated DEM's band at their
    # load cases, as the main job's report gives them (each band that of a measurement with
    # the row's own stderr and degrees of freedom). It said upper bounds 0.43-0.89; the
    # report's are 0.43-0.90. Compared at the README's own digits.
    from pidcore.calibrate import load_calibration
    from pidcore.dem import LoadCase
    from pidcore.measure import AnalysisOptions, analyze_file

    text = " ".join(README.read_text(encoding="utf-8").split())
    quoted = re.search(r"their SDCs \(([\d.]+)–([\d.]+)\).*?predictions ([\d.]+)–([\d.]+), "
                       r"upper bounds ([\d.]+)–([\d.]+) at", text)
    assert quoted is not None
    calibration = load_calibration(ROOT / "data_samples" / "paper_calibration")
    sdcs, predicted, upper = [], [], []
    for export in sorted((ROOT / "data_samples" / "exports").iterdir()):
        # data_samples/loadcases.csv: 50 % fill and a 50 µs vibrometer delay for every file
        analysis = analyze_file(export, AnalysisOptions(velocity_delay_s=50e-6)).analysis
        prediction = calibration.lookup(LoadCase(analysis.frequency_hz,
                                                 analysis.acceleration_g, 50.0))
        sdcs.append(analysis.sdc)
        predicted.append(prediction.sdc)
        upper.append(prediction.band(analysis.sdc_stderr, analysis.sdc_stderr_dof)[1])

    def shown(values, digits):
        return [f"{min(values):.{digits}f}", f"{max(values):.{digits}f}"]

    assert list(quoted.groups()) == [*shown(sdcs, 1), *shown(predicted, 2), *shown(upper, 2)]


def test_measurement_page_quotes_the_bundled_exports_loss_factors_as_analysed_today():
    # docs/measurement.md's table of the drift model's moves: the "after" loss factor of each
    # bundled export (50 µs delay, as data_samples/loadcases.csv states) and the MAT sample's
    # SDC, as `pidcore analyze --sidecar data_samples/loadcases.csv` prints them. It said
    # SDC 4.091 for 0.651017, whose 2 pi x is 4.0905 (printed 4.09046). Compared at the page's
    # own digits; data_samples/README.md's 4.09 (with the delay) and 2.81 (without) as well.
    from pidcore.measure import AnalysisOptions, analyze_file

    page = (ROOT / "docs" / "measurement.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (f\d+Hz_a\d+g) \([^)]*\) \| [\d.]+ → ([\d.]+)(?: \(SDC [\d.]+ → "
                      r"([\d.]+)\))? \|", page, re.M)
    assert len(rows) == 5
    exports = ROOT / "data_samples" / "exports"
    for case, loss_factor, sdc in rows:
        export, = exports.glob(f"synthetic_{case}_fill50_*")
        analysis = analyze_file(export, AnalysisOptions(velocity_delay_s=50e-6)).analysis
        assert f"{analysis.loss_factor:.6f}" == loss_factor, export.name
        if sdc:
            assert f"{analysis.sdc:.3f}" == sdc, export.name
    notes = " ".join((ROOT / "data_samples" / "README.md").read_text(encoding="utf-8").split())
    quoted = re.search(r"MAT sample: SDC ([\d.]+); without the delay it would be ([\d.]+)\)",
                       notes)
    mat, = exports.glob("*.mat")
    shown = [f"{analyze_file(mat, AnalysisOptions(velocity_delay_s=delay)).analysis.sdc:.2f}"
             for delay in (50e-6, 0.0)]
    assert quoted is not None and list(quoted.groups()) == shown


def test_readme_quotes_steel_6mm_time_steps_as_specimen_check_and_dem_run_print_them():
    # README's specimen section: the automatic step at 50 Hz, 10 g (specimen check) and at
    # 500 Hz, 5 g, and the dt `dem run` prints at both. It said dem run prints 6.98e-7 s at
    # 500 Hz, 5 g; it printed 6.793e-07 (the step shortened to whole steps per sample).
    from pidcore.dem.simulate import DemConfig, LoadCase, choose_time_step, drive_sampling
    from pidcore.specimen import contact_law, load_specimen

    text = " ".join(README.read_text(encoding="utf-8").split())
    quoted = re.search(r"([\d.e-]+) s here is ([\d.e-]+) s at 500 Hz, 5 g for `steel_6mm`;.*?"
                       r"prints that step as `dt`: ([\d.e-]+) s at 50 Hz, 10 g, ([\d.e-]+) s at "
                       r"500 Hz, 5 g;", text)
    assert quoted is not None
    steel = load_specimen(ROOT / "data_samples" / "specimens" / "steel_6mm.toml")
    law, geometry = contact_law(steel), steel.geometry()
    automatic, run = [], []
    for frequency_hz, acceleration_g in ((50.0, 10.0), (500.0, 5.0)):
        case = LoadCase(frequency_hz, acceleration_g, 50.0, material="steel")
        automatic.append(choose_time_step(case, law, geometry, "auto"))
        run.append(drive_sampling(case, automatic[-1], DemConfig().samples_per_cycle)[1])
    assert list(quoted.groups()) == [f"{value:.2e}".replace("e-0", "e-")
                                     for value in (*automatic, *run)]


def test_calibration_page_shows_the_bundled_calibrations_own_tables():
    # docs/calibration.md's "The chosen model" tables (posterior, correlations, in-sample,
    # leave-one-out, energy check) are data_samples/paper_calibration/summary.md's: its energy
    # rows at 500 and 1000 Hz / 1 g were of the 21-node grid (3.92e-10, 1.43e-09, 4.55e-10)
    # after the bundled calibration was regenerated with 31 (3.94e-10, 1.45e-09, 4.56e-10).
    page = (ROOT / "docs" / "calibration.md").read_text(encoding="utf-8")
    section = page[page.index("### The chosen model"):page.index("### Time")]
    summary = set((ROOT / "data_samples" / "paper_calibration" / "summary.md")
                  .read_text(encoding="utf-8").splitlines())
    rows = [line for line in section.splitlines() if line.startswith("|")]
    assert len(rows) > 40  # four tables of 12 load cases and the posterior's two
    assert [row for row in rows if row not in summary] == []


def test_physics_audit_outputs_stay_out_of_git():
    # run_all.sh writes its results beside itself; round 14's r14_store.h5 (a 14 MB copy of
    # the bundled store), r14_rep/ and r14_damp/ showed up in `git status` after a run
    import fnmatch

    script = (AUDIT / "run_all.sh").read_text(encoding="utf-8")
    written = set(re.findall(r"(?:>|--out|--store|mkdir -p)\s+([\w$./-]+)", script))
    written |= set(re.findall(r"^cp \S+ ([\w./-]+)$", script, re.M))
    written = {w.replace("$s", "paper").split("/")[0] for w in written
               if not w.startswith(("/", "..", "&"))}
    patterns = [line.strip().rstrip("/") for line in
                (AUDIT / ".gitignore").read_text(encoding="utf-8").splitlines()
                if line.strip() and not line.startswith("#")]
    assert {"r14_store.h5", "r14_rep", "damper"} <= written  # the parse finds them
    assert sorted(w for w in written
                  if not any(fnmatch.fnmatch(w, p) for p in patterns)) == []


def test_report_store_option_says_it_has_no_default(parser):
    # analyze and dem sweep default to ./pid_store.h5; report does not read or write it
    # unless named: a user who swept into ./pid_store.h5 got `no_dem_runs` rows from
    # `report FILES --out DIR`, and neither --help nor the README said why
    report = _subparsers(parser)["report"]
    store = next(a for a in report._actions if "--store" in a.option_strings)
    assert store.default is None and "no default" in store.help
    readme = " ".join(README.read_text(encoding="utf-8").split())
    assert "(`--store` has no default here, unlike `analyze` and `dem sweep`" in readme


def _specimen_section() -> str:
    text = README.read_text(encoding="utf-8")
    start = text.index("### Specimen files")
    return text[start:text.index("\n### ", start + 1)]


def test_readme_specimen_section_lists_every_command_taking_specimen(parser):
    # the section named `dem run`, `dem sweep` and `report` only; `analyze` and `calibrate`
    # take --specimen too, and a user reading it did not know they could name their specimen
    taking = {p.prog for p in _all_parsers(parser) if "--specimen" in _options(p)}
    assert {"pidcore analyze", "pidcore calibrate"} <= taking  # the two left out before
    rows = _table(_specimen_section(), "| command | what `--specimen FILE` does there |")
    listed = {cell.strip().strip("`") for cell in rows}
    assert listed == taking


def test_own_specimen_exports_are_pointed_to_from_readme_and_samples_help(parser):
    # neither the README nor `pidcore samples --help` said how to make measurement exports of
    # one's own specimen; the pattern is the trial's script
    script = "docs/trial_own_specimen/make_measurements.py"
    assert (ROOT / script).is_file()
    assert f"`{script}`" in _specimen_section()
    samples = _subparsers(parser)["samples"]
    for command in (samples, _subparsers(samples)["make"]):
        assert script in command.description, command.prog


def test_mass_convention_says_the_coupon_mass_holds_the_fixture(parser):
    # "m_c = coupon + particles" (README, --mass-convention's help): a 41 g coupon with a 120 g
    # fixture divided by 0.395 kg, not the 0.275 kg the words gave, and the user's hand check
    # of E (Eq. 10) was off by 44 %; both now name the fixture
    from pidcore.specimen import load_specimen

    steel = load_specimen(ROOT / "data_samples" / "specimens" / "steel_6mm.toml")
    assert steel.vibrated_mass_kg(0, "coupon") == steel.coupon.mass_kg + \
        steel.coupon.fixture_mass_kg
    dem = _subparsers(_subparsers(parser)["dem"])
    for command in ("run", "sweep"):
        (action,) = [a for a in dem[command]._actions if "--mass-convention" in a.option_strings]
        assert "coupon and fixture" in action.help, command
    text = " ".join(README.read_text(encoding="utf-8").split())
    assert ("m_c = coupon + particles by default (`--mass-convention`; the coupon's mass there "
            "is the moving mass, `[coupon] mass_kg` + `fixture_mass_kg`)") in text


def test_own_specimen_section_sets_the_dem_beside_the_like_for_like_measured_column():
    # a user of heavy beads set `SDC DEM (ours)` 0.96 beside `SDC measured (Eq. 11)` 2.64 and
    # read the DEM as 2.7 x low; the like-for-like column (1.03) was named only deep in the
    # report section. The own-specimen paragraph names it, by the report's own column names.
    from pidcore.report.render import PDF_COLUMNS

    section = _specimen_section()
    start = section.index("**Measurements of your own specimen.**")
    paragraph = " ".join(section[start:section.index("\n\n", start)].split())
    assert ("set `SDC DEM (ours)` beside `SDC measured, E of Eq. 10`, not beside `SDC measured "
            "(Eq. 11)`") in paragraph
    for name in ("SDC DEM (ours)", "SDC measured, E of Eq. 10", "SDC measured (Eq. 11)"):
        assert f"{name} [-]" in PDF_COLUMNS, name


def test_readme_specimen_section_counts_the_commands_it_lists():
    # "given as `--specimen FILE` to the six commands below" sat over a table of seven (model
    # damper and figures joined it); the number written must be the table's row count
    words = {"five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}
    text = " ".join(_specimen_section().split())
    said = re.search(r"given as `--specimen FILE` to the (\w+) commands below", text)
    assert said is not None
    rows = _table(_specimen_section(), "| command | what `--specimen FILE` does there |")
    assert words.get(said.group(1)) == len(rows)


def test_readme_sweep_json_names_every_stored_result_of_a_case():
    # `dem sweep --json` gives each case SWEEP_CASE_FIELDS from its stored run; the README's
    # list of "the stored results" left out `sdc_stderr_dof`, which a script needs to judge
    # the run's standard error (Student's t of cells - 1)
    from pidcore.dem.sweep import SWEEP_CASE_FIELDS

    text = " ".join(README.read_text(encoding="utf-8").split())
    listed = re.search(r"and the stored results \((.*?), as the text output's summary line", text)
    assert listed is not None
    assert set(re.findall(r"`(\w+)`", listed.group(1))) == set(SWEEP_CASE_FIELDS)
