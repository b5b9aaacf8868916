"""Re-implementation of the file and stream functions of ModelicaExternalC and ModelicaIO
(``ModelicaInternal_*``, ``ModelicaStreams_*``, ``ModelicaIO_writeRealMatrix``).

``print`` writes to standard output for an empty file name, else appends a line to the file
(opened and closed at each call, so ``closeFile`` has nothing to do). ``stat`` returns the
``Modelica.Utilities.Types.FileType`` index (NoFile=1, RegularFile=2, Directory=3,
SpecialFile=4). ``writeRealMatrix`` writes MATLAB MAT files with scipy (v4, or v6/v7 as
format 5; v7 compressed).
"""

from __future__ import annotations

import os
import shutil
import stat as _stat
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .errors import ExternalFunctionError

#: Modelica.Utilities.Types.FileType
NO_FILE, REGULAR_FILE, DIRECTORY, SPECIAL_FILE = 1, 2, 3, 4


def full_path_name(name: str) -> str:
    """``ModelicaInternal_fullPathName``: absolute path (symbolic links resolved, '/')."""
    return os.path.realpath(name).replace("\\", "/")


def file_type(name: str) -> int:
    """``ModelicaInternal_stat``: FileType index of ``name``."""
    try:
        mode = os.stat(name).st_mode
    except OSError:
        return NO_FILE
    if _stat.S_ISREG(mode):
        return REGULAR_FILE
    if _stat.S_ISDIR(mode):
        return DIRECTORY
    return SPECIAL_FILE


def remove_file(file_name: str) -> None:
    """``ModelicaInternal_removeFile``: delete a file (an error if that fails)."""
    try:
        os.remove(file_name)
    except OSError as exc:
        raise ExternalFunctionError(f"cannot remove file {file_name!r}: {exc.strerror}") \
            from None


def print_line(string: str, file_name: str = "") -> None:
    """``ModelicaInternal_print``: ``string`` and a newline to stdout or appended to a
    file."""
    if not file_name:
        sys.stdout.write(string + "\n")
        return
    try:
        with open(file_name, "a", encoding="utf-8") as fh:
            fh.write(string + "\n")
    except OSError as exc:
        raise ExternalFunctionError(f"cannot print to file {file_name!r}: {exc.strerror}") \
            from None


def close_file(file_name: str) -> None:
    """``ModelicaStreams_closeFile``: nothing is kept open."""
    return None


def read_line(file_name: str, line_number: int, end_of_file: Any = False) -> tuple[str, bool]:
    """``ModelicaInternal_readLine``: (line ``line_number`` (1-based), endOfFile)."""
    lines = _lines(file_name)
    n = int(line_number)
    if 1 <= n <= len(lines):
        return lines[n - 1], False
    return "", True


def count_lines(file_name: str) -> int:
    """``ModelicaInternal_countLines``: number of lines of a text file."""
    return len(_lines(file_name))


def _lines(file_name: str) -> list[str]:
    try:
        return Path(file_name).read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise ExternalFunctionError(f"cannot read file {file_name!r}: {exc.strerror}") \
            from None


def make_directory(name: str) -> None:
    """``ModelicaInternal_mkdir``."""
    try:
        os.mkdir(name)
    except OSError as exc:
        raise ExternalFunctionError(f"cannot make directory {name!r}: {exc.strerror}") \
            from None


def rename(old: str, new: str) -> None:
    """``ModelicaInternal_rename``."""
    try:
        os.replace(old, new)
    except OSError as exc:
        raise ExternalFunctionError(f"cannot rename {old!r} to {new!r}: {exc.strerror}") \
            from None


def copy_file(source: str, target: str) -> None:
    """``ModelicaInternal_copyFile``."""
    try:
        shutil.copyfile(source, target)
    except OSError as exc:
        raise ExternalFunctionError(f"cannot copy {source!r} to {target!r}: "
                                    f"{exc.strerror}") from None


def write_real_matrix(file_name: str, matrix_name: str, matrix: Any, n_row: int, n_col: int,
                      append: bool = False, fmt: str = "4") -> bool:
    """``ModelicaIO_writeRealMatrix``: store ``matrix`` as ``matrix_name`` in a MAT file;
    ``append`` keeps the other matrices of an existing file (and its format)."""
    from scipy.io import loadmat, savemat
    from scipy.io.matlab import matfile_version

    data: dict[str, Any] = {}
    version = str(fmt).strip()
    m = np.asarray(matrix, dtype=float).reshape(int(n_row), int(n_col))
    try:
        if append and os.path.isfile(file_name):
            major, _ = matfile_version(file_name)
            version = "4" if major == 0 else "6"
            data = {k: v for k, v in loadmat(file_name).items() if not k.startswith("__")}
        if version not in ("4", "6", "7"):
            raise ValueError(f"format {fmt!r} not supported (\"4\", \"6\" or \"7\")")
        data[matrix_name] = m
        savemat(file_name, data, format="4" if version == "4" else "5",
                do_compression=version == "7")
    except (OSError, ValueError) as exc:
        sys.stderr.write(f"writeRealMatrix: cannot write {matrix_name!r} to "
                         f"{file_name!r}: {exc}\n")
        return False
    return True


REGISTRY: dict[str, Callable[..., Any]] = {
    "ModelicaInternal_fullPathName": full_path_name,
    "ModelicaInternal_stat": file_type,
    "ModelicaInternal_removeFile": remove_file,
    "ModelicaInternal_print": print_line,
    "ModelicaStreams_closeFile": close_file,
    "ModelicaInternal_readLine": read_line,
    "ModelicaInternal_countLines": count_lines,
    "ModelicaInternal_mkdir": make_directory,
    "ModelicaInternal_rename": rename,
    "ModelicaInternal_copyFile": copy_file,
    "ModelicaIO_writeRealMatrix": write_real_matrix,
}
