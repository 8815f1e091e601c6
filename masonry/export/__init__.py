"""Exporters, one module per format, and the registry the pipeline iterates.

Each exporter turns what a run made (:class:`RunOutputs`) into files, as bytes or text
keyed by their path inside the run folder; :mod:`masonry.runfolder` is the one place that
writes them. An exporter may also return a record for ``run.json`` (the printable body's
checks). A new format is a module and one :class:`Exporter` row in :data:`EXPORTERS`.
"""

import dataclasses
import functools
import logging
from functools import cache
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import PurePosixPath

import numpy as np

from masonry.blocks import web_motion, web_name, whole_of_web
from masonry.export import (compas_json, csv, html, obj, rhino, stl, summaries, threemf,
                            vtu)
from masonry.printable import PrintableError, printable_blocks, printable_body
from masonry.rbe.equilibrium import VariableLayout
from masonry.rbe.resultants import interface_resultants
from masonry.tolerances import TENSION_REPORTED_REL

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class RunOutputs:
    """What one run made, handed to every exporter.

    Parameters
    ----------
    params : masonry.params.Params
        The run's inputs; its ``outputs`` say what to write.
    scene : masonry.scenes.base.Scene
    model : masonry.rbe.boundary.Model
        The analysed blocks (the scene's, then any neighbour images) and interfaces.
    result : masonry.rbe.result.RBEResult or None
        The rigid block equilibrium; None when the run only builds.
    collapse : masonry.rbe.collapse.CollapseResult or None
        The collapse load factor of the run's live load (docs/model.md 6.8), if it has
        one.
    centering : masonry.rbe.centering.CenteringResult or None
        The centering force (docs/model.md 6.10) of a structure that cannot stand.
    adhesion : masonry.rbe.adhesion.AdhesionResult or None
        The least adhesion (docs/model.md 6.12).
    title : str
        The run's name in figures (its structure id).
    """

    params: object
    scene: object
    model: object
    result: object = None
    collapse: object = None
    centering: object = None
    adhesion: object = None
    title: str = ""

    @property
    def outputs(self):
        """The run's :class:`~masonry.outputs.Outputs`."""
        return self.params.outputs

    @property
    def figure_title(self) -> str:
        """The line naming the structure and scene under every figure's title."""
        return f"{self.scene.kind.describe(self.params.analysis.boundary)} | {self.title}"

    @property
    def webs(self) -> int | None:
        """The webs of the whole dome a section stands for by rotation (a cyclic
        section, docs/model.md 6.4), drawn as the whole dome; None otherwise."""
        symmetry = self.scene.symmetry
        if symmetry.unit and self.params.analysis.boundary == "cyclic":
            return symmetry.order
        return None

    @functools.cached_property
    def shown(self):
        """The blocks of the files that show the structure (``bricks.obj``,
        ``dome.html``, ``locations.csv``; ``bricks.3dm`` turns the section to the other
        webs by block instances): the scene's, or the whole dome a cyclic section stands
        for (:func:`~masonry.blocks.whole_of_web`: the section first, under the names its
        analysis reports, then its turned copies, web after web), so that the files are
        the structure the verdict is about."""
        return self._whole(self.scene.blocks)

    @functools.cached_property
    def shown_cad_vertices(self) -> np.ndarray:
        """(V, 3) float, metres: :attr:`shown`'s vertices moved by the CAD offset."""
        blocks = self.scene.blocks
        cad = dataclasses.replace(blocks, vertices=self.scene.cad_vertices(
            self.outputs.cad_offset))
        return self._whole(cad).vertices

    @property
    def is_solved(self) -> np.ndarray:
        """(B,) bool per block of :attr:`shown`: whether the analysis solved it (every
        block but a cyclic section's turned copies)."""
        return np.arange(self.shown.n_blocks) < self.scene.blocks.n_blocks

    def per_shown(self, values) -> np.ndarray:
        """(B,) values per block of :attr:`shown` from ``values`` per block of the scene:
        a turned copy carries its section block's (cyclic symmetry: the same forces in
        every web)."""
        return np.tile(np.asarray(values), self.shown.n_blocks // self.scene.blocks.n_blocks)

    def _whole(self, blocks):
        return blocks if self.webs is None else whole_of_web(blocks, self.webs)

    @functools.cached_property
    def forces(self) -> dict | None:
        """Per-interface force sums (:func:`masonry.rbe.result.interface_forces`), newtons;
        None without an accepted solution."""
        if self.result is None or self.result.x is None:
            return None
        return self.result.per_interface()


@dataclass(frozen=True)
class Export:
    """Files (path in the run folder -> bytes or text) and an optional run.json record."""

    files: dict
    record: dict | None = None


@dataclass(frozen=True)
class Exporter:
    """One row of the registry.

    Parameters
    ----------
    name : str
        Also the run.json key of its record, if it returns one.
    stage : str
        The timing stage it counts towards (``forces``, ``exports``, ``printable``,
        ``html``, ``plots``).
    make : callable RunOutputs -> Export
    wanted : callable RunOutputs -> bool
        Whether this run writes it.
    record_key : str
        The run.json key of its record when not its name; exporters that share one
        merge their records' entries.
    imports : tuple of str
        Modules its ``make`` imports when it runs: a run imports them once before its
        two processes part (:func:`masonry.pipeline.write_exports`), not once in each.
    output : str
        The key of run.json's ``outputs`` that says whether the run wrote its files
        (an output switch of :class:`masonry.outputs.Outputs`, or ``3dm``): true when
        it, or another exporter of that key, wrote one (:func:`written_outputs`); ''
        for the files every run writes when it can.
    """

    name: str
    stage: str
    make: Callable
    wanted: Callable = field(default=lambda made: True)
    record_key: str = ""
    imports: tuple = ()
    output: str = ""

    @property
    def key(self) -> str:
        """The run.json key of its record."""
        return self.record_key or self.name


def _model_files(made: RunOutputs) -> Export:
    model, solved = made.model, made.is_solved
    groups = None if solved.all() else np.where(solved, obj.SOLVED_GROUP, obj.COPIES_GROUP)
    blocks = made.shown
    if made.params.analysis.boundary == "rigid":  # the neighbours its verdict stands on
        blocks = model.blocks
        groups = np.where(np.arange(blocks.n_blocks) < made.scene.blocks.n_blocks,
                          obj.SOLVED_GROUP, obj.NEIGHBOURS_GROUP)
    return Export({
        "00_parameters.txt": summaries.parameters_text(made.params, made.title),
        "locations.csv": csv.locations_csv(made.shown, made.shown_cad_vertices),
        "bricks.obj": obj.blocks_obj(blocks, groups=groups),
        "interfaces.csv": csv.interfaces_csv(model.blocks, model.interfaces),
    })


@cache
def _say_rhino_missing():
    """Once per process (a sweep runs many variants in one)."""
    log.warning(rhino.MISSING)


def _rhino_wanted(made: RunOutputs) -> bool:
    """Whether the run can write ``bricks.3dm`` (asked in the run's process, before its
    two processes part); says once why not."""
    if rhino.available():
        return True
    _say_rhino_missing()
    return False


def _rhino_files(made: RunOutputs) -> Export:
    """``bricks.3dm``: the scene's blocks, and a cyclic section's turned copies as
    instances of them, named and marked as the webs of :attr:`RunOutputs.shown`."""
    blocks = made.scene.blocks
    text = rhino.block_user_text(blocks, made.model, made.forces)
    copies = None
    if made.webs is not None:
        text["solved"] = np.full(blocks.n_blocks, "yes")
        copies = {web_name(web): (web_motion(web, made.webs),
                                  {"web": str(web), "solved": "no (a turned copy)"})
                  for web in range(1, made.webs)}
    return Export({"bricks.3dm": rhino.blocks_3dm(blocks, user_text=text, copies=copies)})


@functools.lru_cache(maxsize=1)
def _resultants(made: RunOutputs) -> dict:
    """The interface resultants of a run with forces, computed once for all exporters."""
    return interface_resultants(made.model.interfaces, made.result.layout, made.result.x)


def force_tables(blocks, interfaces, result, forces: dict, resultants=None,
                 folder="RBE", flags=None, weight_N=None) -> dict:
    """The per-interface files of a solve: ``RBE/forces.csv``, ``RBE/tension_top.csv``
    and ``RBE/interfaces.vtu`` (path -> bytes), as a run writes them; the collapse load
    factor's forces at collapse go through it too (``folder="collapse"``).

    Parameters
    ----------
    blocks, interfaces : the analysed model's
    result : masonry.rbe.result.RBEResult or masonry.rbe.collapse.CollapseResult
        With a solution (``x``) in the layout of ``interfaces``.
    forces : dict str -> (K,) float, N
        ``result.per_interface()`` (a collapse result's ``forces``).
    resultants : dict, optional
        :func:`~masonry.rbe.resultants.interface_resultants`, computed when None.
    folder : str
        The folder of the files in the run folder.
    flags : dict str -> (K,) bool or float, optional
        More cell data for the VTU (the collapse mechanism's ``opens``, ``slides``,
        ``hinge``, written as 0/1, and its ``gap_rel`` and ``slip_rel``).
    weight_N : float, optional, N
        The reference weight of ``tension_top.csv``; None: ``result.weight_N``.
    """
    if resultants is None:
        resultants = interface_resultants(
            interfaces, VariableLayout.from_interfaces(interfaces), result.x)
    top = csv.tension_top(forces, result.weight_N if weight_N is None else weight_N)
    files = {f"{folder}/forces.csv": csv.forces_csv(blocks, interfaces, forces, resultants),
             f"{folder}/tension_top.csv": csv.tension_top_csv(blocks, interfaces, forces,
                                                              resultants, top)}
    if len(interfaces):
        # named as the columns of forces.csv, units included
        cell_data = {**{f"{name}_N": value for name, value in forces.items()},
                     "shear_N": resultants["shear"], "point_m": resultants["point"],
                     "eccentricity": resultants["eccentricity"],
                     "torsion_Nm": resultants["torsion"],
                     **{name: np.asarray(value, dtype=float)
                        for name, value in (flags or {}).items()}}
        files[f"{folder}/interfaces.vtu"] = vtu.interfaces_vtu(interfaces, cell_data)
    return files


def _rbe_files(made: RunOutputs) -> Export:
    files = {"RBE/00_objective.txt": summaries.objective_text(made.result, made.centering)}
    centering = made.centering
    if centering is not None and centering.total_N is not None:
        files["RBE/centering.csv"] = csv.held_csv(made.scene.blocks, centering.held_forces())
    adhesion = made.adhesion
    if adhesion is not None and adhesion.a_kPa is not None:
        files["RBE/adhesion.csv"] = csv.adhesion_csv(made.model.blocks, made.model.interfaces,
                                                     adhesion.interface_kPa)
    if made.forces is not None:
        files.update(force_tables(made.model.blocks, made.model.interfaces, made.result,
                                  made.forces, _resultants(made)))
    return Export(files)


def _is_whole(made: RunOutputs) -> bool:
    """Whether the run's analysis model is its whole structure, each block bearing its
    own forces (no neighbour images, cyclic routing or half model): what a COMPAS
    assembly can hold."""
    model = made.model
    return (made.result is not None and model.blocks.n_blocks == made.scene.blocks.n_blocks
            and all(value is None for value in model.assembly.values()))


def _compas_files(made: RunOutputs) -> Export:
    model = made.model
    return Export({"assembly.json": compas_json.assembly_json(
        model.blocks, model.interfaces, made.result.x, made.result.to_dict(), made.title)})


def _collapse_files(made: RunOutputs) -> Export:
    result = made.collapse
    files = {"collapse/00_collapse.txt": summaries.collapse_text(result)}
    if result.azimuths:
        files["collapse/azimuths.csv"] = csv.azimuths_csv(result.azimuths + result.refined)
    if result.forces is not None and result.load_factor is not None:
        blocks, interfaces = made.model.blocks, made.model.interfaces
        flags = {name: getattr(result, name) for name in ("opens", "slides", "hinge")}
        flags |= {f"{name}_rel": getattr(result, name) for name in ("gap", "slip")}
        files.update(force_tables(blocks, interfaces, result, result.forces,
                                  folder="collapse", flags=flags,
                                  weight_N=made.result.weight_N))
        files["collapse/mechanism.csv"] = csv.mechanism_csv(blocks, result.mechanism)
        files["collapse/mechanism.vtu"] = vtu.mechanism_vtu(blocks, result.mechanism)
    return Export(files)


def _printable_files(made: RunOutputs) -> Export:
    """The printable body's files; none, with a warning and the reason in run.json's
    ``printable.skipped``, when the blocks make no body that passes its checks (blocks
    read from a file may touch at slivers): the body is an extra, the analysis goes on."""
    try:
        blocks, vertices, copies = printable_blocks(made.scene, made.params.analysis.boundary,
                                                    made.outputs.cad_offset)
        body, report = printable_body(blocks, vertices, copies=copies)
        data = stl.stl_bytes(body)
        report["readback"] = stl.readback_check(data, report["volume_m3"])
    except PrintableError as error:
        reason = str(error).splitlines()[0]
        log.warning("printable body skipped (dome.stl, dome.obj): %s", reason)
        return Export({}, {"skipped": reason})
    files = {"dome.stl": data, "dome.obj": stl.obj_body_bytes(body)}
    size = made.outputs.print_size
    if size is not None:
        files["dome.3mf"] = threemf.threemf_bytes(body, size)
        report["print"] = {"size_mm": size, "mm_per_m": threemf.print_scale(body, size),
                           "readback": threemf.readback_3mf(files["dome.3mf"])}
    return Export(files, report)


def _html_files(made: RunOutputs) -> Export:
    return Export({"dome.html": html.dome_html(made)})


def _mechanism_plots(made: RunOutputs) -> dict:
    from masonry import plots  # matplotlib: imported by the runs that draw

    collapse, model = made.collapse, made.model
    if collapse is None or collapse.mechanism is None or not collapse.load_factor:
        return {}
    title = (f"collapse mechanism: lambda = {collapse.load_factor:.4g}, "
             f"{collapse.live.description['kind']} load"
             + ("" if collapse.azimuth_deg is None else f" at {collapse.azimuth_deg:g} deg"))
    render = plots.Render.of(made.outputs)
    files = plots.mechanism_pngs(model.blocks, model.interfaces, collapse, title,
                                 made.outputs.quick, made.figure_title, render)
    if collapse.azimuths:
        files.update(plots.as_files("collapse/azimuths.png", plots.azimuths_png(
            collapse, made.figure_title, render)))
    return files


def _figures(drawn: dict) -> Export:
    """The figures of ``drawn`` (path -> bytes, or the reason (str) a figure was left out,
    under its PNG's path); run.json's ``figures.files`` lists the files written,
    ``figures.skipped`` names those left out and why."""
    files = {path: data for path, data in drawn.items() if not isinstance(data, str)}
    skipped = {path: why for path, why in drawn.items() if isinstance(why, str)}
    return Export(files, {"files": sorted(files)} | ({"skipped": skipped} if skipped else {}))


def _structure_plot_files(made: RunOutputs) -> Export:
    """The model's plots of its blocks: the flattened pattern and the structure views."""
    # matplotlib takes most of a second to import: a run without plots never does
    from masonry import plots

    scene, model, fast, title = made.scene, made.model, made.outputs.quick, made.figure_title
    render = plots.Render.of(made.outputs)
    files = {}
    if scene.layout is not None:
        files.update(plots.as_files("00_pattern.png", plots.pattern_png(scene, fast, title,
                                                                        render)))
    files.update(plots.structure_pngs(scene, fast, title, made.webs, model.interfaces,
                                      render))
    return _figures(files)


def _interface_plot_files(made: RunOutputs) -> Export:
    """The model's plots of its interfaces (their areas) and of a collapse mechanism."""
    from masonry import plots

    files = plots.interface_pngs(made.model.blocks, made.model.interfaces,
                                 made.outputs.quick, made.figure_title,
                                 plots.Render.of(made.outputs))
    files.update(_mechanism_plots(made))
    return _figures(files)


def _force_plot_files(made: RunOutputs) -> Export:
    """The forces' plots: per view, the thrust line and where it fails."""
    from masonry import plots

    scene, model, fast, title = made.scene, made.model, made.outputs.quick, made.figure_title
    render = plots.Render.of(made.outputs)
    drawn = plots.force_pngs(model.blocks, model.interfaces, made.forces, fast, title,
                             made.webs, noise=TENSION_REPORTED_REL * made.result.weight_N,
                             render=render)
    files = {f"RBE/{name}": data for name, data in drawn.items()}
    section = scene.kind.thrust_section(scene)
    if section is not None:
        thrust = plots.thrust_line_png(model.interfaces, _resultants(made), section, fast,
                                       title, render)
        if thrust is not None:
            files.update(plots.as_files("RBE/thrust_line.png", thrust))
    top = csv.tension_top(made.forces, made.result.weight_N)
    if len(top):
        files.update(plots.as_files("RBE/where_it_fails.png", plots.failure_png(
            model.blocks, model.interfaces, top, made.forces, fast, title, render)))
    return _figures(files)


def _adhesion_plot_files(made: RunOutputs) -> Export:
    """The joints coloured by the adhesion they use (``RBE/<view>/adhesion.png``, as the
    force figures)."""
    from masonry import plots

    adhesion, model = made.adhesion, made.model
    drawn = plots.adhesion_pngs(model.blocks, model.interfaces, adhesion.interface_kPa,
                                adhesion.a_kPa, made.outputs.quick, made.figure_title,
                                plots.Render.of(made.outputs))
    return _figures({f"RBE/{PurePosixPath(name).stem}/adhesion{PurePosixPath(name).suffix}":
                     data for name, data in drawn.items()})


def _needs_adhesion(made: RunOutputs) -> bool:
    """Whether the run's structure needs adhesion to stand (``a* > 0``)."""
    return made.adhesion is not None and bool(made.adhesion.a_kPa)


EXPORTERS = (
    # the forces first, under a stage of their own: parameters to forces is the time a
    # user waits for results (the model's files do not need them)
    Exporter("rbe", "forces", _rbe_files, wanted=lambda made: made.result is not None),
    # then the long ones first: two processes share what follows, each taking the next
    # (masonry.pipeline.write_exports), and finish about together
    Exporter("force_plots", "plots", _force_plot_files,
             wanted=lambda made: made.outputs.plots and made.forces is not None,
             record_key="figures", imports=("masonry.plots",), output="plots"),
    Exporter("adhesion_plots", "plots", _adhesion_plot_files,
             wanted=lambda made: made.outputs.plots and _needs_adhesion(made),
             record_key="figures", imports=("masonry.plots",), output="plots"),
    Exporter("printable", "printable", _printable_files,
             wanted=lambda made: made.outputs.printable, imports=("manifold3d", "trimesh"),
             output="printable"),
    Exporter("structure_plots", "plots", _structure_plot_files,
             wanted=lambda made: made.outputs.plots, record_key="figures",
             imports=("masonry.plots",), output="plots"),
    Exporter("interface_plots", "plots", _interface_plot_files,
             wanted=lambda made: made.outputs.plots, record_key="figures",
             imports=("masonry.plots",), output="plots"),
    Exporter("rhino", "exports", _rhino_files, wanted=_rhino_wanted, output="3dm"),
    Exporter("html", "html", _html_files, wanted=lambda made: made.outputs.writes_html,
             output="html"),
    Exporter("collapse", "exports", _collapse_files,
             wanted=lambda made: made.collapse is not None),
    Exporter("compas", "exports", _compas_files, wanted=_is_whole),
    Exporter("model", "exports", _model_files),
)
"""Every exporter, in the order a run takes them."""


def written_outputs(written: dict) -> dict:
    """run.json's ``outputs`` switches from what the exporters wrote (``written``: an
    exporter's name -> the paths of its files): a switch (an :attr:`Exporter.output`) is
    true when one of its exporters wrote a file, in the order of :data:`EXPORTERS`."""
    out = {}
    for exporter in EXPORTERS:
        if exporter.output:
            out[exporter.output] = (out.get(exporter.output, False)
                                    or bool(written.get(exporter.name)))
    return out
