"""The one place that writes a run's files, atomically (SPEC 7).

A run writes into a hidden temporary folder beside its target and swaps it into place
only when everything is written. A failed or interrupted run removes its temporary folder
and leaves the previous output exactly as it was. Single files outside a run folder (the
geometry cache) are written the same way by :func:`write_file_atomically`.
"""

import json
import os
import shutil
import uuid
from pathlib import Path


def write_file_atomically(path, data: bytes):
    """Write ``data`` to ``path`` through a hidden temporary file beside it, renamed into
    place when complete: a reader sees the old file or the whole new one, never a part.

    Parameters
    ----------
    path : str or Path
        The file to write; missing parent folders are created.
    data : bytes
        The whole content.

    Raises
    ------
    OSError
        When the file cannot be written; the temporary file is removed and ``path`` is
        left as it was.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp-{uuid.uuid4().hex[:8]}")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


class RunFolder:
    """Collects a run's files and publishes them as ``root/name`` in one step.

    Use as a context manager: the folder is published when the block ends normally and
    discarded when it raises (including ``KeyboardInterrupt``).

    Parameters
    ----------
    root : str or Path
        The output root (created on entry when missing).
    name : str
        The run folder's name inside ``root`` (the structure id).

    Attributes
    ----------
    target : Path
        ``root/name``, where the folder is published.
    tmp : Path
        The hidden temporary folder the files are written into until then.

    Examples
    --------
    >>> with RunFolder("exports", "wall_L32") as folder:  # doctest: +SKIP
    ...     folder.write("notes.txt", "text")
    ...     folder.write_json("run.json", {"complete": True})
    """

    def __init__(self, root, name):
        self.root = Path(root)
        self.target = self.root / name
        tag = uuid.uuid4().hex[:8]
        self.tmp = self.root / f".{name}.tmp-{tag}"
        self._old = self.root / f".{name}.old-{tag}"

    def __enter__(self):
        self.root.mkdir(parents=True, exist_ok=True)
        self.tmp.mkdir()
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.publish()
        else:
            shutil.rmtree(self.tmp, ignore_errors=True)
        return False

    def path(self, relative) -> Path:
        """Where ``relative`` (a path inside the run folder, ``/``-separated) lives in the
        temporary folder, its parent folders created: for writers that need a path."""
        path = self.tmp / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def write(self, relative, data):
        """Write ``data`` (bytes, or text, written as UTF-8) to ``relative``, a path
        inside the run folder."""
        self.path(relative).write_bytes(data if isinstance(data, bytes)
                                        else data.encode("utf-8"))

    def write_json(self, relative, record):
        """Write ``record`` (a dict of JSON values, numpy scalars and arrays) to
        ``relative`` as indented JSON; numpy values become plain numbers and lists.

        Raises
        ------
        TypeError
            For a value JSON cannot hold (not a number, string, list, dict or numpy
            value).
        """
        self.write(relative, json.dumps(record, indent=2, sort_keys=False, default=_jsonable)
                   + "\n")

    def publish(self):
        """Swap the temporary folder into place as :attr:`target` (called on a normal
        exit of the ``with`` block); a previous folder of that name is removed."""
        # two renames: the old folder moves aside, the new one takes its name, then the
        # old one is removed; at no moment is a half-written folder under the target name
        if self.target.exists():
            os.rename(self.target, self._old)
        os.rename(self.tmp, self.target)
        shutil.rmtree(self._old, ignore_errors=True)


def _jsonable(value):
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")
