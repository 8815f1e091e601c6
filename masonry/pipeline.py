"""A whole run: parameters to bricks, interfaces, forces and exports in a run folder.

The library logs progress; it never prints. Timings of every stage go into ``run.json``.
Geometry and interfaces are cached under ``<out>/.cache`` keyed by the geometric inputs,
so a run that changes only ``mu``, ``friction``, ``density`` or the solver reuses them.
"""

import dataclasses
import hashlib
import json
import logging
import pickle
import time
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import numpy as np

from . import __version__, plots
from .blocks import BLOCK_CLASSES
from .export.csv import forces_csv, interfaces_csv, locations_csv
from .export.obj import blocks_obj
from .boundary import analysis_model
from .params import Params, structure_id, validate
from .runfolder import RunFolder
from .scenes import build

log = logging.getLogger(__name__)

G = 9.81  # m/s^2, SPEC 2

PACKAGES = ("numpy", "scipy", "trimesh", "manifold3d", "cvxpy", "osqp", "highspy",
            "clarabel", "meshio", "matplotlib")


def versions() -> dict:
    out = {"masonry": __version__}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


class Timer:
    """Wall-clock seconds per stage, logged as each stage starts."""

    def __init__(self):
        self.seconds = {}

    @contextmanager
    def stage(self, name):
        log.info("%s ...", name)
        start = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[name] = round(time.perf_counter() - start, 4)


def cad_vertices(scene) -> np.ndarray:
    """Vertices moved inward by ``cad_offset`` units along each brick's inward normal
    (``scene.block_inward``; thesis 3.4.1). Scenes without one are not moved."""
    blocks = scene.blocks
    if scene.block_inward is None:
        return blocks.vertices
    shift = scene.params.cad_offset * scene.params.unit * scene.block_inward
    return blocks.vertices + np.repeat(shift, np.diff(blocks.vertex_offsets), axis=0)


def model_record(scene) -> dict:
    """Counts, volume and weight of a built scene, and its pattern report."""
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


def parameters_text(params: Params, sid: str) -> str:
    lines = [f"structure id: {sid}", ""]
    lines += [f"{f.name:>12} = {getattr(params, f.name)}" for f in dataclasses.fields(params)]
    return "\n".join(lines) + "\n"


def objective_text(result) -> str:
    """``RBE/00_objective.txt``: the thesis's summary of a solve, readable."""
    d = result.to_dict()
    verdict = "feasible" if d["feasible"] else "infeasible"
    lines = [
        f"feasibility:        {verdict}",
        f"friction method:    friction-{d['friction']} (mu = {d['mu']:g})",
        f"objective:          {d['objective']:.6g} N^2",
        f"MoI:                {d['moi']:.6g} N",
        f"MoI factor:         {d['moi_factor']:.6g}",
        f"weight:             {d['weight_N']:.6g} N",
        f"solver:             {d['solver']} ({d['status']}, {d['iterations']} iterations)",
        f"residual (eq):      {d['residual_eq']:.3g}",
        f"friction violation: {d['friction_violation']:.3g}",
        f"LP check (HiGHS):   {d['lp_feasible']}",
        f"time:               {d['time_s']:.3g} s",
    ]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------- cache
def _geometry_key(params: Params) -> str:
    key = json.dumps({**params.geometry_key, "version": __version__}, sort_keys=True)
    return hashlib.sha1(key.encode()).hexdigest()[:16]


def _model(params: Params, out_root, timer: Timer):
    """Scene and analysis model (interfaces, boundary routing), from the geometry cache
    when present."""
    cache = Path(out_root) / ".cache" / f"{_geometry_key(params)}.pickle"
    if cache.is_file():
        with timer.stage("model (cached)"):
            with open(cache, "rb") as f:
                scene, model = pickle.load(f)
            # the cached scene carries the geometry; the rest of the inputs are this run's
            scene = dataclasses.replace(scene, params=params)
        return scene, model, "reused"
    with timer.stage("model"):
        scene = build(params)
    with timer.stage("interfaces"):
        model = analysis_model(scene)
    cache.parent.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_suffix(f".tmp{id(scene)}")
    with open(tmp, "wb") as f:
        pickle.dump((scene, model), f, protocol=pickle.HIGHEST_PROTOCOL)
    tmp.replace(cache)
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
    scene : Scene, optional
        An already built scene (``masonry analyze``: blocks read from files, see
        :func:`masonry.assembly.load_assembly`), used as is instead of building
        ``params``, and never cached; ``params`` (with its ``assembly`` name) still names
        the run folder.
    source : dict, optional
        Where such a scene came from (files, supports), recorded in run.json.
    analyse : bool
        Solve the rigid block equilibrium (``masonry run``); False only builds the model
        and its interfaces (``masonry build``).
    plots_wanted, printable : bool
        Write the plots; unite and write the printable body.
    force : bool
        Recompute even when the folder holds a complete run of the same input.

    Returns
    -------
    dict
        The run record (the content of ``run.json``) and its ``path``.
    """
    params = validate(params)
    sid = structure_id(params)
    target = Path(out_root) / sid
    outputs = {"analyse": analyse, "plots": plots_wanted, "printable": printable}
    if not force:
        previous = _previous(target, params, outputs)
        if previous is not None:
            log.info("%s is up to date (use --force to recompute)", sid)
            return {**previous, "path": str(target), "reused": True}

    timer = Timer()
    if scene is None:
        scene, model, cached = _model(params, out_root, timer)
    else:
        scene, cached = dataclasses.replace(scene, params=params), "given"
        with timer.stage("interfaces"):
            model = analysis_model(scene)
    interfaces = model.interfaces
    record = {
        "structure_id": sid,
        "scene": params.scene,
        "params": dataclasses.asdict(params),
        "outputs": outputs,
        **model_record(scene),
        "cache": {"geometry": cached},
    }
    if source is not None:
        record["source"] = source
    record["counts"]["interfaces"] = interfaces.counts()
    result = forces = None
    if analyse:
        from .solve import RBEProblem

        with timer.stage("assembly"):
            problem = RBEProblem(model.blocks, interfaces, side_block=model.side_block,
                                 side_rotation=model.side_rotation)
        with timer.stage("solve"):
            result = problem.solve(mu=params.mu, density=params.density,
                                   friction=params.friction, solver=params.solver,
                                   accuracy=params.solver_accuracy)
        record["rbe"] = {**result.to_dict(), "attempts": list(result.attempts)}
        forces = result.per_interface() if result.x is not None else None

    with RunFolder(out_root, sid) as folder:
        with timer.stage("exports"):
            folder.write("00_parameters.txt", parameters_text(params, sid))
            cad = cad_vertices(scene)
            folder.write("locations.csv", locations_csv(scene.blocks, cad))
            folder.write("bricks.obj", blocks_obj(scene.blocks))
            folder.write("interfaces.csv", interfaces_csv(model.blocks, interfaces))
            _write_rhino(folder, scene.blocks)
            if result is not None:
                folder.write("RBE/00_objective.txt", objective_text(result))
            if forces is not None:
                from .export.vtu import interfaces_vtu

                folder.write("RBE/forces.csv", forces_csv(model.blocks, interfaces, forces))
                if len(interfaces):
                    folder.write("RBE/interfaces.vtu", interfaces_vtu(interfaces, forces))
        if printable:
            with timer.stage("printable"):
                record["printable"] = _write_printable(folder, *printable_blocks(scene))
        if plots_wanted:
            with timer.stage("plots"):
                _write_plots(folder, scene, model, forces)
        record["timings_s"] = timer.seconds
        record["versions"] = versions()
        record["complete"] = True
        folder.write_json("run.json", record)
    record["path"] = str(folder.target)
    return record


def printable_blocks(scene):
    """Blocks and CAD-offset vertices of the printable body: the whole dome in dome mode
    (a section with a boundary, or the dome scene; SPEC 7), else the scene itself."""
    params = scene.params
    if params.scene == "section" and params.boundary != "free":
        from .boundary import rotated_web, rotation_z
        from .blocks import concatenate

        n = params.n
        cad = cad_vertices(scene)
        blocks = concatenate([rotated_web(scene.blocks, k, n) for k in range(n)])
        vertices = np.concatenate([cad @ rotation_z(2 * np.pi * k / n).T for k in range(n)])
        return blocks, vertices
    return scene.blocks, cad_vertices(scene)


def _write_printable(folder, blocks, cad) -> dict:
    from .export.stl import obj_body_bytes, readback_check, stl_bytes
    from .printable import printable_body

    body, report = printable_body(blocks, cad)
    stl = stl_bytes(body)
    report["readback"] = readback_check(stl, report["volume_m3"], rtol=1e-5)
    folder.write("dome.stl", stl)
    folder.write("dome.obj", obj_body_bytes(body))
    return report


def _write_rhino(folder, blocks):
    """``bricks.3dm`` when the optional rhino3dm package is installed."""
    try:
        import rhino3dm  # noqa: F401
    except ImportError:
        log.info("bricks.3dm skipped: pip install 'masonry[rhino]' to write it")
        return
    from .export.rhino import blocks_3dm

    folder.write("bricks.3dm", blocks_3dm(blocks))


def _write_plots(folder, scene, model, forces):
    fast = scene.params.fast
    interfaces = model.interfaces
    if scene.layout is not None:
        folder.write("00_pattern.png", plots.pattern_png(scene, fast))
    for name, png in plots.structure_pngs(scene, fast).items():
        folder.write(name, png)
    for name, png in plots.interface_pngs(model.blocks, interfaces, fast).items():
        folder.write(name, png)
    if forces is not None:
        for name, png in plots.force_pngs(model.blocks, interfaces, forces, fast).items():
            folder.write(f"RBE/{name}", png)
