"""What a run writes, declared (:mod:`masonry.parameters`): which outputs, at what size
and detail, and where the CAD files put the bricks."""

from dataclasses import dataclass

from masonry.parameters import check_fields, declare

FIGURE_FORMATS = ("png", "svg", "pdf")
"""The files a figure can be written as: a raster PNG, or vector SVG and PDF (matplotlib's
own backends) for a paper."""

PLOTLY_SOURCES = ("shared", "inline")
"""Where ``dome.html`` finds plotly.js: ``shared``, one file beside the run folders in their
output root (:data:`masonry.export.html.PLOTLY_FILE`), written once for all of them;
``inline``, inside the page (4.8 MB), which then opens wherever it is copied."""

WRITTEN_OUTPUTS = ("plots", "printable", "html")
"""The switches of files a run writes or not (each the ``output`` of its exporters'
rows, :data:`masonry.export.EXPORTERS`): ``run.json``'s ``outputs`` records them as what
the run wrote, not among its parameters."""

DPI_RANGE = (50, 600)
"""Resolutions a raster figure may ask for: below 50 dpi a figure's labels do not read,
600 dpi is what a printer prints (a 7 inch figure 4,200 pixels wide)."""


def figure_formats(value):
    """``value`` as a tuple of format names, in the order given, each once: a text
    ``"png,pdf"`` or a list of names; anything else as it is (for the check to refuse)."""
    if isinstance(value, str):
        value = [value]
    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        # several given (a repeated option), each perhaps of several
        return tuple(dict.fromkeys(name.strip().lower() for v in value
                                   for name in v.split(",")))
    return value


def _are_formats(value) -> bool:
    return (isinstance(value, tuple) and len(value) > 0
            and all(v in FIGURE_FORMATS for v in value))


@dataclass(frozen=True)
class Outputs:
    """The outputs a run writes besides its results.

    ``plots`` the figures; ``quick`` draws them in one view at lower resolution;
    ``printable`` the printable body (``dome.stl``, ``dome.obj``); ``print_size`` also
    writes it as ``dome.3mf`` of that size in millimetres; ``figure_format`` the files each figure is
    written as (:data:`FIGURE_FORMATS`); ``dpi`` a raster figure's resolution (None: each
    figure's own, 110 dots per inch for most); ``html`` the page
    ``dome.html`` (the bricks in 3D in a browser; None: with the figures,
    :attr:`writes_html`); ``html_plotly`` where the page finds plotly.js
    (:data:`PLOTLY_SOURCES`); ``cad_offset`` moves every brick of the
    CAD files inward by that many units (thesis 3.4.1).
    """

    plots: bool = declare(True, "write the figures", kind="bool", off_help="skip all plots")
    quick: bool = declare(False, "one view, lower resolution", kind="bool",
                          help="the figures in one view at lower resolution (also with "
                               "--fast)")
    printable: bool = declare(True, "write the printable body", kind="bool",
                              off_help="skip the printable body (dome.stl, dome.obj)")
    print_size: float | None = declare(
        None, "mm, largest dimension of dome.3mf (None: no 3MF)", low=1.0, high=1e4,
        optional=True, expected="1 to 10000 (millimetres, the largest dimension of "
                                "dome.3mf: printers' beds are 100 to 1000 mm)",
        metavar="MM", help="also write dome.3mf for a slicer, in millimetres, its largest "
                           "dimension MM (1 to 10000; default: no 3MF)")
    figure_format: tuple = declare(
        ("png",), "the files each figure is written as", kind="any", check=_are_formats,
        expected=f"one or more of {', '.join(FIGURE_FORMATS)}, separated by commas",
        metavar="|".join(FIGURE_FORMATS), repeat=True,
        help="the files of every figure: png (raster), svg or pdf (vector, text as text, "
             "for a paper); several separated by commas or the option repeated (default "
             "png)")
    dpi: int | None = declare(
        None, "dots per inch of a PNG figure (None: each figure's own)", kind="int",
        low=DPI_RANGE[0], high=DPI_RANGE[1], optional=True,
        expected=f"an integer {DPI_RANGE[0]} to {DPI_RANGE[1]} (dots per inch)",
        metavar="N", help=f"dots per inch of the PNG figures, {DPI_RANGE[0]} to "
                          f"{DPI_RANGE[1]} (default: each figure's own, 110 for most, 130 "
                          f"to 150 for the pattern, the whole dome and the thrust line; "
                          f"lower with --fast)")
    html: bool | None = declare(
        None, "write dome.html, the bricks in 3D in a browser (None: with the figures)",
        kind="bool", optional=True,
        help="write dome.html (the bricks in 3D, for a browser) also with --no-plots "
             "(default: with the figures)",
        off_help="skip dome.html (default: with the figures)")
    html_plotly: str = declare(
        "shared", "where dome.html finds plotly.js: one file beside the run folders, or "
                  "inside the page", kind="str", choices=PLOTLY_SOURCES,
        help="where dome.html finds plotly.js: shared, one file beside the run folders, "
             "written once per --out (the default); inline, inside the page (4.8 MB "
             "more), which then opens wherever it is copied")
    cad_offset: float = declare(1.0, "units the CAD files move each brick inward", low=0.0,
                                high=4.0, expected="0 to 4 (units)", tag="cad",
                                metavar="UNITS",
                                help="units the CAD files (locations.csv, dome.stl, "
                                     "dome.obj, dome.3mf) move each brick inward along its "
                                     "normal (0 to 4; default 1; thesis 3.4.1)")

    def __post_init__(self):
        # "png,pdf" (a command line, the API) or ["png", "pdf"] (TOML) alike
        object.__setattr__(self, "figure_format", figure_formats(self.figure_format))

    @property
    def writes_html(self) -> bool:
        """Whether the run writes ``dome.html``: as ``html`` says, else with the
        figures."""
        return self.plots if self.html is None else self.html

    def checked(self) -> "Outputs":
        """These outputs validated; raises :class:`~masonry.errors.ParameterError`."""
        check_fields(self)
        return self
