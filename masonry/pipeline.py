"""A whole run: parameters to bricks, interfaces, forces and exports in a run folder.

The library logs progress; it never prints. Timings of every stage go into ``run.json``.
Geometry and interfaces are cached under ``<out>/.cache`` keyed by the geometric inputs
and the source of the code that builds them, so a run that changes only ``mu``,
``friction``, ``density`` or the solver reuses them, and an edited geometry stage does not.
"""

import dataclasses
import functools
import hashlib
import json
import logging
import pickle
import threading
import time
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import masonry
from masonry import __version__, forking
from masonry.blocks import BLOCK_CLASSES
from masonry.export import EXPORTERS, RunOutputs
from masonry.params import Params, structure_id, validate
from masonry.rbe.boundary import Model, analysis_model
from masonry.rbe.collapse import CollapseResult, collapse_load, worst_lateral
from masonry.rbe.loads import crown_load, lateral, point_loads
from masonry.rbe.solve import RBEProblem, RBEResult, friction_model
from masonry.runfolder import RunFolder, check_output_root, write_file_atomically
from masonry.scenes import Scene, build, check_size
from masonry.tolerances import MAX_BRICKS, G

log = logging.getLogger(__name__)

PACKAGES = ("numpy", "scipy", "trimesh", "manifold3d", "cvxpy", "osqp", "highspy",
            "clarabel", "meshio", "matplotlib")


def versions() -> dict:
    """The versions of masonry and of the :data:`PACKAGES` it runs on, for run.json.

    Returns
    -------
    dict str -> str or None
        ``{"masonry": version, package: version or None when not installed}``.
    """
    out = {"masonry": __version__}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


HEARTBEAT_S = 15.0
"""A stage running longer logs how long it has run, every this many seconds."""


class Timer:
    """Wall-clock seconds per stage, logged as each stage starts (and, while progress is
    logged, every :data:`HEARTBEAT_S` seconds of a long stage).

    Attributes
    ----------
    seconds : dict str -> float
        Seconds per stage name, rounded to 0.1 ms; run.json's ``timings_s``.
    """

    def __init__(self):
        self.seconds = {}

    @contextmanager
    def stage(self, name):
        """Context manager timing the block under stage ``name`` (str); a stage entered
        again (several exporters) adds up."""
        log.info("%s ...", name)
        start = time.perf_counter()
        done = threading.Event()

        def heartbeat():
            while not done.wait(HEARTBEAT_S):
                log.info("%s ... %.0f s", name, time.perf_counter() - start)

        beating = threading.Thread(target=heartbeat, daemon=True)
        if log.isEnabledFor(logging.INFO):
            beating.start()
        try:
            yield
        finally:
            done.set()
            if beating.is_alive():
                beating.join()  # no beat after the stage
            total = self.seconds.get(name, 0.0) + time.perf_counter() - start
            self.seconds[name] = round(total, 4)


def model_record(scene) -> dict:
    """Counts, volume and weight of a built scene, and its pattern report.

    Parameters
    ----------
    scene : masonry.scenes.base.Scene

    Returns
    -------
    dict
        ``counts`` (free bricks, by class, courses; ints), ``volume_m3`` (m^3) and
        ``weight_N`` (N) of the free blocks (supports left out), and where the scene has
        them ``layout`` (repeated joints, short fill-ins) and ``pattern`` (nodes, near
        nodes, boundary bounces, ended lines).
    """
    blocks, params = scene.blocks, scene.params
    free = ~blocks.block_is_support
    classes = {name: int(((blocks.block_class == i) & free).sum())
               for i, name in enumerate(BLOCK_CLASSES)}
    volume = float(blocks.block_volume[free].sum())
    record = {
        "counts": {
            "bricks": int(free.sum()),
            "regular": classes["regular"],
            "pattern": classes["pattern"],
            "fill_in": classes["fill_in"],
            "courses": int(blocks.block_course.max()),
        },
        "volume_m3": volume,
        "weight_N": volume * params.density * G,
    }
    if scene.layout is not None:
        record["layout"] = {
            "repeated_joints": int(scene.layout.repeated_joints.sum()),
            "short_fill_ins": int(scene.layout.short_fill_ins),
        }
    if scene.pattern is not None:
        record["pattern"] = {
            "nodes": len(scene.pattern.nodes),
            "near_nodes": len(scene.pattern.near_nodes),
            "boundary_bounces": len(scene.pattern.boundary_bounces),
            "lines_ended": len(scene.pattern.ended),
        }
    return record


# ---------------------------------------------------------------------------- cache
GEOMETRY_SOURCES = ("params.py", "tolerances.py", "blocks.py", "meshing.py", "interfaces.py",
                    "dome", "scenes", "rbe/boundary.py")
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
    key = json.dumps({**params.geometry_key, "version": __version__,
                      "code": geometry_code_digest()}, sort_keys=True)
    return hashlib.sha1(key.encode()).hexdigest()[:16]


def run_model(params: Params, out_root, timer: Timer, scene=None, check=None):
    """Scene and analysis model of a run: ``(scene, model, 'reused' | 'computed' |
    'given')``. Built from ``params`` through the geometry cache (:func:`_cached_model`),
    or, when ``scene`` is given (blocks read from files), that scene with ``params``,
    analysed as is and never cached. ``check(scene)`` runs before the interfaces are
    detected, as in :func:`_cached_model`."""
    if scene is None:
        return _cached_model(params, out_root, timer, check=check)
    scene = dataclasses.replace(scene, params=params)
    if check is not None:
        check(scene)
    with timer.stage("interfaces"):
        model = analysis_model(scene)
    return scene, model, "given"


def _cached_model(params: Params, out_root, timer: Timer, check=None):
    """Scene and analysis model (interfaces, boundary routing), from the geometry cache
    when it holds them: ``(scene, model, 'reused' | 'computed')``. ``check(scene)``, when
    given, runs on the scene before the interfaces are detected (it raises on bad input).
    A computed model is not cached here: :func:`write_cache` does it once the run's
    folder is published."""
    cached = _read_cache(_cache_path(params, out_root))
    if cached is not None:
        with timer.stage("model (cached)"):
            # the cached scene carries the geometry; the rest of the inputs are this run's
            scene = dataclasses.replace(cached[0], params=params)
        if check is not None:
            check(scene)
        return scene, cached[1], "reused"
    with timer.stage("model"):
        scene = build(params)
    if check is not None:
        check(scene)
    with timer.stage("interfaces"):
        model = analysis_model(scene)
    return scene, model, "computed"


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


def _read_cache(path: Path):
    """``(scene, model)`` from a cache file, or None when there is none or it is unusable
    (truncated, corrupt, naming anything but this package's classes and numpy arrays, or
    not a cache of this code): then it is rebuilt, with a warning."""
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
    """Cache a model computed by :func:`_cached_model` for ``params`` under ``out_root``;
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


OUTPUT_FIELDS = ("print_size",)
"""``Params`` fields that only choose a file's form (the 3MF's size), not the results:
they are not in the structure id, and a folder whose run differs only in them holds the
same input."""


def _input(fields) -> dict:
    """A run's parameters without :data:`OUTPUT_FIELDS`."""
    return {k: v for k, v in fields.items() if k not in OUTPUT_FIELDS}


def _previous(target: Path, params: Params):
    """The record of a complete earlier run of the same input in ``target``, else None."""
    try:
        record = json.loads((target / "run.json").read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or not isinstance(record.get("params"), dict):
        return None
    same = (_input(record["params"]) == _input(json.loads(json.dumps(
        dataclasses.asdict(params)))) and record.get("complete") is True)
    return record if same else None


def _print_size(record):
    """The size (mm) of the ``dome.3mf`` a run record wrote, or None."""
    printable = record.get("printable")
    written = printable.get("print") if isinstance(printable, dict) else None
    return written.get("size_mm") if isinstance(written, dict) else None


def _covers(record, outputs: dict, print_size=None) -> bool:
    """Whether a run record wrote at least ``outputs`` (solve, plots, printable body) and,
    when ``print_size`` (mm) asks for a 3MF beside the printable body, one of that size."""
    had = record.get("outputs") or {}
    wrote = all(had.get(name) is True or not wanted for name, wanted in outputs.items())
    return wrote and (print_size is None or not outputs.get("printable")
                      or _print_size(record) == print_size)


def _stamp(target: Path):
    """Identity of the run.json in ``target`` (inode, mtime), or None: tells whether
    another command published the folder while this run was computing."""
    try:
        stat = (target / "run.json").stat()
    except OSError:
        return None
    return stat.st_ino, stat.st_mtime_ns


# ---------------------------------------------------------------------------- the run
def run(params: Params, out_root="exports", *, analyse=True, plots_wanted=True,
        printable=True, force=False, scene=None, source=None,
        max_bricks=MAX_BRICKS) -> dict:
    """Build, analyse and export ``params`` into ``out_root/<structure id>``.

    A run folder only grows (no command degrades another's results): a folder that
    already holds a complete run of the same input with at least the outputs asked for
    is reused as it is (``masonry build`` after ``masonry run``, a sweep variant after a
    full run); otherwise the run writes what is asked for *and* what the folder held
    (``masonry run`` after a sweep writes the plots and the solve, ``--force`` after a
    run with plots writes the plots again). ``print_size`` is an output choice here
    (:data:`OUTPUT_FIELDS`): a run without it keeps the folder's ``dome.3mf``, a run with
    another size writes the 3MF at that size. When another command publishes the same
    folder while this one computes, the richer of the two stays.

    Parameters
    ----------
    params : Params
    out_root : str or Path
        The output root; the run folder is ``out_root/<structure id>``.
    analyse : bool
        Solve the rigid block equilibrium (``masonry run``); False only builds the model
        and its interfaces (``masonry build``).
    plots_wanted, printable : bool
        Write the plots; unite and write the printable body.
    force : bool
        Recompute even when the folder holds a complete run of the same input (with at
        least the outputs that run wrote).
    scene : Scene, optional
        An already built scene (``masonry analyze``: blocks read from files, see
        :func:`masonry.scenes.imported.load_assembly`), used as is instead of building
        ``params``, and never cached; ``params`` (with its ``assembly`` name) still names
        the run folder.
    source : dict, optional
        Where such a scene came from (files, supports), recorded in run.json.
    max_bricks : int
        A model estimated larger (:func:`masonry.scenes.check_size`) is refused before
        anything is built.

    Returns
    -------
    dict
        The run record (the content of ``run.json``) and its ``path``.
    """
    params = validate(params)
    check_output_root(out_root)
    if scene is None:
        check_size(params, max_bricks)
    sid = structure_id(params)
    target = Path(out_root) / sid
    outputs = {"analyse": analyse, "plots": plots_wanted, "printable": printable}
    previous, seen = _previous(target, params), _stamp(target)
    if previous is not None:
        if not force and _covers(previous, outputs, params.print_size):
            log.info("%s is up to date (use --force to recompute)", sid)
            return {**previous, "path": str(target), "reused": True}
        # a run folder only grows: what the earlier run wrote is written again (its 3MF
        # too, at its size, unless this run asks for another)
        outputs = {name: wanted or (previous.get("outputs") or {}).get(name) is True
                   for name, wanted in outputs.items()}
        if params.print_size is None and _print_size(previous) is not None:
            params = params.replace(print_size=_print_size(previous))

    timer = Timer()
    scene, model, cached = run_model(params, out_root, timer, scene)
    record = run_record(scene, model, outputs, cached, source)
    result = _solve(model, params, timer) if outputs["analyse"] else None
    if result is not None:
        record["rbe"] = {**result.to_dict(), "attempts": list(result.attempts)}
    collapse = None
    if outputs["analyse"] and params.live_load_kind is not None:
        with timer.stage("collapse"):
            collapse = collapse_of(model, params, result)
        record["collapse"] = collapse.to_dict()
    made = RunOutputs(scene, model, result,
                      result.per_interface() if result is not None and result.x is not None
                      else None, plots=outputs["plots"], printable=outputs["printable"],
                      collapse=collapse)

    def keep(existing):
        # another command published this input meanwhile, with at least these outputs
        other = _previous(existing, params)
        return (_stamp(existing) != seen and other is not None
                and _covers(other, outputs, params.print_size))

    with RunFolder(out_root, sid, keep=keep) as folder:
        write_exports(folder, made, record, timer)
        record["coordinates"] = _held(record["coordinates"], folder)
        record["timings_s"] = timer.seconds
        record["versions"] = versions()
        record["complete"] = True
        folder.write_json("run.json", record)
    if cached == "computed":  # only a model whose run completed is cached
        write_cache(params, out_root, scene, model)
    record["path"] = str(folder.target)
    return record


def _held(coordinates: dict, folder: RunFolder) -> dict:
    """``coordinates`` with the files ``folder`` holds only (no 3DM without rhino3dm, no
    3MF without a size, no forces in a build)."""
    return {key: [name for name in value if (folder.tmp / name).exists()]
            if isinstance(value, list) else value for key, value in coordinates.items()}


def run_record(scene: Scene, model: Model, outputs: dict, cached: str, source=None) -> dict:
    """The run.json record of a built model, before any solve.

    Parameters
    ----------
    scene : masonry.scenes.base.Scene
    model : masonry.rbe.boundary.Model
        Its analysis model; its interface counts by kind go into ``counts``.
    outputs : dict str -> bool
        What the run writes (``analyse``, ``plots``, ``printable``).
    cached : str
        ``'reused'``, ``'computed'`` or ``'given'``: where the geometry came from.
    source : dict, optional
        Where an imported scene came from.

    Returns
    -------
    dict
        Structure id, scene name, parameters, outputs, :func:`model_record`, cache
        state and source.
    """
    params = scene.params
    record = {
        "structure_id": structure_id(params),
        "scene": params.scene,
        "params": dataclasses.asdict(params),
        "outputs": outputs,
        **model_record(scene),
        "coordinates": coordinates_record(scene),
        "cache": {"geometry": cached},
    }
    if source is not None:
        record["source"] = source
    record["counts"]["interfaces"] = model.interfaces.counts()
    return record


MOVED_FILES = ("locations.csv", "dome.stl", "dome.obj", "dome.3mf")
"""The files whose bricks are moved inward by the CAD offset (SPEC 7, thesis 3.4.1)."""


def coordinates_record(scene: Scene) -> dict:
    """run.json's ``coordinates``: which files hold model coordinates and which are moved
    inward by ``cad_offset`` (metres, along each brick's inward normal), so that files
    imported together line up once the user knows it."""
    params = scene.params
    moved = scene.block_inward is not None and params.cad_offset != 0
    return {
        "cad_offset_m": params.cad_offset * params.unit if moved else 0.0,
        "moved_inward": list(MOVED_FILES) if moved else [],
        "model": ["bricks.obj", "bricks.3dm", "interfaces.csv", "RBE/forces.csv",
                  "RBE/interfaces.vtu"] + ([] if moved else list(MOVED_FILES)),
    }


def _solve(model: Model, params: Params, timer: Timer) -> RBEResult:
    with timer.stage("assembly"):
        problem = RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                             side_rotation=model.side_rotation)
    with timer.stage("solve"):
        return problem.solve(mu=params.mu, density=params.density, friction=params.friction,
                             solver=params.solver, accuracy=params.solver_accuracy,
                             cone=params.friction_cone)


def collapse_of(model: Model, params: Params, rbe: RBEResult | None = None) -> CollapseResult:
    """The collapse load factor of the run's live load (SPEC 6.8). A feasible RBE verdict
    stands for the dead load; otherwise the LP decides it. ``--crown-load`` is the load on
    the whole dome: a section carries its ``1/n`` share."""
    known = True if rbe is not None and rbe.feasible else None
    options = dict(mu=params.mu, density=params.density,
                   cone=friction_model(params.solver_accuracy, params.friction_cone))
    if params.lateral == "all":
        webs = params.n if params.scene in ("section", "dome") else None
        # the full dome repeats every 360/n degrees (tests/test_collapse.py checks it)
        period = 360.0 / params.n if params.scene == "dome" else None
        return worst_lateral(model, n_webs=webs, period_deg=period,
                             dead_load_feasible=known, **options)
    if params.lateral is not None:
        live = lateral(model, params.lateral, params.density)
    elif params.point_loads:
        live = point_loads(model.blocks, params.point_loads)
    else:
        live = crown_load(model.blocks, params.crown_load,
                          copies=params.n if params.scene == "section" else 1)
    result = collapse_load(model, live, dead_load_feasible=known,
                           friction=params.friction_law, **options)
    if params.lateral is not None:
        result = dataclasses.replace(result, azimuth_deg=float(params.lateral))
    return result


def write_exports(folder: RunFolder, made: RunOutputs, record: dict, timer: Timer):
    """Every wanted exporter of :data:`masonry.export.EXPORTERS` into ``folder``; their
    records go into ``record`` under their names.

    Where processes fork (Linux), the exporters marked ``aside`` (the 3DM file, the
    plots) are made in a second process, on the second core, while this one makes and
    writes the others; this process writes every file. Their stage then counts the time
    this process waited for them.

    Parameters
    ----------
    folder : RunFolder
        Anything with ``write(relative, data)``.
    made : masonry.export.RunOutputs
        What the run made; each exporter's ``wanted(made)`` decides whether it writes.
    record : dict
        The run record, updated in place.
    timer : Timer
        Each exporter's time counts towards its stage.
    """
    wanted = [exporter for exporter in EXPORTERS if exporter.wanted(made)]
    aside = [exporter for exporter in wanted if exporter.aside] if forking.can_fork() else []
    with forking.Forked([functools.partial(e.make, made) for e in aside]) as second:
        for exporter in [e for e in wanted if e not in aside] + aside:
            with timer.stage(exporter.stage):
                export = second.result() if exporter in aside else exporter.make(made)
                for relative, data in export.files.items():
                    folder.write(relative, data)
            if export.record is not None:
                record[exporter.name] = export.record
