"""Blocks read from files as a structure to analyse: the ``assembly`` scene
(:func:`masonry.scenes.imported.load_assembly`) and the inputs of its analysis, the one
way ``masonry analyze``, ``masonry stages FILE...`` and :func:`masonry.read` read an
assembly (docs/assemblies.md)."""

from masonry.parameters import plain
from masonry.params import Params, validate
from masonry.rbe.loads import LOAD_OPTIONS, point_load_spec
from masonry.scenes.imported import AssemblyError, load_assembly
from masonry.tolerances import Tolerances


def read_assembly(paths, *, support=(), support_below=None, ground=False,
                  overlap_tolerance=None, inputs=None, check=None) -> tuple:
    """The structure of blocks read from mesh files, and its inputs.

    Parameters
    ----------
    paths : sequence of str or Path
        The mesh files (OBJ, STL, PLY, COMPAS JSON).
    support, support_below, ground, overlap_tolerance
        The supports and the overlaps accepted, as
        :func:`~masonry.scenes.imported.load_assembly` takes them (``support``: name
        patterns).
    inputs : dict, optional
        Analysis, live-load and output inputs (flat names); they win over a compas_dem
        Problem's (:func:`assembly_inputs`).
    check : callable, optional
        ``check(params)``: the caller's own refusals of ``inputs``, run with
        :func:`~masonry.params.validate` before any file is read.

    Returns
    -------
    params : masonry.params.Params
        Validated, of the ``assembly`` scene named after the files.
    scene : masonry.scenes.Scene
    source : dict
        Where the blocks came from, as ``run.json`` records it.

    Raises
    ------
    masonry.scenes.imported.AssemblyError
        A file or block that cannot be read, no support, overlapping blocks, a Problem's
        load that masonry cannot state.
    masonry.errors.ParameterError
        An input out of its range (before any file is read).
    """
    inputs = {} if inputs is None else inputs
    placeholder = validate(Params.of(scene="assembly", assembly="-", **inputs))
    if check is not None:
        check(placeholder)
    scene, source = load_assembly(paths, supports=tuple(support),
                                  support_below=plain(support_below), ground=ground,
                                  overlap_tolerance=overlap_tolerance)
    inputs = assembly_inputs(scene.blocks, source, inputs)
    params = validate(Params.of(scene="assembly", assembly=scene.geometry.assembly, **inputs))
    return params, scene, source


def assembly_inputs(blocks, source: dict, given: dict) -> dict:
    """The analysis inputs of read blocks: a compas_dem Problem's (``source["problem"]``,
    :func:`masonry.scenes.imported.load_assembly`), then ``given`` (the caller's) over
    them; a live load given drops the Problem's point loads.

    Raises
    ------
    masonry.scenes.imported.AssemblyError
        A point load of the Problem that masonry cannot state, naming the file and load.
    """
    problem = (source or {}).get("problem")
    given = {k: v for k, v in given.items() if v is not None and not (
        isinstance(v, (list, tuple)) and not v)}
    if problem is None:
        return given
    stated = {"mu": problem["mu"], "density": problem["density"],
              "cohesion_kpa": _kilo(problem["cohesion_Pa"]),
              "tensile_kpa": _kilo(problem["tensile_Pa"])}
    if not any(name in given for name in LOAD_OPTIONS):
        tol = Tolerances.for_points(blocks.vertices)
        specs = []
        for load in problem["point_loads"]:
            try:
                specs.append(point_load_spec(blocks, load["block"], load["force"],
                                             load["point"], tol.length))
            except ValueError as error:
                raise AssemblyError(f"{problem['file']}: {load['where']}: {error}; not "
                                    "supported") from None
        stated["point_loads"] = tuple(specs)
    return {**{k: v for k, v in stated.items() if v is not None and v != ()}, **given}


def _kilo(pascals):
    return None if pascals is None else pascals / 1000.0
