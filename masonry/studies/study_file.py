"""A study file read (``masonry sweep STUDY.toml``, ``masonry optimize STUDY.toml``): its
tables checked, one line naming the file and the table and key at fault, into a
:class:`masonry.studies.sweep.Study` (docs/cli.md, "Parameter studies").

The file names its inputs as 'masonry run' options without their dashes, the names that
follow from their declarations (:func:`masonry.params.option_of`): a new declared input
is a study's key without a line here. Every variant is checked as ``masonry run`` (and,
for a study of stages, ``masonry stages``) checks its inputs before anything runs.
"""

import dataclasses
import math

from masonry.errors import ParameterError
from masonry.mortars import LAYING_INPUTS, split_laying
from masonry.outputs import Outputs, figure_formats
from masonry.parameters import declarations, read_toml
from masonry.params import (FILE_OUTPUTS, MORTAR_KEYS, PRESETS, Params, names, option_of,
                            validate)
from masonry.stages.laying import stage_laying
from masonry.stages.orders import BLOCK_ORDERS, BRICK_ORDERS


NOT_AN_INPUT = {
    "out": "an input of each variant: the study's output root is masonry sweep's --out",
    "preset": "an input of [base] (preset = 3), not of another table",
    "params": "an input of each variant: a study names the inputs themselves",
}
"""Why a study table refuses an option of 'masonry run' that is not an input."""

SHORTHANDS = ("scene", "fast", "dome")
"""Study keys that are no declared input, as 'masonry run' has them: the scene, the fast
preset, and ``dome`` (the boundary: true is cyclic, false free)."""

STAGE_OUTPUTS = ("stages", "stages_course", "stages_order")
"""The ``[outputs]`` keys of a study of stages (:func:`_stage_outputs`)."""


def _spellings(name) -> set:
    """The keys that name input ``name``: it and its option, with dashes or
    underscores."""
    option = option_of(name)
    return {name, option, option.replace("-", "_")}


def input_keys() -> dict:
    """The keys of a study's ``[base]``, ``[grid]`` and ``[sample]`` -> the input each
    gives: every input of a run (:func:`masonry.params.names`) but the outputs that
    ``[outputs]`` chooses (:data:`~masonry.params.FILE_OUTPUTS`), the
    :data:`SHORTHANDS` and a stage study's mortar by age, each spelled as its name or as
    its 'masonry run' option without the dashes."""
    return {key: name for name in (*SHORTHANDS, *names(), *LAYING_INPUTS)
            if name not in FILE_OUTPUTS for key in _spellings(name)}


def output_keys() -> dict:
    """The spellings of the outputs ``[outputs]`` chooses (their names, options and a
    switch's ``no-`` option) -> the output, which the other tables refuse by name."""
    keys = {}
    for name in FILE_OUTPUTS:
        for key in _spellings(name):
            keys[key] = name
            if declarations(Outputs)[name].kind == "bool":
                keys[f"no-{key}"] = keys[f"no_{key}"] = name
    return keys


TABLES = ("base", "grid", "sample", "mortar", "outputs", "constraints")
MAX_VARIANTS = 100_000
"""Largest study (grid points times samples): a study file asking for more is refused."""


def load_study(path, draws=True):
    """Read a study file; names are 'masonry run' options without their dashes
    (:func:`input_keys`, :func:`output_keys`). ``draws``: the
    ``[sample]`` ranges are drawn ``count`` times (a sweep: ``count`` required with them);
    False for an optimisation, which searches them.

    Raises
    ------
    ParameterError
        Named ``study`` when the file cannot be read or is not TOML, else named after the
        table and key at fault (``grid.mu``), with the file as ``where``.
    """
    data = read_toml(path, "study")
    where = str(path)

    def refuse(key, value, expected):
        raise ParameterError(key, value, expected, where=where)

    for key, value in data.items():
        if key not in TABLES:
            refuse(key, value, f"one of the tables [{'], ['.join(TABLES)}]")
        if not isinstance(value, dict):
            refuse(key, value, f"a table [{key}]")
    base, grid = dict(data.get("base", {})), dict(data.get("grid", {}))
    sample, outputs = dict(data.get("sample", {})), data.get("outputs", {})
    constraints = _constraints(data.get("constraints", {}), where)
    preset = base.pop("preset", None)
    if preset is not None and str(preset) not in PRESETS:
        refuse("base.preset", preset, f"one of {', '.join(PRESETS)}")
    count, seed = sample.pop("count", 0), sample.pop("seed", 0)
    for key, value, ok, expected in (
            ("sample.count", count, isinstance(count, int) and not isinstance(count, bool)
             and 0 <= count <= MAX_VARIANTS, f"an integer 1 to {MAX_VARIANTS}"),
            ("sample.seed", seed, isinstance(seed, int) and not isinstance(seed, bool)
             and seed >= 0, "an integer >= 0")):
        if not ok:
            refuse(key, value, expected)
    stages = _stage_outputs(outputs, refuse)
    mortar = _mortar_table(data.get("mortar", {}), base, refuse)
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            refuse(f"grid.{key}", values, "a non-empty list of values")
    for key, bounds in sample.items():
        if not (isinstance(bounds, list) and len(bounds) == 2
                and all(isinstance(b, (int, float)) and not isinstance(b, bool)
                        for b in bounds) and bounds[0] <= bounds[1]):
            refuse(f"sample.{key}", bounds, "[low, high], two numbers with low <= high")
    if sample and count < 1 and draws:
        refuse("sample.count", count, f"an integer 1 to {MAX_VARIANTS}")
    size = math.prod(len(v) for v in grid.values()) * max(count, 1)
    if size > MAX_VARIANTS and draws:
        refuse("grid", f"{size} variants", f"at most {MAX_VARIANTS} variants")
    from masonry.studies.sweep import Study  # the pipeline: once the file is read

    tables = {"base": _fields(base, "base", where),
              "grid": _fields(grid, "grid", where, lists=True),
              "sample": _fields(sample, "sample", where), "mortar": mortar}
    _check_laying(tables, stages, where)
    chosen = {**Study.outputs_default(), **_outputs_table(outputs, refuse)}
    if chosen.get("print_size") is not None and not chosen.get("printable", True):
        refuse("outputs.print_size", chosen["print_size"],
               "printable = true beside it in [outputs] (dome.3mf is the printable body "
               "at that size; a study writes none unless asked)")
    study = Study(
        base={**(PRESETS[str(preset)] if preset is not None else {}), **tables["base"],
              **mortar},
        grid=tables["grid"], sample=tables["sample"], count=count, seed=seed,
        outputs=chosen, constraints=constraints, **stages)
    study = _checked_constraints(study, where)
    _check_variants(study, where, None if draws else _search_probes(study), mortar)
    return study


MORTAR_TABLE = (*MORTAR_KEYS, *LAYING_INPUTS)
"""The keys of a study's ``[mortar]`` table: the analysis's mortar inputs and, for a
study of stages, their mortar by age."""


def _mortar_table(table, base, refuse) -> dict:
    """``[mortar]``: fixed inputs of every variant (:data:`MORTAR_TABLE`, as a parameter
    file's ``[mortar]``), refused by key when it is another key, not one value, or
    ``[base]`` gives it too."""
    out = {}
    for key, value in table.items():
        name = key.replace("-", "_")
        if name not in MORTAR_TABLE:
            refuse(f"mortar.{key}", value, f"one of {', '.join(MORTAR_TABLE)}")
        if isinstance(value, (list, dict)):
            refuse(f"mortar.{key}", value, "one value, the same in every variant (a list "
                                           "to sweep goes in [grid])")
        if name in base or key in base:
            refuse(f"mortar.{key}", value, "in [mortar] or in [base], not in both")
        out[name] = value
    return out


def _check_laying(tables, stages, where):
    """Refuse a mortar by age (:data:`~masonry.mortars.LAYING_INPUTS`) in a study
    without stage studies: it ages the joints of the stages, not of a run."""
    if stages:
        return
    for table, inputs in tables.items():
        for name in LAYING_INPUTS:
            if name in inputs:
                raise ParameterError(f"{table}.{name}", inputs[name], "[outputs] stages "
                                     "beside it: the mortar by age of every variant's "
                                     "stage study (masonry stages --mortar)", where=where)


def _constraints(table, where) -> dict:
    """``[constraints]``: result column -> ``[low, high]`` (TOML's ``inf`` for an open
    end); the columns are checked against the study's (:func:`_check_constraints`)."""
    out = {}
    for key, bounds in table.items():
        if not (isinstance(bounds, list) and len(bounds) == 2
                and all(isinstance(b, (int, float)) and not isinstance(b, bool)
                        for b in bounds) and bounds[0] <= bounds[1]):
            raise ParameterError(f"constraints.{key}", bounds, "[low, high], two numbers "
                                 "with low <= high (inf or -inf for an open end)",
                                 where=where)
        out[key] = list(bounds)
    return out


def _checked_constraints(study, where):
    """``study`` with its constraints keyed by record key, once every constrained column
    is one its summary has and that is a number, named as ``summary.csv`` names it
    (:func:`~masonry.studies.sweep.measure_columns`: a study of stages has its stage
    columns)."""
    from masonry.studies.sweep import column_key, measure_columns

    columns = measure_columns(study)
    for key, bounds in study.constraints.items():
        if key not in columns:
            raise ParameterError(f"constraints.{key}", bounds, f"a result column of the "
                                 f"summary, one of {', '.join(columns)}", where=where)
    return dataclasses.replace(study, constraints={
        column_key(key): bounds for key, bounds in study.constraints.items()})


def _search_probes(study) -> list:
    """Variants that try every choice and both ends of every range of a search space,
    one input at a time (the others at their first choice or lower end), then every
    input at its upper end: an optimisation cannot check its whole space beforehand."""
    first = {**{k: v[0] for k, v in study.grid.items()},
             **{k: b[0] for k, b in study.sample.items()}}
    probes = [dict(first)]
    for name, values in [*study.grid.items(), *study.sample.items()]:
        probes += [{**first, name: value} for value in values[1:]]
    probes.append({**first, **{k: b[1] for k, b in study.sample.items()}})
    return [{**study.base, **probe} for probe in probes]


def _stage_plans() -> dict:
    """``[outputs] stages`` values (``masonry stages --by``) and their laying orders."""
    return {"course": (), "brick": BRICK_ORDERS, "block": BLOCK_ORDERS}


def _outputs_table(outputs, refuse) -> dict:
    """``[outputs]``'s outputs (:data:`~masonry.params.FILE_OUTPUTS`), each checked by its
    declaration (:class:`masonry.outputs.Outputs`) as ``masonry run`` checks its option;
    a key of neither them nor :data:`STAGE_OUTPUTS` is refused. Returns them by name."""
    given = {}
    for key, value in outputs.items():
        if key in STAGE_OUTPUTS:
            continue
        name = key.replace("-", "_")
        if name not in FILE_OUTPUTS:
            refuse(f"outputs.{key}", value, f"one of {', '.join(FILE_OUTPUTS)}, "
                                            f"{', '.join(STAGE_OUTPUTS)}")
        value = figure_formats(value) if name == "figure_format" else value
        error = declarations(Outputs)[name].refusal(name, value)
        if error is not None:
            refuse(f"outputs.{key}", outputs[key], error.expected)
        given[name] = value
    return given


def _stage_outputs(outputs, refuse) -> dict:
    """A stage study's ``[outputs]`` checked: ``stages`` (``course``, ``brick`` or
    ``block``), ``stages_course`` (the course of ``brick``; none: every course) and
    ``stages_order``; returns :class:`Study`'s ``stages*``."""
    by, course = outputs.get("stages"), outputs.get("stages_course")
    order = outputs.get("stages_order")
    if by is None:
        if course is not None or order is not None:
            key = "stages_course" if course is not None else "stages_order"
            refuse(f"outputs.{key}", outputs[key], "with outputs.stages only")
        return {}
    plans = _stage_plans()
    if not isinstance(by, str) or by not in plans:
        refuse("outputs.stages", by, '"course", "brick" or "block" (the stage plan of '
                                     "'masonry stages --by')")
    if by == "brick" and course is not None and not (
            isinstance(course, int) and not isinstance(course, bool) and course >= 1):
        refuse("outputs.stages_course", course, 'the course laid brick by brick with '
                                                'stages = "brick", an integer >= 1 (none: '
                                                'every course)')
    if by != "brick" and course is not None:
        refuse("outputs.stages_course", course, 'none: a course only with stages = "brick"')
    if order is not None and order not in plans[by]:
        expected = (f"one of {', '.join(plans[by])}" if plans[by] else
                    "none: a course plan has no laying order")
        refuse("outputs.stages_order", order, expected)
    return {"stages": by, "stages_course": course, "stages_order": order}


def _check_variants(study, where, variants=None, mortar=()):
    """Every variant's inputs (or ``variants``) checked as ``masonry run`` (and for a
    study of stages ``masonry stages``, its mortar by age too) checks them, before any
    runs: a value out of range names the table and key it came from (the input refused,
    else the first other input the check involves that the study gives; one the study
    leaves at its default says so; ``mortar`` the keys of the ``[mortar]`` table); a
    plan by course or brick of a scene not laid in courses names ``outputs.stages``."""
    for inputs in variants if variants is not None else study.variants():
        try:
            run_inputs, laying = split_laying(inputs)
            params = validate(Params.of(**run_inputs))
            if study.stages:  # what 'masonry stages' would refuse of the variant
                from masonry.stages.run import check_live_load, stage_params

                check_live_load(params)
                stage_laying(stage_params(params, "boundary" in inputs), **laying)
        except ParameterError as error:
            names = (error.name, *error.related)
            tables = {"grid": study.grid, "sample": study.sample, "mortar": mortar,
                      "base": study.base}
            table, name = next(((t, n) for n in names for t in tables if n in tables[t]),
                               (None, error.name))
            key = name if table == "mortar" else option_of(name)
            raise ParameterError(f"{table}.{key}" if table else f"{key} (the default)",
                                 inputs.get(name, error.value), error.expected,
                                 where=where) from None
        if study.stages in ("course", "brick") and not params.kind.has_courses:
            raise ParameterError("outputs.stages", study.stages, f'"block": scene '
                                 f"{params.scene} is not laid in courses", where=where)


def _fields(table, name, where, lists=False) -> dict:
    """A study table's keys (:func:`input_keys`) -> the inputs they give (``dome`` is the
    boundary: true is cyclic); ``lists``: the values are lists of values."""
    inputs, outputs = input_keys(), output_keys()
    out = {}
    for key, value in table.items():
        if key in outputs:
            raise ParameterError(f"{name}.{key}", value, f"an input of each variant: the "
                                 f"[outputs] table chooses it for all variants "
                                 f"(outputs.{outputs[key]})", where=where)
        if key not in inputs:
            raise ParameterError(f"{name}.{key}", value, NOT_AN_INPUT.get(
                key, "an input of each variant, named as its 'masonry run' option "
                     "without the dashes (not an option of the command)"), where=where)
        dest = inputs[key]
        if dest == "dome":
            def boundary(flag):
                if not isinstance(flag, bool):
                    raise ParameterError(f"{name}.{key}", value, "true or false", where=where)
                return "cyclic" if flag else "free"
            dest, value = "boundary", [boundary(v) for v in value] if lists else boundary(value)
        out[dest] = value
    return out
