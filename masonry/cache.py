"""The geometry cache of a run's output root: a built scene and its analysis model under
``<out>/.cache``, keyed by the geometric inputs and the source of the code that builds
them, so a run that changes only ``mu``, ``friction``, ``density`` or the solver reuses
them, and an edited geometry stage does not (:func:`masonry.pipeline.run_model`)."""

import functools
import hashlib
import json
import logging
import pickle
from pathlib import Path

import masonry
from masonry import __version__
from masonry.params import Params, geometry_key
from masonry.rbe.boundary import Model
from masonry.runfolder import write_file_atomically
from masonry.scenes import Scene

log = logging.getLogger(__name__)


GEOMETRY_SOURCES = ("params.py", "parameters.py", "tolerances.py", "blocks.py", "meshing.py",
                    "interfaces.py", "dome", "scenes", "rbe/boundary.py")
"""The package's files (or folders) whose code decides a cached scene and model."""


@functools.cache
def geometry_code_digest() -> str:
    """SHA-1 of the source of :data:`GEOMETRY_SOURCES`: part of the cache key, so an edited
    geometry stage never reuses a stale cache at the same version number.

    Returns
    -------
    str
        40 hex digits over every file's path and bytes, in sorted order; computed once
        per process.
    """
    root = Path(masonry.__file__).parent
    digest = hashlib.sha1()
    for name in GEOMETRY_SOURCES:
        path = root / name
        for file in sorted(path.rglob("*.py")) if path.is_dir() else [path]:
            digest.update(file.relative_to(root).as_posix().encode())
            digest.update(file.read_bytes())
    return digest.hexdigest()


def _geometry_key(params: Params) -> str:
    key = json.dumps({"geometry": geometry_key(params), "version": __version__,
                      "code": geometry_code_digest()}, sort_keys=True)
    return hashlib.sha1(key.encode()).hexdigest()[:16]


def _cache_path(params: Params, out_root) -> Path:
    return Path(out_root) / ".cache" / f"{_geometry_key(params)}.pickle"


NUMPY_REBUILDERS = {("numpy._core.multiarray", "_reconstruct"),
                    ("numpy._core.multiarray", "scalar"),
                    ("numpy._core.numeric", "_frombuffer"),
                    ("numpy.core.multiarray", "_reconstruct"),
                    ("numpy.core.multiarray", "scalar"),
                    ("numpy.core.numeric", "_frombuffer")}
"""The functions a pickled numpy array or scalar is rebuilt by (numpy 2 and 1.26)."""


class _CacheUnpickler(pickle.Unpickler):
    """Loads this package's classes and numpy's arrays only: a cache file put in an output
    folder by someone else cannot name a function to run (the pickle module's
    "Restricting Globals"); anything else is refused before its module is imported."""

    def find_class(self, module, name):
        ours = module.startswith("masonry.") or module in ("numpy", "numpy.dtypes")
        if (module, name) in NUMPY_REBUILDERS:
            return super().find_class(module, name)
        found = super().find_class(module, name) if ours else None
        if not isinstance(found, type):
            raise pickle.UnpicklingError(f"{module}.{name} is not allowed in a geometry "
                                         f"cache")
        return found


def read_cache(params: Params, out_root):
    """``(scene, model)`` of ``params`` from ``out_root``'s cache file, or None when there
    is none or it is unusable (truncated, corrupt, naming anything but this package's
    classes and numpy arrays, or not a cache of this code): then it is rebuilt, with a
    warning."""
    path = _cache_path(params, out_root)
    try:
        with open(path, "rb") as f:
            content = _CacheUnpickler(f).load()
    except (FileNotFoundError, NotADirectoryError):
        return None
    except Exception as error:  # unpickling garbage can raise anything
        log.warning("the geometry cache %s is unreadable (%s: %s): rebuilding the model",
                    path, type(error).__name__, error)
        return None
    if not (isinstance(content, tuple) and len(content) == 2
            and isinstance(content[0], Scene) and isinstance(content[1], Model)):
        log.warning("the geometry cache %s holds something else: rebuilding the model", path)
        return None
    return content


def write_cache(params: Params, out_root, scene: Scene, model: Model):
    """Cache a model computed by :func:`masonry.pipeline.run_model` for ``params`` under ``out_root``;
    called once the run's folder is published, so a failed run caches nothing. A cache
    that cannot be written only costs the next run the rebuild (warned), never this
    run's results."""
    path = _cache_path(params, out_root)
    try:
        write_file_atomically(path, pickle.dumps((scene, model),
                                                 protocol=pickle.HIGHEST_PROTOCOL))
    except OSError as error:
        log.warning("the geometry cache %s was not written (%s): the next run rebuilds the "
                    "model", path, error.strerror or error)
