"""The Python interface: build a structure or read one from mesh files, solve its
equilibrium, its centering force, its collapse load and its construction stages, read the
forces, export.

A :class:`Structure` is what ``masonry run`` analyses, held in memory: its inputs
(:class:`~masonry.params.Params`), the built scene and the analysed model (the scene's
blocks and any neighbour images, and their contact interfaces). Every method answers
one of the command line's questions with the same code and the same defaults.

    >>> import masonry
    >>> arch = masonry.build(scene="arch", arch_thickness=1.0)
    >>> arch.solve().verdict
    'feasible'
    >>> forces = arch.forces()          # pandas: one row per interface, forces.csv's columns
    >>> round(float(forces["compression_N"].max()))  # doctest: +SKIP
"""

import dataclasses
import functools
import math
import numbers
import os
from collections.abc import Iterable

from masonry.assembly import read_assembly
from masonry.errors import MasonryError, NoForcesError, ParameterError
from masonry.export.csv import HEADERS, column_types, forces_columns, missing_values
from masonry.params import (Params, from_preset, names, section_default, structure_id,
                            validate)
from masonry.pipeline import (Timer, adhesion_of, build_model, centering_of, collapse_of, run,
                              solve)
from masonry.rbe.boundary import analysis_model
from masonry.rbe.loads import LOAD_OPTIONS
from masonry.rbe.resultants import interface_resultants
from masonry.scenes import check_size
from masonry.stages.analysis import STAGE_COLUMNS, analyse_stages
from masonry.stages.laying import stage_laying
from masonry.stages.plans import make_plan
from masonry.stages.run import check_live_load


@dataclasses.dataclass(frozen=True, eq=False)
class Structure:
    """A built structure and its analysis model (:func:`build`, :func:`read`).

    Parameters
    ----------
    params : masonry.params.Params
        Its inputs, validated: geometry, analysis, live load, outputs.
    scene : masonry.scenes.base.Scene
        The blocks as built (or read), their supports and, for domes, their layout.
    model : masonry.rbe.boundary.Model
        The analysed blocks (the scene's, then a section's neighbour images) and their
        interfaces (:attr:`blocks`, :attr:`interfaces`).
    source : dict or None
        Where read blocks came from (files, supports), as ``run.json`` records it.
    """

    params: Params
    scene: object
    model: object
    source: dict | None = None

    @functools.cached_property
    def id(self) -> str:
        """The structure id: the name of its run folder."""
        return structure_id(self.params)

    @property
    def blocks(self):
        """The analysed :class:`~masonry.blocks.Blocks` (arrays, metres)."""
        return self.model.blocks

    @property
    def interfaces(self):
        """The contact :class:`~masonry.interfaces.Interfaces` (arrays, metres)."""
        return self.model.interfaces

    @functools.cached_property
    def _equilibrium(self):
        return solve(self.model, self.params, Timer())

    def solve(self):
        """The rigid block equilibrium under self-weight (docs/model.md 6): its verdict
        (``feasible``, ``infeasible``, ``not solved``), the MoI factor and the forces.

        Returns
        -------
        masonry.rbe.result.RBEResult
            Computed once per structure; :meth:`forces` reads it.
        """
        return self._equilibrium

    def forces(self):
        """The forces of :meth:`solve` per interface, as ``RBE/forces.csv`` has them.

        Returns
        -------
        pandas.DataFrame
            One row per interface, indexed by its id; the columns of ``forces.csv``
            (docs/outputs.md "Columns"): the two blocks, kind, centre, normal, area,
            the force sums in newtons (tension positive in ``normal_N``), the shear, the
            point of application of the resultant, its eccentricity and the torsion.

        Raises
        ------
        masonry.errors.NoForcesError
            The solve returned no forces: verdict ``not solved``, or ``infeasible`` under
            ``friction="net"`` (no forces balance the blocks; ``"auto"`` or ``"plus"``
            give the forces of least tension).
        """
        import pandas  # a notebook's library, imported by the calls that return a frame

        result = self.solve()
        if result.x is None:
            hint = ("; friction='auto' or 'plus' give the forces of least tension"
                    if result.verdict == "infeasible" else "")
            raise NoForcesError(f"no forces: the equilibrium is {result.verdict} "
                                f"({result.friction}: {result.status}){hint}")
        forces = result.per_interface()
        resultants = interface_resultants(self.interfaces, result.layout, result.x)
        columns = forces_columns(self.blocks, self.interfaces, forces, resultants)
        return pandas.DataFrame(dict(columns)).set_index("id")

    def centering(self):
        """The centering force (docs/model.md 6.10): the least total force that supports
        at the blocks' centroids must give so that the structure stands, and the blocks
        that need one (0 and none when it stands).

        Returns
        -------
        masonry.rbe.centering.CenteringResult
            ``total_N``, ``fraction`` (of the weight), per free block its ``force``
            (newtons) and the blocks that need one, largest first
            (:meth:`~masonry.rbe.centering.CenteringResult.held_forces`).
        """
        return centering_of(self.model, self.params)

    def least_adhesion(self):
        """The least adhesion (docs/model.md 6.12): the least uniform strength ``a`` of
        mortar (cohesion ``c = a``, tensile strength ``t_c = r a``, ``r`` the analysis's
        ``adhesion_tension_ratio``) with which the structure stands without centering,
        by one conic program; 0 when it stands with dry joints.

        Returns
        -------
        masonry.rbe.adhesion.AdhesionResult
            ``a_kPa`` (None, with ``reason``, when no value passed its check), per
            interface the adhesion it uses (``interface_kPa``) and the joints that need
            most (:meth:`~masonry.rbe.adhesion.AdhesionResult.joints`).
        """
        return adhesion_of(self.model, self.params)

    def collapse(self, **load):
        """The collapse load factor of a live load and its mechanism (docs/model.md 6.8).

        Parameters
        ----------
        **load
            The live load, as the command line's options name it: ``lateral`` (an
            azimuth in degrees, or ``"all"`` for the worst), ``point_loads`` (strings
            ``"PATTERN:FX,FY,FZ"``, newtons) or ``crown_load`` (newtons). None given:
            the structure's own (``params.load``).

        Returns
        -------
        masonry.rbe.collapse.CollapseResult
            ``load_factor``, the ``mechanism`` (per block ``(u, theta)``) and the joints
            that carry it.

        Raises
        ------
        masonry.errors.ParameterError
            No live load, or one the scene does not take.
        """
        params = self.params if not load else validate(self.params.replace(
            **{"lateral": None, "point_loads": (), "crown_load": None, **load}))
        if params.load is None:
            raise ParameterError("load", None, f"a live load: one of {', '.join(LOAD_OPTIONS)}")
        # a solved equilibrium stands for the dead load; else the program decides it
        return collapse_of(self.model, params, self.__dict__.get("_equilibrium"))

    def stages(self, by="course", order=None, course=None, mortar=None, laying_rate=None,
               masons=None):
        """Whether it stands at every stage of its construction without centering
        (docs/model.md 4.7): one row per stage, as ``masonry stages`` writes
        ``stages.csv``.

        Parameters
        ----------
        by : {'course', 'brick', 'block'}
            Course by course; brick by brick within ``course`` (the courses below
            laid); block by block in ``order``.
        order : str, optional
            The laying order of bricks or blocks (``masonry stages --help``).
        course : int, optional
            The course laid brick by brick.
        mortar : {'constant', 'lime', 'gypsum'}, optional
            Every joint has the strength of its age (docs/model.md 6.13): a named
            mortar's table, or ``constant`` (the analysis's ``cohesion_kpa`` and
            ``tensile_kpa`` at every age). None: the analysis's contact law at every
            joint.
        laying_rate : float, optional
            Bricks per hour per mason (> 0; needed by ``lime`` and ``gypsum``).
        masons : int, optional
            Masons laying side by side (>= 1, default 1).

        Returns
        -------
        pandas.DataFrame
            The columns of ``stages.csv``, one row per stage (docs/stages.md): blocks
            laid, verdict, MoI factor, centering force, least adhesion
            (``adhesion_kPa``, docs/model.md 6.12), the load factor of the live load if
            the structure has one, the hours from the start to the stage's end
            (``time_h``, with a laying rate).

        Raises
        ------
        masonry.errors.ParameterError
            A mortar, rate or number of masons refused (named as the argument), a
            mortar that ages beside the analysis's strengths, or a plan the structure
            does not take.
        """
        import pandas

        check_live_load(self.params)
        laying = stage_laying(self.params, mortar, laying_rate, masons)
        plan = make_plan(self.scene, by, order, course)
        rows = analyse_stages(self.model, self.params, plan, laying=laying)
        frame = pandas.DataFrame(rows, columns=STAGE_COLUMNS)
        return frame.rename(columns=HEADERS).set_index("stage")

    def export(self, out="exports", **outputs) -> dict:
        """Write the run folder ``out/<id>`` that ``masonry run`` writes (forces, CAD
        files, plots, printable body), by the same protocol: a complete folder of the same
        inputs is reused, a failed export leaves the previous one.

        Parameters
        ----------
        out : str or Path
            The output root.
        **outputs
            What to write (docs/model.md 7): ``plots``, ``quick``, ``printable``,
            ``print_size``, ``figure_format`` (``"png,pdf"`` or ``["png", "svg"]``),
            ``dpi``, ``html`` (None: with the plots), ``html_plotly`` (``"shared"``:
            plotly.js in one file of ``out`` for every page, ``"inline"``: in the page),
            ``cad_offset``.

        Returns
        -------
        dict
            The run record (``run.json``) and the folder's ``path``.
        """
        unknown = set(outputs) - {n for n, part in names().items() if part == "outputs"}
        if unknown:
            name = sorted(unknown)[0]
            raise ParameterError(name, outputs[name], "an output option: " + ", ".join(
                n for n, part in names().items() if part == "outputs"))
        params = validate(self.params.replace(**outputs))
        return run(params, out, scene=self.scene, source=self.source)


def build(preset=None, **inputs) -> Structure:
    """A structure from its inputs (docs/model.md 3, 4): a preset's with changes, or a
    scene's defaults with changes.

    Parameters
    ----------
    preset : {'1', '2', '3', 'wall'}, optional
        The thesis's structures 1-3 (a section of the dome) or the straight wall.
    **inputs
        Flat input names as the command line's options (``scene``, ``n``, ``mu``,
        ``boundary``, ``lateral`` ...; ``masonry run --help``), with its defaults: a
        section's boundary is ``cyclic`` (the whole dome) unless given.

    Raises
    ------
    masonry.errors.ParameterError
        An input out of its range or not of the scene, or a model too large
        (:data:`masonry.scenes.MAX_BRICKS` bricks).
    """
    params = from_preset(preset, **inputs) if preset is not None \
        else validate(Params.of(**inputs))
    params = section_default(params, "boundary" in inputs)
    check_size(params)
    scene, model = build_model(params)
    return Structure(params, scene, model)


def read(*paths, support=(), support_below=None, ground=False, overlap_tolerance=None,
         **inputs) -> Structure:
    """A structure of blocks read from mesh files (OBJ, STL, PLY, COMPAS JSON;
    docs/assemblies.md).

    Parameters
    ----------
    *paths : str or Path
        The files; every closed convex body is a block.
    support : str or sequence of str
        Name patterns of the fixed blocks (``pier_*``); None or empty: none (a COMPAS
        file's ``is_support`` blocks). With ``support_below``, replaces a COMPAS file's.
    support_below : float, optional
        Every block reaching below this height (metres) is fixed.
    ground : bool
        Add a ground slab (a support) under the lowest blocks.
    overlap_tolerance : float, optional
        Accept blocks that interpenetrate by up to this fraction of the smaller one's
        size (default :data:`masonry.tolerances.INTERPENETRATION_REL`; docs/assemblies.md).
    **inputs
        Analysis, live-load and output inputs (``mu``, ``density``, ``lateral`` ...);
        they win over a compas_dem Problem's
        (:func:`masonry.assembly.assembly_inputs`).

    Raises
    ------
    masonry.scenes.imported.AssemblyError
        A file or block that cannot be read, no support, overlapping blocks.
    masonry.errors.ParameterError
        An input out of its range or of the wrong type (``overlap_tolerance`` too), or a
        ``scene`` (the blocks are the scene).
    """
    supports = _checked_supports(paths, support, support_below, ground, inputs)
    params, scene, source = read_assembly(paths, support=supports, support_below=support_below,
                                          ground=ground, overlap_tolerance=overlap_tolerance,
                                          inputs=inputs)
    return Structure(params, scene, analysis_model(scene, params.analysis.boundary), source)


def _checked_supports(paths, support, support_below, ground, inputs) -> tuple:
    """The support patterns of :func:`read` as a tuple (one string is one pattern, None
    none), its other arguments checked before any file is read."""
    for name in ("scene", "assembly"):
        if name in inputs:
            raise ParameterError(name, inputs[name], "no scene: blocks read from files are "
                                 "an assembly (masonry.build builds a scene)")
    if not paths or not all(isinstance(p, str | os.PathLike) for p in paths):
        raise ParameterError("paths", paths, "one or more mesh file paths (str or Path)")
    support = () if support is None else (support,) if isinstance(support, str) else support
    if not isinstance(support, Iterable) or not all(isinstance(s, str) for s in support):
        raise ParameterError("support", support, "block name patterns (strings)")
    if support_below is not None and (isinstance(support_below, bool) or not isinstance(
            support_below, numbers.Real) or not math.isfinite(support_below)):
        raise ParameterError("support_below", support_below, "a height in metres (a "
                             "finite number) or None")
    if not isinstance(ground, bool):
        raise ParameterError("ground", ground, "true or false")
    return tuple(support)


def read_table(path):
    """One of the CSV files masonry writes (``RBE/forces.csv``, ``tension_top.csv``,
    ``stages.csv``, a sweep's ``summary.csv``, ...) as a pandas DataFrame with every
    column's type, also when the file holds only its header (nothing in tension): integer
    ids and counts, text names (also a study's inputs whose values are names, such as
    ``pattern``), booleans ``True``/``False``, floats for the rest (their names carry the
    unit; an empty cell or ``nan`` is NaN).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    masonry.errors.MasonryError
        The file cannot be read, or is not such a table (empty, binary, a cell not of its
        column's type).
    """
    import pandas

    try:
        with open(path, encoding="utf-8") as f:
            names = f.readline().strip().split(",")
        if not all(name.isprintable() and name for name in names):
            raise ValueError("no header of column names")
        return pandas.read_csv(path, dtype=column_types(names), keep_default_na=False,
                               na_values=missing_values(names))
    except (OSError, UnicodeDecodeError, ValueError) as error:  # pandas' errors included
        reason = str(error).strip().splitlines()[0] if str(error).strip() else "unreadable"
        raise MasonryError(f"{path}: expected a CSV table that masonry writes ({reason})") \
            from None
