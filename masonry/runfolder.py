"""The one place that writes a run's files, atomically, and the protocol by which every
command publishes a run folder (docs/model.md 7).

A run writes into a hidden temporary folder beside its target and swaps it into place
only when everything is written. A failed or interrupted run removes its temporary folder
and leaves the previous output exactly as it was. Single files outside a run folder (the
geometry cache) are written the same way by :func:`write_file_atomically`.

Temporary names carry the host and process id of their writer
(``.<name>.tmp-<host>-<pid>-<tag>``), so the next run into the same root removes the
leftovers of a killed run (its process is gone) and never those of a run still going.
Publishing happens under an exclusive lock on the output root, so two commands writing
into the same root at once never see a half-swapped folder; a caller may ask to keep the
folder already there (see :meth:`RunFolder.publish`).

:class:`Publication` is the protocol every command that publishes a run folder follows
(``masonry run``, ``build``, ``stages``, a sweep's variants): a folder holding a complete
run of the same input with at least the outputs asked for is reused as it is; otherwise
the run writes what is asked for *and* what the folder held (a run folder only grows);
when another command publishes the same folder meanwhile, the richer of the two stays.
"""

import json
import logging
import math
import os
import re
import shutil
import socket
import tempfile
import uuid
from contextlib import contextmanager
from pathlib import Path

from masonry.errors import MasonryError, ParameterError

try:
    import fcntl
except ImportError:  # Windows: no advisory locks; publishing stays two renames
    fcntl = None

log = logging.getLogger(__name__)

_HOST = re.sub(r"[^A-Za-z0-9]", "_", socket.gethostname()) or "host"
_LEFTOVER = re.compile(r"^\..+\.(tmp|old)-(?P<host>[A-Za-z0-9_]+)-(?P<pid>\d+)-[0-9a-f]{8}$")
_LEGACY = re.compile(r"^\..+\.(tmp|old)-[0-9a-f]{8}$")  # masonry 0.1: no writer in the name


NAME_MAX = 200
"""Longest folder name accepted in an output root (bytes): file systems allow 255, and
the run folders' temporary names add up to about 50 to a structure id."""


RUN_FOLDER_DEPTH = NAME_MAX + 150
"""Bytes a run folder adds to its root's path: its (temporary) name and the longest path of
a file inside it, with room to spare."""


def _path_max(folder) -> int:
    """The longest path the file system of ``folder`` takes, in bytes (Windows: 260)."""
    try:
        return os.pathconf(folder, "PC_PATH_MAX")
    except (AttributeError, OSError, ValueError):  # no pathconf (Windows) or no answer
        return 260 if os.name == "nt" else 4096


def _tag() -> str:
    """``<host>-<pid>-<random>``: who writes a temporary file, and a unique suffix."""
    return f"{_HOST}-{os.getpid()}-{uuid.uuid4().hex[:8]}"


def check_output_root(root, option="out") -> Path:
    """Refuse an output root that cannot hold run folders, before anything is written.

    The root may not exist yet; its nearest existing ancestor must be a folder this
    process can create entries in (probed with a temporary folder, removed at once).

    Parameters
    ----------
    root : str or Path
        The output root as the user gave it.
    option : str
        The parameter named in the error (the front end shows it as typed, ``--out``).

    Returns
    -------
    Path
        ``root``.

    Raises
    ------
    ParameterError
        Named ``option``: the root is empty, has a name or a path too long for a run
        folder inside it, is (or lies under) a file, or is not writable.
    """
    if str(root).strip() == "":
        raise ParameterError(option, str(root), "a folder path (an empty one names nothing)")
    path = Path(root)
    longest = max((len(os.fsencode(part)) for part in path.parts), default=0)
    if longest > NAME_MAX:
        raise ParameterError(option, str(root), f"a folder path whose names are at most "
                                                f"{NAME_MAX} bytes long (one has {longest})")
    existing = path
    while not os.path.lexists(existing) and existing != existing.parent:
        existing = existing.parent
    length, limit = len(os.fsencode(os.path.abspath(path))), _path_max(existing)
    if length + RUN_FOLDER_DEPTH > limit:
        raise ParameterError(option, str(root), f"a folder path at most "
                                                f"{limit - RUN_FOLDER_DEPTH} bytes long (this "
                                                f"one has {length}; the system takes paths "
                                                f"of {limit} bytes, and a run folder adds up "
                                                f"to {RUN_FOLDER_DEPTH})")
    if not existing.is_dir():
        what = "is a file" if existing == path else f"lies under the file {existing}"
        raise ParameterError(option, str(root), f"a folder, but it {what}")
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".masonry-probe-", dir=existing))
    except OSError as error:
        raise ParameterError(option, str(root), f"a folder masonry can write in (creating "
                                                f"an entry in {existing} failed: "
                                                f"{error.strerror or error})") from None
    return path


def remove_leftovers(folder) -> list:
    """Remove the temporary files and folders that killed runs left in ``folder``.

    Only names of this host whose process no longer exists are removed. A previous folder
    set aside by a publish that was killed before the new one took its name is put back.

    Parameters
    ----------
    folder : str or Path
        An output root (or the folder of a single file written atomically); a missing
        or unreadable one holds no leftovers.

    Returns
    -------
    list of Path
        What was removed.
    """
    removed = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    for entry in entries:
        match = _LEFTOVER.match(entry.name)
        if match is None:
            if not _LEGACY.match(entry.name):
                continue
        elif match["host"] != _HOST or _alive(int(match["pid"])):
            continue
        original = entry.with_name(entry.name[1:].rsplit(".old-", 1)[0])
        if ".old-" in entry.name and not os.path.lexists(original):
            # killed between the two renames of a publish: the previous folder goes back
            os.rename(entry, original)
            log.warning("restored %s, set aside by a run that was killed", original)
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
        else:
            entry.unlink(missing_ok=True)
        removed.append(entry)
    if removed:
        log.info("removed %d leftover(s) of interrupted runs in %s", len(removed), folder)
    return removed


def _alive(pid: int) -> bool:
    if pid == os.getpid() or os.name == "nt":  # Windows' os.kill(pid, 0) would kill it
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process
        return True
    return True


@contextmanager
def locked(folder):
    """Hold an exclusive lock on ``folder`` (an existing directory) for the block (POSIX
    advisory lock; nothing on systems without one)."""
    if fcntl is None:
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


@contextmanager
def alone(path):
    """Hold ``path`` (a file, created empty with its folder if missing) for the block,
    or refuse at once if another process holds it: a file that one process at a time
    may append to (an optimisation's journal). A POSIX advisory lock, released when the
    process ends however it ends; nothing on systems without one.

    Raises
    ------
    MasonryError
        Another process holds ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise MasonryError(f"{path} is in use by another process (another "
                                   f"'masonry optimize' of this study into this --out): "
                                   f"wait for it to end, or give another --out") from None
        yield
    finally:
        os.close(fd)  # closing releases the lock


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
    remove_leftovers(path.parent)
    tmp = path.with_name(f".{path.name}.tmp-{_tag()}")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


class RunFolder:
    """Collects a run's files and publishes them as ``root/name`` in one step.

    Use as a context manager: the folder is published when the block ends normally and
    discarded when it raises (including ``KeyboardInterrupt``). Entering it removes the
    leftovers of killed runs in ``root``.

    Parameters
    ----------
    root : str or Path
        The output root (created on entry when missing).
    name : str
        The run folder's name inside ``root`` (the structure id).
    keep : callable, optional
        ``keep(target) -> bool``, asked under the root's lock just before publishing: True
        keeps the folder already at ``target`` and discards this one (it holds at least
        what this one would write; see :func:`masonry.pipeline.run`).

    Attributes
    ----------
    target : Path
        ``root/name``, where the folder is published.
    tmp : Path
        The hidden temporary folder the files are written into until then.
    kept : bool
        True when ``keep`` kept the folder already at ``target`` (this one was discarded).

    Examples
    --------
    >>> with RunFolder("exports", "wall_L32") as folder:  # doctest: +SKIP
    ...     folder.write("notes.txt", "text")
    ...     folder.write_json("run.json", {"complete": True})
    """

    def __init__(self, root, name, keep=None):
        self.root = Path(root)
        self.target = self.root / name
        tag = _tag()
        self.tmp = self.root / f".{name}.tmp-{tag}"
        self._old = self.root / f".{name}.old-{tag}"
        self._keep = keep
        self.kept = False

    def __enter__(self):
        self.root.mkdir(parents=True, exist_ok=True)
        remove_leftovers(self.root)
        try:
            self.tmp.mkdir()
        except BaseException:  # an interrupt right after the mkdir: no __exit__ follows
            shutil.rmtree(self.tmp, ignore_errors=True)
            raise
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
        ``relative`` as indented, strict JSON (:func:`strict_json`).

        Raises
        ------
        TypeError
            For a value JSON cannot hold (not a number, string, list, dict or numpy
            value).
        """
        self.write(relative, strict_json(record))

    def publish(self):
        """Swap the temporary folder into place as :attr:`target` (called on a normal
        exit of the ``with`` block), under the root's lock; a previous folder of that name
        is removed, unless ``keep`` keeps it (then this one is discarded).

        Two renames: the old folder moves aside, the new one takes its name, then the old
        one is removed; at no moment is a half-written folder under the target name.
        """
        with locked(self.root):
            if self._keep is not None and self.target.is_dir() and self._keep(self.target):
                shutil.rmtree(self.tmp, ignore_errors=True)
                self.kept = True
                return
            if os.path.lexists(self.target):
                os.rename(self.target, self._old)
            os.rename(self.tmp, self.target)
        shutil.rmtree(self._old, ignore_errors=True)


def strict_json(record) -> str:
    """``record`` as indented JSON that every reader takes (JavaScript, ``jq``): numpy
    values become plain numbers and lists, and a missing or unbounded number (NaN,
    infinity) becomes ``null``; the record's statuses say why."""
    return json.dumps(_plain(record), indent=2, sort_keys=False, allow_nan=False) + "\n"


def _plain(value):
    """``value`` with numpy values as Python ones and non-finite floats as None."""
    import numpy as np

    if isinstance(value, dict):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(item) for item in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


class Publication:
    """One command's results for ``root/name``, published by the run-folder protocol.

    Parameters
    ----------
    root : str or Path
        The output root.
    name : str
        The run folder's name (a structure id, with a study's suffix).
    identity : dict
        What makes the folder's result (its ``params`` in ``run.json``, plus anything
        else the command records as inputs, e.g. a stage plan): a JSON-able dict; an
        earlier record with other keys or values is of another input.
    wanted : dict
        The outputs asked for, as ``run.json`` records them under ``outputs``: names ->
        True/False (``plots``, ``printable``, ...), ``quick`` (figures in one view: they do
        not stand for the full ones), ``print_size`` (mm of ``dome.3mf`` or None: a
        3MF of another size is not the one asked for), ``figure_format`` (the figures'
        formats: a folder without one of them does not hold what is asked) and ``dpi``
        (figures at another resolution are not the ones asked for), ``html_plotly``
        (where ``dome.html`` finds plotly.js: a page that reads a shared file is not the
        one asked for with plotly.js inside).
    force : bool
        Recompute even when the folder holds what is asked for (it still only grows).
    identify : callable, optional
        ``identify(record) -> dict``: the part of a record compared with ``identity``
        (default: its keys of ``identity``).
    """

    def __init__(self, root, name, identity: dict, wanted: dict, *, force=False,
                 identify=None):
        self.root, self.name = Path(root), name
        self.target = self.root / name
        self.identity = _round_trip(identity)
        self._identify = identify or (lambda record: {key: record.get(key)
                                                      for key in self.identity})
        self.wanted, self.force = dict(wanted), force
        self.previous = self._complete_record(self.target)
        self._seen = _stamp(self.target)

    def reusable(self) -> dict | None:
        """The earlier record when it holds everything asked for (and not ``force``):
        the command then writes nothing."""
        if self.previous is None or self.force or not covers(self.previous, self.wanted):
            return None
        log.info("%s is up to date (use --force to recompute)", self.name)
        return {**self.previous, "path": str(self.target), "reused": True}

    def outputs(self) -> dict:
        """What to write: the outputs asked for and those the folder held (a run folder
        only grows; its 3MF at its size, unless another is asked for)."""
        had = (self.previous or {}).get("outputs") or {}
        grown = {name: (value or had.get(name) is True) if isinstance(value, bool) else value
                 for name, value in self.wanted.items() if name not in ("quick",
                                                                        "print_size")}
        if "figure_format" in self.wanted:  # the figures in every format asked or held
            held = figure_formats_of(had) if had.get("plots") is True else ()
            grown["figure_format"] = tuple(dict.fromkeys((*self.wanted["figure_format"],
                                                          *held)))
        full_plots = had.get("plots") is True and had.get("quick") is not True
        grown["quick"] = bool(self.wanted.get("quick")) and not full_plots
        size = self.wanted.get("print_size")
        grown["print_size"] = size if size is not None else printed_size(self.previous)
        return grown

    def publish(self, write) -> "RunFolder":
        """Write the folder with ``write(folder)`` (a :class:`RunFolder`) and publish it,
        unless another command published a record of the same input covering these
        outputs while this one computed (then that folder stays)."""

        def keep(existing):
            other = self._complete_record(existing)
            return (_stamp(existing) != self._seen and other is not None
                    and covers(other, self.outputs()))

        with RunFolder(self.root, self.name, keep=keep) as folder:
            write(folder)
        return folder

    def _complete_record(self, target) -> dict | None:
        try:
            record = json.loads((Path(target) / "run.json").read_text())
        except (OSError, ValueError):
            return None
        if not isinstance(record, dict) or record.get("complete") is not True:
            return None
        try:
            same = _round_trip(self._identify(record)) == self.identity
        except (AttributeError, TypeError):  # a record of another shape
            return None
        return record if same else None


def covers(record: dict, wanted: dict) -> bool:
    """Whether a run record wrote at least ``wanted`` (see :class:`Publication`)."""
    had = record.get("outputs") or {}
    for name, value in wanted.items():
        if name == "quick":
            if not value and had.get("plots") is True and had.get("quick") is True:
                return False
        elif name == "figure_format":
            if wanted.get("plots") and not set(value) <= set(figure_formats_of(had)):
                return False
        elif name == "dpi":  # figures at another resolution are not the ones asked
            if wanted.get("plots") and had.get("plots") is True and had.get("dpi") != value:
                return False
        elif name == "html_plotly":  # a page with plotly.js inside opens anywhere
            if (value == "inline" and wanted.get("html") and had.get("html") is True
                    and had.get("html_plotly", "inline") != "inline"):
                return False
        elif name == "print_size":
            if value is not None and wanted.get("printable") and printed_size(record) != value:
                return False
        elif value is True and had.get(name) is not True:
            return False
    return True


def figure_formats_of(outputs: dict) -> tuple:
    """The formats of the figures a record's ``outputs`` wrote (PNG before there were
    others)."""
    return tuple(outputs.get("figure_format") or ("png",)) if outputs.get("plots") else ()


def printed_size(record) -> float | None:
    """The size (mm) of the ``dome.3mf`` a run record wrote, or None."""
    printable = (record or {}).get("printable")
    written = printable.get("print") if isinstance(printable, dict) else None
    return written.get("size_mm") if isinstance(written, dict) else None


def _stamp(target: Path):
    """Identity of the run.json in ``target`` (inode, mtime), or None: tells whether
    another command published the folder while this run was computing."""
    try:
        stat = (Path(target) / "run.json").stat()
    except OSError:
        return None
    return stat.st_ino, stat.st_mtime_ns


def _round_trip(value):
    """``value`` as it reads back from ``run.json`` (tuples as lists, numpy values plain),
    for comparisons with a record."""
    return json.loads(strict_json(value))


def source_file(path) -> str:
    """The absolute path of the file a study's folder is named after, as its ``run.json``
    records it (``study_file``): :func:`check_study_folder`."""
    return str(Path(path).resolve())


def check_study_folder(out_root, name: str, study_file) -> None:
    """Refuse ``out_root/name`` (a study's folder, named after its file) to a study
    file other than the one whose folder it is (``run.json``'s ``study_file``): two
    studies of one file name in different folders would overwrite each other's.

    Raises
    ------
    ParameterError
        Named ``study``, with the folder and the other file.
    """
    try:
        record = json.loads((Path(out_root) / name / "run.json").read_text())
    except (OSError, ValueError):
        return
    other = record.get("study_file") if isinstance(record, dict) else None
    if isinstance(other, str) and other != source_file(study_file):
        raise ParameterError("study", str(study_file), f"a study file whose name no other "
                             f"study's folder in {out_root} has: {name} is that of {other}; "
                             f"rename this file or give another --out")
