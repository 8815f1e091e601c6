"""The columns of the tables masonry writes, declared once: name, where the value comes
from, type, unit and meaning (docs/outputs.md, "Adding an output or a column").

A sweep's summary columns (:data:`RUN_COLUMNS`, :data:`STAGE_COLUMNS`) are read from a
run's or a stage study's ``run.json`` record by their ``source``; the other tables' columns
that are not floats (:data:`TABLE_COLUMNS`) are written by their exporters. The CSV types
(:func:`masonry.export.csv.column_types`), the headers that name a unit
(:data:`masonry.export.csv.HEADERS`) and a summary row
(:func:`masonry.studies.sweep.run_summary`, :func:`masonry.stages.records.
stage_summary`) all follow from these rows: a new column is one row here.
"""

from dataclasses import dataclass

DTYPES = {"int": "Int64", "str": "str", "bool": "boolean", "float": "float64"}
"""The pandas dtype a table reads a column of each kind as."""


@dataclass(frozen=True)
class Column:
    """One column of masonry's tables.

    Parameters
    ----------
    name : str
        Its key in a row (and in ``run.json``'s summaries).
    kind : {'int', 'str', 'bool', 'float'}
        Its type (:data:`DTYPES`); a float column's name says its unit.
    unit : str
        Its unit ('' when it has none).
    doc : str
        What it means.
    source : str or callable, optional
        Where a summary row finds it in a ``run.json`` record: a dotted path (``rbe.moi``;
        a missing or None step gives None), or ``source(record)``. None: the study or an
        exporter writes it.
    header : str, optional
        Its CSV name when that says the unit the key does not (``moi`` -> ``moi_N``).
    """

    name: str
    kind: str
    unit: str = ""
    doc: str = ""
    source: object = None
    header: str | None = None

    def value(self, record):
        """This column's value in a ``run.json`` record (:attr:`source`)."""
        if callable(self.source):
            return self.source(record)
        value = record
        for key in self.source.split("."):
            value = value.get(key) if isinstance(value, dict) else None
        return value


def _unless_stands(path):
    """A centering column: 0 where the structure stands, else the record's value."""
    def source(record):
        if (record.get("rbe") or {}).get("feasible") is True:
            return 0.0
        return Column(path, "float", source=path).value(record)
    return source


def _interfaces(record) -> int:
    return sum(record["counts"].get("interfaces", {}).values())


RUN_COLUMNS = (
    Column("variant", "int", doc="the variant's index in the study"),
    Column("status", "str", doc="computed, reused or failed"),
    Column("error", "str", doc="why the variant failed (empty unless failed)"),
    Column("feasible", "bool", doc="the RBE verdict: the structure stands",
           source="rbe.feasible"),
    Column("friction_used", "str", doc="the friction flow solved (net or plus)",
           source="rbe.friction"),
    Column("friction_model", "str", doc="the friction model (circle, polygon:K, square)",
           source="rbe.friction_model"),
    Column("moi", "float", "N", "the measure of infeasibility", "rbe.moi", header="moi_N"),
    Column("moi_factor", "float", "", "the MoI over the weight", "rbe.moi_factor"),
    Column("centering_N", "float", "N", "the centering force (docs/model.md 6.10); 0 "
           "where the structure stands", _unless_stands("centering.total_N")),
    Column("centering_fraction", "float", "", "the centering force over the weight",
           _unless_stands("centering.fraction")),
    Column("adhesion_kPa", "float", "kPa", "the least adhesion (docs/model.md 6.12); empty "
           "where none was found", "adhesion.a_kPa"),
    Column("objective", "float", "N^2", "the RBE program's optimum", "rbe.objective",
           header="objective_N2"),
    Column("weight_N", "float", "N", "the structure's weight", "weight_N"),
    Column("bricks", "int", doc="blocks of the model", source="counts.bricks"),
    Column("interfaces", "int", doc="interfaces of every kind", source=_interfaces),
    Column("residual_eq", "float", "", "the equilibrium residual over the weight",
           "rbe.residual_eq"),
    Column("load_factor", "float", "", "the collapse load factor of the live load "
           "(docs/model.md 6.8)", "collapse.load_factor"),
    Column("load_azimuth_deg", "float", "degrees", "the lateral load's azimuth (the worst "
           "with lateral = \"all\")", "collapse.azimuth_deg"),
    Column("time_s", "float", "s", "the variant's wall clock"),
    Column("structure_id", "str", doc="the run folder's name", source="structure_id"),
)
"""A sweep's result columns of one run, after the swept inputs."""

STAGE_COLUMNS = (
    Column("stages", "int", doc="stages of the plan", source="stages.count"),
    Column("stages_standing", "int", doc="stages that stand", source="stages.standing"),
    Column("first_unsupported_stage", "int", doc="the first stage that needs support "
           "(empty when every stage stands)", source="stages.first_unsupported.stage"),
    Column("first_unsupported_course", "int", doc="its course",
           source="stages.first_unsupported.course"),
    Column("first_unsupported_brick", "int", doc="its brick's rank on its course (a "
           "brick plan)", source="stages.first_unsupported.brick"),
    Column("centering_max_N", "float", "N", "the largest centering force over the stages",
           "stages.centering_max_N"),
    Column("centering_max_fraction", "float", "", "that stage's centering force over its "
           "weight", "stages.centering_max_fraction"),
    Column("stages_load_factor_min", "float", "", "the smallest lateral load factor over "
           "the stages", "stages.load_factor_min"),
    Column("adhesion_max_kPa", "float", "kPa", "the largest least adhesion over the stages",
           "stages.adhesion_max_kPa"),
    Column("adhesion_max_course", "int", doc="the course where it peaks",
           source="stages.adhesion_max_course"),
)
"""A stage study's columns in a sweep's summary, after :data:`RUN_COLUMNS`."""

TABLE_COLUMNS = (
    Column("id", "int", doc="an interface's index (interfaces.csv, forces.csv)"),
    Column("rank", "int", doc="an interface's rank by tension (RBE/tension_top.csv)"),
    Column("brick", "int", doc="a brick's index (locations.csv)"),
    Column("block", "int", doc="a block's index (RBE/centering.csv, collapse/mechanism.csv)"),
    Column("block_a", "int", doc="an interface's first block"),
    Column("block_b", "int", doc="its second block"),
    Column("course", "int", doc="a brick's course"),
    Column("course_a", "int", doc="the first block's course"),
    Column("course_b", "int", doc="the second block's course"),
    Column("vertex", "int", doc="a brick's corner (locations.csv)"),
    Column("vertices", "int", doc="an interface polygon's vertices"),
    Column("stage", "int", doc="a stage of a stage study (stages.csv)"),
    Column("step", "int", doc="a step of a search (arch-thickness's steps.csv)"),
    Column("interface", "int", doc="an interface's id (RBE/adhesion.csv)"),
    Column("trial", "int", doc="an optimisation's trial (trials.csv)"),
    Column("loose", "int", doc="a stage's blocks with no chain of contacts to a support"),
    Column("masons", "int", doc="masons laying at once (a mortar by age)"),
    Column("name", "str", doc="a block's name"),
    Column("name_a", "str", doc="the first block's name"),
    Column("name_b", "str", doc="the second block's name"),
    Column("class", "str", doc="a block's class (masonry.blocks.BLOCK_CLASSES)"),
    Column("kind", "str", doc="an interface's kind (masonry.interfaces.INTERFACE_KINDS)"),
    Column("laid", "str", doc="the blocks a stage lays (stages.csv)"),
    Column("mortar", "str", doc="the mortar by age a stage study swept"),
    Column("stands", "bool", doc="a stage stands (stages.csv)"),
    Column("constraints_met", "bool", doc="every [constraints] bound holds (an "
           "optimisation)"),
    Column("best", "bool", doc="a trial on the best front (trials.csv)"),
)
"""The other columns of masonry's tables that are not floats."""

COLUMNS = {c.name: c for c in (*RUN_COLUMNS, *STAGE_COLUMNS, *TABLE_COLUMNS)}
"""Every declared column by name: a name means one thing, of one type, in every table."""


def column_names(columns) -> tuple:
    """The names of ``columns``, in order."""
    return tuple(c.name for c in columns)


def summary_row(columns, record) -> dict:
    """The columns of ``columns`` that a ``run.json`` record gives, from ``record``."""
    return {c.name: c.value(record) for c in columns if c.source is not None}
