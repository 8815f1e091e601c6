"""The inputs of a run, by concern, and the names that follow from them (docs/model.md 3).

A run's :class:`Params` is four declared parts (:mod:`masonry.parameters`): the scene kind
and its geometry (:mod:`masonry.scenes`), the analysis (:class:`~masonry.rbe.settings.
Analysis`), the live load (one of :mod:`masonry.rbe.loads`' load cases, or none) and the
outputs (:class:`~masonry.outputs.Outputs`). A user names every input by one flat
name (``n``, ``mu``, ``lateral``, ``print_size``), on the command line, in a TOML file or
in :meth:`Params.of`; each name belongs to the one part that declares it. The structure
id, the geometry cache's key and the record of ``run.json`` are made here, from those
declarations alone.
"""

import dataclasses
import hashlib
import json
from dataclasses import dataclass

from masonry.errors import ParameterError
from masonry.mortars import LAYING_INPUTS
from masonry.outputs import WRITTEN_OUTPUTS, Outputs
from masonry.parameters import (check_fields, declarations, defaults, plain, read_toml, text_of,
                                values)
from masonry.rbe.loads import LOAD_OPTIONS, Lateral, live_load
from masonry.rbe.settings import Analysis
from masonry.scenes import KINDS, kind_of

PRESETS = {
    # the thesis's three structures (thesis 3.4.1, docs/model.md 3)
    "1": dict(stretch=1.0, n=8, r=1, p=10, cut=0.1),
    "2": dict(stretch=2.0, n=6, r=1, p=8, cut=0.05),
    "3": dict(stretch=0.8, n=4, r=1, p=13, cut=0.01),
    # thesis 3.3.6 straight wall test: 10 courses of 8 regular bricks, about 12.5 kN
    "wall": dict(scene="wall", wall_length=32.0, wall_courses=10),
}

FILE_OUTPUTS = tuple(name for name, declaration in declarations(Outputs).items()
                     if declaration.tag is None)
"""Inputs that choose files, not results (the outputs without a tag in the structure id):
a folder whose run differs only in them holds the same input; a study chooses them once
for every variant, in its ``[outputs]`` table."""

LOAD_SPELLINGS = {"point_loads": "point-load"}
"""The load options spelled otherwise than their input: one point load per option."""

@dataclass(frozen=True)
class Params:
    """Every input of a run, by concern.

    Parameters
    ----------
    kind : type
        The scene's :class:`~masonry.scenes.base.SceneKind`.
    geometry : object
        Its geometry (the kind's declared dataclass).
    analysis : masonry.rbe.settings.Analysis
    load : Lateral, PointLoads, CrownLoad or None
        The live load of a collapse load factor (:mod:`masonry.rbe.loads`).
    outputs : masonry.outputs.Outputs
    """

    kind: type
    geometry: object
    analysis: Analysis = Analysis()
    load: object = None
    outputs: Outputs = Outputs()

    @classmethod
    def of(cls, scene="section", **inputs) -> "Params":
        """A run's inputs from their flat names (:func:`names`), not yet validated
        (:func:`validate`). ``fast`` is the command line's shorthand: the fast accuracy
        preset (unless ``accuracy`` is given) and quick figures.

        Raises
        ------
        ParameterError
            A name that no part declares, or the scene's geometry does not.
        """
        kind = kind_of(scene)
        if "fast" in inputs:
            fast = inputs.pop("fast")
            if not isinstance(fast, bool):
                raise ParameterError("fast", fast, "true or false")
            if fast:
                inputs.setdefault("accuracy", "fast")
                inputs.setdefault("quick", True)
        parts = {"geometry": {}, "analysis": {}, "load": {}, "outputs": {}}
        for name, value in inputs.items():
            parts[_part_of(name, kind, value)][name] = plain(value)
        load = {"point_loads": ()} | parts["load"]
        return cls(kind, kind.geometry(**parts["geometry"]), Analysis(**parts["analysis"]),
                   live_load(**load) if any(v not in (None, ()) for v in load.values())
                   else None, Outputs(**parts["outputs"]))

    @property
    def scene(self) -> str:
        """The scene's name."""
        return self.kind.name

    def inputs(self) -> dict:
        """Flat name -> value of every input, as :meth:`of` takes them back."""
        load = {"lateral": None, "point_loads": (), "crown_load": None}
        if self.load is not None:
            load.update(self.load.options())
        return {"scene": self.scene, **values(self.geometry), **values(self.analysis),
                **load, **values(self.outputs)}

    def record(self) -> dict:
        """The inputs ``run.json`` records (:func:`inputs` but the outputs that are
        recorded as what the run wrote, :data:`~masonry.outputs.WRITTEN_OUTPUTS`)."""
        return {name: value for name, value in self.inputs().items()
                if name not in WRITTEN_OUTPUTS}

    def replace(self, **changes) -> "Params":
        """The same inputs with ``changes`` (flat names), not yet validated."""
        return Params.of(**{**self.inputs(), **changes})


def names(kind=None) -> dict:
    """Flat input name -> the part that declares it (``geometry``, ``analysis``, ``load``,
    ``outputs``): of one scene kind, or (``kind`` None) of every kind."""
    geometry = {}
    for k in KINDS.values() if kind is None else (kind,):
        geometry.update(dict.fromkeys(declarations(k.geometry), "geometry"))
    return {**geometry, **dict.fromkeys(declarations(Analysis), "analysis"),
            **dict.fromkeys(LOAD_OPTIONS, "load"),
            **dict.fromkeys(declarations(Outputs), "outputs")}


def option_of(name: str) -> str:
    """The command line's option of input ``name`` (:func:`names`), without its dashes:
    its declaration's ``option`` (``arch_blocks`` -> ``blocks``), a load's spelling
    (:data:`LOAD_SPELLINGS`), else the name with dashes (``cohesion_kpa`` ->
    ``cohesion-kpa``)."""
    if name in LOAD_SPELLINGS:
        return LOAD_SPELLINGS[name]
    parts = (*(kind.geometry for kind in KINDS.values()), Analysis, Outputs)
    option = next((declarations(part)[name].option for part in parts
                   if name in declarations(part)), None)
    return option[2:] if option else name.replace("_", "-")


def input_dtypes() -> dict:
    """pandas dtypes of the inputs as tables write them (a sweep's ``summary.csv``, an
    optimisation's trials): every declared input by its kind (integers, booleans and
    floats; text for names, friction models and figure formats), the scene and the
    preset as text, ``lateral`` as text (an azimuth or ``all``), point loads as text."""
    dtypes = {"int": "Int64", "bool": "boolean", "float": "float64"}
    out = {"scene": "str", "preset": "str", "fast": "boolean", "lateral": "str",
           "point_loads": "str", "crown_load": "float64"}
    for part in (*(k.geometry for k in KINDS.values()), Analysis, Outputs):
        out.update({name: dtypes.get(d.kind, "str")
                    for name, d in declarations(part).items()})
    return out


def applies(name: str, kind) -> bool:
    """Whether the input ``name`` applies to scenes of ``kind`` (a boundary only to the
    kinds that take one)."""
    if name == "boundary":
        return len(kind.boundaries) > 1
    return name in names(kind)


def _part_of(name, kind, value) -> str:
    part = names(kind).get(name)
    if part is None:
        scenes = [k.name for k in KINDS.values() if name in declarations(k.geometry)]
        expected = (f"an option of the {' or '.join(scenes)} scene, not of this "
                    f"{kind.name} scene" if scenes else "a parameter name (" + ", ".join(
                        ["scene", "fast", *names()]) + ")")
        raise ParameterError(name, value, expected)
    return part


def validate(params: Params) -> Params:
    """Check every input; return ``params`` normalised (the friction model in its
    canonical spelling) or raise :class:`~masonry.errors.ParameterError`."""
    check_fields(params.geometry)
    params.kind.check(params.geometry)
    analysis = params.analysis.checked()
    outputs = params.outputs.checked()
    _check_across(params.kind, analysis, params.load)
    return dataclasses.replace(params, analysis=analysis, outputs=outputs)


def _check_across(kind, analysis, load):
    """The checks that join two parts: the boundary against the scene, the load against
    the scene and its boundary, the friction law against the load."""
    if analysis.boundary not in kind.boundaries:
        raise ParameterError("boundary", analysis.boundary,
                             f"{' or '.join(kind.boundaries)} for a {kind.name} scene")
    if load is not None and load.kind == "crown" and not kind.crown:
        raise ParameterError("crown_load", load.newtons, "a dome: --scene section or dome")
    if analysis.friction_law != "associated" and (
            load is None or (isinstance(load, Lateral) and load.azimuth_deg == "all")):
        raise ParameterError("friction_law", analysis.friction_law,
                             "associated without a live load or with --lateral all (the "
                             "estimate is of one load case: --lateral AZIMUTH, --point-load "
                             "or --crown-load)")
    if analysis.boundary == "cyclic" and load is not None and load.kind != "crown":
        # one web with the load repeated in every web is not the asked load case
        option, value = next(iter(load.options().items()))
        raise ParameterError(option, value[0] if option == "point_loads" else value,
                             "a symmetric load on a cyclic section (a section's default "
                             "boundary): this load breaks the dome's rotational symmetry; "
                             "use --scene dome (or --boundary free: the web alone)")


def section_default(params: Params, boundary_given: bool) -> Params:
    """``params`` with a section's boundary ``cyclic`` where the inputs did not give
    one: a section stands for the whole dome, the question a run answers first
    (docs/cli.md); the command line and the Python API alike."""
    if boundary_given or "cyclic" not in params.kind.boundaries:
        return params
    return validate(params.replace(boundary="cyclic"))


def from_preset(name, **overrides) -> Params:
    """The inputs of a preset (``1``, ``2``, ``3`` or ``wall``) with overrides, validated."""
    key = str(name)
    if key not in PRESETS:
        raise ParameterError("preset", name, f"one of {', '.join(PRESETS)}")
    return validate(Params.of(**{**PRESETS[key], **overrides}))


def load(path, *, laying=False, **overrides) -> Params:
    """The inputs of a TOML file of flat names (e.g. ``fixtures/presets/*.toml``), at the
    top level or in a ``[params]`` table, and the mortar's in a ``[mortar]`` table
    (:data:`MORTAR_KEYS`); ``overrides`` win over the file. ``laying``: the file is a
    stage study's, whose ``[mortar]`` may also give :data:`LAYING_INPUTS`
    (:func:`laying_inputs` reads them); else they are refused.

    Raises
    ------
    ParameterError
        Named ``params`` when the file cannot be read or is not TOML; named after the key
        (with ``where`` the file) when a key is unknown or its value invalid.
    """
    data, mortar = _file_tables(path)
    if not laying:
        for key in LAYING_INPUTS:
            if key in mortar:
                raise ParameterError(key, mortar[key], "none for masonry run: the mortar "
                                     "by age of a construction's stages (masonry stages)",
                                     where=str(path))
    data.update({key: value for key, value in mortar.items() if key not in LAYING_INPUTS})
    known = ["scene", "fast", *names()]
    for key, value in data.items():
        if key not in known:
            raise ParameterError(key, value, f"a parameter name ({', '.join(known)})",
                                 where=str(path))
    built = [name for name, kind in KINDS.items() if kind.from_parameters]
    if "scene" in data and data["scene"] not in built:
        raise ParameterError("scene", data["scene"], f"one of {', '.join(built)} (blocks read "
                             f"from files are masonry analyze's assembly scene)",
                             where=str(path))
    try:
        return validate(Params.of(**{**data, **overrides}))
    except ParameterError as error:
        if error.name not in data or error.name in overrides or error.where:
            raise
        raise ParameterError(error.name, error.value, error.expected,
                             related=error.related, where=str(path)) from None


MORTAR_KEYS = ("cohesion_kpa", "tensile_kpa", "head_joint_ratio", "support_joint_ratio",
               "adhesion_tension_ratio")
"""The analysis's keys of a parameter file's ``[mortar]`` table (its mortar inputs); a
stage study's file may also give :data:`~masonry.mortars.LAYING_INPUTS`."""


def laying_inputs(path) -> dict:
    """The :data:`~masonry.mortars.LAYING_INPUTS` a parameter file's ``[mortar]`` table
    gives (``mortar``, ``laying_rate``, ``masons``), unchecked: a stage study checks them
    (:func:`masonry.stages.laying.stage_laying`)."""
    _, mortar = _file_tables(path)
    return {key: value for key, value in mortar.items() if key in LAYING_INPUTS}


def _file_tables(path) -> tuple:
    """A parameter file's flat inputs (dict) and its ``[mortar]`` table (dict), refused
    when either is not a table or ``[mortar]`` names a key of neither :data:`MORTAR_KEYS`
    nor :data:`~masonry.mortars.LAYING_INPUTS`."""
    raw = read_toml(path, "params")
    data = raw.get("params", raw)
    if not isinstance(data, dict):
        raise ParameterError("params", str(path), "a file whose [params] is a table")
    table = raw.get("mortar", data.get("mortar", {}))
    keys = (*MORTAR_KEYS, *LAYING_INPUTS)
    if not isinstance(table, dict):
        raise ParameterError("mortar", table, f"a table of {', '.join(keys)}",
                             where=str(path))
    for key, value in table.items():
        if key not in keys:
            raise ParameterError(key, value, f"{', '.join(keys)} in [mortar]",
                                 where=str(path))
    return {key: value for key, value in data.items() if key != "mortar"}, dict(table)


def structure_id(params: Params) -> str:
    """Name of a run's output folder, built from every input that changes the result.

    The thesis's form for defaults, e.g. ``dome0_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1``:
    the scene kind's prefix, the fast accuracy preset (0 or 1) and the friction flow,
    then the geometry's dimensions (their declarations' tags); inputs away from their
    defaults are appended (``_mu0.3``: every other tagged input, the boundary first, then
    the geometry's, the analysis's and the outputs' in their declarations' order), then
    the live load and the collapse's friction law, so a run overwrites only the folder of
    an identical input.
    """
    analysis, geometry = params.analysis, params.geometry
    head = (f"{params.kind.id_prefix(geometry, analysis.boundary)}"
            f"_fast{int(analysis.accuracy == 'fast')}_fric{analysis.friction}")
    for name, declaration in declarations(geometry).items():
        value = getattr(geometry, name)
        if declaration.head and value is not None:
            head += f"_{declaration.tag}{text_of(value)}"
    extras = [("boundary", analysis)]
    for part in (geometry, analysis, params.outputs):
        extras += [(name, part) for name, declaration in declarations(part).items()
                   if declaration.tag is not None and not declaration.head
                   and name != "boundary"]
    for name, part in extras:
        if _named(name, getattr(part, name), defaults(part)[name]):
            tag = declarations(part)[name].tag
            head += f"_{tag}{text_of(getattr(part, name))}"
    if params.load is not None:
        head += params.load.tag
    return head + ("" if analysis.friction_law == "associated" else "_nonassoc")


def _named(name, value, default) -> bool:
    """Whether an extra input goes into the id: away from its default (a boundary only
    when rigid, as the prefix says free or cyclic; the accuracy only when accurate, as
    the fast token says fast)."""
    if name == "boundary":
        return value == "rigid"
    if name == "accuracy":
        return value not in ("balanced", "fast")
    return value != default


def geometry_key(params: Params) -> str:
    """The inputs that decide the geometry and interfaces, as one string: the scene kind
    and every input whose declaration says it names the geometry."""
    named = {name: getattr(part, name)
             for part in (params.geometry, params.analysis)
             for name, declaration in declarations(part).items()
             if declaration.names_geometry}
    return json.dumps({"scene": params.scene, **named}, sort_keys=True)


def digest(text: str) -> str:
    """A short digest of ``text`` for file names."""
    return hashlib.sha1(text.encode()).hexdigest()[:16]
