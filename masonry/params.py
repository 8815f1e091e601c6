"""Parameters, modes, presets and the structure id (SPEC 3).

Every input of a run is a field of :class:`Params`. :func:`validate` checks them all
before any work starts; a bad value raises one :class:`ParameterError` that names the
parameter, the value and the valid range.
"""

import dataclasses
import hashlib
import math
import os
import tomllib
from dataclasses import dataclass

from masonry.friction import FrictionCone, FrictionModelError
from masonry.tolerances import MIN_LIVE_LOAD_N

SCENES = ("section", "wall", "dome", "assembly", "arch")
FRICTIONS = ("net", "plus", "auto")
FRICTION_LAWS = ("associated", "non-associative")
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


SCENE_FIELDS = {
    # a parameter -> the scenes it applies to; the others ignore it
    **{name: ("section", "dome") for name in ("stretch", "n", "r", "p", "cut", "min_fill")},
    "unit": ("section", "dome", "wall"),
    "boundary": ("section",),
    "wall_length": ("wall",),
    "wall_courses": ("wall",),
    **{name: ("arch",) for name in ("arch_blocks", "arch_span", "arch_thickness",
                                    "arch_depth", "arch_shape", "arch_rise")},
}
"""The parameters that apply to some scenes only (a front end refuses them for others)."""


class ParameterError(ValueError):
    """A parameter is out of its valid range. The message names parameter, value, range.

    ``related`` names the other parameters the check depends on (a front end names the
    ones its user gave when ``name`` itself was not given); ``where`` says where the value
    was read (a file), if not from the caller.
    """

    def __init__(self, name, value, expected, *, related=(), where=None):
        super().__init__(f"invalid parameter {name}={value!r}: expected {expected}"
                         + (f" ({where})" if where else ""))
        self.name = name
        self.value = value
        self.expected = expected
        self.related = tuple(related)
        self.where = where


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
    auto, ``friction_cone`` the friction model (``circle`` | ``polygon:K`` | ``square``,
    :mod:`masonry.friction`; None: the accuracy preset's, an isotropic one), ``accuracy``
    solver preset (fast | balanced | accurate; None: fast in fast
    mode, else balanced, SPEC 3), ``solver`` (None: the preset's; a name overrides it).
    Output: ``fast`` (one view, low resolution), ``cad_offset`` (units), ``print_size``
    (mm: the largest dimension of ``dome.3mf``; None writes no 3MF).
    Live loads (SPEC 6.8, :mod:`masonry.rbe.loads`), each making the run compute a collapse
    load factor: ``lateral`` azimuth in degrees from +x toward +y of a horizontal body
    force of each block's weight, or ``'all'`` for the worst azimuth; ``point_loads``
    ``'NAME_OR_PATTERN:FX,FY,FZ'`` strings (newtons at the centre of each matched block's
    top face); ``crown_load`` newtons, downward, on the top course by brick top area. At
    most one kind per run. ``friction_law`` of the collapse load factor: ``associated``
    (the LP of SPEC 6.8) or ``non-associative`` (joints that slide without dilating: the
    estimate of :func:`masonry.rbe.collapse.fixed_capacity_factor`).
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
    friction_cone: str | None = None
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
    lateral: float | str | None = None
    point_loads: tuple = ()
    crown_load: float | None = None
    friction_law: str = "associated"

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
    def live_load_kind(self) -> str | None:
        """``'lateral'``, ``'point'``, ``'crown'`` or None: the run's live load."""
        if self.lateral is not None:
            return "lateral"
        if self.point_loads:
            return "point"
        return None if self.crown_load is None else "crown"

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
    """Parameters from a TOML file of ``Params`` fields (e.g. ``fixtures/presets/*.toml``),
    at the top level or in a ``[params]`` table; ``overrides`` win over the file.

    Raises
    ------
    ParameterError
        Named ``params`` when the file cannot be read or is not TOML; named after the key
        (with ``where`` the file) when a key is unknown or its value invalid.
    """
    data = read_toml(path, "params")
    data = data.get("params", data)
    if not isinstance(data, dict):
        raise ParameterError("params", str(path), "a file whose [params] is a table")
    known = [f.name for f in dataclasses.fields(Params)]
    for key, value in data.items():
        if key not in known:
            raise ParameterError(key, value, f"a parameter name ({', '.join(known)})",
                                 where=str(path))
    try:
        return validate(Params(**{**data, **overrides}))
    except ParameterError as error:
        if error.name not in data or error.name in overrides or error.where:
            raise
        raise ParameterError(error.name, error.value, error.expected,
                             related=error.related, where=str(path)) from None


MAX_TOML_BYTES = 2**20
"""Parameter and study files are a few hundred bytes; a larger one is not one of them."""


def read_toml(path, name) -> dict:
    """The table of a TOML file (UTF-8, a byte order mark allowed).

    Raises
    ------
    ParameterError
        Named ``name`` (the option that gave the path): the path is empty, the file is
        missing, unreadable or a folder, not UTF-8, or not TOML.
    """
    if str(path).strip() == "":
        raise ParameterError(name, str(path), "a TOML file (an empty path names nothing)")
    try:
        if os.path.exists(path) and not os.path.isfile(path):
            raise ParameterError(name, str(path), "a TOML file, not a folder or a device")
        if os.path.getsize(path) > MAX_TOML_BYTES:
            raise ParameterError(name, str(path), f"a TOML file of at most "
                                                  f"{MAX_TOML_BYTES // 2**20} MiB")
        with open(path, "rb") as f:
            text = f.read().decode("utf-8-sig")
        return tomllib.loads(text)
    except OSError as error:
        raise ParameterError(name, str(path), f"a readable TOML file "
                                              f"({error.strerror or error})") from None
    except UnicodeDecodeError as error:
        raise ParameterError(name, str(path), f"a UTF-8 text file (byte {error.start} is "
                                              f"not UTF-8)") from None
    except tomllib.TOMLDecodeError as error:
        raise ParameterError(name, str(path), f"a valid TOML file ({error})") from None


RANGES = {
    # name: (low, high, why); the extremes tests (tests/test_extremes.py) solve at the
    # ends of each range with residuals below tolerance
    "unit": (1e-3, 1e2, "metres: bricks of 1 mm to 100 m; forces scale with unit^3"),
    "density": (1.0, 1e7, "kg/m^3: forces scale with it exactly; masonry is 1500 to 3000"),
    "mu": (0.01, 10.0, "friction coefficients of masonry are 0.3 to 1; beyond these ends "
                       "the friction cones are flat or closed to the solvers' precision"),
    "stretch": (0.05, 20.0, "dome height / circumradius"),
    "arch_span": (0.01, 1e4, "metres"),
    "print_size": (1.0, 1e4, "millimetres, the largest dimension of dome.3mf: printers' "
                             "beds are 100 to 1000 mm"),
}
"""Physically meaningful and numerically safe ranges, checked by :func:`validate`."""

ARCH_RATIOS = {
    # name: (low, high) as multiples of the span: the interface detector's tolerances are
    # relative to the scene's size (1e-6), so a part 1e-9 of it would vanish in them
    "arch_thickness": (1e-3, None),
    "arch_depth": (1e-3, 1e3),
    "arch_rise": (1e-2, 1e2),
}


MAX_INTEGER = 10**12
"""No count of anything here comes near it; larger integers would overflow floats."""


def _check(name, value, ok, expected):
    if not ok:
        raise ParameterError(name, value, expected)


def _number(name, value, integer=False):
    kinds = (int,) if integer else (int, float)
    if isinstance(value, bool) or not isinstance(value, kinds):
        raise ParameterError(name, value, "an integer" if integer else "a number")
    if not math.isfinite(value):
        raise ParameterError(name, value, "a finite number")
    if integer and abs(value) > MAX_INTEGER:
        raise ParameterError(name, value, f"an integer of at most {MAX_INTEGER:.0e}")
    return value


def parse_point_load(spec: str) -> tuple:
    """``'NAME_OR_PATTERN:FX,FY,FZ'`` -> ``(pattern, (fx, fy, fz))`` in newtons; raises
    :class:`ParameterError` naming ``point_loads`` (``--point-load``)."""
    expected = "NAME_OR_PATTERN:FX,FY,FZ (a block name or fnmatch pattern, newtons)"
    pattern, colon, numbers = str(spec).rpartition(":")
    parts = numbers.split(",")
    if not colon or not pattern or len(parts) != 3:
        raise ParameterError("point_loads", spec, expected)
    try:
        force = tuple(float(v) for v in parts)
    except ValueError:
        raise ParameterError("point_loads", spec, expected) from None
    if not all(math.isfinite(v) for v in force) or not any(force):
        raise ParameterError("point_loads", spec, "finite forces, not all zero")
    if max(abs(v) for v in force) < MIN_LIVE_LOAD_N:
        raise ParameterError("point_loads", spec, f"a force of at least {MIN_LIVE_LOAD_N:g} "
                                                  "N (a smaller one has no finite load "
                                                  "factor)")
    return pattern, force


def _live_loads(p: Params) -> Params:
    """Check the live-load fields (SPEC 6.8); return them normalised (``lateral`` a float
    or ``'all'``, ``point_loads`` a tuple)."""
    lateral = p.lateral
    if isinstance(lateral, str) and lateral != "all":
        try:
            lateral = float(lateral)
        except ValueError:
            raise ParameterError("lateral", p.lateral,
                                 "an azimuth in degrees or 'all'") from None
    if lateral is not None and lateral != "all":
        _check("lateral", p.lateral, isinstance(lateral, (int, float))
               and not isinstance(lateral, bool), "an azimuth in degrees or 'all'")
        lateral = float(_number("lateral", lateral)) % 360.0
    specs = p.point_loads
    specs = (specs,) if isinstance(specs, str) else specs
    _check("point_loads", p.point_loads, isinstance(specs, (tuple, list))
           and all(isinstance(spec, str) for spec in specs),
           "NAME_OR_PATTERN:FX,FY,FZ strings")
    specs = tuple(specs)
    for spec in specs:
        parse_point_load(spec)
    if p.crown_load is not None:
        _check("crown_load", p.crown_load,
               _number("crown_load", p.crown_load) >= MIN_LIVE_LOAD_N,
               f">= {MIN_LIVE_LOAD_N:g} (newtons, downward; a smaller load has no finite "
               f"load factor)")
        _check("crown_load", p.crown_load, p.scene in ("section", "dome"),
               "a dome: --scene section or dome")
    given = [(name, value) for name, value, present in (
        ("lateral", p.lateral, lateral is not None), ("point_loads", specs and specs[0],
                                                      bool(specs)),
        ("crown_load", p.crown_load, p.crown_load is not None)) if present]
    if len(given) > 1:
        raise ParameterError(*given[1], "one live load per run: --lateral, --point-load "
                                        "or --crown-load", related=(given[0][0],))
    _choice("friction_law", p.friction_law, FRICTION_LAWS)
    if p.friction_law != "associated" and (not given or lateral == "all"):
        raise ParameterError("friction_law", p.friction_law, "associated without a live "
                             "load or with --lateral all (the estimate is of one load "
                             "case: --lateral AZIMUTH, --point-load or --crown-load)")
    if p.scene == "section" and p.boundary == "cyclic" and (lateral is not None or specs):
        # one web with the load repeated in every web is not the asked load case
        raise ParameterError("lateral" if lateral is not None else "point_loads",
                             p.lateral if lateral is not None else specs[0],
                             "a symmetric load on a cyclic section: this load breaks the "
                             "dome's rotational symmetry; use --scene dome")
    return dataclasses.replace(p, lateral=lateral, point_loads=specs)


POLYHEDRAL_SOLVERS = ("osqp", "osqp-cvxpy")
"""QP solvers that take linear constraints only (the pyramids, not the circle)."""


def _friction_cone(p: Params) -> Params:
    """Check ``friction_cone`` (and that the solver can state it); return it in its
    canonical spelling."""
    if p.friction_cone is None:
        if p.solver in POLYHEDRAL_SOLVERS:
            raise ParameterError("solver", p.solver, "a solver of Coulomb's cone (the "
                                 "default friction model): newton, interior, clarabel or "
                                 "clarabel-cvxpy; or a pyramid: --friction-cone polygon:16")
        return p
    try:
        cone = FrictionCone.parse(p.friction_cone)
    except FrictionModelError as error:
        raise ParameterError("friction_cone", p.friction_cone, str(error)) from None
    if p.solver in POLYHEDRAL_SOLVERS and not cone.is_polyhedral:
        raise ParameterError("friction_cone", p.friction_cone, f"a pyramid (polygon:K or "
                             f"square) with --solver {p.solver}, which takes linear "
                             f"constraints only", related=("solver",))
    return dataclasses.replace(p, friction_cone=cone.name)


def _choice(name, value, choices, optional=False):
    if optional and value is None:
        return
    if not isinstance(value, str) or value not in choices:
        raise ParameterError(name, value, f"one of {', '.join(choices)}")


def _in_range(p: Params, name):
    low, high, why = RANGES[name]
    value = _number(name, getattr(p, name))
    _check(name, value, low <= value <= high, f"{low:g} to {high:g} ({why})")


def validate(params: Params) -> Params:
    """Check every parameter; return ``params`` (live loads normalised) or raise
    :class:`ParameterError`."""
    p = _live_loads(params)
    _choice("scene", p.scene, SCENES)
    _choice("boundary", p.boundary, BOUNDARIES)
    _choice("friction", p.friction, FRICTIONS)
    _choice("solver", p.solver, SOLVERS, optional=True)
    _choice("accuracy", p.accuracy, ACCURACIES, optional=True)
    p = _friction_cone(p)
    _choice("arch_shape", p.arch_shape, ARCH_SHAPES)
    _check("fast", p.fast, isinstance(p.fast, bool), "true or false")
    _check("assembly", p.assembly, isinstance(p.assembly, str), "a name")
    for name in ("unit", "density", "mu", "stretch", "arch_span"):
        _in_range(p, name)
    _check("n", p.n, _number("n", p.n, integer=True) >= 3, "an integer >= 3")
    _check("r", p.r, _number("r", p.r, integer=True) >= 0, "an integer >= 0")
    _check("p", p.p, _number("p", p.p, integer=True) >= 1, "an integer >= 1")
    _check("cut", p.cut, 0 <= _number("cut", p.cut) < 1, "0 <= cut < 1")
    _check("min_fill", p.min_fill, 0 < _number("min_fill", p.min_fill) <= 4,
           "0 < min_fill <= 4 (units)")
    _check("cad_offset", p.cad_offset, 0 <= _number("cad_offset", p.cad_offset) <= 4,
           "0 to 4 (units)")
    if p.print_size is not None:
        _in_range(p, "print_size")
    _check("wall_length", p.wall_length, _number("wall_length", p.wall_length) >= 4,
           ">= 4 (units, one regular brick)")
    _check("wall_courses", p.wall_courses,
           _number("wall_courses", p.wall_courses, integer=True) >= 1, "an integer >= 1")
    _check("arch_blocks", p.arch_blocks,
           _number("arch_blocks", p.arch_blocks, integer=True) >= 2,
           "an integer >= 2 (one voussoir is no arch, and a semicircular one is not convex)")
    for name in ("arch_thickness", "arch_depth"):
        _check(name, getattr(p, name), _number(name, getattr(p, name)) > 0, "> 0 (metres)")
    if p.arch_rise is not None:
        _check("arch_rise", p.arch_rise, _number("arch_rise", p.arch_rise) > 0,
               "> 0 (metres) or none")
    if p.scene == "arch":
        check_arch(p)
    if p.scene == "assembly":
        _check("assembly", p.assembly, bool(p.assembly),
               "the name of an imported model (masonry analyze sets it)")
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
    :func:`masonry.params.validate`; here: thickness, depth and rise against the span
    (:data:`ARCH_RATIOS`), the rise against the shape, an even number of voussoirs for a
    pointed arch, and a thickness that leaves an intrados.
    """
    p = params
    span, rise, t = p.arch_span, p.arch_rise, p.arch_thickness
    for name, (low, high) in ARCH_RATIOS.items():
        value = getattr(p, name)
        if value is None:
            continue
        if value < low * span or (high is not None and value > high * span):
            bounds = f"{low:g} to {high:g}" if high is not None else f"at least {low:g}"
            raise ParameterError(name, value, f"{bounds} times the span ({span:g} m): the "
                                              "contact tolerances are relative to the arch's "
                                              "size", related=("arch_span",))
    if p.arch_shape == "semicircular" and rise is not None and rise != span / 2:
        raise ParameterError("arch_rise", rise, f"none for a semicircular arch (its rise is "
                                                f"span / 2 = {span / 2:g} m)",
                             related=("arch_shape",))
    if p.arch_shape == "segmental" and rise is not None and not 0 < rise < span / 2:
        raise ParameterError("arch_rise", rise, f"0 < rise < span / 2 = {span / 2:g} m for "
                                                "a segmental arch",
                             related=("arch_span", "arch_shape"))
    if p.arch_shape == "pointed":
        if rise is not None and not rise > span / 2:
            raise ParameterError("arch_rise", rise, f"> span / 2 = {span / 2:g} m for a "
                                                    "pointed arch",
                                 related=("arch_span", "arch_shape"))
        if p.arch_blocks % 2:
            raise ParameterError("arch_blocks", p.arch_blocks, "an even number for a "
                                                               "pointed arch",
                                 related=("arch_shape",))
    radius, _ = arch_radius(p.arch_shape, span, rise)
    # the intrados must exist: radius R - t/2 > 0, and for a pointed arch it must still
    # reach the crown, R - t/2 > R - span/2
    limit = span if p.arch_shape == "pointed" else 2 * radius
    if not t < limit:
        raise ParameterError("arch_thickness", t, f"< {limit:g} m (the intrados of this "
                                                  f"arch vanishes at t = {limit:g} m)",
                             related=("arch_span", "arch_shape", "arch_rise"))


def structure_id(params: Params) -> str:
    """Name of a run's output folder, built from every input that changes the result.

    The thesis's form for defaults, e.g. ``dome0_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1``;
    inputs away from their defaults are appended (``_mu0.3``), so a run overwrites only the
    folder of an identical input.
    """
    p = params
    default = Params()
    if p.scene == "wall":
        head = f"wall_fast{int(p.fast)}_fric{p.friction}_L{_n(p.wall_length)}_k{p.wall_courses}"
    elif p.scene == "arch":
        head = (f"arch_fast{int(p.fast)}_fric{p.friction}_{p.arch_shape}_N{p.arch_blocks}"
                f"_s{_n(p.arch_span)}_t{_n(p.arch_thickness)}_d{_n(p.arch_depth)}"
                + ("" if p.arch_rise is None else f"_h{_n(p.arch_rise)}"))
    elif p.scene == "assembly":
        head = f"assembly_{p.assembly}_fast{int(p.fast)}_fric{p.friction}"
    else:
        mode = "fulldome" if p.scene == "dome" else f"dome{int(p.boundary != 'free')}"
        head = (f"{mode}_fast{int(p.fast)}_fric{p.friction}_s{_n(p.stretch)}_n{p.n}_r{p.r}"
                f"_p{p.p}_c{_n(p.cut)}")
    if p.scene not in ("arch", "assembly"):  # no brick unit in these scenes
        head += f"_u{_n(p.unit)}"
    extras = [("boundary", "b"), ("mu", "mu"), ("density", "rho"), ("min_fill", "mf"),
              ("friction_cone", "cone"), ("accuracy", ""), ("solver", ""),
              ("cad_offset", "cad")]
    for name, tag in extras:
        value = getattr(p, name)
        if name == "boundary" and (p.scene == "wall" or value != "rigid"):
            continue  # dome0 / dome1 already say free / cyclic
        if value != getattr(default, name):
            text = _n(value) if isinstance(value, float) else str(value).replace(":", "")
            head += f"_{tag}{text}"
    return head + _live_load_tag(p) + _friction_law_tag(p)


def _live_load_tag(p: Params) -> str:
    """Structure id suffix of the live load: ``_latall``, ``_lat30``, ``_crown500``, or
    ``_pl`` and a digest of the point loads (they can be long)."""
    if p.lateral is not None:
        return "_latall" if p.lateral == "all" else f"_lat{_n(p.lateral)}"
    if p.crown_load is not None:
        return f"_crown{_n(p.crown_load)}"
    if p.point_loads:
        digest = hashlib.sha1("\n".join(p.point_loads).encode()).hexdigest()[:8]
        return f"_pl{digest}"
    return ""


def _n(value: float) -> str:
    """A number in a structure id: ``%g`` (``0.1``, ``1``, ``1e-05``) where that is the
    value to 15 significant digits, else those 15 digits, trailing zeros dropped
    (``2011.8216``: ``%g`` would give ``2011.82``, the name of another input). Fifteen
    tell any two decimal inputs apart, and name ``0.1 + 0.2`` as ``0.3``."""
    value = float(f"{value:.15g}")
    short = f"{value:g}"
    return short if float(short) == value else f"{value:.15g}"


def _friction_law_tag(p: Params) -> str:
    """Structure id suffix of the collapse's friction law: none for associated."""
    return "" if p.friction_law == "associated" else "_nonassoc"
