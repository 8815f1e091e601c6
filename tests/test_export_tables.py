"""The CSV tables: column types, units, order (docs/model.md 7)."""

import numpy as np

from masonry.export._text import format_floats


def test_whole_floats_print_as_floats():
    """A float column reads back as float whatever its values (a tension column of
    zeros printed as ``0`` read as integers)."""
    assert format_floats([0.0, -0.0, 3.0, 1e20, 2.5, np.nan, np.inf, -np.inf]).tolist() == [
        "0.0", "-0.0", "3.0", "1e+20", "2.5", "nan", "inf", "-inf"]
