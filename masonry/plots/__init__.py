"""Plots as PNG bytes (matplotlib, Agg), one module per figure family: the flattened
pattern (:mod:`.pattern`), the structure views (:mod:`.structure`), the interfaces
coloured by their area, forces and the adhesion they use (:mod:`.forces`), the thrust
line (:mod:`.thrust`), where the structure fails (:mod:`.failure`), the collapse mechanism
(:mod:`.mechanism`) and its load factor by azimuth (:mod:`.azimuths`), and the
construction stages (:mod:`.stages`), and an optimisation's convergence
(:mod:`.convergence`). They share the views, the drawing helpers
(:mod:`.common`) and the colour scales (:mod:`.colours`).

Every function returns a figure's files (``{format: bytes}``, :func:`.common.figure_files`)
or ``{relative path: bytes}`` of several, in the formats a :class:`.common.Render` asks
(PNG, SVG, PDF), so the run folder writer is the one place that touches the disk.
"""

import os

import matplotlib
from matplotlib import mathtext

# before any module of the package imports pyplot: runs draw without a display
matplotlib.use("Agg")

# A run draws its plots in a forked copy of itself beside this process (masonry.forking).
# A FreeType font reads its file through an open file, and a forked copy shares that
# file's offset: when both processes read glyphs through fonts made before the fork, each
# moves the other's offset and a glyph loads from the wrong bytes ("failed to load
# glyph"). matplotlib forgets its fonts in the child; mathtext's parses (the arrow
# markers) keep theirs, so the child forgets those too and opens its own.
if hasattr(os, "register_at_fork"):  # not on Windows, which does not fork
    os.register_at_fork(after_in_child=mathtext.MathTextParser._parse_cached.cache_clear)

from masonry.plots.azimuths import azimuths_png  # noqa: E402
from masonry.plots.colours import (  # noqa: E402
    BAR_3D, COLOUR_PERCENTILE, DIVERGING, ONE_SIDED, SEQUENTIAL, colour_scale, force_unit)
from masonry.plots.common import (  # noqa: E402
    ANGLE, CLASS_COLOURS, ELEVATIONS, HORIZONTAL_KINDS, NO_FILL, PNG, VIEWS, Render, as_files,
    figure_files)
from masonry.plots.convergence import convergence_png  # noqa: E402
from masonry.plots.failure import RANKED, failure_png  # noqa: E402
from masonry.plots.forces import (  # noqa: E402
    FORCE_LABELS, FORCE_PLOTS, adhesion_pngs, force_pngs, interface_pngs)
from masonry.plots.mechanism import MECHANISM_SCALE, mechanism_pngs  # noqa: E402
from masonry.plots.pattern import pattern_png  # noqa: E402
from masonry.plots.stages import (  # noqa: E402
    FRESH_MORTAR_KPA, MARK_DECADES, OUTLINE_COLOUR, marked_structure_pngs,
    stage_adhesion_png, stage_chart_png)
from masonry.plots.structure import structure_pngs  # noqa: E402
from masonry.plots.thrust import HINGE_ECCENTRICITY, thrust_line_png  # noqa: E402

__all__ = [
    "ANGLE", "BAR_3D", "CLASS_COLOURS", "COLOUR_PERCENTILE", "DIVERGING", "ELEVATIONS",
    "FORCE_LABELS", "FORCE_PLOTS", "FRESH_MORTAR_KPA", "HINGE_ECCENTRICITY",
    "HORIZONTAL_KINDS", "MARK_DECADES", "MECHANISM_SCALE", "NO_FILL", "ONE_SIDED",
    "OUTLINE_COLOUR", "PNG", "RANKED", "Render", "SEQUENTIAL", "VIEWS", "adhesion_pngs", "as_files",
    "azimuths_png", "figure_files", "colour_scale", "convergence_png", "failure_png", "force_pngs",
    "force_unit", "interface_pngs", "marked_structure_pngs", "mechanism_pngs", "pattern_png",
    "stage_adhesion_png", "stage_chart_png", "structure_pngs", "thrust_line_png",
]
