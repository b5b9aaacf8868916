"""Safe reading and extraction of zip archives (FMUs and SSPs).

:class:`SafeZip` opens an archive and checks *every* member before anything is read or
written, so that a bad archive is refused as a whole with one clear error naming the file
and the member at fault:

* not a zip, truncated or corrupt (no central directory, bad CRC, broken compressed data),
  encrypted or with an unsupported compression: :class:`~.errors.ArchiveError` (or the
  ``error`` class given by the caller: :class:`~.errors.FmuFormatError`,
  :class:`~.errors.SspFormatError`);
* the required file (``modelDescription.xml``, ``SystemStructure.ssd``) missing: the same;
* member names that could land outside the extraction folder -- ``..`` components, absolute
  paths, drive letters (``C:``), backslash-separated variants of these --, symbolic links and
  other special files (from the Unix mode in the external attributes), the same name twice
  (also after normalisation or differing only in case), a file that is also a folder, more
  than :data:`MAX_MEMBERS` members, or more than :data:`MAX_UNCOMPRESSED_BYTES` bytes
  uncompressed in all (a zip bomb): :class:`~.errors.UnsafeArchiveError`.

Extraction (:meth:`SafeZip.extract_all`, :meth:`SafeZip.extract_member`) writes regular
files only, never follows a symbolic link already present in the target folder, checks that
every resolved path stays inside the target, counts the bytes actually decompressed against
the declared sizes and the limit, and is all-or-nothing: :meth:`~SafeZip.extract_all`
unpacks into a hidden staging folder next to the target and renames it at the end; a
single member is written to a temporary name and renamed. So a failing archive leaves no
partial output.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import struct
import tempfile
import zipfile
import zlib
from pathlib import Path

from .errors import ArchiveError, UnsafeArchiveError

MAX_UNCOMPRESSED_BYTES = 1 << 30      # 1 GiB in all: far above any FMU/SSP we make
MAX_MEMBERS = 100_000
_CHUNK = 1 << 20
_DRIVE = re.compile(r"^[A-Za-z]:")
_OPEN_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, ValueError,
                NotImplementedError, struct.error, OverflowError, UnicodeDecodeError)
_READ_ERRORS = (zipfile.BadZipFile, zlib.error, OSError, EOFError, ValueError,
                NotImplementedError, RuntimeError, struct.error)


def _size(n: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} TiB"   # pragma: no cover


def _one_line(text: object, limit: int = 300) -> str:
    s = " ".join(str(text).split())
    return s if len(s) <= limit else s[: limit - 3] + "..."


def unsafe_reason(name: str) -> str | None:
    """Why the archive member (or resource) name ``name`` could write outside its folder,
    or None if it is a plain relative path."""
    if not name or not name.strip("/\\"):
        return "an empty name"
    if "\x00" in name:
        return "a NUL character"
    if name.startswith(("/", "\\")):
        return "an absolute path"
    if _DRIVE.match(name):
        return "a drive letter"
    parts = re.split(r"[/\\]", name)
    if any(p == ".." for p in parts):
        return "a '..' component"
    if any(":" in p for p in parts):
        return "a ':' (drive, stream or URL scheme)"
    return None


def normalize(name: str) -> str:
    """``name`` with ``\\`` as ``/``, without ``.`` and empty components (call
    :func:`unsafe_reason` first)."""
    parts = [p for p in re.split(r"[/\\]", name) if p not in ("", ".")]
    return "/".join(parts)


def inside(path: Path, root: Path) -> bool:
    """Whether ``path`` (resolved, symbolic links followed) lies in ``root`` (resolved)."""
    try:
        path.resolve().relative_to(root.resolve())
    except ValueError:
        return False
    return True


class SafeZip:
    """A checked zip archive (see the module docstring); use as a context manager.

    ``kind`` ("FMU", "SSP") and ``required`` (a member that must exist) shape the messages;
    ``error`` is the class raised for unreadable archives (unsafe ones always raise
    :class:`~.errors.UnsafeArchiveError`); ``max_bytes`` caps the total uncompressed size
    (default :data:`MAX_UNCOMPRESSED_BYTES`).
    """

    def __init__(self, path: str | Path, kind: str = "zip", required: str | None = None, *,
                 error: type[ArchiveError] = ArchiveError, max_bytes: int | None = None,
                 max_members: int | None = None) -> None:
        self.path = Path(path)
        self.kind = kind
        self.error = error
        self.max_bytes = MAX_UNCOMPRESSED_BYTES if max_bytes is None else int(max_bytes)
        max_members = MAX_MEMBERS if max_members is None else int(max_members)
        if not self.path.is_file():
            what = "does not exist" if not self.path.exists() else "is not a file"
            raise error(f"{kind} file {self.path} {what}")
        try:
            self.zf = zipfile.ZipFile(self.path)
        except _OPEN_ERRORS as err:
            raise error(f"{self.path} is not an {kind} archive (not a zip file, or a "
                        f"truncated or corrupt one: {_one_line(err)})") from None
        try:
            self.members = self._check(max_members)
            if required is not None and required not in self.members:
                raise error(f"{self.path}: no {required} in the archive (not an {kind})")
        except BaseException:
            self.zf.close()
            raise

    # -- checks ---------------------------------------------------------------------------
    def _check(self, max_members: int) -> dict[str, zipfile.ZipInfo]:
        infos = self.zf.infolist()
        where = f"{self.kind} archive {self.path}"
        if len(infos) > max_members:
            raise UnsafeArchiveError(f"{where} has {len(infos)} members, more than the limit "
                                     f"of {max_members}; refusing to extract it")
        members: dict[str, zipfile.ZipInfo] = {}
        folded: dict[str, str] = {}
        total = 0
        for info in infos:
            name = info.filename
            reason = unsafe_reason(name)
            if reason is not None:
                raise UnsafeArchiveError(f"{where}: member {name!r} has {reason}; it would be "
                                         "written outside the extraction folder, refusing "
                                         "to extract")
            mode = info.external_attr >> 16
            if mode and stat.S_IFMT(mode) and not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
                what = "a symbolic link" if stat.S_ISLNK(mode) else "a special file"
                raise UnsafeArchiveError(f"{where}: member {name!r} is {what}; only regular "
                                         "files and folders are allowed")
            if info.flag_bits & 0x1:
                raise self.error(f"{where}: member {name!r} is encrypted")
            key = normalize(name)
            if key.casefold() in folded:
                raise UnsafeArchiveError(f"{where}: the name {name!r} occurs twice (also as "
                                         f"{folded[key.casefold()]!r}); which one is meant "
                                         "is ambiguous")
            folded[key.casefold()] = name
            if info.is_dir():
                continue
            members[key] = info
            total += max(0, int(info.file_size))
        for key in members:                      # a file that is also a folder
            parts = key.split("/")
            for k in range(1, len(parts)):
                parent = "/".join(parts[:k])
                if parent in members:
                    raise UnsafeArchiveError(f"{where}: {parent!r} is both a file and the "
                                             f"folder of {key!r}")
        if total > self.max_bytes:
            raise UnsafeArchiveError(
                f"{where}: its members declare {total} bytes ({_size(total)}) uncompressed, "
                f"more than the limit of {_size(self.max_bytes)}; refusing to extract it "
                "(a zip bomb?)")
        return members

    # -- reading --------------------------------------------------------------------------
    def __enter__(self) -> SafeZip:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.zf.close()

    def names(self) -> list[str]:
        """The (normalised) names of the file members."""
        return list(self.members)

    def info(self, name: str, what: str = "") -> zipfile.ZipInfo:
        """The member ``name`` (normalised; :class:`ArchiveError` naming ``what`` if absent)."""
        reason = unsafe_reason(name)
        if reason is not None:
            raise UnsafeArchiveError(f"{self.kind} archive {self.path}: {what or 'the name'} "
                                     f"{name!r} has {reason}")
        key = normalize(name)
        if key not in self.members:
            raise self.error(f"{self.path}: {what + ' ' if what else ''}{name!r} is not in the "
                             "archive")
        return self.members[key]

    def _chunks(self, info: zipfile.ZipInfo):
        """The decompressed data of ``info`` in chunks, within its declared size."""
        left = int(info.file_size)
        try:
            with self.zf.open(info) as src:
                while True:
                    chunk = src.read(_CHUNK)
                    if not chunk:
                        break
                    left -= len(chunk)
                    if left < 0:
                        raise UnsafeArchiveError(
                            f"{self.kind} archive {self.path}: member {info.filename!r} "
                            f"decompresses to more than its declared {info.file_size} bytes")
                    yield chunk
        except _READ_ERRORS as err:
            raise self.error(f"{self.kind} archive {self.path}: member {info.filename!r} is "
                             f"corrupt or truncated ({_one_line(err)})") from None
        if left != 0:
            raise self.error(f"{self.kind} archive {self.path}: member {info.filename!r} is "
                             f"truncated ({left} of {info.file_size} bytes missing)")

    def read(self, name: str, what: str = "") -> bytes:
        """The content of the member ``name``."""
        return b"".join(self._chunks(self.info(name, what)))

    # -- extraction -----------------------------------------------------------------------
    def _write(self, info: zipfile.ZipInfo, dest: Path, root: Path) -> int:
        dest.parent.mkdir(parents=True, exist_ok=True)
        if not inside(dest.parent, root) or (dest.is_symlink()):
            raise UnsafeArchiveError(f"{self.kind} archive {self.path}: member "
                                     f"{info.filename!r} would be written through a symbolic "
                                     f"link to outside {root}")
        fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=".part", dir=dest.parent)
        n = 0
        try:
            with os.fdopen(fd, "wb") as out:
                for chunk in self._chunks(info):
                    out.write(chunk)
                    n += len(chunk)
            os.chmod(tmp, 0o644)
            os.replace(tmp, dest)        # replaces a link at dest, never writes through it
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return n

    def extract_member(self, name: str, root: str | Path, rel: str | None = None,
                       what: str = "") -> Path:
        """Write the member ``name`` to ``root/rel`` (``rel`` default: the member name; a
        relative path, checked like member names) and return that path."""
        info = self.info(name, what)
        rel = normalize(info.filename) if rel is None else rel
        reason = unsafe_reason(rel)
        if reason is not None:
            raise UnsafeArchiveError(f"{self.kind} archive {self.path}: {what or 'target'} "
                                     f"{rel!r} has {reason}")
        root = Path(root)
        root.mkdir(parents=True, exist_ok=True)
        dest = root.joinpath(*normalize(rel).split("/"))
        if not inside(dest, root):
            raise UnsafeArchiveError(f"{self.kind} archive {self.path}: {rel!r} resolves "
                                     f"outside {root}")
        self._write(info, dest, root)
        return dest

    def extract_all(self, target: str | Path) -> Path:
        """Extract every file member into ``target`` (created; must not exist or be an empty
        folder): all or nothing. Returns ``target``."""
        target = Path(target)
        if target.exists() and (not target.is_dir() or any(target.iterdir())):
            raise ArchiveError(f"cannot extract {self.path} into {target}: it exists and is "
                               "not an empty folder")
        target.parent.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".part",
                                      dir=target.parent))
        try:
            total = 0
            for key, info in self.members.items():
                dest = stage.joinpath(*key.split("/"))
                if not inside(dest, stage):                     # pragma: no cover
                    raise UnsafeArchiveError(f"{self.kind} archive {self.path}: member "
                                             f"{info.filename!r} resolves outside {target}")
                total += self._write(info, dest, stage)
                if total > self.max_bytes:                      # pragma: no cover
                    raise UnsafeArchiveError(f"{self.kind} archive {self.path} decompresses "
                                             f"to more than {_size(self.max_bytes)}")
            if target.exists():
                target.rmdir()
            os.replace(stage, target)
        except BaseException:
            shutil.rmtree(stage, ignore_errors=True)
            raise
        return target
