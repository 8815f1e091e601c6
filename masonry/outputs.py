"""What a run writes, declared (:mod:`masonry.parameters`): which outputs, at what size
and detail, and where the CAD files put the bricks."""

from dataclasses import dataclass

from masonry.parameters import check_fields, declare


@dataclass(frozen=True)
class Outputs:
    """The outputs a run writes besides its results.

    ``plots`` the figures; ``quick`` draws them in one view at lower resolution;
    ``printable`` the printable body (``dome.stl``, ``dome.obj``); ``print_size`` also
    writes it as ``dome.3mf`` of that size in millimetres; ``html`` the page
    ``dome.html`` (the bricks in 3D in a browser); ``cad_offset`` moves every brick of the
    CAD files inward by that many units (thesis 3.4.1).
    """

    plots: bool = declare(True, "write the figures", kind="bool")
    quick: bool = declare(False, "one view, lower resolution", kind="bool")
    printable: bool = declare(True, "write the printable body", kind="bool")
    print_size: float | None = declare(
        None, "mm, largest dimension of dome.3mf (None: no 3MF)", low=1.0, high=1e4,
        optional=True, expected="1 to 10000 (millimetres, the largest dimension of "
                                "dome.3mf: printers' beds are 100 to 1000 mm)")
    html: bool = declare(True, "write dome.html, the bricks in 3D in a browser", kind="bool")
    cad_offset: float = declare(1.0, "units the CAD files move each brick inward", low=0.0,
                                high=4.0, expected="0 to 4 (units)", tag="cad")

    def checked(self) -> "Outputs":
        """These outputs validated; raises :class:`~masonry.errors.ParameterError`."""
        check_fields(self)
        return self
