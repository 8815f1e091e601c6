"""A whole run: parameters to bricks (and later interfaces and forces) to a run folder.

The library logs progress; it never prints. Timings of every stage go into ``run.json``.
"""

import dataclasses
import logging
import time
from contextlib import contextmanager
from importlib import metadata

import numpy as np

from . import __version__, plots
from .blocks import BLOCK_CLASSES
from .export.csv import interfaces_csv, locations_csv
from .export.obj import blocks_obj
from .interfaces import detect
from .params import Params, structure_id, validate
from .runfolder import RunFolder
from .scenes import build

log = logging.getLogger(__name__)

G = 9.81  # m/s^2, SPEC 2

PACKAGES = ("numpy", "scipy", "trimesh", "manifold3d", "shapely", "cvxpy", "osqp",
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
    (the normal of its inner face, face 0 of a hexahedral brick; thesis 3.4.1)."""
    blocks = scene.blocks
    first_face = np.searchsorted(blocks.face_block, np.arange(blocks.n_blocks))
    inward = blocks.face_normal[first_face]
    shift = scene.params.cad_offset * scene.params.unit * inward
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


def build_run(params: Params, out_root="exports", plots_wanted=True) -> dict:
    """Build the model of ``params`` and write its run folder ``out_root/<structure id>``.

    Returns the run record (the content of ``run.json``).
    """
    params = validate(params)
    sid = structure_id(params)
    timer = Timer()
    with timer.stage("model"):
        scene = build(params)
    with timer.stage("interfaces"):
        interfaces = detect(scene.blocks, up=scene.block_up)
    record = {
        "structure_id": sid,
        "scene": params.scene,
        "params": dataclasses.asdict(params),
        **model_record(scene),
    }
    record["counts"]["interfaces"] = interfaces.counts()
    with RunFolder(out_root, sid) as folder:
        with timer.stage("exports"):
            folder.write("00_parameters.txt", parameters_text(params, sid))
            folder.write("locations.csv", locations_csv(scene.blocks, cad_vertices(scene)))
            folder.write("bricks.obj", blocks_obj(scene.blocks))
            folder.write("interfaces.csv", interfaces_csv(scene.blocks, interfaces))
        if plots_wanted:
            with timer.stage("plots"):
                if scene.layout is not None:
                    folder.write("00_pattern.png", plots.pattern_png(scene, params.fast))
                for name, png in plots.structure_pngs(scene, params.fast).items():
                    folder.write(name, png)
                for name, png in plots.interface_pngs(scene.blocks, interfaces,
                                                      params.fast).items():
                    folder.write(name, png)
        record["timings_s"] = timer.seconds
        record["versions"] = versions()
        folder.write_json("run.json", record)
    record["path"] = str(folder.target)
    return record
