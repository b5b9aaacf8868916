"""Malicious and broken FMU/SSP archives: refused with one typed error naming the file and
member, nothing written outside (or left inside) the extraction folder."""

from __future__ import annotations

import copy
import io
import stat
import struct
import warnings
import zipfile
from pathlib import Path

import pytest

from bgmodelica.cosim import archive, fmu
from bgmodelica.cosim.archive import SafeZip
from bgmodelica.cosim.errors import (
    ArchiveError,
    FmuFormatError,
    SspFormatError,
    UnsafeArchiveError,
)
from bgmodelica.cosim.fmu import read_fmu_info
from bgmodelica.cosim.master import Master
from bgmodelica.cosim.ssp import ssd_xml, write_ssp
from bgmodelica.cosim.ssp_read import read_ssp
from bgmodelica.errors import ModelError

MD = b'<?xml version="1.0"?><fmiModelDescription fmiVersion="2.0"/>'
SSD = b'<?xml version="1.0"?><x/>'


def make_zip(path: Path, members: list[tuple[str | zipfile.ZipInfo, bytes]]) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # "Duplicate name" on purpose
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
            for name, data in members:
                zf.writestr(name, data)
    return path


def symlink(name: str, target: bytes = b"/etc/passwd") -> tuple[zipfile.ZipInfo, bytes]:
    info = zipfile.ZipInfo(name)
    info.create_system = 3
    info.external_attr = (stat.S_IFLNK | 0o777) << 16
    return info, target


def snapshot(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


@pytest.fixture
def unzip_root(tmp_path, monkeypatch):
    """FMU extraction (``read_fmu_info`` and the units) goes to ``tmp_path/unzip``."""
    extracted = fmu._Extracted()
    extracted.root = tmp_path / "unzip"
    extracted.root.mkdir()
    monkeypatch.setattr(fmu, "_EXTRACTED", extracted)
    return extracted.root


UNSAFE = [
    ("../evil.txt", "a '..' component"),
    ("resources/../../evil.txt", "a '..' component"),
    ("..\\evil.txt", "a '..' component"),
    ("/abs/path/evil.txt", "an absolute path"),
    ("\\abs\\evil.txt", "an absolute path"),
    ("C:/evil.txt", "a drive letter"),
    ("c:evil.txt", "a drive letter"),
]


@pytest.mark.parametrize("name, reason", UNSAFE)
def test_unsafe_member_names_in_an_fmu(tmp_path, unzip_root, name, reason):
    bad = make_zip(tmp_path / "Bad.fmu", [("modelDescription.xml", MD), (name, b"pwned")])
    before = snapshot(tmp_path)
    with pytest.raises(UnsafeArchiveError) as err:
        read_fmu_info(bad)
    msg = str(err.value)
    assert str(bad) in msg and repr(name) in msg and reason in msg and "\n" not in msg
    assert snapshot(tmp_path) == before                 # nothing written, nothing left
    assert not any(unzip_root.iterdir())
    assert not Path("/abs/path").exists() and not (tmp_path.parent / "evil.txt").exists()


@pytest.mark.parametrize("name, reason", UNSAFE[:4])
def test_unsafe_member_names_in_an_ssp(tmp_path, name, reason):
    bad = make_zip(tmp_path / "bad.ssp", [("SystemStructure.ssd", SSD), (name, b"pwned")])
    out = tmp_path / "out"
    with pytest.raises(UnsafeArchiveError, match=reason) as err:
        read_ssp(bad, out)
    assert str(bad) in str(err.value) and repr(name) in str(err.value)
    assert not out.exists() and snapshot(tmp_path) == {"bad.ssp"}


def test_symlink_member(tmp_path, unzip_root):
    bad = make_zip(tmp_path / "Link.fmu", [("modelDescription.xml", MD),
                                           symlink("resources/passwd")])
    with pytest.raises(UnsafeArchiveError, match=r"'resources/passwd' is a symbolic link"):
        read_fmu_info(bad)
    assert not any(unzip_root.iterdir())
    other = make_zip(tmp_path / "fifo.ssp", [("SystemStructure.ssd", SSD)])
    info = zipfile.ZipInfo("resources/fifo")
    info.external_attr = (stat.S_IFIFO | 0o644) << 16
    with zipfile.ZipFile(other, "a") as zf:
        zf.writestr(info, b"")
    with pytest.raises(UnsafeArchiveError, match="is a special file"):
        read_ssp(other, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_duplicate_and_conflicting_names(tmp_path):
    for members, what in [
        ([("a.txt", b"1"), ("a.txt", b"2")], "'a.txt' occurs twice"),
        ([("dir/a.txt", b"1"), ("dir//./a.txt", b"2")], "occurs twice"),
        ([("A.TXT", b"1"), ("a.txt", b"2")], "occurs twice"),
        ([("x", b"1"), ("x/y", b"2")], "'x' is both a file and the folder"),
    ]:
        path = make_zip(tmp_path / "dup.zip", members)
        with pytest.raises(UnsafeArchiveError, match=what):
            SafeZip(path).extract_all(tmp_path / "out")
        assert not (tmp_path / "out").exists()


def test_not_an_fmu_or_ssp(tmp_path, unzip_root):
    plain = make_zip(tmp_path / "plain.fmu", [("readme.txt", b"hello")])
    with pytest.raises(FmuFormatError, match=r"no modelDescription\.xml in the archive "
                                             r"\(not an FMU\)") as err:
        read_fmu_info(plain)
    assert str(plain) in str(err.value)
    plain_ssp = make_zip(tmp_path / "plain.ssp", [("readme.txt", b"hello")])
    with pytest.raises(SspFormatError, match=r"no SystemStructure\.ssd in the archive"):
        read_ssp(plain_ssp)
    text = tmp_path / "text.fmu"
    text.write_text("not a zip at all")
    with pytest.raises(FmuFormatError, match="is not an FMU archive .not a zip file"):
        read_fmu_info(text)
    with pytest.raises(FmuFormatError, match="does not exist"):
        read_fmu_info(tmp_path / "missing.fmu")
    with pytest.raises(FmuFormatError, match="not a file"):
        read_fmu_info(tmp_path)
    garbage = make_zip(tmp_path / "Garbage.fmu", [("modelDescription.xml", b"<oops")])
    with pytest.raises(FmuFormatError, match=r"modelDescription\.xml is not a valid FMI") \
            as err:
        read_fmu_info(garbage)
    assert "\n" not in str(err.value)
    assert not any(p.name.endswith(".part") for p in unzip_root.rglob("*"))


def test_truncated_archives(tmp_path, robot_fmus, unzip_root):
    data = Path(robot_fmus["Motor"]).read_bytes()
    for n in (len(data) // 2, len(data) - 10, 30):
        cut = tmp_path / "Cut.fmu"
        cut.write_bytes(data[:n])
        with pytest.raises(FmuFormatError, match="truncated or corrupt") as err:
            read_fmu_info(cut)
        assert str(cut) in str(err.value)
        ssp = tmp_path / "cut.ssp"
        ssp.write_bytes(data[:n])
        with pytest.raises(SspFormatError, match="not a zip file, or a truncated"):
            read_ssp(ssp, tmp_path / "out")
    assert not any(unzip_root.iterdir()) and not (tmp_path / "out").exists()


def _corrupt(src: Path, dst: Path, member_suffix: str) -> str:
    """Copy ``src`` with bytes flipped in the compressed data of a member."""
    data = bytearray(src.read_bytes())
    with zipfile.ZipFile(src) as zf:
        info = next(i for i in zf.infolist() if i.filename.endswith(member_suffix))
    name_len, extra_len = struct.unpack("<HH", data[info.header_offset + 26:
                                                    info.header_offset + 30])
    start = info.header_offset + 30 + name_len + extra_len
    for k in range(start + info.compress_size // 3, start + info.compress_size // 3 + 64):
        data[k] ^= 0xA5
    dst.write_bytes(bytes(data))
    return info.filename


def test_corrupt_member_leaves_nothing(tmp_path, robot_fmus, unzip_root):
    bad = tmp_path / "Motor.fmu"
    member = _corrupt(Path(robot_fmus["Motor"]), bad, ".so")
    with pytest.raises(FmuFormatError, match="is corrupt or truncated") as err:
        read_fmu_info(bad)
    assert repr(member) in str(err.value) and str(bad) in str(err.value)
    assert not any(unzip_root.iterdir())                # the staging folder is gone too


def test_declared_size_lie_is_caught(tmp_path):
    """A member that decompresses to more than its header says (CRC no longer matches)."""
    path = make_zip(tmp_path / "lie.zip", [("big.bin", b"x" * 5000)])
    data = bytearray(path.read_bytes())
    for sig, off in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):
        pos = data.index(sig)
        data[pos + off:pos + off + 4] = struct.pack("<I", 10)
    path.write_bytes(bytes(data))
    with pytest.raises(ArchiveError, match="'big.bin' is corrupt or truncated"):
        SafeZip(path).extract_all(tmp_path / "out")
    assert snapshot(tmp_path) == {"lie.zip"}


def _declare_size(path: Path, name: str, size: int) -> None:
    """Patch the uncompressed size of ``name`` in the local and central headers."""
    data = bytearray(path.read_bytes())
    raw = name.encode()
    for sig, off, name_at in ((b"PK\x03\x04", 22, 30), (b"PK\x01\x02", 24, 46)):
        pos = 0
        while True:
            pos = data.index(sig, pos)
            if data[pos + name_at:pos + name_at + len(raw)] == raw:
                data[pos + off:pos + off + 4] = struct.pack("<I", size)
                break
            pos += 4
    path.write_bytes(bytes(data))


def test_zip_bomb_declared_size(tmp_path, unzip_root):
    bomb = make_zip(tmp_path / "Bomb.fmu", [("modelDescription.xml", MD),
                                            ("resources/a.bin", b"0" * 100),
                                            ("resources/b.bin", b"0" * 100)])
    _declare_size(bomb, "resources/a.bin", 0xF0000000)
    with pytest.raises(UnsafeArchiveError, match=r"declare \d+ bytes \(3\.8 GiB\) "
                                                 r"uncompressed, more than the limit of "
                                                 r"1\.0 GiB.*zip bomb") as err:
        read_fmu_info(bomb)
    assert str(bomb) in str(err.value)
    assert not any(unzip_root.iterdir())
    ssp = make_zip(tmp_path / "bomb.ssp", [("SystemStructure.ssd", SSD),
                                           ("resources/x.fmu", b"0" * 100)])
    _declare_size(ssp, "resources/x.fmu", 0xF0000000)
    with pytest.raises(UnsafeArchiveError, match="zip bomb"):
        read_ssp(ssp, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_real_deflate_bomb_and_member_count(tmp_path, unzip_root, monkeypatch):
    bomb = make_zip(tmp_path / "Bomb.fmu", [("modelDescription.xml", MD),
                                            ("resources/zeros", bytes(8 << 20))])
    assert bomb.stat().st_size < 100_000
    monkeypatch.setattr(archive, "MAX_UNCOMPRESSED_BYTES", 1 << 20)
    with pytest.raises(UnsafeArchiveError, match="more than the limit of 1.0 MiB"):
        read_fmu_info(bomb)
    many = make_zip(tmp_path / "many.zip", [(f"f{k}", b"") for k in range(50)])
    with pytest.raises(UnsafeArchiveError, match="has 50 members, more than the limit of 10"):
        SafeZip(many, max_members=10)
    assert not any(unzip_root.iterdir())


def test_encrypted_member(tmp_path):
    path = make_zip(tmp_path / "enc.zip", [("a.txt", b"secret")])
    data = bytearray(path.read_bytes())
    for sig, off in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        pos = data.index(sig)
        data[pos + off] |= 0x1
    path.write_bytes(bytes(data))
    with pytest.raises(ArchiveError, match="'a.txt' is encrypted"):
        SafeZip(path)


def test_extraction_never_follows_links_in_the_target(tmp_path):
    """A symbolic link already in the target folder is not written through."""
    outside = tmp_path / "outside"
    outside.mkdir()
    root = tmp_path / "root"
    root.mkdir()
    (root / "resources").symlink_to(outside, target_is_directory=True)
    path = make_zip(tmp_path / "ok.zip", [("resources/x.fmu", b"data")])
    with SafeZip(path) as zf, pytest.raises(UnsafeArchiveError, match="resolves outside"):
        zf.extract_member("resources/x.fmu", root)
    assert not any(outside.iterdir())
    with SafeZip(path) as zf:                     # extract_all needs a new, empty folder
        with pytest.raises(ArchiveError, match="not an empty folder"):
            zf.extract_all(root)
        assert zf.extract_all(tmp_path / "fresh") == tmp_path / "fresh"
    assert (tmp_path / "fresh/resources/x.fmu").read_bytes() == b"data"
    assert not list(tmp_path.glob(".fresh.*"))


def test_unsafe_sources_in_the_ssd(tmp_path, robot_ssp):
    """Component sources and parameter files must be plain paths inside the archive."""
    text = ssd_xml(robot_ssp).decode()
    fmus = {c.source: c.fmu_path for c in robot_ssp.elements}

    def ssp(ssd: str, name: str) -> Path:
        members = [("SystemStructure.ssd", ssd.encode())]
        members += [(src, Path(p).read_bytes()) for src, p in fmus.items()]
        return make_zip(tmp_path / name, members)

    for source, reason in (("../evil.fmu", "a '..' component"),
                           ("/abs/evil.fmu", "an absolute path"),
                           ("C:/evil.fmu", "a drive letter"),
                           ("file:///abs/evil.fmu", "':'")):
        path = ssp(text.replace('source="resources/Arm.fmu"', f'source="{source}"', 1),
                   "src.ssp")
        with pytest.raises(UnsafeArchiveError, match=reason) as err:
            read_ssp(path, tmp_path / "out")
        assert "component 'arm'" in str(err.value) and repr(source) in str(err.value)
        assert not (tmp_path / "out").exists()
    start = text.index("<ssd:ParameterBindings>", text.index('name="controller"'))
    end = text.index("</ssd:ParameterBindings>", start) + len("</ssd:ParameterBindings>")
    bad_ssv = ('<ssd:ParameterBindings><ssd:ParameterBinding source="../params.ssv"/>'
               '</ssd:ParameterBindings>')
    path = ssp(text[:start] + bad_ssv + text[end:], "ssv.ssp")
    with pytest.raises(UnsafeArchiveError, match=r"parameter file '\.\./params\.ssv' has a "
                                                 r"'\.\.' component"):
        read_ssp(path, tmp_path / "out")
    assert not (tmp_path / "out").exists()
    assert not (tmp_path.parent / "evil.fmu").exists()


def test_malicious_fmu_inside_a_valid_ssp(tmp_path, robot_ssp, unzip_root):
    """The SSP is fine, one of its FMUs is not: refused when the FMU is read, by name."""
    evil = make_zip(tmp_path / "Evil.fmu", [("modelDescription.xml", MD),
                                            ("../../evil.txt", b"pwned")])
    system = copy.deepcopy(robot_ssp)
    system.element("arm").fmu_path = evil
    path = write_ssp(system, tmp_path / "nested.ssp")
    again = read_ssp(path, tmp_path / "unpacked")
    with pytest.raises(UnsafeArchiveError, match=r"Evil\.fmu: member '\.\./\.\./evil\.txt'"):
        Master(again)
    assert not (tmp_path.parent / "evil.txt").exists() and not (tmp_path / "evil.txt").exists()
    assert not any(unzip_root.iterdir())


def test_extract_to_is_refreshed_and_confined(tmp_path, robot_ssp):
    """Reading into an existing folder replaces stale files and writes nowhere else."""
    out = tmp_path / "out"
    (out / "resources").mkdir(parents=True)
    stale = out / "resources" / "Arm.fmu"
    stale.write_bytes(b"stale")
    path = write_ssp(robot_ssp, tmp_path / "robot.ssp")
    before = snapshot(tmp_path)
    system = read_ssp(path, out)
    arm = system.element("arm")
    assert arm.fmu_path == stale and stale.read_bytes() == Path(
        robot_ssp.element("arm").fmu_path).read_bytes()
    new = snapshot(tmp_path) - before
    assert new == {"out/resources/Motor.fmu", "out/resources/Controller.fmu"}
    assert not [p for p in out.rglob("*") if p.name.endswith(".part")]


def test_errors_are_model_errors():
    for cls in (ArchiveError, UnsafeArchiveError, FmuFormatError, SspFormatError):
        assert issubclass(cls, ModelError) and issubclass(cls, ArchiveError)


def test_unsafe_reason_and_normalize():
    assert archive.unsafe_reason("resources/a.fmu") is None
    assert archive.unsafe_reason("./a/./b") is None
    assert archive.unsafe_reason("") == "an empty name"
    assert archive.unsafe_reason("a/\x00") == "a NUL character"
    assert archive.normalize("./a//b/./c") == "a/b/c"
    assert archive.normalize("a\\b") == "a/b"


def test_bytes_io_parse_unchanged():
    """parse_ssd still accepts a plain ZipFile (the SSD tests use one)."""
    from bgmodelica.cosim.ssp_read import parse_ssd

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w"):
        pass
    with pytest.raises(SspFormatError, match="root element"):
        parse_ssd(b'<?xml version="1.0"?><x/>', zipfile.ZipFile(io.BytesIO(buf.getvalue())))
