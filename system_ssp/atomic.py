"""Writing files so that a reader never sees half of one (`atomic_write`, the one helper every
writer uses) and results folders as one unit (`StagedFolder`).

The content goes to a temporary file in the target's folder, which is renamed over the target
only when everything was written; on any failure (an exception, Ctrl-C) the temporary file is
removed and an earlier target is left as it was."""
from contextlib import contextmanager
import os
from pathlib import Path
import shutil
import tempfile
from typing import IO, Any, Iterator, Optional, Union

from .errors import SSPError


PathLike = Union[str, "os.PathLike[str]"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_write(path: PathLike, mode: str = "w", **open_kwargs: Any) -> Iterator[IO[Any]]:
    """`with atomic_write(path, "w") as f: f.write(...)`; `mode` "w" (text) or "wb". The file
    gets the permissions a plain open() would give it (0666 less the umask)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, mode, **open_kwargs) as f:
            yield f
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
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
        if self.target.exists() and not self.target.is_dir():
            raise SSPError(f"{what} {self.target}: exists and is not a folder")
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
            self.path = Path(tempfile.mkdtemp(prefix=f".{self.target.name}.", suffix=".tmp",
                                              dir=self.target.parent))
            os.chmod(self.path, 0o777 & ~_umask())
        except OSError as exc:
            raise SSPError(f"{what} {self.target}: cannot write in {self.target.parent} "
                           f"({exc.strerror or exc})") from None

    def commit(self, target: Optional[PathLike] = None) -> Path:
        target = Path(target) if target is not None else self.target
        old: Optional[Path] = None
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old", dir=target.parent))
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
