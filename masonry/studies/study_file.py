"""A study file read (``masonry sweep STUDY.toml``, ``masonry optimize STUDY.toml``): its
tables checked, one line naming the file and the table and key at fault, into a
:class:`masonry.studies.sweep.Study` (docs/cli.md, "Parameter studies").

The file names its inputs as 'masonry run' options without their dashes; the command
line gives the options it declares (:func:`load_study`'s ``options``). Every variant is
checked as ``masonry run`` (and, for a study of stages, ``masonry stages``) checks its
inputs before anything runs.
"""

import dataclasses
import math

from masonry.errors import ParameterError
from masonry.mortars import LAYING_INPUTS, split_laying
from masonry.outputs import Outputs, figure_formats
from masonry.parameters import declarations, read_toml
from masonry.params import MORTAR_KEYS, PRESETS, Params, validate
from masonry.stages.laying import stage_laying
from masonry.stages.orders import BLOCK_ORDERS, BRICK_ORDERS


NOT_AN_INPUT = {
    "plots": "an input of each variant: the figures are chosen in the [outputs] table "
             "(plots = false)",
    "printable": "an input of each variant: the printable body is chosen in the [outputs] "
                 "table (printable = false)",
    "html": "an input of each variant: dome.html is chosen in the [outputs] table "
            "(html = false)",
    "html_plotly": "an input of each variant: where dome.html finds plotly.js is chosen "
                   "in the [outputs] table (html_plotly = \"inline\")",
    "figure_format": "an input of each variant: the figures' formats are chosen in the "
                     "[outputs] table (figure_format = [\"png\", \"pdf\"])",
    "dpi": "an input of each variant: the figures' resolution is chosen in the [outputs] "
           "table (dpi = 300)",
    "out": "an input of each variant: the study's output root is masonry sweep's --out",
    "preset": "an input of [base] (preset = 3), not of another table",
    "params": "an input of each variant: a study names the inputs themselves",
}
"""Why a study table refuses a run option that is not an input, by its destination."""


TABLES = ("base", "grid", "sample", "mortar", "outputs", "constraints")
MAX_VARIANTS = 100_000
"""Largest study (grid points times samples): a study file asking for more is refused."""


def load_study(path, options, draws=True):
    """Read a study file; names are 'masonry run' options without their dashes.

    ``options``: 'masonry run''s long options (with dashes or underscores, without the
    leading ``--``) -> ``(Params field, whether it is a run's input)``, as the command
    line declares them (``masonry_cli.sweep.run_option_names``). ``draws``: the
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
    names = {**options, **{spelling: (name, True) for name in LAYING_INPUTS
                                      for spelling in (name, name.replace("_", "-"))}}
    from masonry.studies.sweep import Study  # the pipeline: once the file is read

    tables = {"base": _fields(base, "base", names, where),
              "grid": _fields(grid, "grid", names, where, lists=True),
              "sample": _fields(sample, "sample", names, where), "mortar": mortar}
    _check_laying(tables, stages, where)
    study = Study(
        base={**(PRESETS[str(preset)] if preset is not None else {}), **tables["base"],
              **mortar},
        grid=tables["grid"], sample=tables["sample"], count=count, seed=seed,
        plots=outputs.get("plots", False), printable=outputs.get("printable", False),
        html=outputs.get("html"), constraints=constraints, **stages,
        **_figure_outputs(outputs, refuse))
    study = _checked_constraints(study, where)
    _check_variants(study, where, options, None if draws else _search_probes(study),
                    mortar)
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


FIGURE_OUTPUTS = ("figure_format", "dpi", "html_plotly")
"""The ``[outputs]`` keys of the figures' and the page's files, checked by their declarations
(:class:`masonry.outputs.Outputs`)."""


def _figure_outputs(outputs, refuse) -> dict:
    """``[outputs] figure_format`` (a name or a list of names) and ``dpi``, checked as
    ``masonry run`` checks its options; returns :class:`Study`'s fields they give."""
    given = {}
    for key in FIGURE_OUTPUTS:
        if key in outputs:
            value = figure_formats(outputs[key]) if key == "figure_format" else outputs[key]
            error = declarations(Outputs)[key].refusal(key, value)
            if error is not None:
                refuse(f"outputs.{key}", outputs[key], error.expected)
            given[key] = value
    return given


def _stage_outputs(outputs, refuse) -> dict:
    """The ``[outputs]`` table checked: ``plots``, ``printable``, ``html`` (true or
    false) and a stage study's ``stages`` (``course``, ``brick`` or ``block``),
    ``stages_course`` (the course of ``brick``; none: every course) and ``stages_order``; returns
    :class:`Study`'s ``stages*``."""
    for key, value in outputs.items():
        if key in ("plots", "printable", "html"):
            if not isinstance(value, bool):
                refuse(f"outputs.{key}", value, "true or false")
        elif key not in ("stages", "stages_course", "stages_order", *FIGURE_OUTPUTS):
            refuse(f"outputs.{key}", value, "plots, printable, html, figure_format, dpi, "
                                            "html_plotly, stages, stages_course or "
                                            "stages_order")
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


def _check_variants(study, where, options, variants=None, mortar=()):
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
            key = name if table == "mortar" else _option_of(name, options)
            raise ParameterError(f"{table}.{key}" if table else f"{key} (the default)",
                                 inputs.get(name, error.value), error.expected,
                                 where=where) from None
        if study.stages in ("course", "brick") and not params.kind.has_courses:
            raise ParameterError("outputs.stages", study.stages, f'"block": scene '
                                 f"{params.scene} is not laid in courses", where=where)


def _option_of(field: str, options) -> str:
    """The 'masonry run' option (without dashes) a study names a Params field by
    (``arch_thickness`` -> ``thickness``), of ``options`` (:func:`load_study`)."""
    spelled = {}
    for option, (dest, _) in options.items():
        spelled.setdefault(dest, option)
    return spelled.get(field, field.replace("_", "-"))


def _fields(table, name, names, where, lists=False) -> dict:
    """A study table's 'masonry run' option names -> Params fields (``dome`` is the
    boundary: true is cyclic); ``lists``: the values are lists of values."""
    out = {}
    for key, value in table.items():
        if key not in names:
            raise ParameterError(f"{name}.{key}", value, "a 'masonry run' option (without "
                                 "its dashes)", where=where)
        dest, is_input = names[key]
        if not is_input:
            raise ParameterError(f"{name}.{key}", value, NOT_AN_INPUT.get(
                dest, "an input of each variant, not an option of the command"),
                where=where)
        if dest == "dome":
            def boundary(flag):
                if not isinstance(flag, bool):
                    raise ParameterError(f"{name}.{key}", value, "true or false", where=where)
                return "cyclic" if flag else "free"
            dest, value = "boundary", [boundary(v) for v in value] if lists else boundary(value)
        out[dest] = value
    return out
