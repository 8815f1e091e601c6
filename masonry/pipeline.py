"""A whole run: parameters to bricks, interfaces, forces and exports in a run folder.

The library logs progress; it never prints. Timings of every stage go into ``run.json``.
Geometry and interfaces are cached under ``<out>/.cache`` keyed by the geometric inputs
and the source of the code that builds them, so a run that changes only ``mu``,
``friction``, ``density`` or the solver reuses them, and an edited geometry stage does not.
"""

import dataclasses
import hashlib
import json
import logging
import pickle
import time
from functools import cache
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import masonry
from masonry import __version__
from masonry.blocks import BLOCK_CLASSES
from masonry.export import EXPORTERS, RunOutputs
from masonry.params import Params, structure_id, validate
from masonry.rbe.boundary import Model, analysis_model
from masonry.rbe.solve import RBEProblem, RBEResult
from masonry.runfolder import RunFolder, write_file_atomically
from masonry.scenes import Scene, build
from masonry.tolerances import G

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


class Timer:
    """Wall-clock seconds per stage, logged as each stage starts.

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
        try:
            yield
        finally:
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


@cache
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


def cached_model(params: Params, out_root, timer: Timer, check=None):
    """Scene and analysis model (interfaces, boundary routing), from the geometry cache
    when present: ``(scene, model, 'reused' | 'computed')``. ``check(scene)``, when
    given, runs on the scene before anything is written (it raises on bad input)."""
    cache = Path(out_root) / ".cache" / f"{_geometry_key(params)}.pickle"
    if cache.is_file():
        with timer.stage("model (cached)"):
            with open(cache, "rb") as f:
                scene, model = pickle.load(f)
            # the cached scene carries the geometry; the rest of the inputs are this run's
            scene = dataclasses.replace(scene, params=params)
        if check is not None:
            check(scene)
        return scene, model, "reused"
    with timer.stage("model"):
        scene = build(params)
    if check is not None:
        check(scene)
    with timer.stage("interfaces"):
        model = analysis_model(scene)
    write_file_atomically(cache, pickle.dumps((scene, model),
                                              protocol=pickle.HIGHEST_PROTOCOL))
    return scene, model, "computed"


def _previous(target: Path, params: Params, outputs: dict):
    """The record of a complete earlier run of the same input, else None."""
    try:
        record = json.loads((target / "run.json").read_text())
    except (OSError, ValueError):
        return None
    same = (record.get("params") == json.loads(json.dumps(dataclasses.asdict(params)))
            and record.get("outputs") == outputs and record.get("complete"))
    return record if same else None


# ---------------------------------------------------------------------------- the run
def run(params: Params, out_root="exports", *, analyse=True, plots_wanted=True,
        printable=True, force=False, scene=None, source=None) -> dict:
    """Build, analyse and export ``params`` into ``out_root/<structure id>``.

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
        Recompute even when the folder holds a complete run of the same input.
    scene : Scene, optional
        An already built scene (``masonry analyze``: blocks read from files, see
        :func:`masonry.scenes.imported.load_assembly`), used as is instead of building
        ``params``, and never cached; ``params`` (with its ``assembly`` name) still names
        the run folder.
    source : dict, optional
        Where such a scene came from (files, supports), recorded in run.json.

    Returns
    -------
    dict
        The run record (the content of ``run.json``) and its ``path``.
    """
    params = validate(params)
    sid = structure_id(params)
    outputs = {"analyse": analyse, "plots": plots_wanted, "printable": printable}
    previous = None if force else _previous(Path(out_root) / sid, params, outputs)
    if previous is not None:
        log.info("%s is up to date (use --force to recompute)", sid)
        return {**previous, "path": str(Path(out_root) / sid), "reused": True}

    timer = Timer()
    if scene is None:
        scene, model, cached = cached_model(params, out_root, timer)
    else:
        scene, cached = dataclasses.replace(scene, params=params), "given"
        with timer.stage("interfaces"):
            model = analysis_model(scene)
    record = run_record(scene, model, outputs, cached, source)
    result = _solve(model, params, timer) if analyse else None
    if result is not None:
        record["rbe"] = {**result.to_dict(), "attempts": list(result.attempts)}
    made = RunOutputs(scene, model, result,
                      result.per_interface() if result is not None and result.x is not None
                      else None, plots=plots_wanted, printable=printable)
    with RunFolder(out_root, sid) as folder:
        write_exports(folder, made, record, timer)
        record["timings_s"] = timer.seconds
        record["versions"] = versions()
        record["complete"] = True
        folder.write_json("run.json", record)
    record["path"] = str(folder.target)
    return record


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
                             solver=params.solver, accuracy=params.solver_accuracy)


def write_exports(folder: RunFolder, made: RunOutputs, record: dict, timer: Timer):
    """Every wanted exporter of :data:`masonry.export.EXPORTERS` into ``folder``; their
    records go into ``record`` under their names.

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
    for exporter in EXPORTERS:
        if not exporter.wanted(made):
            continue
        with timer.stage(exporter.stage):
            export = exporter.make(made)
            for relative, data in export.files.items():
                folder.write(relative, data)
        if export.record is not None:
            record[exporter.name] = export.record
