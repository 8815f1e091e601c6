"""What ``masonry clean`` removes from an output root: the files a command makes again
when asked (the figures, ``dome.html`` and the shared plotly.js, the printable body,
``bricks.3dm``, the geometry cache), keeping what cannot be remade without the run or is
small (``run.json``, the CSV tables, ``00_parameters.txt``, the model's files).

Only the run folders of the root are touched (a folder whose ``run.json`` is a complete
masonry record), and of each only the files above; its ``run.json`` then says the run no
longer holds them (``outputs.plots``, ``html``, ``printable``, ``3dm`` false), so that a
command asking for them again writes them (:class:`masonry.runfolder.Publication`).
"""

import json
import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from masonry.errors import ParameterError
from masonry.runfolder import locked, strict_json, write_file_atomically

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
"""The figures' files, at any depth of a run folder."""

REMADE = {"html": ("dome.html",), "printable": ("dome.stl", "dome.obj", "dome.3mf"),
          "3dm": ("bricks.3dm",)}
"""The output (``run.json``'s ``outputs`` key) -> its files at the top of a run folder,
besides the figures (``plots``)."""

DROPPED_RECORDS = {"plots": "figures", "printable": "printable"}
"""The ``run.json`` entries that describe an output's files, dropped with them."""

SHARED_PLOTLY = re.compile(r"^plotly-[0-9A-Za-z.\-]+\.min\.js$")
"""The shared plotly.js files of the root (:func:`masonry.export.html.plotly_file`)."""

CACHE = ".cache"
"""The geometry cache's folder in the root (:func:`masonry.cache.write_cache`)."""

WRITING = re.compile(r"^\..+\.tmp-")
"""A run folder being written (:class:`masonry.runfolder.RunFolder`): while one is, the
shared plotly.js stays (its page may be published next)."""


@dataclass(frozen=True)
class Cleaning:
    """What cleaning an output root removes.

    Attributes
    ----------
    root : Path
    files : tuple of (Path, int)
        Each file removed and its size, bytes.
    records : dict Path -> dict
        Each run folder's ``run.json`` as it is written after the removal.
    """

    root: Path
    files: tuple
    records: dict

    @property
    def bytes(self) -> int:
        """The bytes removed."""
        return sum(size for _, size in self.files)


def run_record(folder: Path) -> dict | None:
    """The ``run.json`` of ``folder`` when it is a complete masonry record, else None."""
    try:
        record = json.loads((folder / "run.json").read_text())
    except (OSError, ValueError):
        return None
    if (not isinstance(record, dict) or record.get("complete") is not True
            or not isinstance(record.get("outputs"), dict)
            or "masonry" not in (record.get("versions") or {})):
        return None
    return record


def plan(root) -> Cleaning:
    """What :func:`clean` would remove from ``root``; removes nothing.

    Raises
    ------
    ParameterError
        Named ``out``: ``root`` is not a folder holding a masonry run folder or the
        geometry cache.
    """
    root = Path(root)
    folders = sorted(p for p in root.iterdir() if _is_folder(p)) if root.is_dir() else []
    records = {p: r for p in folders if (r := run_record(p)) is not None}
    if not records and not (root / CACHE).is_dir():
        raise ParameterError("out", str(root), "a masonry output root: a folder holding "
                                               "run folders (each with its run.json)")
    files, cleaned = [], {}
    for folder, record in records.items():
        removed = _remade_files(folder)
        if removed:
            files.extend(path for paths in removed.values() for path in paths)
            cleaned[folder] = _cleaned_record(record, removed)
    if (root / CACHE).is_dir():
        files.extend(p for p in sorted((root / CACHE).rglob("*")) if p.is_file())
    if not any(WRITING.match(p.name) for p in root.iterdir()):
        files.extend(p for p in sorted(root.iterdir())
                     if p.is_file() and SHARED_PLOTLY.match(p.name))
    return Cleaning(root, tuple((p, p.stat().st_size) for p in files), cleaned)


def clean(cleaning: Cleaning) -> None:
    """Remove the files of ``cleaning`` (:func:`plan`) under the root's lock (no command
    publishes a folder meanwhile) and write each run folder's new ``run.json``, read
    back."""
    with locked(cleaning.root):
        for path, _ in cleaning.files:
            path.unlink(missing_ok=True)
        for folder, record in cleaning.records.items():
            text = strict_json(record)
            write_file_atomically(folder / "run.json", text.encode("utf-8"))
            if (folder / "run.json").read_text() != text:
                raise OSError(f"{folder / 'run.json'} reads back other than was written")
            _remove_empty_folders(folder)
        if (cleaning.root / CACHE).is_dir() and not any((cleaning.root / CACHE).iterdir()):
            shutil.rmtree(cleaning.root / CACHE)


def _is_folder(path: Path) -> bool:
    return path.is_dir() and not path.is_symlink() and not path.name.startswith(".")


def _remade_files(folder: Path) -> dict:
    """Output -> its files in ``folder`` (figures at any depth; a symlink never)."""
    found = {"plots": [p for p in sorted(folder.rglob("*"))
                       if p.suffix.lower() in FIGURE_SUFFIXES and p.is_file()
                       and not p.is_symlink()]}
    for output, names in REMADE.items():
        found[output] = [folder / n for n in names
                         if (folder / n).is_file() and not (folder / n).is_symlink()]
    return {output: paths for output, paths in found.items() if paths}


def _cleaned_record(record: dict, removed: dict) -> dict:
    """``record`` saying its folder no longer holds the outputs of ``removed``."""
    outputs = dict(record["outputs"])
    record = dict(record)
    for output in removed:
        if output in outputs:
            outputs[output] = False
        if output in DROPPED_RECORDS:
            record.pop(DROPPED_RECORDS[output], None)
    record["outputs"] = outputs
    return record


def _remove_empty_folders(folder: Path) -> None:
    """The folders of figures ``folder`` holds that cleaning left empty."""
    inside = (p for p in folder.rglob("*") if p.is_dir() and not p.is_symlink())
    for path in sorted(inside, reverse=True):
        if not any(path.iterdir()):
            os.rmdir(path)
