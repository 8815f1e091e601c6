"""Figures: units and colour scales chosen by the data, and the thrust line's points."""

import os

import matplotlib
import numpy as np
import pytest

from masonry import forking
from masonry.export.csv import tension_top
from masonry.pipeline import build_model
from masonry.params import Params, from_preset, validate
from masonry.plots import (COLOUR_PERCENTILE, VIEWS, azimuths_png, colour_scale, force_unit,
                           mechanism_pngs)
from masonry.plots.failure import _rank_labels
from masonry.scenes import build
from masonry.rbe.collapse import collapse_load
from masonry.rbe.lateral_search import worst_lateral
from masonry.rbe.loads import lateral, point_loads
from masonry.tolerances import TENSION_REPORTED_REL
from test_collapse import DENSITY, SMALL_DOME, column


@pytest.mark.parametrize("magnitude, unit", [(12.0, "N"), (999.0, "N"), (1e3, "kN"),
                                             (4.39e4, "kN"), (2.5e6, "MN")])
def test_force_unit_by_magnitude(magnitude, unit):
    factor, got = force_unit(magnitude)
    assert got == unit and 1 <= magnitude * factor < 1000


def test_sequential_scale_ends_at_the_percentile_and_counts_the_rest():
    rng = np.random.default_rng(0)
    values = np.concatenate([rng.uniform(0, 2e3, 990), np.full(10, 4e4)])  # 10 supports
    scale = colour_scale(values, signed=False)
    assert scale["unit"] == "kN" and scale["factor"] == 1e-3
    top = np.percentile(values, COLOUR_PERCENTILE)
    assert scale["norm"].vmin == 0 and scale["norm"].vmax == pytest.approx(top * 1e-3)
    assert scale["above"] == (values > top).sum() and scale["below"] == 0
    assert scale["extend"] == "max"
    assert scale["largest"] == pytest.approx(40.0)
    assert scale["cmap"].name == "viridis"


def test_signed_scale_is_symmetric_about_zero_on_a_diverging_map():
    values = np.array([-5e3, -1e3, 0.0, 2e2, 3e3])
    scale = colour_scale(values, signed=True)
    assert scale["norm"].vmin == -scale["norm"].vmax
    assert scale["norm"](0.0) == pytest.approx(0.5)
    assert scale["cmap"].name == "RdBu_r"
    # zero is the map's middle, white
    assert np.allclose(scale["cmap"](0.5)[:3], matplotlib.colormaps["RdBu_r"](0.5)[:3])
    # beyond the range's two ends, counted apart (the bar's two arrows)
    wide = np.concatenate([np.linspace(-1e3, 1e3, 996), [-9e4, -8e4, 7e4, 6e4]])
    scale = colour_scale(wide, signed=True)
    top = np.percentile(np.abs(wide), COLOUR_PERCENTILE)
    assert (scale["above"], scale["below"]) == ((wide > top).sum(), (wide < -top).sum())
    assert scale["extend"] == "both"


def test_signed_scale_of_one_sign_keeps_that_half_of_the_map():
    """No tension anywhere (rounding aside): the bar runs from the largest compression to
    zero, in the blue half of the map, zero white at its end."""
    values = np.array([-5e3, -1e3, -2e2, 1e-9, 0.0])
    scale = colour_scale(values, signed=True)
    full = matplotlib.colormaps["RdBu_r"]
    assert scale["norm"].vmax == 0 and scale["norm"].vmin == pytest.approx(
        -np.percentile(np.abs(values), COLOUR_PERCENTILE) * 1e-3)
    assert np.allclose(scale["cmap"](1.0), full(0.5), atol=0.01)
    assert np.allclose(scale["cmap"](0.0), full(0.0), atol=0.01)
    tension = colour_scale(-values, signed=True)
    assert tension["norm"].vmin == 0 and np.allclose(tension["cmap"](0.0), full(0.5),
                                                     atol=0.01)


def test_all_zero_values_still_have_a_scale():
    scale = colour_scale(np.zeros(5), signed=False)
    assert scale["norm"].vmax > scale["norm"].vmin and scale["above"] == 0


def test_tension_top_orders_by_tension_and_drops_solver_noise():
    weight = 1e5
    tension = np.array([0.0, 30.0, 1e-3, 500.0, 30.0, 2 * TENSION_REPORTED_REL * weight])
    top = tension_top({"tension": tension}, weight, count=4)
    assert top.tolist() == [3, 1, 4, 5]
    assert tension_top({"tension": np.full(3, 1e-3)}, weight).tolist() == []


def test_mid_plane_cuts_a_joint_where_its_edges_cross_it():
    from test_rbe import make_interfaces

    from masonry.plots.thrust import _cut_at_y

    # a joint tilted about y: (0, -1, 0) .. (1, 1, 0.5), cut at y = 0.25
    square = np.array([[0, -1, 0], [1, -1, 0.5], [1, 1, 0.5], [0, 1, 0]], float)
    normal = np.cross(square[1] - square[0], square[2] - square[1])
    joint = make_interfaces([(0, 1)], [square], [normal / np.linalg.norm(normal)], 0)
    segment = _cut_at_y(joint, [0], 0.25)[0]
    np.testing.assert_allclose(sorted(segment.tolist()), [[0, 0.25, 0], [1, 0.25, 0.5]],
                               atol=1e-15)


def test_cyclic_runs_get_whole_dome_views():
    from masonry.export import RunOutputs
    from masonry.interfaces import detect
    from masonry.plots import force_pngs, structure_pngs

    cyclic, free = (validate(from_preset("3", boundary=b, p=4)) for b in ("cyclic", "free"))
    scene = build(cyclic)
    webs = RunOutputs(cyclic, scene, None).webs
    assert webs == 4 and RunOutputs(free, scene, None).webs is None
    interfaces = detect(scene.blocks, up=scene.block_up)
    forces = {key: np.ones(len(interfaces)) for key in
              ("compression", "tension", "normal", "t1", "t2", "friction")}
    assert {"05_dome/normal.png", "05_dome/tension.png"} <= set(
        force_pngs(scene.blocks, interfaces, forces, fast=True, webs=webs))
    assert "05_dome/3_structure.png" in structure_pngs(scene, fast=True, webs=webs)
    assert not any(k.startswith("05_dome") for k in structure_pngs(scene, fast=True))


def test_rank_labels_of_neighbouring_interfaces_share_one_label():
    bounds = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])  # 3 % of the diagonal: 0.3
    centres = np.array([[0.0, 0, 0], [5.0, 0, 0], [0.2, 0, 0], [9.0, 0, 0], [5.29, 0, 0]])
    labels = _rank_labels(centres, bounds)
    assert [text for text, _ in labels] == ["1, 3", "2, 5", "4"]
    assert np.allclose(labels[1][1], [5.0, 0, 0])


@pytest.mark.parametrize("load", ["lateral", "point", "push and pull"])
def test_mechanism_plots_are_written_in_the_views_of_the_model(load):
    model = column(2, (0.1, 0.3, 0.15))
    specs = {"point": ["b1:100,0,0"], "push and pull": ["b0:100,0,0", "b1:-100,0,0"]}
    live = (lateral(model, 0.0, DENSITY) if load == "lateral"
            else point_loads(model.blocks, specs[load]))
    result = collapse_load(model, live, mu=0.9, density=DENSITY)
    pngs = mechanism_pngs(model.blocks, model.interfaces, result, "column")
    # the ground slab, 2 m square and 0.1 m thick, sets the extent: the 3D view and the
    # top at least (an elevation only where the mechanism lifts the blocks enough)
    assert {"collapse/01_angle_mechanism.png", "collapse/03_top_mechanism.png"} <= set(pngs)
    assert {f"collapse/{view}_mechanism.png" for view in VIEWS} >= set(pngs)
    assert all(png.startswith(b"\x89PNG") for png in pngs.values())


def test_the_azimuth_search_is_drawn_on_polar_axes():
    params = validate(Params.of(scene="dome", **SMALL_DOME))
    worst = worst_lateral(build_model(params)[1], n_webs=6, period_deg=60.0)
    assert len(worst.azimuths) >= 24
    assert azimuths_png(worst)["png"].startswith(b"\x89PNG")



def _font_file_offsets():
    """{descriptor: offset} of the font files this process holds open."""
    offsets = {}
    for name in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink(f"/proc/self/fd/{name}")
        except OSError:  # closed meanwhile (the listing's own descriptor)
            continue
        if target.endswith((".ttf", ".otf")):
            offsets[int(name)] = os.lseek(int(name), 0, os.SEEK_CUR)
    return offsets


def _arrow_marker():
    """The mechanism plot's arrow marker's outline: glyphs loaded through the font of
    mathtext's cached parse."""
    from matplotlib.textpath import TextPath

    return TextPath((0, 0), r"$\rightarrow$", size=8).vertices


@pytest.mark.skipif(not forking.can_fork() or not os.path.isdir("/proc/self/fd"),
                    reason="needs fork and /proc")
def test_a_forked_process_draws_without_moving_the_font_files_of_the_one_that_forked_it():
    """Two processes that read glyphs through one open font file move each other's file
    offset, and a glyph loads from the wrong bytes ("failed to load glyph"): the process
    that forks keeps its offsets whatever the forked one draws, here an arrow marker it
    drew before the fork (mathtext keeps that parse's fonts)."""
    from matplotlib.textpath import TextPath

    import masonry.plots  # noqa: F401 (what the run's forked exporters import first)

    arrow = _arrow_marker()
    TextPath((0, 0), r"$\mathrm{abc}$", size=8)  # the font's file read elsewhere
    before = _font_file_offsets()
    assert before, "no font file open: the test reads no glyph"
    with forking.Forked([_arrow_marker]) as forked:
        assert np.array_equal(forked.result(), arrow)
    assert _font_file_offsets() == before
