"""The one place for tolerances, thresholds and physical constants.

Every length tolerance is relative to the scene's size (the diagonal of its bounding box),
so a model built with ``unit=0.001`` and one built with ``unit=100`` are treated alike.
Pass a :class:`Tolerances` explicitly; never hard-code a tolerance in a stage.

The module constants below are thresholds that are not lengths (angles, sines, ratios,
positions counted in brick units), so they do not scale with the scene; each says which
stage compares against it. Solver settings live with their solver
(:mod:`masonry.rbe.solve`, :mod:`masonry.rbe.solvers`).
"""

from dataclasses import dataclass

import numpy as np

G = 9.81
"""Gravitational acceleration, m/s^2 (docs/model.md 2)."""

MAX_BRICKS = 50_000
"""Largest model built without being asked (``--max-bricks``): a run of that many bricks
that stands takes about 3 GiB at the balanced preset (:data:`BYTES_PER_BRICK`)."""

BYTES_PER_BRICK = {"fast": 64e3, "balanced": 64e3, "accurate": 106e3}
"""Peak memory of a run (``masonry run`` without plots, ``masonry bench --scale``: its
largest process) of a structure that stands, per brick by accuracy preset (every one of
:data:`masonry.rbe.accuracy.ACCURACY`), beyond :data:`RUN_BYTES`. Fitted to preset 1's
full dome (1,664 to 31,712 bricks) and a running-bond wall (1,025 to 100,250 bricks) at
the balanced preset, within 22 % of every row; the fast and accurate presets measured
on preset 1's full dome at 13,680 bricks (0.81 and 1.45 GiB, balanced 0.81 GiB;
docs/bench.md, "How time and memory grow"). One that cannot stand takes more: 8.2 GiB,
214 kB a brick, for preset 1's 41,072-brick dome when Clarabel decided it
(docs/scale.md)."""

RUN_BYTES = 100e6
"""Peak memory of a run besides its bricks': Python, numpy, scipy and the solvers
(0.16 GiB at 1,025 bricks)."""

UNITS_PER_BRICK = 2.7
"""Intrados area of a dome section per brick, in square units, for the first size
estimate made before building (:func:`masonry.scenes.polygonal.intrados_bricks`): 2.0
to 3.7 on the presets and their extremes (pattern and fill-in bricks are smaller than
regular ones, and the share of them falls as p grows)."""

COUNTED_BRICKS = 100_000
"""A polygonal dome's web that :data:`UNITS_PER_BRICK` puts at no more bricks than this
is counted from its plan before it is built (:func:`masonry.scenes.polygonal.web_bricks`):
exactly, at a cost that grows with the web (docs/bench.md, "The size check"); a larger
web keeps the first estimate."""

REVOLUTION_UNITS_PER_BRICK = 4.17
BRICKS_PER_COURSE_AND_NODE = 1.53
"""The size estimate of a dome of revolution (:func:`masonry.scenes.revolution.
intrados_bricks`): intrados area in square units per brick (a regular brick's is 4) and
the bricks added per course and start node (pattern bricks and the fill-ins beside
them); fitted to domes of radius 20 to 60 units, p 2 to 10, both helices, where the
estimate is within 6 % of the bricks built."""

PATTERN_CHECKED_BRICKS = 2e6
"""A dome of revolution estimated larger is not laid out to check its oculus when its
inputs are checked (:func:`masonry.scenes.revolution.check_revolution`): the layout takes
time and memory in proportion to the bricks, and a dome this large is refused by its size
first unless ``--max-bricks`` allows it, in which case its build checks it."""

UNITS_PER_PLAIN_BRICK = 3.8
"""The same for a plain dome (docs/model.md 4.9), whose courses are regular bricks but for
their ends: 3.76 to 3.89 on the presets."""

TENSION_REPORTED_REL = 1e-6
"""An interface's tension counts as tension in ``RBE/tension_top.csv`` above this fraction
of the structure's weight; below, it is the solver's tolerance (a feasible structure's
tensions are of the order of its residual, 1e-5 relative in the balanced preset, spread
over thousands of interfaces)."""

ACCEPT_RESIDUAL = 1e-5
"""The acceptance tolerance of the analyses: a returned point counts as a solution when
its relative equilibrium residual ``||A_eq x + f||_inf / ||f||_inf`` (and, for the rigid
block equilibrium, its friction violation per reference weight) is at most this, recomputed
from the matrices whatever the solver says. :attr:`Tolerances.residual` and the balanced
accuracy preset (:data:`masonry.rbe.accuracy.ACCURACY`) take it for the rigid block
equilibrium; the collapse load factor's interior point method stops when its primal rows
meet it (:class:`masonry.rbe.solvers.interior_lp.LoadFactorOptions`), and Clarabel's
"almost solved" collapse points are kept when they do
(:mod:`masonry.rbe.solvers.direct_clarabel`). The fast and accurate presets trade it
for 1e-4 and 1e-6."""


@dataclass(frozen=True)
class Tolerances:
    """Named, documented tolerances.

    Parameters
    ----------
    scale : float
        Scene size in metres (bounding box diagonal). Length tolerances scale with it.
    contact_rel : float
        Two faces touch when their polygons are within ``contact_rel * scale`` of each
        other (docs/model.md 5, default 1e-6).
    max_gap_angle : float
        Largest wedge angle (radians) between two faces that gap closing rotates shut;
        faces whose outward normals are farther from anti-parallel are not in contact
        (docs/model.md 5, default 10 degrees).
    min_area_rel : float
        An interface is kept when its area exceeds ``min_area_rel`` times the smaller of
        the two faces' areas (docs/model.md 5, default 1e-4).
    length_rel : float
        Generic geometric tolerance (point coincidence, coplanarity), relative to
        ``scale``.
    residual : float
        Largest accepted relative equilibrium residual ``||A x + f||_inf / ||f||_inf``
        and relative friction violation for a result to count as solved
        (:data:`ACCEPT_RESIDUAL`).
    """

    scale: float = 1.0
    contact_rel: float = 1e-6
    max_gap_angle: float = float(np.radians(10.0))
    min_area_rel: float = 1e-4
    length_rel: float = 1e-9
    residual: float = ACCEPT_RESIDUAL

    @property
    def contact(self) -> float:
        """Contact distance in metres."""
        return self.contact_rel * self.scale

    @property
    def length(self) -> float:
        """Point coincidence distance in metres."""
        return self.length_rel * self.scale

    @classmethod
    def for_points(cls, points, **kwargs) -> "Tolerances":
        """Tolerances scaled to the bounding box of ``points`` ((n, 3) float, metres)."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        scale = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
        return cls(scale=scale if scale > 0 else 1.0, **kwargs)


# ---------------------------------------------------------------------- inputs
STRETCH_USUAL_RANGE = (0.2, 5.0)
"""Dome height over circumradius outside this range is accepted with a warning, logged
once when such a dome is built (:func:`masonry.scenes.polygonal.build_web`): the
thesis's structures have 0.8 to 2.0, and beyond the range the dome is unusually flat or
tall. (The range refused outright is declared with ``stretch`` in
:mod:`masonry.scenes.polygonal`.)"""

MIN_LIVE_LOAD_N = 1e-9
"""Newtons. A point or crown load smaller than this is refused: its collapse load factor
(the dead load's weight over the load) passes 1e13 for a 0.1 m brick and overflows to
infinity below about 1e-300 N; no structure is asked about a nanonewton."""

MAX_LIVE_LOAD_N = 1e18
"""Newtons. A point or crown load larger than this is refused: the squares of forces of
1e154 N and more overflow. The programs take a live load at the dead load's size (the
factor scales back), so a block tips at its lever ratio under 1e15 N as under 100 N
(tests/test_collapse.py); 1e18 N is the weight of a hundred trillion tonnes."""

# ---------------------------------------------------------------------- model (dome/)
UNIT_SLACK = 1e-9
"""Brick units. Positions along the flattened section (pattern cells, joints, the
course half widths ``W_k``, piece lengths) that are equal in exact arithmetic are
compared with this slack: a pattern brick fits a course, a piece is a regular brick
(4 units), a sequence is empty or shorter than ``min_fill``, a joint repeats the one
below (:mod:`masonry.dome.pattern`, :mod:`masonry.dome.courses`). Rounding of sums of a
few dozen units is about 1e-14, and real differences are whole or half units or
``min_fill``, so any value between those works."""

PATTERN_END_REPORTED = 0.9
"""A pattern line that ends on a course below this fraction of the highest course a
pattern brick starts on (one below the top) ends far below the top: ``run.json`` lists it
(``pattern.ended_far_below_top``) and the command line says so
(:meth:`masonry.dome.pattern.Pattern.ended_far_below_top`). Lines end near the top where
the web has narrowed (preset 3's two, on course 39 of 42; two of an 11-course dome on
course 9); lower, a part of the dome has fewer pattern lines than the rest (preset 1 with
``p = 2``: two of four end on course 8 of 17)."""

LEVEL_TOP_REL = 1e-12
"""A contact point up to ``(1 + LEVEL_TOP_REL) z_max`` still counts as below the cut
(:func:`masonry.dome.levels.level_table`): a top level that lands on ``z_max`` exactly
is kept whatever the rounding of the ellipse."""

LEVEL_ANGLE_XTOL = 1e-15
"""Radians: absolute tolerance of the root finder for the ellipse angle of each contact
point (:func:`masonry.dome.levels.level_table`; ``brentq``'s ``xtol``, with ``rtol``
four machine epsilons): contact points exact to rounding."""

# ---------------------------------------------------------------------- blocks
HORIZONTAL_SIN = 1e-6
"""A face is horizontal when ``|z x n|`` (the sine of its tilt) is below this; its
in-plane basis then follows a direction of the face's own
(:func:`masonry.blocks.tangent_basis`)."""

TIE_REL = 1e-9
"""Two lengths within this fraction of each other are equal: the first of the longest
edges of a face is taken (:attr:`masonry.blocks.Blocks.face_longest_edge`), whatever
the rounding of the edge lengths of a square face."""

# ---------------------------------------------------------------------- imported meshes
CONVEXITY_REL = 1e-4
"""A block read from a mesh is convex when its volume falls short of its convex hull's by
at most this fraction of the hull's (:mod:`masonry.scenes.imported`). Float32 rounding
(binary STL) of a brick 20 m from the origin moves its corners by about 1e-6 m and its
volume by about 1e-5 of a 0.2 m brick; a real concavity (an L-shaped block, a notch) is a
few percent or more. The hull's merged faces must give the hull's volume within the
same fraction."""

COINCIDENT_ANGLE = 1e-6
"""Radians. Two triangles around an edge whose half-planes are closer than this lie on
top of each other: the faces of two blocks in contact, never the two faces of one block's
edge (no block has a dihedral angle that small; :mod:`masonry.scenes.imported`)."""

COLLINEAR_SIN = 1e-9
"""A point of a hull face's ring where the ring turns by less than this sine (or turns
back) lies inside an edge or inside the face and is dropped
(:mod:`masonry.scenes.imported`)."""

INTERPENETRATION_REL = 1e-3
"""Two blocks of an imported assembly overlap when they interpenetrate by more than this
fraction of the smaller one's size (its bounding box diagonal): overlapping solids are
not a structure (:func:`masonry.scenes.overlaps.overlapping_pairs`). Less is taken for
the imprecision of a drawing (the interface detector closes such gaps). The default of
``--overlap-tolerance``, which accepts models that overlap by design (docs/assemblies.md)."""

OVERLAP_TOLERANCE_RANGE = (1e-6, 0.1)
"""The overlaps ``--overlap-tolerance`` may accept, as fractions of the smaller block's
size: from the contact tolerance's order (blocks that merely touch are never taken for
overlapping) to a tenth of a block, beyond which the blocks are not the model's but
something else (compas_cra's Armadillo's convex hulls overlap by up to 4%)."""

PARALLEL_SIN = 1e-9
"""Two unit edge directions whose cross product is shorter than this (the sine of their
angle) are parallel: their cross product is no separating axis, and the blocks' face
normals already test that direction (:func:`masonry.scenes.overlaps.overlapping_pairs`)."""

GROUND_MARGIN_REL = 0.05
"""The ground slab that ``masonry analyze --ground`` adds reaches past the footprint of
the lowest blocks by this fraction of the footprint's larger side on every side, and is
as thick as that margin (:func:`masonry.scenes.imported.with_ground`)."""

FACE_COVERED = 1 - 1e-3
"""A face of a brick whose interfaces with other bricks cover this fraction of its area
is inside the structure, never seen: ``dome.html`` does not draw it
(:func:`masonry.export.html.outer_faces`)."""

# ---------------------------------------------------------------------- interfaces
BED_JOINT_ANGLE = float(np.pi / 4)
"""Radians. A face whose normal is within this angle of its block's course direction
(``up``) is a bed face: the lower block's face is then the main one, and the interface
is ``horizontal``, else ``vertical`` (a head joint; :mod:`masonry.interfaces`)."""

# ---------------------------------------------------------------------- equilibrium
COEFFICIENT_NOISE = 1e-12
"""Scaled ``A_eq`` coefficients (unit directions, arms per ``L_ref``: of order one) at or
below this are floating-point noise of exact zeros and are not stored
(:func:`masonry.rbe.equilibrium.assemble`)."""

# ---------------------------------------------------------------------- printable body
OVERLAP_REL = 1e-5
"""Default growth of every brick of the printable body, relative to the scene size
``Tolerances.scale`` (:func:`masonry.printable.printable_body`): 80 micrometres for the
CAD-offset section of preset 1 (8 m), 34 for the wall. Ten times the cleaning distance
``Tolerances.contact`` (1e-6 of the size), so cleaning never undoes an overlap, and small
against a brick (unit 0.1 m). The union grows by its exposed surface times the overlap:
+0.15 to +0.16 % of the volume for the sections of presets 1 to 3, +0.04 % for the
wall."""

MIN_CORNER_DET = 1e-6
"""A vertex lies on exactly three faces of a simple convex block (every box and mitered
box). Its three unit face normals are independent when the absolute determinant of
their matrix exceeds this; a corner of nearly parallel faces goes to the halfspace path,
which has no conditioning issue (:func:`masonry.printable.grown_blocks`)."""

# ---------------------------------------------------------------------- exports
READBACK_VOLUME_RTOL = 1e-5
"""The printable body read back from its STL as a slicer would (float32 vertices, merged)
must keep the union's volume within this fraction
(:func:`masonry.export.stl.readback_check`). Float32 rounding moves a vertex of an 8 m
dome by about 5e-7 m; the measured changes are -8.3e-8 (section of preset 1), -3.5e-8
(preset 3) and -7.8e-8 (the wall)."""

# ---------------------------------------------------------------------- studies
THICKNESS_BRACKET = (0.01, 0.8)
"""Default starting ``(infeasible, feasible)`` thickness ratios ``t/R`` of the arch's
minimum-thickness bisection (:func:`masonry.studies.thickness.minimum_thickness`)."""

THICKNESS_RTOL = 1e-4
"""Default relative width of the final bracket of the arch's minimum-thickness
bisection (:func:`masonry.studies.thickness.minimum_thickness`, ``masonry
arch-thickness --rtol``)."""

MIN_SEARCH_RTOL = 1e-15
"""The least relative width a search by bisection takes (``masonry arch-thickness
--rtol``): a few units in the last place of a float64 (2.2e-16); a bracket narrower than
that cannot shrink, and the search would never end."""

MIN_THICKNESS_BLOCKS = 4
"""The fewest voussoirs whose minimum thickness is searched: an arch needs four hinges
to move, and one of three voussoirs has only four joints, so it stands at every
thickness (its thrust line fits any)."""

THICKNESS_LIMIT_FRACTION = 0.99
"""The thickest arch the bisection starts from is at most this fraction of the
thickness at which the shape's intrados vanishes
(:func:`masonry.studies.thickness.minimum_thickness`)."""

THRUST_SCAN = (1e-3, 0.999, 60)
"""The thrust-line minimum thickness scans ``t/R`` on a geometric grid of 60 points
from 1e-3 up to 0.999 of the ratio at which the intrados vanishes, for the first
thickness a thrust line fits, before refining it by root finding
(:func:`masonry.studies.thrust_line.thrust_line_minimum_thickness`)."""

THRUST_XTOL = 1e-12
"""Default absolute tolerance on ``t/R`` of that refinement (Brent's ``xtol``)."""

THRUST_MARGIN_XATOL_REL = 1e-13
"""Absolute tolerance of the bounded search for the thrust ``H`` that maximises the
thrust line's margin, relative to the half arch's total weight
(:func:`masonry.studies.thrust_line.thrust_line_margin`)."""

THRUST_ACTIVE_REL = 1e-7
"""A joint's intrados or extrados bound is active at the best thrust line when the line
passes within this fraction of (total weight x R) of it
(:func:`masonry.studies.thrust_line.thrust_line_margin`)."""

THRUST_PLANE_REL = 1e-6
"""A bed joint reaches the thrust line's plane when its polygon comes within this
fraction of the model's size of it: a joint that only touches the plane along its edge
(the plane on a head joint, two bricks meeting there) counts
(:func:`masonry.plots.thrust.plane_joints`)."""

MOTION_TOL = 1e-3
"""Relative motion at a vertex, per largest block displacement (1 after normalising),
above which an interface counts as opening or sliding in a collapse mechanism
(:mod:`masonry.rbe.collapse`). Not a rounding tolerance: an interior point's dual is the
centre of all optimal mechanisms and carries motions of order its tolerance elsewhere (at
1e-6, preset 2's dome had every web hinging); 0.1 % of the largest displacement keeps
the mechanism that matters."""

MECHANISM_MAIN = 0.05
"""Of the joints that open or slip by :data:`MOTION_TOL`, those that carry a collapse
mechanism: hinges that open, and joints that slip, by at least this fraction of the
largest opening or slip (preset 3's full dome at azimuth 0: 124 of 1,811 hinges). The
plots mark these, the summaries count both."""

MAX_COORDINATE_M = 1e8
"""Largest coordinate of a block read from a file, metres: map coordinates reach 1e7 m
(UTM northings), and far beyond that double precision loses the blocks' geometry (at
1e12 m a 0.4 m cube's volume is 5e-4 off); 1e300 overflows the geometry's sums."""

FACTOR_TIE_REL = 1e-6
"""Load factors of two azimuths this close (relative) are the same worst case: the search
reports the first azimuth (a symmetric structure's 0 and 180 degrees differ by the LP's
rounding only)."""

AZIMUTH_NEAR_LEAST_REL = 1e-3
"""An azimuth search refines the brackets with an end whose factor is within this
(relative) of the least sampled (:mod:`masonry.rbe.azimuth_refine`): the least's
neighbours and those of samples tied with it."""

AZIMUTH_REFINE_REL = 1e-7
"""An azimuth search (``--lateral all``) refines its least sample until the least factor
it found is within this (relative) of the least over every azimuth beside it
(:mod:`masonry.rbe.azimuth_refine`): below the 1e-6 the collapse program's factor is
compared to, above its gaps (1e-8). The balanced and accurate presets' ``azimuth_rel``
(the fast one's is 1e-4: :mod:`masonry.rbe.accuracy`)."""

CENTERING_REPORTED_REL = 1e-3
"""A block needs a temporary support when the centering force on it (docs/model.md 6.10,
:mod:`masonry.rbe.centering`) exceeds this fraction of its own weight. Clarabel solves
to gaps of 1e-8 of the mean block weight, but where the optimum is not unique (a brick
held directly or through the one it rests on) its interior point spreads forces of
1e-9 to 1e-5 of the structure's weight over many bricks (preset 1's free section: 169
bricks above 1e-9 of the weight, 83 above 1e-3 of their own, carrying all but 4e-5 of the
total); a thousandth of a brick's weight is no support anyone gives."""

ADHESION_REPORTED_REL = 1e-3
"""A joint needs adhesion (docs/model.md 6.12, :mod:`masonry.rbe.adhesion`) when it uses
more than this fraction of the least adhesion ``a*`` at the optimum: below it, the
interior point's spread over joints that dry friction could carry as well (as
:data:`CENTERING_REPORTED_REL` for supports)."""

ADHESION_TIE_REL = 1e-4
"""Least adhesions of two construction stages this close (relative) are the same: a stage
study reports the first stage that reaches the largest. Clarabel solves each stage's
program to about 1e-5 of ``a*`` (preset 1's course 61 laid brick by brick: eight stages
held by the same first pattern brick, within 2.3e-5 of each other)."""

# ---------------------------------------------------------------------- mirror symmetry
MIRROR_ANGLE_DEG = 1e-9
"""Degrees within which a load's azimuth lies in a mirror plane
(:func:`masonry.rbe.mirror.in_plane`)."""

MIRROR_VOLUME_REL = 1e-5
"""Two blocks whose centroids are mirror images within the contact tolerance and whose
volumes agree to this fraction are mirror images (:func:`masonry.rbe.mirror.half_model`).
The polygonal dome's bricks agree to rounding, and so do those of a small dome of
revolution; on the default dome of revolution some differ by up to 5.4e-6 of their
volume (centroids by 5.5e-7 m): a brick is the hull of its corners, and the hull merges
the nearly coplanar facets of a bed in the order qhull finds them. A brick and the one
the mirror would put beside it differ by far more."""

MIRROR_NORMAL_MISS = 1e-6
"""A joint and its mirror image face as each other's mirror when their unit normals,
mapped by the mirror, differ by at most this (:func:`masonry.rbe.mirror.half_model`)."""
