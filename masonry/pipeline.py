"""A whole run: parameters to bricks, interfaces, forces and exports in a run folder.

The library logs progress; it never prints. Timings of every stage go into ``run.json``.
Geometry and interfaces are cached under ``<out>/.cache`` (:mod:`masonry.cache`), so a run
that changes only ``mu``, ``friction``, ``density`` or the solver reuses them.
"""

import dataclasses
import importlib
import logging
import threading
import time
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

from masonry import __version__, forking
from masonry.blocks import BLOCK_CLASSES
from masonry.cache import read_cache, write_cache
from masonry.export import EXPORTERS, RunOutputs, html, rhino, written_outputs
from masonry.outputs import WRITTEN_OUTPUTS
from masonry.params import FILE_OUTPUTS, Params, structure_id, validate
from masonry.rbe.accuracy import ACCURACY
from masonry.rbe.adhesion import AdhesionResult, least_adhesion, stands_dry
from masonry.rbe.boundary import Model, analysis_model
from masonry.rbe.centering import CenteringResult, centering_force
from masonry.rbe.collapse import CollapseResult, collapse_load, collapse_on_half
from masonry.rbe.lateral_search import worst_lateral
from masonry.rbe.loads import Lateral
from masonry.rbe.mirror import (equilibrium_on_the_whole, half_model, states_exactly,
                                 symmetric_plane)
from masonry.rbe.result import RBEResult
from masonry.rbe.solve import RBEProblem
from masonry.runfolder import (Publication, RunFolder, check_output_root,
                               write_file_atomically)
from masonry.scenes import Scene, build, check_size
from masonry.tolerances import MAX_BRICKS, G

log = logging.getLogger(__name__)

PACKAGES = ("numpy", "scipy", "trimesh", "manifold3d", "cvxpy", "osqp", "highspy",
            "clarabel", "meshio", "matplotlib", "plotly")


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


def model_record(scene, density: float) -> dict:
    """Counts, volume and weight of a built scene, and its pattern report.

    Parameters
    ----------
    scene : masonry.scenes.base.Scene
    density : float, kg/m^3

    Returns
    -------
    dict
        ``counts`` (free bricks, by class, courses; ints), ``volume_m3`` (m^3) and
        ``weight_N`` (N) of the free blocks (supports left out), and where the scene has
        them ``layout`` (repeated joints, short fill-ins) and ``pattern`` (lines, nodes,
        near nodes, boundary bounces, ended lines; ``ended`` and
        ``ended_far_below_top``: ``[course, s]`` of the last brick of every line that
        ended, and of those that ended far below the top, docs/model.md 4.3).
    """
    blocks = scene.blocks
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
        "weight_N": volume * density * G,
    }
    if scene.layout is not None:
        record["layout"] = {
            "repeated_joints": int(scene.layout.repeated_joints.sum()),
            "short_fill_ins": int(scene.layout.short_fill_ins),
        }
    if scene.pattern is not None:
        pattern = scene.pattern
        record["pattern"] = {
            "lines": pattern.n_lines,
            "nodes": len(pattern.nodes),
            "near_nodes": len(pattern.near_nodes),
            "boundary_bounces": len(pattern.boundary_bounces),
            "lines_ended": len(pattern.ended),
            "ended": pattern.ended.tolist(),
            "ended_far_below_top": pattern.ended_far_below_top(
                scene.levels.n_courses).tolist(),
            "ended_why": scene.kind.pattern_ends,
        }
    return record


def build_model(params: Params) -> tuple:
    """``(scene, model)``: the scene of ``params`` and its analysis model, with the
    analysis's boundary (no cache)."""
    scene = build(params)
    return scene, analysis_model(scene, params.analysis.boundary)


def run_model(params: Params, out_root, timer: Timer, scene=None, check=None):
    """Scene and analysis model of a run: ``(scene, model, 'reused' | 'computed' |
    'given')``. Built from ``params`` through the geometry cache (:func:`_cached_model`),
    or, when ``scene`` is given (blocks read from files), that scene, analysed as is and
    never cached. ``check(scene)`` runs before the interfaces are detected, as in
    :func:`_cached_model`."""
    if scene is None:
        return _cached_model(params, out_root, timer, check=check)
    if check is not None:
        check(scene)
    with timer.stage("interfaces"):
        model = analysis_model(scene, params.analysis.boundary)
    return scene, model, "given"


def _cached_model(params: Params, out_root, timer: Timer, check=None):
    """Scene and analysis model (interfaces, boundary routing), from the geometry cache
    when it holds them: ``(scene, model, 'reused' | 'computed')``. ``check(scene)``, when
    given, runs on the scene before the interfaces are detected (it raises on bad input).
    A computed model is not cached here: :func:`write_cache` does it once the run's
    folder is published."""
    cached = read_cache(params, out_root)
    if cached is not None:
        with timer.stage("model (cached)"):
            scene, model = cached
        if check is not None:
            check(scene)
        return scene, model, "reused"
    with timer.stage("model"):
        scene = build(params)
    if check is not None:
        check(scene)
    with timer.stage("interfaces"):
        model = analysis_model(scene, params.analysis.boundary)
    return scene, model, "computed"


def identity(params: Params) -> dict:
    """What makes a run's result: its inputs as ``run.json`` records them, without those
    that only choose files (:data:`~masonry.params.FILE_OUTPUTS`)."""
    return {name: value for name, value in params.record().items()
            if name not in FILE_OUTPUTS}


def _identify(record) -> dict:
    return {"params": {name: value for name, value in record["params"].items()
                       if name not in FILE_OUTPUTS}}


def with_outputs(params: Params, outputs: dict) -> Params:
    """``params`` writing ``outputs`` (:meth:`masonry.runfolder.Publication.outputs`;
    the :data:`~masonry.params.FILE_OUTPUTS` it names)."""
    chosen = {name: outputs[name] for name in FILE_OUTPUTS if name in outputs}
    return dataclasses.replace(params, outputs=dataclasses.replace(params.outputs, **chosen))


# ---------------------------------------------------------------------------- a job
@dataclasses.dataclass
class Job:
    """A command's run folder in the making: what :func:`run` and
    :func:`masonry.stages.run.run_stages` do before and after their own analysis.

    :meth:`open` checks the inputs, the output root and the model's size before anything
    is built or written, and names the structure once; :meth:`publication` opens its run
    folder by the run-folder protocol (:class:`~masonry.runfolder.Publication`);
    :meth:`publish` writes it and then caches a model the job computed.

    Attributes
    ----------
    params : Params
        Validated; after :meth:`publication`, writing the folder's outputs.
    out_root : str or Path
        The output root.
    structure_id : str
        :func:`masonry.params.structure_id` of ``params``: the run folder's name (or its
        start), in the record and the figures' titles.
    timer : Timer
        The job's stages' times.
    outputs : dict or None
        After :meth:`publication`: what the folder gets (those asked for and those it
        held, :meth:`~masonry.runfolder.Publication.outputs`).
    """

    params: Params
    out_root: object
    structure_id: str
    timer: Timer
    outputs: dict | None = None
    folder: Publication | None = None

    @classmethod
    def open(cls, params: Params, out_root, scene=None, max_bricks=MAX_BRICKS) -> "Job":
        """``params`` validated, ``out_root`` checked and, unless ``scene`` is given
        (blocks read from files), a model estimated larger than ``max_bricks`` refused
        (:func:`masonry.scenes.check_size`): raises before anything is built."""
        params = validate(params)
        check_output_root(out_root)
        if scene is None:
            check_size(params, max_bricks)
        return cls(params, out_root, structure_id(params), Timer())

    def publication(self, name: str, identity: dict, wanted: dict, *, force=False,
                    identify=None) -> dict | None:
        """The run folder ``out_root/name`` (:class:`~masonry.runfolder.Publication`'s
        arguments): its earlier record when it holds what is ``wanted`` (the job then
        writes nothing), else None, and :attr:`params` writes :attr:`outputs`."""
        folder = Publication(self.out_root, name, identity, wanted, force=force,
                             identify=identify)
        reused = folder.reusable()
        if reused is None:
            self.folder, self.outputs = folder, folder.outputs()
            self.params = with_outputs(self.params, self.outputs)
        return reused

    def publish(self, write, scene: Scene, model: Model, cached: str):
        """The folder written by ``write(folder)`` and published
        (:meth:`~masonry.runfolder.Publication.publish`); then a model the job computed
        (``cached``, :func:`run_model`) is cached: only a model whose job completed."""
        folder = self.folder.publish(write)
        if cached == "computed":
            write_cache(self.params, self.out_root, scene, model)
        return folder


# ---------------------------------------------------------------------------- the run
def run(params: Params, out_root="exports", *, analyse=True, force=False, scene=None,
        source=None, max_bricks=MAX_BRICKS) -> dict:
    """Build, analyse and export ``params`` into ``out_root/<structure id>``.

    The run folder is published by the run-folder protocol
    (:class:`masonry.runfolder.Publication`): a folder that already holds a complete run
    of the same input with at least the outputs asked for (``params.outputs``) is
    reused as it is; otherwise the run writes what is asked for and what the folder
    held (``print_size`` chooses a file, not the input: a run without it keeps the
    folder's ``dome.3mf``).

    Parameters
    ----------
    params : Params
    out_root : str or Path
        The output root; the run folder is ``out_root/<structure id>``.
    analyse : bool
        Solve the rigid block equilibrium and, where the structure cannot stand, its
        centering force (``masonry run``; ``outputs.centering`` in run.json: a folder
        written before the centering force is not reused); False only builds the model
        and its interfaces (``masonry build``).
    force : bool
        Recompute even when the folder holds a complete run of the same input.
    scene : Scene, optional
        An already built scene (``masonry analyze``: blocks read from files, see
        :func:`masonry.assembly.read_assembly`), used as is instead of building
        ``params``, and never cached.
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
    job = Job.open(params, out_root, scene, max_bricks)
    out = job.params.outputs
    # bricks.3dm whenever rhino3dm is there: a folder written without it is not up to
    # date once it is
    wanted = {"analyse": analyse, "centering": analyse, "adhesion": analyse,
              "3dm": rhino.available(),
              **{name: getattr(out, name) for name in FILE_OUTPUTS}, "html": out.writes_html}
    reused = job.publication(job.structure_id, {"params": identity(job.params)}, wanted,
                             force=force, identify=_identify)
    if reused is not None:
        share_plotly(out_root, reused["outputs"])
        return reused
    params, outputs, timer = job.params, job.outputs, job.timer
    scene, model, cached = run_model(params, out_root, timer, scene)
    record = run_record(params, job.structure_id, scene, model, outputs, cached, source)
    result = solve(model, params, timer) if outputs["analyse"] else None
    centering = collapse = None
    if result is not None and not result.feasible:
        with timer.stage("centering"):
            centering = centering_of(model, params)
    adhesion = None
    if result is not None:
        with timer.stage("adhesion"):
            adhesion = adhesion_of(model, params, result)
    if result is not None and params.load is not None:
        with timer.stage("collapse"):
            collapse = collapse_of(model, params, result)
    record.update(results_record(result, collapse, centering, model.blocks.block_name,
                                 adhesion))
    made = RunOutputs(params, scene, model, result, collapse=collapse, centering=centering,
                      adhesion=adhesion, title=job.structure_id)
    share_plotly(out_root, outputs)  # once the run has a page, before it is published
    folder = job.publish(lambda folder: write_run(folder, made, record, timer), scene, model,
                         cached)
    return {**record, "path": str(folder.target)}


def share_plotly(out_root, outputs: dict):
    """The plotly.js file the pages of ``out_root``'s run folders read
    (:func:`masonry.export.html.plotly_file`), when ``outputs`` (a run's, as ``run.json``
    records them) has a page that reads it: written once per output root, and read back.

    Raises
    ------
    OSError
        When the file cannot be written or reads back other than it was written.
    """
    if outputs.get("html") is not True or outputs.get("html_plotly") != "shared":
        return
    path, data = Path(out_root) / html.plotly_file(), html.plotly_js()
    if path.is_file() and path.read_bytes() == data:
        return
    write_file_atomically(path, data)
    if path.read_bytes() != data:
        raise OSError(f"{path} reads back other than was written")


def results_record(result: RBEResult | None, collapse: CollapseResult | None,
                   centering: CenteringResult | None = None, names=None,
                   adhesion: AdhesionResult | None = None) -> dict:
    """run.json's ``rbe``, ``collapse``, ``centering`` and ``adhesion`` (the blocks named
    by ``names``, per block of the model), where the run has them."""
    out = {}
    if result is not None:
        out["rbe"] = {**result.to_dict(), "attempts": list(result.attempts)}
    if centering is not None:
        out["centering"] = centering.to_dict(names)
    if adhesion is not None:
        out["adhesion"] = adhesion.to_dict(names)
    if collapse is not None:
        out["collapse"] = collapse.to_dict()
    return out


def write_run(folder: RunFolder, made: RunOutputs, record: dict, timer: Timer):
    """Every file of a run and, last, its ``run.json`` (``record``, completed)."""
    written = write_exports(folder, made, record, timer)
    # what was written, as the exporters say (a printable body skipped: run.json's
    # printable says why)
    record["outputs"].update(written_outputs(written))
    files = {path for paths in written.values() for path in paths}
    record["coordinates"] = _held(record["coordinates"], files)
    record["timings_s"] = timer.seconds
    record["versions"] = versions()
    record["complete"] = True
    folder.write_json("run.json", record)


def _held(coordinates: dict, files: set) -> dict:
    """``coordinates`` with the run's written ``files`` only (no 3DM without rhino3dm, no
    3MF without a size, no forces in a build)."""
    return {key: [name for name in value if name in files]
            if isinstance(value, list) else value for key, value in coordinates.items()}


def run_record(params: Params, name: str, scene: Scene, model: Model, outputs: dict,
               cached: str, source=None) -> dict:
    """The run.json record of a built model, before any solve.

    Parameters
    ----------
    params : Params
    name : str
        Its structure id (:func:`masonry.params.structure_id`).
    scene : masonry.scenes.base.Scene
    model : masonry.rbe.boundary.Model
        Its analysis model; its interface counts by kind go into ``counts``.
    outputs : dict str -> bool
        What the run writes (``analyse``, ``centering``,
        :data:`~masonry.outputs.WRITTEN_OUTPUTS`, ``quick``).
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
    record = {
        "structure_id": name,
        "scene": params.scene,
        "params": params.record(),
        "outputs": {name: outputs[name] for name in ("analyse", "centering", "adhesion",
                                                     *WRITTEN_OUTPUTS, "quick",
                                                     "figure_format", "dpi",
                                                     "html_plotly")},
        **model_record(scene, params.analysis.density),
        "coordinates": coordinates_record(scene, params.outputs.cad_offset),
        "cache": {"geometry": cached},
    }
    if source is not None:
        record["source"] = source
    record["counts"]["interfaces"] = model.interfaces.counts()
    return record


MOVED_FILES = ("locations.csv", "dome.stl", "dome.obj", "dome.3mf")
"""The files whose bricks are moved inward by the CAD offset (docs/model.md 7, thesis
3.4.1)."""


def coordinates_record(scene: Scene, cad_offset: float) -> dict:
    """run.json's ``coordinates``: which files hold model coordinates and which are moved
    inward by ``cad_offset`` units (metres in the record, along each brick's inward
    normal), so that files imported together line up once the user knows it."""
    moved = scene.block_inward is not None and cad_offset != 0
    return {
        "cad_offset_m": cad_offset * scene.unit if moved else 0.0,
        "moved_inward": list(MOVED_FILES) if moved else [],
        "model": ["bricks.obj", "bricks.3dm", "interfaces.csv", "RBE/forces.csv",
                  "RBE/interfaces.vtu"] + ([] if moved else list(MOVED_FILES)),
    }


def solve(model: Model, params: Params, timer: Timer) -> RBEResult:
    """The rigid block equilibrium of a run's model (docs/model.md 6): on its half in
    the scene's first mirror plane, if it has one and the friction model is Coulomb's
    cone (self weight is its own mirror image in every plane), reported on the whole
    (docs/model.md 6.11) once its forces pass the check there
    (:meth:`~masonry.rbe.result.RBEResult.checked`); where they do not, the whole is
    solved (``solved_on``, logged as a warning)."""
    analysis = params.analysis
    mirrors = params.kind.symmetry(params.geometry).mirrors
    half = None
    with timer.stage("assembly"):
        if mirrors and states_exactly(analysis.cone, analysis.law.cohesion_Pa):
            half = half_model(model, mirrors[0])
        solved = model if half is None else half.model
        problem = RBEProblem(solved.blocks, solved.interfaces, **solved.assembly)
    options = dict(**analysis.rbe_options(), **analysis.mortar_on(model.interfaces))
    with timer.stage("solve"):
        result = problem.solve(**options)
        if half is None:
            return result
        whole = equilibrium_on_the_whole(half, result, analysis.density)
        if whole.checked():
            return dataclasses.replace(whole, time_s=result.time_s, solved_on="half")
        log.warning("the half's forces fail their check on the whole (equilibrium residual "
                    "%.2g, friction violation %.2g): the whole model is solved instead",
                    whole.residual_eq, whole.friction_violation)
        problem = RBEProblem(model.blocks, model.interfaces, **model.assembly)
        result = problem.solve(**options)
        return dataclasses.replace(result, solved_on="whole, the half rejected")


def centering_of(model: Model, params: Params) -> CenteringResult:
    """The centering force of a run's model (docs/model.md 6.10): the least force that
    supports at the blocks' centroids must give for it to stand, under the run's friction
    model. A run computes it when the structure cannot stand."""
    analysis = params.analysis
    return centering_force(model, **analysis.material_options(),
                           **analysis.mortar_on(model.interfaces))


def adhesion_of(model: Model, params: Params, rbe: RBEResult | None = None) -> AdhesionResult:
    """The least adhesion of a run's model (docs/model.md 6.12) under the run's friction
    model, with its tension ratio: 0 without a program where the run has dry joints and
    its verdict is feasible (``rbe``), else the program's."""
    analysis = params.analysis
    law = analysis.law
    if rbe is not None and rbe.feasible and law.is_dry:
        return stands_dry(model.interfaces, law, analysis.adhesion_tension_ratio)
    return least_adhesion(model, **analysis.adhesion_options())


def collapse_of(model: Model, params: Params, rbe: RBEResult | None = None) -> CollapseResult:
    """The collapse load factor of the run's live load (docs/model.md 6.8). A feasible RBE
    verdict stands for the dead load; otherwise the program decides it. A lateral search
    uses the scene's symmetry; a crown load on a part of the dome (a section) is its
    share of the whole dome's. A load symmetric in one of the scene's mirror planes (a
    lateral load along it, a crown load) is solved on the half in that plane and
    reported on the whole (docs/model.md 6.11), with associated friction."""
    known = True if rbe is not None and rbe.feasible else None
    analysis, load = params.analysis, params.load
    options = analysis.material_options()
    symmetry = params.kind.symmetry(params.geometry)
    copies = symmetry.order if symmetry.unit else 1
    if isinstance(load, Lateral) and load.azimuth_deg == "all":
        result = worst_lateral(model, n_webs=symmetry.webs, period_deg=symmetry.period_deg,
                               mirrors=symmetry.mirrors, dead_load_feasible=known, **options,
                               **analysis.mortar_on(model.interfaces),
                               azimuth_rel=ACCURACY[analysis.accuracy].azimuth_rel)
        return _checked_collapse(model, params, result, 1, known)
    plane = symmetric_plane(load, symmetry.mirrors)
    if (plane is not None and analysis.friction_law == "associated"
            and states_exactly(analysis.cone, analysis.law.cohesion_Pa)):  # dry joints
        result = collapse_on_half(model, load, plane, copies=copies,
                                  dead_load_feasible=known, **options)
    else:
        result = collapse_load(model, load.on(model, analysis.density, copies=copies),
                               dead_load_feasible=known, friction=analysis.friction_law,
                               **options, **analysis.mortar_on(model.interfaces))
    if isinstance(load, Lateral) and load.azimuth_deg != "all":
        result = dataclasses.replace(result, azimuth_deg=float(load.azimuth_deg))
    return _checked_collapse(model, params, result, copies, known)


def _checked_collapse(model, params, result, copies, known) -> CollapseResult:
    """``result``, or where it was solved on a half whose forces fail their check on the
    whole (:meth:`~masonry.rbe.collapse_result.CollapseResult.checked`), the same load
    (at the same azimuth) solved on the whole (``solved_on``, logged as a warning)."""
    if result.solved_on != "half" or result.checked():
        return result
    log.warning("the half's collapse forces fail their check on the whole (residual %.2g): "
                "the whole model is solved instead", result.residual)
    analysis = params.analysis
    load = params.load
    if isinstance(load, Lateral):
        load = Lateral(result.azimuth_deg)
    whole = collapse_load(model, load.on(model, analysis.density, copies=copies),
                          dead_load_feasible=known, friction=analysis.friction_law,
                          **analysis.material_options(), **analysis.mortar_on(model.interfaces))
    return dataclasses.replace(whole, azimuth_deg=result.azimuth_deg,
                               azimuths=result.azimuths, solved_on="whole, the half rejected")


def write_exports(folder: RunFolder, made: RunOutputs, record: dict, timer: Timer) -> dict:
    """Every wanted exporter of :data:`masonry.export.EXPORTERS` into ``folder``; their
    records go into ``record`` under their names. Returns what each wrote: its name ->
    the paths of its files in the folder (:func:`masonry.export.written_outputs`).

    The forces (what a user waits for) are made here first; where processes fork (Linux)
    and the process has two cores, this process and a forked copy then share the others,
    each taking the next exporter not yet taken (:class:`masonry.forking.Shared`; the
    registry lists the long ones first), each writing the files it made into the
    folder and handing back their names and its record (when the forked process fails,
    this one makes and writes its share again, over what it wrote). The exporters made
    here count their time towards their stage, and the time this process waited for the
    other's share counts as ``other_process``.

    Parameters
    ----------
    folder : RunFolder
        Anything with ``write(relative, data)`` that writes to disk (a forked process
        writes its share through its copy of it).
    made : masonry.export.RunOutputs
        What the run made; each exporter's ``wanted(made)`` decides whether it writes.
    record : dict
        The run record, updated in place.
    timer : Timer
        Each exporter's time counts towards its stage.
    """
    wanted = [exporter for exporter in EXPORTERS if exporter.wanted(made)]
    written = {}

    def written_by(exporter):
        """Make ``exporter``'s files and write them (in either process: the folder is a
        path, and a large file does not travel back through a pipe); its files' names
        and its record."""
        export = exporter.make(made)
        for relative, data in export.files.items():
            folder.write(relative, data)
        return tuple(export.files), export.record

    def note(exporter, done):
        written[exporter.name], part = done
        if part is not None:
            _merge(record, exporter.key, part)

    first = [exporter for exporter in wanted if exporter.stage == "forces"]
    for exporter in first:
        with timer.stage(exporter.stage):
            note(exporter, written_by(exporter))
    rest = [exporter for exporter in wanted if exporter not in first]
    for name in dict.fromkeys(name for exporter in rest for name in exporter.imports):
        importlib.import_module(name)  # once, before the processes part
    with forking.Shared(lambda index: written_by(rest[index]), len(rest)) as shared:
        while (index := shared.take()) is not None:
            with timer.stage(rest[index].stage):
                note(rest[index], written_by(rest[index]))
        if shared.forked_off:
            with timer.stage("other_process"):
                for index, done in sorted(shared.theirs().items()):
                    note(rest[index], done)
    return written


def _merge(record: dict, key: str, part: dict):
    """``part`` into ``record[key]``, dict entries of both merged (two exporters' records
    under one key)."""
    held = record.setdefault(key, {})
    for name, value in part.items():
        if isinstance(held.get(name), dict):
            held[name] = {**held[name], **value}
        elif isinstance(held.get(name), list):  # the figures' files: sorted, all of them
            held[name] = sorted(held[name] + value)
        else:
            held[name] = value
