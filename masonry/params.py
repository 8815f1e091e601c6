"""Parameters, modes, presets and the structure id (SPEC 3).

Every input of a run is a field of :class:`Params`. :func:`validate` checks them all
before any work starts; a bad value raises one :class:`ParameterError` that names the
parameter, the value and the valid range.
"""

import dataclasses
import logging
import math
import tomllib
from dataclasses import dataclass

from masonry.tolerances import STRETCH_USUAL_RANGE

log = logging.getLogger(__name__)

SCENES = ("section", "wall", "dome", "assembly", "arch")
FRICTIONS = ("net", "plus", "auto")
BOUNDARIES = ("free", "rigid", "cyclic")
# QP solvers (masonry.rbe.solvers.BACKENDS) and accuracy presets (masonry.rbe.solve.ACCURACY)
SOLVERS = ("newton", "interior", "clarabel", "osqp", "clarabel-cvxpy", "osqp-cvxpy")
ACCURACIES = ("fast", "balanced", "accurate")
ARCH_SHAPES = ("semicircular", "pointed", "segmental")

PRESETS = {
    # SPEC 3 / thesis 3.4.1: the three structures of the thesis
    "1": dict(stretch=1.0, n=8, r=1, p=10, cut=0.1),
    "2": dict(stretch=2.0, n=6, r=1, p=8, cut=0.05),
    "3": dict(stretch=0.8, n=4, r=1, p=13, cut=0.01),
    # thesis 3.3.6 straight wall test: 10 courses of 8 regular bricks, about 12.5 kN
    "wall": dict(scene="wall", wall_length=32.0, wall_courses=10),
}


class ParameterError(ValueError):
    """A parameter is out of its valid range. The message names parameter, value, range."""

    def __init__(self, name, value, expected):
        super().__init__(f"invalid parameter {name}={value!r}: expected {expected}")
        self.name = name
        self.value = value
        self.expected = expected


@dataclass(frozen=True)
class Params:
    """All inputs of a run.

    Geometry (units of ``unit`` metres unless stated): ``stretch`` dome height /
    circumradius; ``n`` walls of the polygonal dome; ``r`` full rhombi across the section;
    ``p`` pattern bricks per rhombus side; ``cut`` fraction of the height cut off at the
    top; ``unit`` brick unit in metres; ``min_fill`` shortest fill-in brick (units).
    Scene: ``scene`` (section, wall, dome, ...), ``boundary`` of a section (free, rigid,
    cyclic), ``wall_length`` (units) and ``wall_courses`` for the wall scene.
    Arch scene (metres, :mod:`masonry.scenes.arch`): ``arch_blocks`` voussoirs, ``arch_span`` and
    ``arch_rise`` (None: the shape's default) of the centre line, ``arch_thickness``,
    ``arch_depth`` (along y), ``arch_shape``. Assembly scene: ``assembly``, the name of
    the imported model (``<file stem>_<content hash>``, set by ``masonry analyze``).
    Analysis: ``mu`` friction coefficient, ``density`` kg/m^3, ``friction`` net | plus |
    auto, ``accuracy`` solver preset (fast | balanced | accurate; None: fast in fast
    mode, else balanced, SPEC 3), ``solver`` (None: the preset's; a name overrides it).
    Output: ``fast`` (one view, low resolution), ``cad_offset`` (units), ``print_size``
    (mm: the largest dimension of ``dome.3mf``; None writes no 3MF).
    """

    stretch: float = 1.0
    n: int = 8
    r: int = 1
    p: int = 10
    cut: float = 0.1
    unit: float = 0.1
    min_fill: float = 1.0
    scene: str = "section"
    boundary: str = "free"
    wall_length: float = 32.0
    wall_courses: int = 10
    mu: float = 0.7
    density: float = 2000.0
    friction: str = "auto"
    accuracy: str | None = None
    solver: str | None = None
    fast: bool = False
    cad_offset: float = 1.0
    print_size: float | None = None
    arch_blocks: int = 16
    arch_span: float = 10.0
    arch_thickness: float = 0.6
    arch_depth: float = 1.0
    arch_shape: str = "semicircular"
    arch_rise: float | None = None
    assembly: str = ""

    def replace(self, **changes) -> "Params":
        return dataclasses.replace(self, **changes)

    @property
    def solver_accuracy(self) -> str:
        """The accuracy preset a run uses: ``accuracy``, else ``fast`` in fast mode (SPEC
        3), else ``balanced``."""
        if self.accuracy is not None:
            return self.accuracy
        return "fast" if self.fast else "balanced"

    @property
    def geometry_key(self) -> dict:
        """The inputs that decide the geometry and interfaces (the cache key)."""
        if self.scene == "wall":
            keys = ("scene", "wall_length", "wall_courses", "unit")
        elif self.scene == "arch":
            keys = ("scene", "arch_blocks", "arch_span", "arch_thickness", "arch_depth",
                    "arch_shape", "arch_rise")
        else:
            keys = ("scene", "stretch", "n", "r", "p", "cut", "unit", "min_fill", "boundary")
        return {k: getattr(self, k) for k in keys}


def from_preset(name, **overrides) -> Params:
    """Parameters of a preset (``1``, ``2``, ``3`` or ``wall``) with overrides."""
    key = str(name)
    if key not in PRESETS:
        raise ParameterError("preset", name, f"one of {', '.join(PRESETS)}")
    return validate(Params(**{**PRESETS[key], **overrides}))


def load(path, **overrides) -> Params:
    """Parameters from a TOML file of ``Params`` fields (e.g. ``fixtures/presets/*.toml``)."""
    with open(path, "rb") as f:
        data = tomllib.load(f)
    data = data.get("params", data)
    unknown = set(data) - {f.name for f in dataclasses.fields(Params)}
    if unknown:
        raise ParameterError("file", str(path), f"only Params fields, not {sorted(unknown)}")
    return validate(Params(**{**data, **overrides}))


def _check(name, value, ok, expected):
    if not ok:
        raise ParameterError(name, value, expected)


def _number(name, value, integer=False):
    kinds = (int,) if integer else (int, float)
    if isinstance(value, bool) or not isinstance(value, kinds):
        raise ParameterError(name, value, "an integer" if integer else "a number")
    if not math.isfinite(value):
        raise ParameterError(name, value, "a finite number")
    return value


def validate(params: Params) -> Params:
    """Check every parameter; return ``params`` or raise :class:`ParameterError`."""
    p = params
    _check("scene", p.scene, p.scene in SCENES, f"one of {', '.join(SCENES)}")
    _check("boundary", p.boundary, p.boundary in BOUNDARIES, f"one of {', '.join(BOUNDARIES)}")
    _check("friction", p.friction, p.friction in FRICTIONS, f"one of {', '.join(FRICTIONS)}")
    _check("solver", p.solver, p.solver is None or p.solver in SOLVERS,
           f"one of {', '.join(SOLVERS)}")
    _check("accuracy", p.accuracy, p.accuracy is None or p.accuracy in ACCURACIES,
           f"one of {', '.join(ACCURACIES)}")
    _check("stretch", p.stretch, _number("stretch", p.stretch) > 0, "> 0")
    _check("n", p.n, _number("n", p.n, integer=True) >= 3, "an integer >= 3")
    _check("r", p.r, _number("r", p.r, integer=True) >= 0, "an integer >= 0")
    _check("p", p.p, _number("p", p.p, integer=True) >= 1, "an integer >= 1")
    _check("cut", p.cut, 0 <= _number("cut", p.cut) < 1, "0 <= cut < 1")
    _check("unit", p.unit, _number("unit", p.unit) > 0, "> 0 (metres)")
    _check("min_fill", p.min_fill, 0 < _number("min_fill", p.min_fill) <= 4,
           "0 < min_fill <= 4 (units)")
    _check("mu", p.mu, _number("mu", p.mu) > 0, "> 0")
    _check("density", p.density, _number("density", p.density) > 0, "> 0 (kg/m^3)")
    _check("cad_offset", p.cad_offset, _number("cad_offset", p.cad_offset) >= 0,
           ">= 0 (units)")
    if p.print_size is not None:
        _check("print_size", p.print_size, _number("print_size", p.print_size) > 0,
               "> 0 (mm, the largest dimension of the print)")
    _check("wall_length", p.wall_length, _number("wall_length", p.wall_length) >= 4,
           ">= 4 (units, one regular brick)")
    _check("wall_courses", p.wall_courses,
           _number("wall_courses", p.wall_courses, integer=True) >= 1, "an integer >= 1")
    _check("arch_blocks", p.arch_blocks,
           _number("arch_blocks", p.arch_blocks, integer=True) >= 1, "an integer >= 1")
    for name in ("arch_span", "arch_thickness", "arch_depth"):
        _check(name, getattr(p, name), _number(name, getattr(p, name)) > 0, "> 0 (metres)")
    _check("arch_shape", p.arch_shape, p.arch_shape in ARCH_SHAPES,
           f"one of {', '.join(ARCH_SHAPES)}")
    if p.arch_rise is not None:
        _check("arch_rise", p.arch_rise, _number("arch_rise", p.arch_rise) > 0,
               "> 0 (metres) or none")
    if p.scene == "arch":
        check_arch(p)
    if p.scene == "assembly":
        _check("assembly", p.assembly, bool(p.assembly),
               "the name of an imported model (masonry analyze sets it)")
    low, high = STRETCH_USUAL_RANGE
    if p.scene in ("section", "dome") and not low <= p.stretch <= high:
        log.warning("stretch=%g is outside %g..%g: the dome is unusually flat or tall",
                    p.stretch, low, high)
    return p


def arch_radius(shape: str, span: float, rise=None) -> tuple:
    """``(R, h)``: centre-line radius and rise of an arch of ``span`` (metres).

    ``rise`` None takes the shape's default: ``span / 2`` (semicircular), ``span / 4``
    (segmental), ``span * sqrt(3) / 2`` (pointed, equilateral).
    """
    if shape == "semicircular":
        return span / 2, span / 2
    if shape == "segmental":
        h = span / 4 if rise is None else rise
        return (span**2 / 4 + h**2) / (2 * h), h
    h = span * math.sqrt(3) / 2 if rise is None else rise
    return (span**2 / 4 + h**2) / span, h


def check_arch(params: Params) -> None:
    """Refuse arch parameters that make no arch (:class:`ParameterError`).

    The ranges that do not depend on the shape are checked by
    :func:`masonry.params.validate`; here: the rise against the shape, an even number of
    voussoirs for a pointed arch, and a thickness that leaves an intrados.
    """
    p = params
    span, rise, t = p.arch_span, p.arch_rise, p.arch_thickness
    if p.arch_shape == "semicircular" and rise is not None and rise != span / 2:
        raise ParameterError("arch_rise", rise, f"none for a semicircular arch (its rise is "
                                                f"span / 2 = {span / 2:g} m)")
    if p.arch_shape == "segmental" and rise is not None and not 0 < rise < span / 2:
        raise ParameterError("arch_rise", rise, f"0 < rise < span / 2 = {span / 2:g} m for "
                                                "a segmental arch")
    if p.arch_shape == "pointed":
        if rise is not None and not rise > span / 2:
            raise ParameterError("arch_rise", rise, f"> span / 2 = {span / 2:g} m for a "
                                                    "pointed arch")
        if p.arch_blocks % 2:
            raise ParameterError("arch_blocks", p.arch_blocks, "an even number for a "
                                                               "pointed arch")
    radius, _ = arch_radius(p.arch_shape, span, rise)
    # the intrados must exist: radius R - t/2 > 0, and for a pointed arch it must still
    # reach the crown, R - t/2 > R - span/2
    limit = span if p.arch_shape == "pointed" else 2 * radius
    if not t < limit:
        raise ParameterError("arch_thickness", t, f"< {limit:g} m (the intrados of this "
                                                  f"arch vanishes at t = {limit:g} m)")


def structure_id(params: Params) -> str:
    """Name of a run's output folder, built from every input that changes the result.

    The thesis's form for defaults, e.g. ``dome0_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1``;
    inputs away from their defaults are appended (``_mu0.3``), so a run overwrites only the
    folder of an identical input.
    """
    p = params
    default = Params()
    if p.scene == "wall":
        head = f"wall_fast{int(p.fast)}_fric{p.friction}_L{p.wall_length:g}_k{p.wall_courses}"
    elif p.scene == "arch":
        head = (f"arch_fast{int(p.fast)}_fric{p.friction}_{p.arch_shape}_N{p.arch_blocks}"
                f"_s{p.arch_span:g}_t{p.arch_thickness:g}_d{p.arch_depth:g}"
                + ("" if p.arch_rise is None else f"_h{p.arch_rise:g}"))
    elif p.scene == "assembly":
        head = f"assembly_{p.assembly}_fast{int(p.fast)}_fric{p.friction}"
    else:
        mode = "fulldome" if p.scene == "dome" else f"dome{int(p.boundary != 'free')}"
        head = (f"{mode}_fast{int(p.fast)}_fric{p.friction}_s{p.stretch:g}_n{p.n}_r{p.r}"
                f"_p{p.p}_c{p.cut:g}")
    if p.scene not in ("arch", "assembly"):  # no brick unit in these scenes
        head += f"_u{p.unit:g}"
    extras = [("boundary", "b"), ("mu", "mu"), ("density", "rho"), ("min_fill", "mf"),
              ("accuracy", ""), ("solver", ""), ("cad_offset", "cad")]
    for name, tag in extras:
        value = getattr(p, name)
        if name == "boundary" and (p.scene == "wall" or value != "rigid"):
            continue  # dome0 / dome1 already say free / cyclic
        if value != getattr(default, name):
            head += f"_{tag}{value:g}" if isinstance(value, float) else f"_{tag}{value}"
    return head
