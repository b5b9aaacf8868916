"""Compile the FMU sources with the system C compiler and zip the FMU.

The compiler is ``$CC`` if set, else the first of ``cc``, ``gcc``, ``clang`` on ``PATH``;
it is called as ``<cc> -O2 -fPIC -shared -fvisibility=hidden -I<src> <src>/*.c -o <lib> -lm``.
Only the FMI functions are exported from the shared library (the FMI headers mark them with
default visibility); all other symbols are hidden.
"""

from __future__ import annotations

import os
import platform
import shlex
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

from .csources import c_files
from .spec import FmuExportError

COMPILER_CANDIDATES = ("cc", "gcc", "clang")
CFLAGS = ("-O2", "-fPIC", "-shared", "-fvisibility=hidden")
ZIP_DATE = (2000, 1, 1, 0, 0, 0)  # fixed timestamps: byte-identical FMUs for identical input


class FmuBuildError(FmuExportError):
    """The FMU binary could not be built (no C compiler, compiler error, unsupported OS)."""


def find_compiler(compiler: str | None = None) -> str:
    """Return the path of the C compiler to use or raise :class:`FmuBuildError`."""
    wanted = compiler or os.environ.get("CC")
    if wanted:
        parts = shlex.split(wanted)
        path = shutil.which(parts[0]) if parts else None
        if path is None:
            raise FmuBuildError(f"C compiler {wanted!r} not found (from "
                                f"{'the compiler argument' if compiler else '$CC'}); install it "
                                "or point $CC to a working C compiler")
        return path
    for name in COMPILER_CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    raise FmuBuildError("no C compiler found: looked for $CC, " + ", ".join(COMPILER_CANDIDATES)
                        + " on PATH. Install one (e.g. 'apt-get install gcc') to export FMUs.")


def platform_dir(fmi_version: int) -> tuple[str, str]:
    """(binaries sub-folder, shared library extension) for this machine."""
    machine = platform.machine().lower()
    bits64 = sys.maxsize > 2**32
    arch = {"amd64": "x86_64", "x86_64": "x86_64", "arm64": "aarch64",
            "aarch64": "aarch64", "i386": "x86", "i686": "x86"}.get(machine, machine)
    if sys.platform.startswith("linux"):
        os_name, ext, fmi2 = "linux", ".so", "linux64" if bits64 else "linux32"
    elif sys.platform == "darwin":
        os_name, ext, fmi2 = "darwin", ".dylib", "darwin64"
    elif sys.platform in ("win32", "cygwin"):
        os_name, ext, fmi2 = "windows", ".dll", "win64" if bits64 else "win32"
    else:
        raise FmuBuildError(f"unsupported operating system {sys.platform!r}")
    if fmi_version == 2:
        return fmi2, ext
    return f"{arch}-{os_name}", ext


def compile_shared_library(src_dir: Path, out_path: Path, compiler: str | None = None) -> Path:
    """Compile every ``*.c`` of ``src_dir`` into the shared library ``out_path``."""
    cc = find_compiler(compiler)
    sources = [str(Path(src_dir) / f) for f in c_files(src_dir)]
    if not sources:
        raise FmuBuildError(f"no C sources in {src_dir}")
    out_path = Path(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    cmd = [cc, *CFLAGS, f"-I{src_dir}", *sources, "-o", str(out_path), "-lm"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    except OSError as err:
        raise FmuBuildError(f"could not run the C compiler {cc}: {err}") from err
    if proc.returncode != 0 or not out_path.is_file():
        raise FmuBuildError("compilation of the FMU failed:\n$ " + shlex.join(cmd) + "\n"
                            + (proc.stderr or proc.stdout).strip())
    return out_path


def zip_fmu(root: Path, fmu_path: Path) -> Path:
    """Zip the directory ``root`` (modelDescription.xml, binaries/, sources/) into an FMU."""
    root = Path(root)
    fmu_path = Path(fmu_path)
    fmu_path.parent.mkdir(parents=True, exist_ok=True)
    tmp = fmu_path.with_name(fmu_path.name + ".part")
    files = sorted(p for p in root.rglob("*") if p.is_file())
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
            for path in files:
                info = zipfile.ZipInfo(path.relative_to(root).as_posix(), ZIP_DATE)
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = (0o755 if path.suffix in (".so", ".dylib", ".dll")
                                      else 0o644) << 16
                zf.writestr(info, path.read_bytes())
        os.replace(tmp, fmu_path)
    except BaseException:
        tmp.unlink(missing_ok=True)      # no partial FMU
        raise
    return fmu_path
