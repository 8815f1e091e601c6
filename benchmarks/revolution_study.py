"""What the herringbone does: domes of one profile with and without the pattern
(docs/revolution.md).

For two meridian profiles (a hemisphere, and the profile of preset 1), the dome with the
double helix and the plain dome (``pattern = none``), each polygonal (a cyclic section
and the whole ``dome``) and of revolution (a cyclic ``sector`` and the whole
``revolution``): eight domes. For each:

- the rigid block equilibrium under self weight of the cyclic part (the whole dome
  under its own weight) and of the part standing free;
- the worst lateral load factor of the whole dome over the azimuths of ``--lateral all``;
- the course stages of the cyclic part: how many stand;
- the brick-by-brick stages, cyclic, of every course whose chord leans more than the
  friction angle (the level table's ``gamma_reg > atan(mu)``) up to the top, in both laying orders (friction-net: the verdict, no MoI); while the lowest of
  them needs support, the courses under it, down to one that stands at every stage. The
  lowest course that needs support and the course under it are solved again at a second
  accuracy preset (``confirm``).

The dome of revolution takes the polygonal dome's mid-plane meridian: its radius is the
polygon's apothem ``a`` (the web's intrados at the springing) and its stretch ``c / a``,
so both have the same contact points, course for course. The hemisphere is ``c = a``:
stretch 1 of revolution, ``cos(pi/n)`` of the polygon (whose stretch is over the
circumradius).

Every measurement is kept as JSON in ``OUT/cases/`` under a key of its inputs, so a
stopped study goes on where it stopped::

    python -m masonry_benchmarks.revolution_study --out exports/revolution_study

writes ``revolution.csv`` (one row per dome), ``revolution_bricks.csv`` (one row per
dome, order and course scanned), ``revolution_azimuths.csv``, the two tables in
``revolution_tables.md`` and the figures ``revolution_domes.png``,
``revolution_bricks.png``, ``revolution_stages_<profile>.png`` and
``revolution_lateral.png``.
"""

import argparse
import csv
import dataclasses
import functools
import hashlib
import io
import json
import logging
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from masonry.blocks import BLOCK_CLASSES, PATTERN
from masonry.cache import geometry_code_digest
from masonry.errors import ParameterError
from masonry.params import Params, validate
from masonry.pipeline import build_model, collapse_of
from masonry.rbe.solve import ACCURACY, RBEProblem
from masonry.stages.analysis import analyse_stages
from masonry.stages.orders import BRICK_ORDERS
from masonry.stages.plans import make_plan
from masonry.tolerances import G

log = logging.getLogger(__name__)

PROFILES = {"hemisphere": 1.0, "preset 1": None}
"""Profile name -> ``c / a`` (None: the polygon's stretch 1, ``c`` its circumradius)."""

DOME_COLUMNS = ("profile", "kind", "pattern", "sectors", "courses", "bricks",
                "pattern_bricks", "volume_m3", "weight_kN", "steep_from", "cyclic",
                "cyclic_moi_factor", "free", "free_moi_factor", "lateral_factor",
                "lateral_azimuth_deg", "course_stages", "course_stages_standing",
                "first_failing_course", "self_weight_s", "course_stages_s", "lateral_s",
                "brick_stages_s")
BRICK_COLUMNS = ("profile", "kind", "pattern", "order", "course", "incline_deg", "stages",
                 "failing", "first_failing_stage", "first_failing_class",
                 "confirm_failing", "verdicts", "seconds")
"""Columns of ``revolution_bricks.csv``: ``verdicts`` holds a letter per stage, ``s`` it
stands, ``f`` it needs support, in capitals where the stage lays a pattern brick."""
AZIMUTH_COLUMNS = ("profile", "kind", "pattern", "azimuth_deg", "factor")


@dataclass(frozen=True)
class Settings:
    """The analysis of every measurement: friction coefficient, the accuracy preset of
    everything, and the preset the lowest failing brick course is solved again at
    (None: not)."""

    mu: float = 0.7
    accuracy: str = "fast"
    confirm: str | None = "balanced"


@dataclass(frozen=True)
class Dome:
    """One dome of the comparison: its part (a cyclic section or sector) and its whole
    scene, and the geometry inputs they share."""

    profile: str
    kind: str
    pattern: str
    part_scene: str
    whole_scene: str
    inputs: dict

    @property
    def name(self) -> str:
        return f"{self.profile}, {self.kind}, {self.pattern}"

    @property
    def slug(self) -> str:
        return "_".join(self.name.replace(",", "").split())

    def params(self, whole=False, boundary="cyclic", **analysis) -> Params:
        """The validated inputs of its part with ``boundary``, or of the whole dome."""
        if whole:
            return validate(Params.of(scene=self.whole_scene, **self.inputs, **analysis))
        return validate(Params.of(scene=self.part_scene, boundary=boundary, **self.inputs,
                                  **analysis))

    def model(self, whole=False, boundary="cyclic") -> tuple:
        """``(scene, model)`` of its part with ``boundary`` or of the whole dome, built
        once for the last few asked (the analysis does not change them)."""
        return _built(self.whole_scene if whole else self.part_scene,
                      json.dumps(self.inputs, sort_keys=True), None if whole else boundary)


@functools.lru_cache(maxsize=3)
def _built(scene, inputs, boundary) -> tuple:
    bounded = {} if boundary is None else {"boundary": boundary}
    return build_model(validate(Params.of(scene=scene, **bounded, **json.loads(inputs))))


def domes(n=8, r=1, p=10, cut=0.1, unit=0.1, profiles=PROFILES) -> list:
    """The domes of the comparison on an ``n``-sided polygon of ``r`` rhombi and ``p``
    pattern bricks per side (preset 1's by default): per profile, polygonal and of
    revolution, with the pattern and plain."""
    apothem = (p + 1) * (r + 1) / np.tan(np.pi / n)  # units (docs/model.md 4.1)
    out = []
    for profile, c_over_a in profiles.items():
        c_over_a = 1 / np.cos(np.pi / n) if c_over_a is None else c_over_a
        for pattern in ("herringbone", "none"):
            shared = {"p": p, "cut": cut, "unit": unit, "pattern": pattern}
            out.append(Dome(profile, "polygonal", pattern, "section", "dome", {
                "n": n, "r": r, **shared,
                "stretch": round(float(c_over_a * np.cos(np.pi / n)), 6)}))
            out.append(Dome(profile, "revolution", pattern, "sector", "revolution", {
                "radius": round(float(apothem), 4), **shared,
                "stretch": round(float(c_over_a), 6)}))
    return out


# ---------------------------------------------------------------------- the cache
def cached(folder, name, key: dict, compute) -> dict:
    """``compute()``'s dict, kept as ``folder/name.json`` with ``key``: read back when
    the file holds the same key, else computed and written (atomically)."""
    path = Path(folder) / f"{name}.json"
    digest = hashlib.sha1(json.dumps(key, sort_keys=True).encode()).hexdigest()
    if path.exists():
        record = json.loads(path.read_text())
        if record.get("key") == digest:
            return record["value"]
    value = compute()
    path.parent.mkdir(parents=True, exist_ok=True)
    part = path.with_suffix(".part")
    part.write_text(json.dumps({"key": digest, "value": value}, allow_nan=False,
                               default=_plain))
    os.replace(part, path)
    return value


def _plain(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON: {value!r}")


def _number(value):
    """A float for JSON, None for a missing or non-finite one."""
    return None if value is None or not math.isfinite(value) else float(value)


# ---------------------------------------------------------------------- measurements
def self_weight(dome: Dome, settings: Settings) -> dict:
    """Counts, volume and the self-weight verdicts of the cyclic and the free part."""
    start = time.perf_counter()

    def verdict(boundary):
        params = dome.params(boundary=boundary, mu=settings.mu, accuracy=settings.accuracy)
        scene, model = dome.model(boundary=boundary)
        result = RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                            side_rotation=model.side_rotation).solve(
            **params.analysis.rbe_options())
        return scene, params, result

    scene, params, cyclic = verdict("cyclic")
    free = verdict("free")[2]
    blocks, order = scene.blocks, params.kind.symmetry(params.geometry).order
    bricks = ~blocks.block_is_support
    volume = order * float(blocks.block_volume[bricks].sum())
    incline = np.degrees(scene.levels.gamma_reg)
    return {"sectors": order, "courses": len(incline), "bricks": order * int(bricks.sum()),
            "pattern_bricks": order * int((blocks.block_class == PATTERN).sum()),
            "volume_m3": volume, "weight_kN": volume * params.analysis.density * G / 1e3,
            "incline_deg": incline.tolist(), "cyclic": cyclic.verdict,
            "cyclic_moi_factor": _number(cyclic.moi_factor), "free": free.verdict,
            "free_moi_factor": _number(free.moi_factor),
            "self_weight_s": time.perf_counter() - start}


def lateral(dome: Dome, settings: Settings) -> dict:
    """The whole dome's worst lateral load factor over ``--lateral all``'s azimuths."""
    start = time.perf_counter()
    params = dome.params(whole=True, mu=settings.mu, accuracy=settings.accuracy,
                         lateral="all")
    scene, model = dome.model(whole=True)
    result = collapse_of(model, params)
    return {"lateral_factor": _number(result.load_factor),
            "lateral_azimuth_deg": _number(result.azimuth_deg),
            "azimuths": [[a, _number(f)] for a, f in result.azimuths or ()],
            "lateral_s": time.perf_counter() - start}


def course_stages(dome: Dome, settings: Settings) -> dict:
    """The cyclic part's course stages: the verdict of each."""
    start = time.perf_counter()
    params = dome.params(mu=settings.mu, accuracy=settings.accuracy)
    scene, model = dome.model()
    rows = analyse_stages(model, params, make_plan(scene, "course"))
    feasible = [bool(row["feasible"]) for row in rows]
    return {"course_stages": len(rows), "course_stages_standing": sum(feasible),
            "first_failing_course": next((k + 1 for k, f in enumerate(feasible) if not f),
                                         None),
            "moi_factor": [_number(row["moi_factor"]) for row in rows],
            "course_stages_s": time.perf_counter() - start}


def brick_course(dome: Dome, order: str, course: int, accuracy: str, mu: float) -> dict:
    """The cyclic part's brick stages of ``course`` in ``order``, friction-net: the
    verdict of each stage and the classes of the bricks it lays."""
    start = time.perf_counter()
    params = dome.params(mu=mu, accuracy=accuracy, friction="net")
    scene, model = dome.model()
    plan = make_plan(scene, "brick", order, course)
    rows = analyse_stages(model, params, plan)
    classes = scene.blocks.block_class[:len(plan.block_stage)]
    return {"feasible": [bool(row["feasible"]) for row in rows],
            "laid": [[BLOCK_CLASSES[c] for c in classes[plan.block_stage == stage]]
                     for stage in range(1, plan.n_stages + 1)],
            "seconds": time.perf_counter() - start}


def steep_from(incline_deg, mu) -> int:
    """The first course whose regular bricks lean inward more than the friction angle
    (``gamma_reg``, the slope of the course's chord, which lies between the slopes of
    its bed and of the bed over it; the top course when none does)."""
    steep = np.flatnonzero(np.asarray(incline_deg) > np.degrees(np.arctan(mu)))
    return int(steep[0]) + 1 if len(steep) else len(incline_deg)


def brick_scan(dome: Dome, settings: Settings, incline, case) -> list:
    """:data:`BRICK_COLUMNS` rows of the brick stages of the courses from
    :func:`steep_from` to the top in both orders, and under them down to a course that
    stands at every stage; the lowest failing course and the one under it again at
    ``settings.confirm``. ``case(name, compute)`` keeps each course's result."""
    def scan(order, course, accuracy):
        found = case(f"brick_{order}_{course}_{accuracy}",
                     lambda: brick_course(dome, order, course, accuracy, settings.mu))
        failing = found["feasible"].count(False)
        log.info("%s, %s, course %d (%s): %d of %d stages need support", dome.name, order,
                 course, accuracy, failing, len(found["feasible"]))
        return found

    steep, rows = steep_from(incline, settings.mu), []
    for order in BRICK_ORDERS:
        found = {k: scan(order, k, settings.accuracy) for k in range(steep, len(incline) + 1)}
        low = steep
        while False in found[low]["feasible"] and low > 1:
            low -= 1
            found[low] = scan(order, low, settings.accuracy)
        failing = [k for k in sorted(found) if False in found[k]["feasible"]]
        checked = {}
        if settings.confirm and failing:
            checked = {k: scan(order, k, settings.confirm)["feasible"].count(False)
                       for k in (failing[0] - 1, failing[0]) if k >= 1}
        for k in sorted(found):
            stands = found[k]["feasible"]
            first = stands.index(False) if False in stands else None
            rows.append({
                "profile": dome.profile, "kind": dome.kind, "pattern": dome.pattern,
                "order": order, "course": k, "incline_deg": incline[k - 1],
                "stages": len(stands), "failing": stands.count(False),
                "first_failing_stage": None if first is None else first + 1,
                "first_failing_class": None if first is None
                else " ".join(sorted(set(found[k]["laid"][first]))),
                "confirm_failing": checked.get(k), "verdicts": verdicts(found[k]),
                "seconds": found[k]["seconds"]})
    return rows


def verdicts(found) -> str:
    """A :func:`brick_course` result as the letters of :data:`BRICK_COLUMNS`."""
    letters = ("s" if stands else "f" for stands in found["feasible"])
    return "".join(letter.upper() if "pattern" in laid else letter
                   for letter, laid in zip(letters, found["laid"]))


def measure(dome: Dome, settings: Settings, cases) -> tuple:
    """``(row, brick_rows)``: the dome's :data:`DOME_COLUMNS` (and ``azimuths``, every
    azimuth's lateral factor) and its :func:`brick_scan`, each measurement kept in
    ``cases/<dome>/``."""
    key = {"inputs": dome.inputs, "scenes": [dome.part_scene, dome.whole_scene],
           "settings": dataclasses.asdict(settings), "code": geometry_code_digest()}

    def case(name, compute):
        return cached(Path(cases) / dome.slug, name, {**key, "case": name}, compute)

    weight = case("self_weight", lambda: self_weight(dome, settings))
    log.info("%s: %d bricks, self weight %s (free %s)", dome.name, weight["bricks"],
             weight["cyclic"], weight["free"])
    courses = case("course_stages", lambda: course_stages(dome, settings))
    log.info("%s: %d of %d course stages stand", dome.name,
             courses["course_stages_standing"], courses["course_stages"])
    bricks = brick_scan(dome, settings, weight["incline_deg"], case)
    side = case("lateral", lambda: lateral(dome, settings))
    log.info("%s: lateral factor %s at %s deg", dome.name, side["lateral_factor"],
             side["lateral_azimuth_deg"])
    row = {"profile": dome.profile, "kind": dome.kind, "pattern": dome.pattern,
           **weight, **courses, **side,
           "steep_from": steep_from(weight["incline_deg"], settings.mu),
           "brick_stages_s": sum(b["seconds"] for b in bricks)}
    return row, bricks


# ---------------------------------------------------------------------- tables
def order_summary(brick_rows) -> list:
    """Per dome and order: the scanned courses, the first that needs support at some
    stage (its incline, failing stages, again at ``confirm``, and what its first failing
    stage lays) and the first where every stage but the closed ring does."""
    out = []
    for key in dict.fromkeys((r["profile"], r["kind"], r["pattern"], r["order"])
                             for r in brick_rows):
        mine = [r for r in brick_rows if (r["profile"], r["kind"], r["pattern"],
                                          r["order"]) == key]
        failing = [r for r in mine if r["failing"]]
        first = failing[0] if failing else None
        every = next((r for r in mine if r["failing"] == r["stages"] - 1), None)
        out.append({**dict(zip(("profile", "kind", "pattern", "order"), key)),
                    "scanned": f"{int(mine[0]['course'])}-{int(mine[-1]['course'])}",
                    "failing_courses": len(failing),
                    "first_failing": first and int(first["course"]),
                    "incline_deg": first and first["incline_deg"],
                    "failing_stages": first and f"{int(first['failing'])}/{int(first['stages'])}",
                    "confirm_failing": first and first["confirm_failing"],
                    "first_failing_lays": first and first["first_failing_class"],
                    "all_fail_from": every and int(every["course"])})
    return out


def markdown(rows, summary) -> str:
    """The study's two tables in Markdown: the domes, and their brick stages."""
    def table(header, lines):
        cells = [header, ["---"] * len(header), *lines]
        return "\n".join("| " + " | ".join(map(str, c)) + " |" for c in cells)

    def num(value, digits=3):
        return "-" if value is None else f"{value:.{digits}g}"

    domes_ = table(
        ["profile", "dome", "bricks (pattern)", "m^3", "sectors", "courses", "self weight",
         "free part (MoI factor)", "lateral factor (azimuth)", "course stages standing"],
        [[r["profile"], _label(r["kind"], r["pattern"]),
          f"{int(r['bricks'])} ({int(r['pattern_bricks'])})", num(r["volume_m3"], 4),
          int(r["sectors"]), int(r["courses"]), r["cyclic"],
          f"{r['free']} ({num(r['free_moi_factor'])})",
          f"{num(r['lateral_factor'], 4)} ({num(r['lateral_azimuth_deg'])} deg)",
          f"{int(r['course_stages_standing'])}/{int(r['course_stages'])}"] for r in rows])
    stages = table(
        ["profile", "dome", "order", "scanned", "courses needing support",
         "first (incline)", "its stages failing (confirm)", "first failing stage lays",
         "all but the last fail from"],
        [[s["profile"], _label(s["kind"], s["pattern"]), s["order"], s["scanned"],
          s["failing_courses"], "-" if s["first_failing"] is None
          else f"{s['first_failing']} ({s['incline_deg']:.1f} deg)",
          "-" if s["failing_stages"] is None
          else f"{s['failing_stages']} ({num(s['confirm_failing'])})",
          s["first_failing_lays"] or "-", s["all_fail_from"] or "-"] for s in summary])
    return f"{domes_}\n\n{stages}\n"


# ---------------------------------------------------------------------- figures
STYLE = {("polygonal", "herringbone"): ("C3", "-", "o"), ("polygonal", "none"): ("C0", "-", "s"),
         ("revolution", "herringbone"): ("C1", "--", "^"),
         ("revolution", "none"): ("C2", "--", "v")}
"""Colour, line and marker of a dome in the figures, by kind and pattern."""


def _label(kind, pattern) -> str:
    return f"{kind}, {'plain' if pattern == 'none' else 'herringbone'}"


def domes_png(domes_, title="") -> bytes:
    """The whole domes in elevation, seen from -y, in their class colours: one row per
    pattern, one column per profile and kind."""
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    from masonry.plots.common import CLASS_COLOURS, png_bytes

    columns = list(dict.fromkeys((d.profile, d.kind) for d in domes_))
    patterns = ("herringbone", "none")
    fig, axes = plt.subplots(len(patterns), len(columns), figsize=(4.2 * len(columns), 5.2),
                             squeeze=False)
    for d in domes_:
        ax = axes[patterns.index(d.pattern)][columns.index((d.profile, d.kind))]
        blocks = d.model(whole=True)[0].blocks
        # the faces of the front half that face the viewer, the farthest drawn first
        shown = (blocks.block_centroid[:, 1] < 0) & ~blocks.block_is_support
        faces = np.flatnonzero(shown[blocks.face_block] & (blocks.face_normal[:, 1] < 0))
        polygons = [blocks.face_polygon(f) for f in faces]
        depth = np.argsort([-p[:, 1].mean() for p in polygons])
        ax.add_collection(PolyCollection(
            [polygons[i][:, [0, 2]] for i in depth], linewidths=0.1, edgecolors="0.3",
            facecolors=[CLASS_COLOURS[BLOCK_CLASSES[blocks.block_class[
                blocks.face_block[faces[i]]]]] for i in depth]))
        lo, hi = blocks.bounds
        ax.set(xlim=(lo[0] - 0.2, hi[0] + 0.2), ylim=(0, hi[2] + 0.2), aspect="equal",
               xlabel="x [m]",
               ylabel="z [m]")
        ax.set_title(f"{d.profile}, {_label(d.kind, d.pattern)}: "
                     f"{int((~blocks.block_is_support).sum())} bricks", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return png_bytes(fig, 90)


def bricks_png(brick_rows, title="") -> bytes:
    """The share of each scanned course's brick stages that need support: one panel per
    profile and order, one line per dome."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    from masonry.plots.common import png_bytes

    profiles = list(dict.fromkeys(r["profile"] for r in brick_rows))
    orders = list(BRICK_ORDERS)
    fig, axes = plt.subplots(len(orders), len(profiles), figsize=(5.2 * len(profiles), 6.4),
                             squeeze=False, sharey=True)
    for col, profile in enumerate(profiles):
        for row, order in enumerate(orders):
            ax = axes[row][col]
            for (kind, pattern), (colour, line, mark) in STYLE.items():
                mine = [r for r in brick_rows if (r["profile"], r["kind"], r["pattern"],
                                                  r["order"]) == (profile, kind, pattern, order)]
                ax.plot([r["course"] for r in mine], [r["failing"] / r["stages"] for r in mine],
                        color=colour, linestyle=line, marker=mark, markersize=3.5,
                        linewidth=1, label=_label(kind, pattern))
            ax.set_title(f"{profile}, {order}", fontsize=10)
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.set(ylim=(-0.04, 1.04), xlabel="course laid brick by brick" if row else None,
                   ylabel="stages that need support\n(share of the course's stages)"
                   if col == 0 else None)
            ax.grid(alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.97))
    return png_bytes(fig, 100)


def stages_png(brick_rows, profile, title="") -> bytes:
    """Every scanned brick stage of one profile's domes as a cell, course against
    stage, green where it stands and red where it needs support, a dot where it lays a
    pattern brick: one column per dome, one row per order."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.ticker import MaxNLocator

    from masonry.plots.common import png_bytes

    mine = [r for r in brick_rows if r["profile"] == profile]
    orders, kinds = list(BRICK_ORDERS), list(STYLE)
    width = max(len(r["verdicts"]) for r in mine)
    fig, axes = plt.subplots(len(orders), len(kinds), figsize=(3.2 * len(kinds), 8.2),
                             squeeze=False, sharex=True, sharey=True)
    for row, order in enumerate(orders):
        for col, (kind, pattern) in enumerate(kinds):
            ax = axes[row][col]
            scanned = [r for r in mine if (r["kind"], r["pattern"], r["order"])
                       == (kind, pattern, order)]
            courses = [int(r["course"]) for r in scanned]
            grid = np.zeros((len(scanned), width))
            for i, r in enumerate(scanned):
                grid[i, :len(r["verdicts"])] = [1 if c in "sS" else 2 for c in r["verdicts"]]
                dots = [j + 1 for j, c in enumerate(r["verdicts"]) if c.isupper()]
                ax.plot(dots, [courses[i]] * len(dots), "k.", markersize=4)
            ax.imshow(grid, cmap=ListedColormap(["white", "#8fd18f", "#d9534f"]), vmin=0,
                      vmax=2, aspect="auto", interpolation="nearest", origin="lower",
                      extent=(0.5, width + 0.5, courses[0] - 0.5, courses[-1] + 0.5))
            ax.set_title(f"{_label(kind, pattern)}\n{order}", fontsize=9)
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
            if row == len(orders) - 1:
                ax.set_xlabel("stage (brick laid) on the course")
            if col == 0:
                ax.set_ylabel("course laid brick by brick")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in ("#8fd18f", "#d9534f")]
    handles.append(plt.Line2D([], [], color="k", marker=".", linestyle=""))
    fig.legend(handles, ["stands", "needs support", "lays a pattern brick"],
               loc="lower center", ncol=3, fontsize=9, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.03, 1, 0.97))
    return png_bytes(fig, 100)


def lateral_png(rows, azimuth_rows, title="") -> bytes:
    """Every azimuth's lateral load factor of the whole domes, one panel per profile."""
    import matplotlib.pyplot as plt

    from masonry.plots.common import png_bytes

    profiles = list(dict.fromkeys(r["profile"] for r in rows))
    fig, axes = plt.subplots(1, len(profiles), figsize=(5.2 * len(profiles), 3.8),
                             squeeze=False, sharey=True)
    for ax, profile in zip(axes[0], profiles):
        for (kind, pattern), (colour, line, mark) in STYLE.items():
            mine = [a for a in azimuth_rows
                    if (a["profile"], a["kind"], a["pattern"]) == (profile, kind, pattern)]
            ax.plot([a["azimuth_deg"] for a in mine],
                    [np.nan if a["factor"] is None else a["factor"] for a in mine],
                    color=colour, linestyle=line, marker=mark, markersize=3.5, linewidth=1,
                    label=_label(kind, pattern))
        ax.set(title=profile, xlabel="azimuth of the lateral load [deg]", xlim=(0, 360),
               xticks=range(0, 361, 45), ylim=(0, 0.6))
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("collapse load factor\n(lateral load / self weight)")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.08, 1, 0.97))
    return png_bytes(fig, 100)


# ---------------------------------------------------------------------- the study
def write_csv(path, rows, columns) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: "" if v is None else round(v, 6) if isinstance(v, float) else v
                      for k, v in row.items()} for row in rows)
    Path(path).write_text(buf.getvalue())


def read_csv(path) -> list:
    """The rows of a CSV the study wrote, numbers as floats (empty cells None)."""
    def value(text):
        try:
            return float(text)
        except ValueError:
            return text or None
    with open(path, newline="") as f:
        return [{k: value(v) for k, v in row.items()} for row in csv.DictReader(f)]


def study(out, domes_=None, settings=Settings()) -> None:
    """Measure every dome (default :func:`domes`), each measurement kept in
    ``out/cases``, and write ``revolution.csv``, ``revolution_bricks.csv`` and
    ``revolution_azimuths.csv`` (every azimuth's lateral factor) to ``out`` after each
    dome; then the figures (:func:`figures`)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    domes_ = domes() if domes_ is None else domes_
    rows, brick_rows, azimuths = [], [], []
    for dome in domes_:
        row, bricks = measure(dome, settings, out / "cases")
        rows.append(row)
        brick_rows += bricks
        azimuths += [{**row, "azimuth_deg": a, "factor": f} for a, f in row["azimuths"]]
        write_csv(out / "revolution.csv", rows, DOME_COLUMNS)
        write_csv(out / "revolution_bricks.csv", brick_rows, BRICK_COLUMNS)
        write_csv(out / "revolution_azimuths.csv", azimuths, AZIMUTH_COLUMNS)
    (out / "revolution_tables.md").write_text(markdown(
        read_csv(out / "revolution.csv"), order_summary(read_csv(out / "revolution_bricks.csv"))))
    figures(out, domes_, f"mu {settings.mu:g}, accuracy {settings.accuracy}")


def figures(out, domes_=None, note="") -> None:
    """``revolution_domes.png``, ``revolution_bricks.png`` and ``revolution_lateral.png``
    in ``out``, from the study's CSVs there."""
    out = Path(out)
    domes_ = domes() if domes_ is None else domes_
    (out / "revolution_domes.png").write_bytes(domes_png(
        [d for d in domes_ if d.profile == domes_[0].profile],
        f"{domes_[0].profile}: the front half of each whole dome, seen from the front "
        f"(red: pattern bricks, orange: fill-ins)"))
    bricks = read_csv(out / "revolution_bricks.csv")
    (out / "revolution_bricks.png").write_bytes(bricks_png(
        bricks,
        f"brick-by-brick stages of the cyclic section or sector ({note})"))
    for profile in dict.fromkeys(r["profile"] for r in bricks):
        (out / f"revolution_stages_{profile.replace(' ', '')}.png").write_bytes(stages_png(
            bricks, profile, f"{profile}: the brick stages of each scanned course, cyclic "
                             f"({note})"))
    (out / "revolution_lateral.png").write_bytes(lateral_png(
        read_csv(out / "revolution.csv"), read_csv(out / "revolution_azimuths.csv"),
        f"the whole domes under a lateral load ({note})"))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="exports/revolution_study")
    parser.add_argument("--mu", type=float, default=0.7,
                        help="friction coefficient (default 0.7)")
    parser.add_argument("--accuracy", default="fast", choices=ACCURACY,
                        help="every solve (default fast)")
    parser.add_argument("--confirm", default="balanced", choices=(*ACCURACY, "none"),
                        help="the lowest failing brick course again (default balanced)")
    parser.add_argument("--figures", default=None, metavar="NOTE",
                        help="only draw the figures from the CSVs in --out, NOTE in "
                             "their titles")
    args = parser.parse_args(argv)
    try:
        validate(Params.of(mu=args.mu))
    except ParameterError as error:
        print(f"error: {error}", file=sys.stderr)
        raise SystemExit(2) from None
    if args.figures is not None:
        figures(args.out, note=args.figures)
        return
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s")
    for name in ("masonry.rbe", "masonry.stages", "masonry.pipeline"):
        logging.getLogger(name).setLevel(logging.WARNING)
    study(args.out, settings=Settings(args.mu, args.accuracy,
                                      None if args.confirm == "none" else args.confirm))


if __name__ == "__main__":
    main()
