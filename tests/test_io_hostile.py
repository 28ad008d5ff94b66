"""Hostile and broken measurement files: every one is refused with one line naming the file and
what was expected (an InputFileError, exit code 2 in the CLI), never a traceback and never a
number computed from samples the file does not hold (complex parts dropped, a matrix flattened).
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from _peak_memory import read_peak_memory

from pidcore.cli import main
from pidcore.errors import InputFileError
from pidcore.io import read_measurement

SAMPLE_H5 = (Path(__file__).resolve().parents[1] / "data_samples" / "exports"
             / "synthetic_f1000Hz_a5g_fill50_acrylic.h5")


def _replace_channel(h5: h5py.File, make) -> None:
    """Replace the velocity channel ``/channels/001`` by ``make(channels, samples)``, keeping
    its attributes."""
    channels = h5["channels"]
    attrs, samples = dict(channels["001"].attrs), channels["001"][()]
    del channels["001"]
    new = make(channels, samples)
    for name, value in attrs.items():
        new.attrs[name] = value


def _enum(ch, v):
    return ch.create_dataset("001", data=np.zeros(v.size, "i1"),
                             dtype=h5py.enum_dtype({"A": 0, "B": 1}, basetype="i1"))


def _refs(ch, v):
    ds = ch.create_dataset("001", (10,), dtype=h5py.ref_dtype)
    for i in range(10):
        ds[i] = ch["000"].ref
    return ds


def _plugin_filter(ch, v):
    """The samples in chunks that declare filter 32099 (no such filter is built in): reading
    them makes HDF5 search its plugin directories for a library to load."""
    ds = ch.create_dataset("001", v.shape, "f8", chunks=v.shape, compression=32099,
                           allow_unknown_filter=True)
    ds.id.write_direct_chunk((0,), np.ascontiguousarray(v, "<f8").tobytes(), filter_mask=0)
    return ds


def _set_attr(name, value):
    def edit(h5):
        h5["channels"]["001"].attrs[name] = value
    return edit


HOSTILE_HDF5 = {
    "complex": (lambda h5: _replace_channel(
        h5, lambda ch, v: ch.create_dataset("001", data=v * (1 + 1j))), "complex numbers"),
    "matrix": (lambda h5: _replace_channel(
        h5, lambda ch, v: ch.create_dataset("001", data=np.stack([v, v]))), "shape (2, "),
    "text": (lambda h5: _replace_channel(
        h5, lambda ch, v: ch.create_dataset("001", data=np.array([b"abc"] * 99))), "text"),
    "compound": (lambda h5: _replace_channel(
        h5, lambda ch, v: ch.create_dataset("001", data=np.zeros(
            v.size, [("re", "f8"), ("im", "f8")]))), "compound"),
    "enum": (lambda h5: _replace_channel(h5, _enum), "enumerated"),
    "plugin filter": (lambda h5: _replace_channel(h5, _plugin_filter),
                      "HDF5 filter 32099, which is not built in"),
    "references": (lambda h5: _replace_channel(h5, _refs), "references"),
    "vlen": (lambda h5: _replace_channel(h5, lambda ch, v: ch.create_dataset(
        "001", (3,), dtype=h5py.vlen_dtype("f8"))), "variable-length"),
    "no samples": (lambda h5: _replace_channel(
        h5, lambda ch, v: ch.create_dataset("001", (0,), "f8")), "holds no samples"),
    "rate text": (_set_attr("sample_rate_hz", "fast"), "sample_rate_hz is 'fast'"),
    "rate nan": (_set_attr("sample_rate_hz", np.nan), "sample_rate_hz is"),
    "rate array": (_set_attr("sample_rate_hz", np.array([1.0, 2.0])), "sample_rate_hz is"),
    "start inf": (_set_attr("start_time_s", np.inf), "start_time_s is"),
    "dangling soft link": (lambda h5: h5["channels"].__setitem__(
        "003", h5py.SoftLink("/nowhere")), "a link to nothing"),
    "group as channel": (lambda h5: h5["channels"].create_group("003"), "is a group"),
    "channels a dataset": (lambda h5: (h5.__delitem__("channels"),
                                       h5.create_dataset("channels", data=np.arange(5))),
                           "not a pidcore measurement group"),
    "metadata a list": (lambda h5: h5.attrs.__setitem__("metadata_json", "[1, 2]"),
                        "expected a JSON object"),
    "reader notes a number": (lambda h5: h5.attrs.__setitem__(
        "metadata_json", '{"reader_notes": 5}'), "reader_notes"),
}


def _refused_in_one_line(path: Path, expected: str, capsys) -> None:
    """The reader refuses ``path`` naming it and saying ``expected``; `pidcore analyze` says
    it in one line, exit 2, without the CSV-only --sample-rate advice."""
    with pytest.raises(InputFileError, match=re.escape(path.name)) as info:
        read_measurement(path)
    assert expected in str(info.value)
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected in err and "--sample-rate" not in err


@pytest.mark.parametrize("case", list(HOSTILE_HDF5))
def test_hostile_hdf5_channel_is_one_line_error(tmp_path, capsys, case):
    edit, expected = HOSTILE_HDF5[case]
    path = tmp_path / "upload.h5"
    shutil.copy(SAMPLE_H5, path)
    with h5py.File(path, "r+") as h5:
        edit(h5)
    _refused_in_one_line(path, expected, capsys)


# --- MATLAB ------------------------------------------------------------------------------------

_FS = 25600.0
_T = np.arange(2560) / _FS
_F = np.sin(2 * np.pi * 100 * _T)
_V = 0.01 * np.sin(2 * np.pi * 100 * _T - 1.2)


def _pidcore_mat(force_data=_F, rate=_FS):
    scipy_io = pytest.importorskip("scipy.io")
    cells = np.array([{"name": "Force", "quantity": "force", "data": force_data,
                       "sample_rate_hz": rate},
                      {"name": "Velocity", "quantity": "velocity", "data": _V,
                       "sample_rate_hz": _FS}], dtype=object)
    return lambda path: scipy_io.savemat(path, {"pidcore_layout": "measurement",
                                                "pidcore_channels": cells})


def _lms_mat(values, **x_values):
    scipy_io = pytest.importorskip("scipy.io")
    signal = {"x_values": {"start_value": 0.0, "increment": 1 / _FS, **x_values},
              "y_values": {"values": values, "quantity": {"unit": "N"}}}
    return lambda path: scipy_io.savemat(path, {"Signal": signal})


def _simple_mat(**variables):
    scipy_io = pytest.importorskip("scipy.io")
    return lambda path: scipy_io.savemat(path, {"Force": _F, "Velocity": _V, **variables})


def _v73(edit):
    def write(path):
        with h5py.File(path, "w", userblock_size=512) as h5:
            for name, data in (("time", _T), ("Force", _F), ("Velocity", _V)):
                h5[name] = data
                h5[name].attrs["MATLAB_class"] = np.bytes_("double")
            edit(h5)
        with open(path, "r+b") as fh:
            fh.write(b"MATLAB 7.3 MAT-file".ljust(128))
    return write


def _self_reference(h5):
    ds = h5.create_dataset("c", (1,), dtype=h5py.ref_dtype)
    ds[0] = ds.ref


def _bad_char(h5):
    h5["name"] = np.array([0x110000, 65], dtype="u4")
    h5["name"].attrs["MATLAB_class"] = np.bytes_("char")


HOSTILE_MAT = {
    # complex samples: the imaginary part was dropped and an SDC printed (exit 0)
    "pidcore layout complex": (_pidcore_mat(_F * (1 + 1j)), "complex numbers"),
    # a matrix in one channel was flattened into one record and analysed (exit 0)
    "pidcore layout matrix": (_pidcore_mat(np.c_[_F, _F]), "expected one vector"),
    "pidcore layout text": (_pidcore_mat("abc"), "samples are text"),
    "pidcore layout rate nan": (_pidcore_mat(rate=np.nan), "field sample_rate_hz is nan"),
    "Test.Lab complex": (_lms_mat(np.c_[_F, _V] * (1 + 1j)), "complex numbers"),
    "Test.Lab negative count": (_lms_mat(np.c_[_F, _V], number_of_values=-3),
                                "number_of_values is -3"),
    "Test.Lab start inf": (_lms_mat(np.c_[_F, _V], start_value=np.inf), "start_value is inf"),
    # an infinite sample interval passed "> 0" and made a 0 Hz sample rate
    "Test.Lab increment inf": (_lms_mat(np.c_[_F, _V], increment=np.inf),
                               "x_values.increment is inf"),
    "Test.Lab increment text": (_lms_mat(np.c_[_F, _V], increment="abc"),
                                "x_values.increment is 'abc'"),
    "rate text": (_simple_mat(fs="fast"), "variable fs is 'fast'"),
    "rate nan": (_simple_mat(fs=np.nan), "variable fs is nan"),
    "v7.3 reference to itself": (_v73(_self_reference), "deeper than"),
    "v7.3 null reference": (_v73(lambda h5: h5.create_dataset("c", (1,), dtype=h5py.ref_dtype)),
                            "invalid reference"),
    "v7.3 char out of range": (_v73(_bad_char), "no characters"),
    "v7.3 dangling soft link": (_v73(lambda h5: h5.__setitem__("s", h5py.SoftLink("/nowhere"))),
                                "link to nothing"),
}


@pytest.mark.parametrize("case", list(HOSTILE_MAT))
def test_hostile_mat_is_one_line_error(tmp_path, capsys, case):
    write, expected = HOSTILE_MAT[case]
    path = tmp_path / "upload.mat"
    write(path)
    _refused_in_one_line(path, expected, capsys)


# --- whatever a reader lets out ----------------------------------------------------------------


@pytest.mark.parametrize("error", [ValueError("could not convert"), KeyError("component"),
                                   RecursionError("maximum recursion depth"),
                                   TypeError("float() argument")])
def test_an_exception_a_reader_lets_out_is_one_line_naming_the_file(tmp_path, capsys,
                                                                     monkeypatch, error):
    """Readers check what they know of; a case they miss must still be a one-line error (exit
    2) naming the file, not a traceback (exit 1)."""
    import pidcore.io as io

    def broken_reader(path, **kwargs):
        raise error

    path = tmp_path / "run.csv"
    path.write_text("Time [s],Force [N]\n0,1\n")
    monkeypatch.setattr(io, "read_csv", broken_reader)
    with pytest.raises(InputFileError, match=r"run\.csv: not a readable csv measurement file"):
        read_measurement(path)
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run.csv" in err and type(error).__name__ in err


def test_ctrl_c_inside_a_reader_stays_an_interruption(tmp_path, monkeypatch):
    import pidcore.io as io

    def interrupted(path, **kwargs):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise Exception("pyuff wraps it") from None  # noqa: TRY002 (as pyuff does)

    path = tmp_path / "run.csv"
    path.write_text("Time [s],Force [N]\n0,1\n")
    monkeypatch.setattr(io, "read_csv", interrupted)
    with pytest.raises(KeyboardInterrupt):
        read_measurement(path)


# --- numbers the analysis cannot square ----------------------------------------------------------


@pytest.mark.parametrize("velocity_scale", [1.0, 1e306])
def test_samples_beyond_any_physical_value_are_refused_not_overflowed(tmp_path, capsys,
                                                                      velocity_scale):
    """A CSV of finite but absurd values (1e306 N) overflowed the products of the analysis:
    it was refused as an inverted channel (Im(P_c) <= 0), or, with both columns that large,
    the spectrum's squares became NaN and it ended in a traceback ('cannot convert float NaN
    to integer')."""
    rows = "\n".join(f"{t:.17g},{f * 1e306:.17g},{v * velocity_scale:.17g}"
                     for t, f, v in zip(_T, _F, _V, strict=True))
    path = tmp_path / "huge.csv"
    path.write_text("Time [s],Force [N],Velocity [m/s]\n" + rows + "\n")
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "huge.csv: channel 'Force'" in err and "above 1e+100" in err


# --- a CSV of one enormous line ------------------------------------------------------------------


def test_a_line_longer_than_any_row_is_refused_before_pandas_buffers_it(tmp_path):
    """A CSV with one 40 MiB line (500 MB in the report) was tokenised whole by pandas,
    holding ~3.3x the file in memory (1.6 GB for 500 MB) before its 'Expected 3 fields'
    error; the line is now found by a streaming scan and refused naming it."""
    path = tmp_path / "one_line.csv"
    with open(path, "w", encoding="ascii") as fh:
        fh.write("Time [s],Force [N],Velocity [m/s]\n")
        fh.writelines(f"{i / 1000!r},{i % 7},{i % 5}\n" for i in range(200))
        chunk = "0.1,0.2,0.3," * 10_000
        fh.writelines(chunk for _ in range(40 * 2**20 // len(chunk)))
        fh.write("\n")
    grown, message = read_peak_memory(path)
    assert grown < path.stat().st_size / 4, (grown, path.stat().st_size, message)
    assert "one_line.csv: line 202 is longer than 16 MiB" in message


def test_long_files_of_ordinary_lines_pass_the_line_scan(tmp_path):
    """The scan runs only on files above the limit; LF, CRLF and CR files of short lines pass,
    and the line named is counted in the file's own line breaks."""
    from pidcore.io import delimited

    for newline in ("\n", "\r\n", "\r"):
        path = tmp_path / "rows.csv"
        path.write_bytes(("1,2,3" + newline).encode() * (4 * 2**20))  # 24-28 MiB
        delimited._check_line_lengths(path, "rows.csv")
        path.write_bytes(("1,2,3" + newline).encode() * 10 + b"9" * (17 * 2**20))
        with pytest.raises(InputFileError, match="rows.csv: line 11 is longer than 16 MiB"):
            delimited._check_line_lengths(path, "rows.csv")


# --- UFF ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("count", ["-5120", "    0"])
def test_uff_record_declaring_no_samples_names_the_field(tmp_path, capsys, count):
    """A UFF58 record 7 declaring -5120 samples kept all samples but 5120 (here none) and was
    refused as 'the channels do not overlap in time (start times 0 s, 0 s)'."""
    from pidcore.io import write_measurement
    from pidcore.records import Channel, Measurement

    path = tmp_path / "run.uff"
    write_measurement(Measurement("run.uff", (Channel("Force", "force", _F, _FS, "N"),
                                              Channel("Velocity", "velocity", _V, _FS, "m/s"))),
                      path)
    text = path.read_text()
    assert text.count("      2560         1") == 2
    path.write_text(text.replace("      2560         1", f"     {count}         1", 1))
    with pytest.raises(InputFileError, match=f"run.uff: record 1 declares {int(count)} samples"):
        read_measurement(path)
    assert main(["analyze", str(path), "--no-store"]) == 2
    assert "declares" in capsys.readouterr().err


def test_hdf5_channels_of_one_name_are_told_apart_as_every_reader_does(tmp_path, capsys):
    """Two HDF5 channels both named 'Force' were listed as ('Force', 'Force'): '--force Force'
    took the first without a word and the second could not be chosen at all."""
    path = tmp_path / "two_forces.h5"
    shutil.copy(SAMPLE_H5, path)
    with h5py.File(path, "r+") as h5:
        first = h5["channels"]["000"]
        second = h5["channels"].create_dataset("003", data=first[()] * 2)
        for name, value in first.attrs.items():
            second.attrs[name] = value
    assert [c.name for c in read_measurement(path).channels][::3] == ["Force", "Force (2)"]
    assert main(["analyze", str(path), "--no-store"]) == 2
    assert "('Force', 'Force (2)')" in capsys.readouterr().err
    energies = []
    for force in ("Force", "Force (2)"):
        assert main(["analyze", str(path), "--no-store", "--json", "--force", force]) == 0
        energies.append(json.loads(capsys.readouterr().out)["records"][0]["energy_per_cycle_j"])
    assert energies[1] == pytest.approx(2 * energies[0])


def _v5_zeros_bomb(path, n_samples):
    """A MATLAB v5 file of one compressed variable 'Force' of ``n_samples`` zeros, written
    streaming (the zeros are never held)."""
    import struct
    import zlib

    def tag(data_type, nbytes):
        return struct.pack("<II", data_type, nbytes)

    name = tag(1, 5) + b"Force" + b"\0" * 3
    head = tag(6, 8) + struct.pack("<II", 6, 0) + tag(5, 8) + struct.pack("<ii", n_samples, 1)
    body = head + name + tag(9, 8 * n_samples)
    deflate = zlib.compressobj(1)
    parts = [deflate.compress(tag(14, len(body) + 8 * n_samples) + body)]
    zeros = bytes(1 << 22)
    for start in range(0, 8 * n_samples, len(zeros)):
        parts.append(deflate.compress(zeros[:min(len(zeros), 8 * n_samples - start)]))
    payload = b"".join([*parts, deflate.flush()])
    header = b"MATLAB 5.0 MAT-file".ljust(116) + bytes(8) + struct.pack("<H", 0x0100) + b"IM"
    path.write_bytes(header + tag(15, len(payload)) + payload)


def test_mat_v5_compressed_bomb_is_refused_before_scipy_inflates_it(tmp_path, capsys):
    """A 1.9 MB v5 file declaring 2 GB of compressed zeros made 'pidcore analyze' reach a
    2.4 GB resident set (scipy inflates every variable) before any message; HDF5 and v7.3
    uploads had this guard, v5 had not."""
    path = tmp_path / "bomb.mat"
    _v5_zeros_bomb(path, 20_000_000)  # 160 MB of float64 in a ~0.5 MB file
    assert path.stat().st_size < 2**20
    with pytest.raises(InputFileError, match=r"bomb\.mat: its variables inflate to more than"):
        read_measurement(path)
    assert main(["analyze", str(path), "--no-store"]) == 2
    assert "refused before reading" in capsys.readouterr().err


def test_mat_v5_within_the_expansion_limit_reads_as_before(tmp_path):
    path = tmp_path / "small.mat"
    _v5_zeros_bomb(path, 1000)
    pytest.importorskip("scipy.io")
    with pytest.raises(InputFileError, match="no time vector"):  # read, then judged
        read_measurement(path)


def test_a_file_variable_named_like_an_option_is_not_shown_as_the_flag(tmp_path, capsys):
    """A MAT file without a time base was told "no sample rate ('fs' or '--sample-rate')":
    the CLI rewrote the variable name sample_rate_hz into the flag, naming a variable that no
    file can hold."""
    scipy_io = pytest.importorskip("scipy.io")
    path = tmp_path / "no_rate.mat"
    scipy_io.savemat(path, {"Force": _F, "Velocity": _V})
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert "('fs' or 'sample_rate_hz')" in err and "give the sample rate (--sample-rate)" in err


@pytest.mark.parametrize("fs", [0.0, np.nan, "fast"])
def test_a_bad_file_rate_gives_way_to_the_sample_rate_given(tmp_path, capsys, fs):
    """--sample-rate overrides a plain MAT file's rate (as it overrides its time vector), but
    a file rate that is no rate (fs = 0, NaN, text) was refused even with --sample-rate given:
    'variable fs is 0.0; expected a finite positive number', with no way round it. Now the
    given rate is used and the file's value noted; without it the file is still refused."""
    path = tmp_path / "plain.mat"
    _simple_mat(fs=fs)(path)
    with pytest.raises(InputFileError, match="variable fs is"):
        read_measurement(path)
    m = read_measurement(path, sample_rate_hz=_FS)
    assert {c.sample_rate_hz for c in m.channels} == {_FS}
    assert main(["analyze", str(path), "--sample-rate", str(_FS), "--force-unit", "N",
                 "--velocity-unit", "m/s", "--fill", "50", "--no-store", "--json"]) == 0
    (rec,) = json.loads(capsys.readouterr().out)["records"]
    assert rec["frequency_hz"] == pytest.approx(100.0, rel=1e-6)
    assert any("variable fs is" in n and "(--sample-rate)" in n for n in rec["notes"])
