"""Mesh readers, measured: masonry's against trimesh's and meshio's (``masonry bench
--readers``).

:mod:`masonry.scenes.mesh_files` uses a library's reader where it is within 1.5 times the
time of our own and gives what the block checks need; this bench is how that was
decided and how it is re-measured (docs/bench.md, "Reading meshes"). Every reader goes
from the file's path to what the checks take: vertices ``(V, 3) float64``, triangles
``(T, 3) int64`` and, for a file of named blocks, each triangle's block and the block
names.
"""

import io
import statistics
import time
from pathlib import Path

import numpy as np
from masonry_benchmarks.markdown import markdown_table

from masonry.scenes.mesh_files import read_mesh

READER_COLUMNS = ("file", "reader", "seconds", "vs_masonry", "triangles", "names",
                  "exact", "note")
"""Columns of a reader bench row (:data:`READER_NOTE` says what they hold)."""

READER_NOTE = """One row per file and reader (`masonry bench --readers`). `seconds`: median
over the repeats, from the path to vertices (float64), triangles (int64) and block names;
`vs_masonry`: over the time of masonry's reader (:mod:`masonry.scenes.mesh_files`, which
calls trimesh's for STL and PLY); `names`: how many named blocks the reader tells apart
(0: it gives none); `exact`: its triangle corners are masonry's, bit for bit (as a set of
points); `note`: why a reader gave nothing."""


def reader_bench(paths, repeats=5, progress=None) -> list:
    """Time masonry's, trimesh's and meshio's readers on each mesh file.

    Parameters
    ----------
    paths : sequence of str or Path
        OBJ, STL or PLY files.
    repeats : int
        Reads per reader and file; times are medians.
    progress : callable(str), optional
        Called with a line per row.

    Returns
    -------
    list of dict
        Keys :data:`READER_COLUMNS`; ``seconds`` and the rest are None for a reader that
        failed (``note`` says how).
    """
    rows = []
    for path in map(Path, paths):
        times, results, failures = {name: [] for name in READERS}, {}, {}
        for _ in range(repeats):
            # the readers take turns, so that a change in the machine's load falls on all
            for name, reader in READERS.items():
                if name in failures:
                    continue
                start = time.perf_counter()
                try:
                    results[name] = reader(path)
                except Exception as error:  # a library that cannot read the file is a result
                    failures[name] = f"cannot read: {type(error).__name__}: {error}"[:120]
                    continue
                times[name].append(time.perf_counter() - start)
        for row in _reader_rows(path.name, times, results, failures):
            if progress:
                progress(f"{row['file']}, {row['reader']}: {row['seconds']} s {row['note'] or ''}")
            rows.append(row)
    return rows


def _reader_rows(file, times, results, failures) -> list:
    """Rows of one file: median times, and each reader against masonry's."""
    reference = None
    if "masonry" in results:
        reference = (statistics.median(times["masonry"]), _corner_set(*results["masonry"][:2]))
    rows = []
    for name in READERS:
        row = dict.fromkeys(READER_COLUMNS)
        row.update(file=file, reader=name, note=failures.get(name))
        if name in results:
            vertices, triangles, names = results[name]
            row.update(seconds=statistics.median(times[name]), triangles=len(triangles),
                       names=len(names))
            if reference is not None:
                row.update(vs_masonry=row["seconds"] / reference[0],
                           exact=bool(np.array_equal(_corner_set(vertices, triangles),
                                                     reference[1])))
        rows.append(row)
    return rows


def readers_markdown(rows) -> str:
    """A Markdown table of reader bench rows, and what its columns hold."""
    return markdown_table(rows, READER_COLUMNS, READER_NOTE, digits=3)


def _corner_set(vertices, triangles) -> np.ndarray:
    """(k, 3) float: the distinct triangle corners, sorted (comparable across readers that
    number or triangulate differently)."""
    return np.unique(np.asarray(vertices, float)[triangles].reshape(-1, 3), axis=0)


# ---------------------------------------------------------------------- the readers
def _masonry(path):
    soup = read_mesh(path)
    return soup.vertices, soup.triangles, [] if soup.split_bodies else soup.block_name


def _trimesh(path):
    """trimesh's reader of the format (OBJ: one mesh per object and group, in file order;
    quads cut in two as ``trimesh.Trimesh`` does)."""
    from trimesh.exchange.obj import load_obj
    from trimesh.exchange.ply import load_ply
    from trimesh.exchange.stl import load_stl
    from trimesh.geometry import triangulate_quads

    suffix = path.suffix.lower()
    data = io.BytesIO(path.read_bytes())
    if suffix == ".obj":
        loaded = load_obj(data, split_objects=True, split_groups=True,
                          group_material=False, skip_materials=True)
        parts = list(loaded["geometry"].items())[::-1]  # trimesh gives the last one first
        names = [name for name, _ in parts]
    else:
        loaded = {".stl": load_stl, ".ply": load_ply}[suffix](data)
        parts = list(loaded.get("geometry", {"": loaded}).items())
        names = []
    counts = [len(part["vertices"]) for _, part in parts]
    base = np.cumsum([0] + counts[:-1])
    vertices = np.concatenate([np.asarray(part["vertices"], float) for _, part in parts])
    # OBJ quads stay quads until a Trimesh is built: cut them as its constructor does
    triangles = np.concatenate([triangulate_quads(part["faces"]) + b
                                for (_, part), b in zip(parts, base)])
    return vertices, triangles, names


def _meshio(path):
    """meshio's reader; its polygons cut into fans (meshio keeps no block names)."""
    import meshio

    mesh = meshio.read(path)
    fans = []
    for cells in mesh.cells:
        polygons = np.asarray(cells.data, np.int64)
        k = np.arange(1, polygons.shape[1] - 1)
        fans.append(np.stack([np.repeat(polygons[:, :1], len(k), axis=1),
                              polygons[:, k], polygons[:, k + 1]], axis=2).reshape(-1, 3))
    return np.asarray(mesh.points, float), np.concatenate(fans), []


READERS = {"masonry": _masonry, "trimesh": _trimesh, "meshio": _meshio}
"""Reader name -> path to ``(vertices, triangles, block names)``; masonry's first (the
reference of ``vs_masonry`` and ``exact``)."""
