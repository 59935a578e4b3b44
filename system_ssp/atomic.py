"""Writing files so that a reader never sees half of one (`atomic_write`, the one helper every
writer uses) and results folders as one unit (`StagedFolder`).

The content goes to a temporary file in the target's folder, which is renamed over the target
only when everything was written; on any failure (an exception, Ctrl-C) the temporary file is
removed and an earlier target is left as it was."""
from contextlib import contextmanager
import errno
import fcntl
import os
from pathlib import Path
import shutil
import stat
import tempfile
from typing import IO, Any, Iterator, Optional, Sequence, Union

from .errors import SSPError


PathLike = Union[str, "os.PathLike[str]"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# Errors of the place written to, not of the input: said in one line (exit 2) naming the file.
_WRITE_ERRORS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO, errno.EACCES, errno.EPERM,
                 errno.ENAMETOOLONG}


def _temporary_prefix(path: Path) -> str:
    # the temporary name must fit where the target's name fits: keep the prefix short
    return f".{path.name[:40]}."


_NULL_DEVICE = os.makedev(1, 3)
_TERMINAL_MAJORS = {4, 5} | set(range(136, 144))  # tty*, /dev/tty and the console, pseudo-terminals


def is_stream(path: PathLike) -> bool:
    """True when `path` exists and is a FIFO, a terminal or the null device: written through, as a
    stream, never replaced (no temporary file, no sidecar files beside it)."""
    try:
        st = os.stat(path)
    except OSError:
        return False
    if stat.S_ISFIFO(st.st_mode):
        return True
    # told apart by their device numbers, never opened to ask (opening a device can act: a
    # watchdog starts, a tape rewinds): the null device, the terminals (Linux' majors)
    return stat.S_ISCHR(st.st_mode) and (st.st_rdev == _NULL_DEVICE or os.major(st.st_rdev) in _TERMINAL_MAJORS)


def _check_name_length(path: Path, folder: Path, what: str) -> None:
    try:
        most = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        most = 255
    size = len(os.fsencode(path.name))
    if size > most:
        raise SSPError(f"{what} {str(path)[:60]!r}...: the name has {size} bytes, the file system takes at most "
                       f"{most}")


@contextmanager
def _folder_lock(folder: Path) -> Iterator[None]:
    """Two commands committing into the same folder at once take turns (flock on the folder)."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def check_output_place(path: PathLike, what: str = "output file", formats: Sequence[str] = ()) -> Path:
    """Refuse, before any work, a file the command could not write or must not replace: a format
    not in `formats` (when given), its folder missing or not a folder, the path a folder or a
    device other than a stream (see is_stream), a name longer than the file system takes, no file
    creatable in the folder (tried). Every command checks its output files with this."""
    path = Path(path)
    shown = _shown(path)
    folder = path.parent if str(path.parent) else Path(".")
    if formats and path.suffix.lower() not in formats:
        raise SSPError(f"{what} {shown}: unknown format {path.suffix!r} (expected {' or '.join(formats)})")
    if is_stream(path):
        return path
    if not folder.exists():
        raise SSPError(f"{what} {shown}: folder {folder} does not exist")
    _check_name_length(path, folder, what)
    if not folder.is_dir():
        raise SSPError(f"{what} {shown}: {folder} is not a folder")
    if path.is_dir():
        raise SSPError(f"{what} {shown}: is a folder")
    if path.exists() and not path.is_file():
        raise SSPError(f"{what} {shown}: is a device or another special file; write to a regular file, a FIFO, a "
                       f"terminal or {os.devnull}")
    _probe(folder, f"{what} {shown}")
    return path


def _shown(path: Path) -> str:
    """A path for a one-line message: quoted when it holds a line break or a tab."""
    return repr(str(path)) if any(c in str(path) for c in "\n\r\t") else str(path)


def _probe(folder: Path, where: str) -> None:
    """Refuse (naming `where`) a folder in which no file can be created: tried, not guessed."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".probe.", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise SSPError(f"{where}: cannot write in {folder} ({exc.strerror or exc})") from None


def _exists_as_non_folder(path: Path) -> bool:
    """One stat, not exists() then is_dir(): another command committing the same folder renames
    it away and back in between, which two calls could see as 'exists and is not a folder'."""
    try:
        return not stat.S_ISDIR(os.stat(path).st_mode)
    except OSError:  # missing (or under a file): the later steps say what is wrong
        return False


def check_output_folder(path: PathLike, what: str = "results folder") -> Path:
    """Refuse, before any work, a folder a command could not create or write into: a file
    there, a name too long, no writable folder above it (tried with a probe file)."""
    path = Path(path)
    shown = _shown(path)
    _check_name_length(path, path.parent, what)
    if _exists_as_non_folder(path):
        raise SSPError(f"{what} {shown}: exists and is not a folder")
    existing = path
    while not existing.exists():  # the folder that will hold the new ones
        existing = existing.parent
    if not existing.is_dir():
        raise SSPError(f"{what} {shown}: {existing} is not a folder")
    _probe(existing, f"{what} {shown}")
    return path


@contextmanager
def atomic_write(path: PathLike, mode: str = "w", **open_kwargs: Any) -> Iterator[IO[Any]]:
    """`with atomic_write(path, "w") as f: f.write(...)`; `mode` "w" (text) or "wb". The file
    gets the permissions a plain open() would give it (0666 less the umask). A stream (a FIFO,
    a terminal, the null device) is written through instead; any other existing non-regular
    file is refused. A full disk or a read-only place raises SSPError naming the file."""
    path = Path(path)
    if is_stream(path):
        with open(path, mode, **open_kwargs) as f:
            yield f
        return
    if os.path.exists(path) and not os.path.isfile(path):
        raise SSPError(f"{path}: is a folder, a device or another special file; not replaced")
    try:
        fd, tmp = tempfile.mkstemp(prefix=_temporary_prefix(path), suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise SSPError(f"cannot write {path} ({exc.strerror or exc})") from None
    try:
        with os.fdopen(fd, mode, **open_kwargs) as f:
            yield f
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError) and exc.errno in _WRITE_ERRORS:
            raise SSPError(f"cannot write {path} ({exc.strerror or exc}); nothing was written there, an earlier "
                           "file is left as it was") from None
        raise


def write_text_atomic(path: PathLike, text: str, encoding: str = "utf-8") -> None:
    with atomic_write(path, "w", encoding=encoding, newline="") as f:
        f.write(text)


class StagedFolder:
    """A results folder written as one unit: files go into a hidden temporary folder beside the
    target (`.path`), created at once, so an unwritable location is refused before any work;
    `commit()` puts it in place of the target (the old folder renamed away, the new one renamed
    in, the old one deleted: a reader sees the old set or the new set, never a mixture);
    `commit_partial(reason)` puts it at <target>.partial with a PARTIAL.txt saying why;
    `discard()` deletes it. Folder and file modes follow the umask."""

    def __init__(self, target: PathLike, what: str = "results folder") -> None:
        self.target = Path(target)
        _check_name_length(self.target, self.target.parent, what)
        if _exists_as_non_folder(self.target):
            raise SSPError(f"{what} {self.target}: exists and is not a folder")
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
            self.path = Path(tempfile.mkdtemp(prefix=_temporary_prefix(self.target), suffix=".tmp",
                                              dir=self.target.parent))
            os.chmod(self.path, 0o777 & ~_umask())
        except OSError as exc:
            raise SSPError(f"{what} {self.target}: cannot write in {self.target.parent} "
                           f"({exc.strerror or exc})") from None

    def commit(self, target: Optional[PathLike] = None) -> Path:
        target = Path(target) if target is not None else self.target
        old: Optional[Path] = None
        with _folder_lock(target.parent):
            if target.exists():
                old = Path(tempfile.mkdtemp(prefix=_temporary_prefix(target), suffix=".old", dir=target.parent))
                os.replace(target, old / "previous")
            os.replace(self.path, target)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return target

    def commit_partial(self, reason: str) -> Path:
        with atomic_write(self.path / "PARTIAL.txt", "w") as f:
            f.write(f"partial results: {reason}\n")
        return self.commit(self.target.with_name(self.target.name + ".partial"))

    def discard(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)
