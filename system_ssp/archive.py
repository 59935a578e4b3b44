"""Unpacking .ssp and .fmu archives (zip files) that may come from anywhere: the one helper every
reader uses, so that a damaged, hostile or oversized archive is refused in one line naming it
and the member, before anything is written outside the target folder.

Refused: a file that is not a zip archive; members whose names are absolute, climb out (`..`),
carry a drive, a colon or a backslash (`C:x`, `resources/C:x`, `resources\\x`: Windows paths a Linux unzip would take
literally), are symbolic links or repeat another; members that fail their CRC-32 or use a
compression zipfile cannot read; more members, more unpacked bytes or a higher compression
ratio than system_ssp.limits allows (a zip bomb)."""
import os
from pathlib import Path, PurePosixPath
import re
import shutil
import stat
from typing import List, Union
import zipfile
import zlib

from .errors import SSPError
from .limits import LIMITS, limit

PathLike = Union[str, "os.PathLike[str]"]
_DRIVE = re.compile(r"^[A-Za-z]:")
_CHUNK = 1 << 20


def _bad_name(name: str) -> str:
    """Why a member name is refused ('' when it is fine)."""
    if not name or "\x00" in name:
        return "an empty name or a NUL character"
    if "\\" in name:
        return "a backslash (a Windows path separator)"
    if _DRIVE.match(name):
        return "a drive"
    if ":" in name:  # Windows: a drive (C:x) or, in a later part, a file's alternate data stream
        return "a colon (a drive, or a Windows alternate data stream)"
    path = PurePosixPath(name)
    if path.is_absolute():
        return "an absolute path"
    if ".." in path.parts:
        return "'..' (it points outside the archive)"
    return ""


def check_members(z: zipfile.ZipFile, display: str) -> List[zipfile.ZipInfo]:
    """The members of `z` once their names, kinds and sizes are checked (nothing read yet)."""
    members = z.infolist()
    most_members, most_bytes, ratio = (limit(name) for name in ("max_archive_members", "max_archive_bytes",
                                                                 "max_compression_ratio"))
    if len(members) > most_members:
        raise SSPError(f"{display}: {len(members):,} archive members, over the limit of "
                       f"{most_members:,} (set {LIMITS['max_archive_members'].variable} to allow more)")
    seen = set()
    total = 0
    for m in members:
        why = _bad_name(m.filename)
        if why:
            raise SSPError(f"{display}: archive member {m.filename!r} has {why}; members are relative paths "
                           "with / between folders")
        if stat.S_ISLNK(m.external_attr >> 16):
            raise SSPError(f"{display}: archive member {m.filename!r} is a symbolic link; members are files and "
                           "folders")
        key = m.filename.rstrip("/")
        if key in seen and not m.is_dir():
            raise SSPError(f"{display}: archive member {m.filename!r} appears twice")
        seen.add(key)
        total += m.file_size
        if m.file_size > 1 << 20 and m.file_size > ratio * max(m.compress_size, 1):
            raise SSPError(f"{display}: archive member {m.filename!r} unpacks {m.compress_size:,} bytes to "
                           f"{m.file_size:,}, a ratio over the limit of {ratio:,} (a zip bomb?; set "
                           f"{LIMITS['max_compression_ratio'].variable} to allow more)")
    if total > most_bytes:
        raise SSPError(f"{display}: unpacks to {total:,} bytes, over the limit of {most_bytes:,} "
                       f"(set {LIMITS['max_archive_bytes'].variable} to allow more)")
    return members


def extract(path: PathLike, target: PathLike, display: str = "") -> Path:
    """Unpack the zip archive `path` into the folder `target` (created); returns `target`.
    `display` names the archive in messages (default: its path)."""
    path, target = Path(path), Path(target)
    display = display or str(path)
    try:
        with zipfile.ZipFile(path) as z:
            members = check_members(z, display)
            target.mkdir(parents=True, exist_ok=True)
            for m in members:
                out = target.joinpath(*PurePosixPath(m.filename).parts)
                if m.is_dir():
                    out.mkdir(parents=True, exist_ok=True)
                    continue
                out.parent.mkdir(parents=True, exist_ok=True)
                try:
                    with z.open(m) as src, open(out, "wb") as dst:
                        shutil.copyfileobj(src, dst, _CHUNK)
                except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError, RuntimeError) as exc:
                    raise SSPError(f"{display}: archive member {m.filename!r} is damaged or unreadable ({exc})") \
                        from None
                mode = (m.external_attr >> 16) & 0o777
                if mode & 0o100:  # keep the executable bit (an FMU's binaries, a packed tool)
                    os.chmod(out, os.stat(out).st_mode | 0o111)
    except zipfile.BadZipFile as exc:
        raise SSPError(f"{display}: not a valid zip archive ({exc})") from None
    except OSError as exc:
        raise SSPError(f"{display}: cannot unpack into {target} ({exc.strerror or exc})") from None
    return target
