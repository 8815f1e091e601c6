"""The CSV tables: column types, units, order (docs/model.md 7)."""

import numpy as np
import pytest

from masonry import read_table
from masonry.export._text import format_floats
from masonry.export.columns import RUN_COLUMNS, STAGE_COLUMNS
from masonry.studies.sweep import (Study, column_key, run_summary, summary_csv,
                                   summary_rows)
from masonry.stages.records import stage_summary


def test_whole_floats_print_as_floats():
    """A float column reads back as float whatever its values (a tension column of
    zeros printed as ``0`` read as integers)."""
    assert format_floats([0.0, -0.0, 3.0, 1e20, 2.5, np.nan, np.inf, -np.inf]).tolist() == [
        "0.0", "-0.0", "3.0", "1e+20", "2.5", "nan", "inf", "-inf"]


# a run's and a stage study's run.json records, as far as a summary row reads them
RUN_RECORD = {
    "structure_id": "dome0_s0.8_mu0.5", "weight_N": 81652.5,
    "counts": {"bricks": 566, "interfaces": {"horizontal": 1000, "vertical": 560,
                                             "support": 7}},
    "rbe": {"feasible": False, "friction": "plus", "friction_model": "circle",
            "moi": 3366972.5, "moi_factor": 41.25, "objective": 2.5e9,
            "residual_eq": 8e-10},
    "centering": {"total_N": 11795.5, "fraction": 0.144},
    "adhesion": {"a_kPa": 404.5},
    "collapse": {"load_factor": None, "azimuth_deg": 0.0},
    "stages": {"count": 42, "standing": 16, "first_unsupported": {"stage": 17, "course": 17,
                                                                  "brick": None},
               "centering_max_N": 11795.5, "centering_max_fraction": 0.144,
               "load_factor_min": 0.33, "adhesion_max_kPa": 404.5,
               "adhesion_max_course": 42}}


def test_a_summary_reads_back_with_every_columns_type(tmp_path):
    """A sweep's summary of stages, written from run.json records and read back by
    masonry.read_table: every column typed as its declaration says, the values those of
    the records (the interfaces summed over their kinds, empty cells missing)."""
    pandas = pytest.importorskip("pandas")
    study = Study(base={"preset": "3"}, grid={"mu": [0.5]}, stages="course")
    row = {"status": "computed", "error": "", "time_s": 1.5,
           **run_summary(RUN_RECORD), **stage_summary(RUN_RECORD)}
    path = tmp_path / "summary.csv"
    path.write_bytes(summary_csv(study, summary_rows(study, [(0, {"mu": 0.5}, row)])))
    table = read_table(path)
    declared = {c.name: c for c in (*RUN_COLUMNS, *STAGE_COLUMNS)}
    assert set(declared) <= set(column_key(c) for c in table.columns)
    for column, dtype in table.dtypes.items():
        kind = declared[column_key(column)].kind if column_key(column) in declared else "float"
        if kind == "str":
            assert pandas.api.types.is_string_dtype(dtype), column
        else:
            assert str(dtype) == {"int": "Int64", "bool": "boolean",
                                  "float": "float64"}[kind], column
    first = table.iloc[0]
    assert first["interfaces"] == 1567 and first["bricks"] == 566
    assert not first["feasible"] and first["friction_used"] == "plus"
    assert first["moi_N"] == pytest.approx(3366972.5, rel=1e-11)
    assert first["centering_N"] == pytest.approx(11795.5, rel=1e-11)
    assert pandas.isna(first["load_factor"]) and pandas.isna(first["first_unsupported_brick"])
    assert first["first_unsupported_course"] == 17 and first["stages"] == 42


def test_a_structure_that_stands_needs_no_centering():
    """A feasible run's summary gives a centering force of 0, whatever its record holds."""
    record = {**RUN_RECORD, "rbe": {**RUN_RECORD["rbe"], "feasible": True}}
    row = run_summary(record)
    assert row["centering_N"] == 0.0 and row["centering_fraction"] == 0.0
    assert row["feasible"] is True
