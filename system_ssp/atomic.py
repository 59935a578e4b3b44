"""Writing files so that a reader never sees half of one: the one helper every writer uses.

The content goes to a temporary file in the target's folder, which is renamed over the target
only when everything was written; on any failure (an exception, Ctrl-C) the temporary file is
removed and an earlier target is left as it was."""
from contextlib import contextmanager
import os
from pathlib import Path
import tempfile


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
