"""Colour scales chosen by the data, and the colour bars that state them.

Forces are shown in N, kN or MN by their magnitude, on a perceptually uniform sequential
map (viridis) for magnitudes and a diverging one (RdBu_r, 0 white, tension red) for
signed quantities. A scale ends at the :data:`COLOUR_PERCENTILE` th percentile of the
plotted magnitudes; values beyond are drawn in the end colour, the colour bar's arrow
and its label say so.
"""

import matplotlib
import numpy as np
from mpl_toolkits.axes_grid1 import make_axes_locatable

STANDS = "#009e73"
"""A stage (or structure) that stands: bluish green."""
NEEDS_SUPPORT = "#d55e00"
"""A stage that needs support (or adhesion): vermillion."""
LOOSE = "#000000"
"""A stage with a block that touches nothing that holds it: black crosses."""
HINGE = "#cc79a7"
"""A hinge (a joint whose resultant reaches its edge), in the mechanism and the thrust
line alike: reddish purple."""
SLIDING = "#56b4e9"
"""A sliding joint of a mechanism: sky blue outlines."""
TENSION = "#b2182b"
"""Tension: the red end of the signed map (:data:`DIVERGING`), and a thrust line's point
outside its joint (it needs tension)."""
WEB_OUTLINE = "#000000"
"""A web's boundary (its level table's half widths), dashed."""
THRUST = "#000000"
"""The thrust line."""
NO_FORCE = "#737373"
"""A joint of the thrust line that carries no normal force (no point): a grey cross."""
NO_ADHESION = "#d9d9d9"
"""A joint that uses no adhesion at the least adhesion's optimum, among joints coloured
by the adhesion they use (the magnitude map): light grey."""
FAILED = "#000000"
"""A variant of a study that failed (no result): a numbered cross at the axis, its
number that of its reason in the legend."""
EMPHASIS = "#000000"
"""A value the figure points at (the least load factor of the azimuths, the load factor
of the stages)."""
# Each concept has one colour in every figure; the block classes' are
# masonry.blocks.CLASS_COLOURS, compression and friction the signed map's blue end and
# the magnitude map (viridis): docs/outputs.md lists them.

BAR_3D = dict(shrink=0.6, pad=0.16, anchor=(0.0, 0.4))
"""A colour bar beside a 3D box (which sits inside its axes) of a 7 inch tall figure:
shorter, a little low (clear of the title), and far enough out to clear the z axis's
label (:func:`bar_3d`)."""


def bar_3d(fig) -> dict:
    """:data:`BAR_3D` for ``fig``: as long as in a 7 inch tall figure in a taller one (the
    box does not grow with it)."""
    return {**BAR_3D, "shrink": BAR_3D["shrink"] * min(1.0, 7.0 / fig.get_figheight())}

COLOUR_PERCENTILE = 99.0
"""Colour scales end at this percentile of the plotted magnitudes: a few support values
would otherwise set the scale and leave every other interface in one colour."""

ONE_VALUE = 1e-6
"""Values that all lie within this fraction of their largest magnitude of one another
would colour a figure in one colour: it has nothing to show (:func:`one_value`)."""


def one_value(values) -> float | None:
    """The value every one of ``values`` has, within :data:`ONE_VALUE` (a figure coloured
    by them would have one colour); None when they differ, or there are none."""
    values = np.asarray(values, dtype=float)
    if not len(values):
        return None
    spread, largest = float(np.ptp(values)), float(np.abs(values).max())
    return float(np.median(values)) if spread <= ONE_VALUE * largest else None


SEQUENTIAL, DIVERGING = "viridis", "RdBu_r"
ONE_SIDED = 1e-6
"""A signed quantity whose values of one sign all stay within this fraction of the colour
range (solver rounding) is drawn on the other sign's half of the diverging map."""


def force_unit(magnitude: float) -> tuple:
    """``(factor, unit)`` that prints forces of ``magnitude`` newtons with at most three
    digits before the point: N, kN or MN."""
    for factor, unit in ((1e-6, "MN"), (1e-3, "kN")):
        if magnitude >= 1 / factor:
            return factor, unit
    return 1.0, "N"


def colour_scale(values, signed: bool, is_force: bool = True, unit: str = "") -> dict:
    """How to colour ``values``: a robust range (:data:`COLOUR_PERCENTILE`), the unit and
    the map.

    Parameters
    ----------
    values : (n,) float
        In newtons when ``is_force``.
    signed : bool
        A diverging map symmetric about 0 (the half of one sign when every value has it,
        within :data:`ONE_SIDED` of the range); else sequential from 0 (or the minimum).
    unit : str
        Of values that are not forces (``is_force`` False).

    Returns
    -------
    dict
        ``factor`` (multiply values for the display unit), ``unit``, ``norm``, ``cmap``,
        ``extend`` (the colour bar's arrows where values are clipped), ``above`` and
        ``below`` (how many values lie beyond the range's ends), ``largest`` (the largest
        magnitude, display unit).
    """
    values = np.asarray(values, dtype=float)
    magnitude = np.abs(values)
    largest = float(magnitude.max()) if len(values) else 0.0
    top = float(np.percentile(magnitude, COLOUR_PERCENTILE)) if len(values) else 0.0
    top = top if top > 0 else (largest if largest > 0 else 1.0)
    # the unit of the bar's range, not of a few clipped supports
    factor, unit = force_unit(top) if is_force else (1.0, unit)
    if signed:
        # one sign only (no tension anywhere): the bar keeps the map's half of that sign,
        # zero still white at its end
        low = -top if (values < -ONE_SIDED * top).any() else 0.0
        high = top if (values > ONE_SIDED * top).any() or low == 0 else 0.0
        norm = matplotlib.colors.Normalize(low * factor, high * factor)
        part = (0.5 + 0.5 * low / top, 0.5 + 0.5 * high / top)
        cmap = matplotlib.colormaps[DIVERGING]
        if part != (0.0, 1.0):
            cmap = matplotlib.colors.ListedColormap(cmap(np.linspace(*part, 128)),
                                                    name=f"{DIVERGING}_part")
        below = int((values < -top).sum())
        extend = "both" if below and (values > top).any() else (
            "min" if below else "max" if (values > top).any() else "neither")
    else:
        low = min(float(values.min()), 0.0) if len(values) else 0.0
        norm = matplotlib.colors.Normalize(low * factor, top * factor)
        below = 0
        extend = "max" if (values > top).any() else "neither"
        cmap = matplotlib.colormaps[SEQUENTIAL]
    return {"factor": factor, "unit": unit, "norm": norm, "cmap": cmap, "extend": extend,
            "above": int((values > top).sum()), "below": below, "largest": largest * factor}


def colour_bar(fig, ax, scale, quantity, place=None):
    """A colour bar of ``scale`` (:func:`colour_scale`) labelled ``quantity [unit]``,
    saying where the scale is clipped. Returns its place, ``(axes, locator)``: pass it
    as ``place`` to draw the next figure's bar on the same axes in its stead (a colour
    bar wraps its axes' locator to make room for its arrows: the place keeps the one
    it had before)."""
    mappable = matplotlib.cm.ScalarMappable(norm=scale["norm"], cmap=scale["cmap"])
    if place is not None:
        cax, locator = place
        cax.clear()
        cax.set_axes_locator(locator)
        bar = fig.colorbar(mappable, cax=cax, extend=scale["extend"])
    elif hasattr(ax, "get_zlim"):  # a 3D box sits inside its axes: a shorter bar
        bar = fig.colorbar(mappable, ax=ax, extend=scale["extend"], **bar_3d(fig))
        place = (bar.ax, None)  # placed by its position
    else:  # as tall as the equal-scale plot
        cax = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.12)
        place = (cax, cax.get_axes_locator())
        bar = fig.colorbar(mappable, cax=cax, extend=scale["extend"])
    label = f"{quantity} [{scale['unit']}]" if scale["unit"] else quantity
    if scale["largest"] == 0:
        label += "\nall zero"
    beyond = [f"{scale[end]} {end}" for end in ("above", "below") if scale[end]]
    if beyond:
        label += (f"\nscale ends at the {COLOUR_PERCENTILE:g}th percentile; "
                  f"{', '.join(beyond)}, up to {scale['largest']:.3g} {scale['unit']}"
                  + (" in size" if scale["below"] else "")).rstrip()
    bar.set_label(label, fontsize=8)
    return place
