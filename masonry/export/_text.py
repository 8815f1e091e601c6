"""Fast number formatting shared by the text exporters (CSV, OBJ)."""

import numpy as np

FLOAT_FORMAT = "%.12g"
"""How the text exporters print a float: 12 significant digits, what ``f"{x:.12g}"``
prints, with ``.0`` added to a whole number (``0.0``, not ``0``) so that a column of floats
reads as floats whatever its values (pandas, spreadsheets)."""


def format_floats(values) -> np.ndarray:
    """Every value printed with :data:`FLOAT_FORMAT`.

    Parameters
    ----------
    values : (...) float

    Returns
    -------
    (...) object array of str
        Same shape as ``values``.

    Notes
    -----
    Each distinct value is printed once (a dome's 151,872 vertex coordinates hold
    22,455 distinct values): printing every value in Python took most of the export
    time. Values are told apart by their bits, so ``-0.0`` keeps its sign.
    """
    values = np.asarray(values, dtype=np.float64)
    bits, inverse = np.unique(values.view(np.int64), return_inverse=True)
    distinct = bits.view(np.float64).tolist()
    # one % over a long format string: faster than a % per value
    text = ((FLOAT_FORMAT + "\n") * len(distinct) % tuple(distinct)).split("\n")[:-1]
    # a whole number has none of ".en" (e: exponent, n: nan, inf); three tests inline
    # are faster than any() over a generator
    text = [t if "." in t or "e" in t or "n" in t else t + ".0" for t in text]
    return np.array(text, dtype=object)[inverse].reshape(values.shape)


def format_float(value) -> str:
    """One value printed as :func:`format_floats` prints it (a cell of a table written
    row by row)."""
    return format_floats([value])[0]
