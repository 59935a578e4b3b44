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

from .errors import SSPError


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_write(path, mode="w", **open_kwargs):
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


def write_text_atomic(path, text, encoding="utf-8"):
    with atomic_write(path, "w", encoding=encoding, newline="") as f:
        f.write(text)


class StagedFolder:
    """A results folder written as one unit: files go into a hidden temporary folder beside the
    target (`.path`), created at once, so an unwritable location is refused before any work;
    `commit()` puts it in place of the target (the old folder renamed away, the new one renamed
    in, the old one deleted: a reader sees the old set or the new set, never a mixture);
    `commit_partial(reason)` puts it at <target>.partial with a PARTIAL.txt saying why;
    `discard()` deletes it. Folder and file modes follow the umask."""

    def __init__(self, target, what="results folder"):
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

    def commit(self, target=None):
        target = Path(target) if target is not None else self.target
        old = None
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old", dir=target.parent))
            os.replace(target, old / "previous")
        os.replace(self.path, target)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return target

    def commit_partial(self, reason):
        with atomic_write(self.path / "PARTIAL.txt", "w") as f:
            f.write(f"partial results: {reason}\n")
        return self.commit(self.target.with_name(self.target.name + ".partial"))

    def discard(self):
        shutil.rmtree(self.path, ignore_errors=True)
