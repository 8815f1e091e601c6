"""A HiGHS linear program from scipy.sparse arrays (highspy), shared by the RBE's LP check
and the collapse LP."""

import highspy
import highspy.highs
import numpy as np

_HIGHS = getattr(highspy.highs, "_Highs", highspy.Highs)
"""The HiGHS class without highspy's Python layer: from highspy 1.16, ``highspy.Highs()``
prints HiGHS's banner to standard output as it sets up its callbacks, before
``output_flag`` can be switched off (HiGHS issues 1702, 2749); the class under it prints
nothing until run, and has every method used here (no callbacks are used)."""


def highs_lp(A, cost, col_lower, col_upper, row_lower, row_upper, options,
             maximize=False) -> _HIGHS:
    """A HiGHS instance holding ``cost @ x`` (minimised, or maximised when ``maximize``)
    subject to ``row_lower <= A x <= row_upper`` and ``col_lower <= x <= col_upper``.

    Parameters
    ----------
    A : (m, n) scipy.sparse CSC array
    cost, col_lower, col_upper : (n,) float (``highspy.kHighsInf`` for no bound)
    row_lower, row_upper : (m,) float
    options : iterable of (name, value)
        HiGHS options; output is switched off first.

    Raises
    ------
    ValueError
        HiGHS refused an option (a misspelt name or a value out of its range).
    """
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = A.shape[1], A.shape[0]
    lp.col_cost_ = np.asarray(cost, dtype=float)
    lp.col_lower_, lp.col_upper_ = col_lower, col_upper
    lp.row_lower_, lp.row_upper_ = row_lower, row_upper
    if maximize:
        lp.sense_ = highspy.ObjSense.kMaximize
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
        A.indptr, A.indices, A.data)
    highs = _HIGHS()
    for name, value in (("output_flag", False), *options):
        if highs.setOptionValue(name, value) != highspy.HighsStatus.kOk:
            raise ValueError(f"HiGHS refused option {name}={value!r}")
    highs.passModel(lp)
    return highs
