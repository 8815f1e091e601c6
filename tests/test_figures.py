"""Figures, by their layout, not their pixels: legends clear of the model, the views of
a model's extent, panels with nothing to show left out and named, the faces drawn, the
thrust line's chains, the azimuths' radius."""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.transforms import Bbox

from cli.options import figures_note
from masonry.export import RunOutputs, _force_plot_files
from masonry.params import Params, from_preset, validate
from masonry.pipeline import build_model, run, solve, Timer
from masonry.plots import (azimuths, common, forces as force_figures, mechanism, pattern,
                           stages, structure)
from masonry.plots.common import views_of
from masonry.plots.faces import hidden_faces
from masonry.plots.forces import force_pngs, interface_pngs
from masonry.plots import thrust
from masonry.plots.thrust import chains, joint_levels
from masonry.rbe.collapse import collapse_load
from masonry.rbe.loads import lateral
from masonry.rbe.resultants import interface_resultants
from masonry.scenes.base import ThrustSection
from test_collapse import DENSITY, column
from test_rbe import make_interfaces


@pytest.fixture
def figures(monkeypatch):
    """What the plot modules' figures show as each is saved (drawn and measured instead
    of turned into PNG bytes: a figure may be drawn on again for the next plot of its
    view), one namespace per figure: ``legends`` (how many legends were checked clear
    of the model and labels, :func:`_legends_clear`), ``extent`` (the polygons' extent,
    display units; None without polygons), ``data`` (the same in data units), ``xlim``,
    ``ylim``, ``area`` (the figure's, display units), ``is_3d``, ``colours`` (the face
    colours of each polygon collection)."""
    kept = []

    def keep(fig, dpi, render=None, close=True):
        fig.canvas.draw()
        ax = fig.axes[0]
        polygons = [c for c in ax.collections if isinstance(c, PolyCollection)]
        extent = _data_extent(ax) if polygons else None
        kept.append(SimpleNamespace(
            legends=_legends_clear(fig), extent=extent, xlim=ax.get_xlim(),
            ylim=ax.get_ylim(), area=fig.bbox.width * fig.bbox.height,
            data=None if extent is None else extent.transformed(ax.transData.inverted()),
            is_3d=hasattr(ax, "get_zlim"),
            colours=[c.get_facecolor().copy() for c in polygons]))
        return {"png": b"\x89PNG kept"}

    for module in (structure, mechanism, stages, azimuths, force_figures, pattern):
        monkeypatch.setattr(module, "figure_files", keep)
    yield kept
    plt.close("all")


def _model(**inputs):
    params = validate(Params.of(**inputs))
    scene, model = build_model(params)
    return params, scene, model


def _data_extent(ax) -> Bbox:
    """Where the axes' collections (the blocks, joints; a 3D one as last projected) are
    drawn, display units."""
    points = np.concatenate([c.get_transform().transform(path.vertices)
                             for c in ax.collections if isinstance(c, PolyCollection)
                             for path in c.get_paths()])
    points = points[np.isfinite(points).all(axis=1)]
    return Bbox([points.min(axis=0), points.max(axis=0)])


def _labels(ax) -> list:
    """The axes' axis labels and tick labels with text, as drawn (display units)."""
    axes = [ax.xaxis, ax.yaxis] + ([ax.zaxis] if hasattr(ax, "zaxis") else [])
    texts = [axis.label for axis in axes] + [label for axis in axes
                                             for label in axis.get_ticklabels()]
    return [text.get_window_extent() for text in texts
            if text.get_visible() and text.get_text()]


def _legends_clear(fig):
    """Every legend of ``fig`` lies clear of its axes' drawn model and labels."""
    checked = 0
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None and ax.collections:
            box = legend.get_window_extent()
            assert not box.overlaps(_data_extent(ax))
            assert not [label for label in _labels(ax) if box.overlaps(label)]
            checked += 1
    return checked


def test_structure_legends_stay_clear_of_the_blocks(figures):
    _, scene, model = _model(**{**from_preset("3").record(), "p": 4})
    pngs = structure.structure_pngs(scene, interfaces=model.interfaces)
    # every figure but the boundaries' (no blocks, no legend)
    assert sum(drawn.legends for drawn in figures) == len(figures) - 4 > 4
    assert len(figures) == len(pngs)


@pytest.mark.parametrize("inputs", [dict(scene="sector", p=6), dict(preset="3", p=4)])
def test_the_flattened_pattern_shows_every_brick_and_its_legend_clear(figures, inputs):
    """A sector's bricks reach past its outline on one side: the axes hold them all."""
    params = validate(Params.of(**{**(from_preset(inputs.pop("preset")).record()
                                      if "preset" in inputs else {}), **inputs}))
    scene, _ = build_model(params)
    pattern.pattern_png(scene)
    (drawn,) = figures
    assert drawn.legends == 1
    (left, right), (bottom, top) = drawn.xlim, drawn.ylim
    data = drawn.data
    assert left < data.x0 and data.x1 < right and bottom < data.y0 and data.y1 < top


def test_mechanism_and_stage_legends_stay_clear_of_the_blocks(figures):
    model = column(3, (0.3, 0.3, 0.4))
    result = collapse_load(model, lateral(model, 0.0, DENSITY), mu=0.9, density=DENSITY)
    mechanism.mechanism_pngs(model.blocks, model.interfaces, result, "column")
    _, scene, _ = _model(scene="arch")
    laid = scene.blocks.block_centroid[:, 2] < 2.0
    stages.marked_structure_pngs(scene, laid, laid * 100.0, "stage",
                                 is_outlined=laid & (scene.blocks.block_centroid[:, 2] > 1))
    assert sum(drawn.legends for drawn in figures) == len(figures) >= 4


@pytest.mark.parametrize("inputs, shown", [
    (dict(scene="arch"), ["01_angle", "04_side"]),  # the arch in x-z
    (dict(scene="wall"), ["01_angle", "02_front"]),  # the wall in y-z
])
def test_an_arch_and_a_wall_are_seen_face_on(figures, inputs, shown):
    """No edge-on elevation: the blocks as projected span more than a seventh of every
    elevation's figure (an arch seen edge on, a stack of rectangles: 0.09; a wall's top:
    0.04)."""
    _, scene, model = _model(**inputs)
    assert views_of(scene.blocks.bounds) == shown
    structure.structure_pngs(scene, interfaces=model.interfaces)
    elevations = [drawn for drawn in figures if not drawn.is_3d]
    assert len(elevations) == 1
    for drawn in elevations:
        assert drawn.extent.width * drawn.extent.height > 0.14 * drawn.area


def test_a_dome_keeps_its_three_elevations():
    _, scene, _ = _model(**{**from_preset("1").record(), "p": 4})
    assert views_of(scene.blocks.bounds) == list(common.VIEWS)
    assert views_of(scene.blocks.bounds, fast=True) == ["01_angle"]


def test_supports_are_drawn_apart_from_the_blocks():
    _, scene, _ = _model(scene="arch")
    colours, legend = structure.block_colours(scene.blocks, np.ones(len(scene.blocks), bool))
    support = scene.blocks.block_is_support
    assert "support" in legend and len(legend) == 2
    assert not np.isclose(colours[support][:, None], colours[~support][None]).all(
        axis=-1).any()


def test_faces_inside_the_structure_are_hidden():
    """Two boxes on a slab: the bed joint hides the lower box's top and the upper box's
    bottom, the support the lower box's bottom; the slab's top stays (half covered)."""
    model = column(2, (1.0, 1.0, 0.5))
    blocks = model.blocks
    hidden = hidden_faces(blocks, model.interfaces)
    normal_z = blocks.face_normal[:, 2]
    expected = ((blocks.face_block == 1) & (np.abs(normal_z) > 0.99)) | (
        (blocks.face_block == 2) & (normal_z < -0.99))
    assert (hidden == expected).all() and hidden.sum() == 3
    # the upper box not drawn: the lower box's top is seen
    drawn = np.array([True, True, False])
    assert hidden_faces(blocks, model.interfaces, drawn).sum() == 1


def test_a_force_with_nothing_to_show_has_no_figure_and_is_named():
    _, scene, model = _model(scene="arch")
    k = len(model.interfaces)
    forces = {"compression": np.linspace(1e3, 5e3, k), "tension": np.full(k, 1e-9),
              "normal": np.linspace(-5e3, -1e3, k), "friction": np.linspace(0, 3e2, k)}
    pngs = force_pngs(model.blocks, model.interfaces, forces, fast=True, noise=1e-3)
    assert isinstance(pngs["*/tension.png"], str) and "noise" in pngs["*/tension.png"]
    assert not [path for path in pngs if path.endswith("/tension.png") and "*" not in path]
    assert isinstance(pngs["01_angle/normal.png"], bytes)


def test_no_figure_is_drawn_in_one_colour(figures):
    """The arch's joints all have one area: their area figures are left out and named;
    every colour figure drawn colours its interfaces in more than one colour."""
    params, scene, model = _model(scene="arch")
    result = solve(model, params, Timer())
    pngs = interface_pngs(model.blocks, model.interfaces, fast=True)
    assert "cm^2" in pngs["*/interfaces_horizontal.png"] and len(pngs) == 1
    forces = result.per_interface()
    pngs = force_pngs(model.blocks, model.interfaces, forces, fast=True,
                      noise=1e-6 * result.weight_N)
    assert "noise" in pngs["*/tension.png"] and len(figures) == len(pngs) - 1 >= 3
    for drawn in figures:
        (faces,) = drawn.colours
        assert len(np.unique(faces, axis=0)) > 1


def test_a_force_the_same_on_every_interface_has_no_figure():
    _, scene, model = _model(scene="arch")
    k = len(model.interfaces)
    forces = {"compression": np.full(k, 5e3), "tension": np.zeros(k),
              "normal": np.linspace(-5e3, -1e3, k), "friction": np.full(k, 3e2)}
    pngs = force_pngs(model.blocks, model.interfaces, forces, fast=True, noise=1e-3)
    assert pngs["*/compression_horizontal.png"].endswith("every one is 5000 N")
    assert "*/friction.png" in pngs and isinstance(pngs["01_angle/normal.png"], bytes)


def test_a_feasible_run_names_its_left_out_figures(tmp_path):
    params = validate(Params.of(scene="arch"))
    record = run(params, tmp_path, analyse=True)
    skipped = record["figures"]["skipped"]
    assert "RBE/*/tension.png" in skipped and "*/1_boundaries.png" not in skipped
    folder = tmp_path / record["structure_id"]
    assert not list(folder.glob("RBE/*/tension.png"))
    assert list(folder.glob("RBE/*/normal.png"))
    lines = []
    figures_note(record, lines.append)
    assert lines and "RBE/*/tension.png" in lines[0]


def test_the_whole_dome_has_no_boundaries_figure_and_no_web_outline():
    params = validate(Params.of(scene="dome", stretch=1.0, n=6, r=0, p=3, cut=0.5))
    scene, model = build_model(params)
    made = RunOutputs(params, scene, model, solve(model, params, Timer()))
    pngs = structure.structure_pngs(scene, fast=True, interfaces=model.interfaces)
    assert isinstance(pngs["*/1_boundaries.png"], str)
    assert "01_angle/3_structure.png" in pngs
    assert "figures" not in _force_plot_files(made).files
    # one web's outline is drawn over its section, not over the whole dome
    section, _ = build_model(validate(Params.of(**{**params.record(), "scene": "section"})))
    for shown, lines in ((scene, 0), (section, 3)):
        fig, ax = plt.subplots()
        common.draw_outline(ax, "02_front", shown)
        assert len(ax.lines) == lines
        plt.close(fig)


def test_thrust_line_chains_follow_one_column_of_blocks():
    # joints as (block below, block above), in order along the section: 0-1-2-3 is a
    # column, 7-8 stands alone, 9-10-11 another column
    pairs = [(0, 1), (1, 2), (2, 3), (7, 8), (9, 10), (10, 11)]
    assert [run.tolist() for run in chains(pairs)] == [[0, 1, 2], [3], [4, 5]]
    assert chains(np.zeros((0, 2), int)) == []
    assert [run.tolist() for run in chains([(4, 5)])] == [[0]]


def test_joints_of_one_level_share_a_block_that_faces_both_the_same_way():
    up = (0.0, 0.0, 1.0)
    # bricks 1 and 2 meet at the plane on the ground 0 and carry brick 3, which carries 4
    pairs = [(0, 1), (0, 2), (1, 3), (2, 3), (3, 4)]
    label = joint_levels(pairs, [up] * 5)
    assert label[0] == label[1] and label[2] == label[3]
    assert len({label[0], label[2], label[4]}) == 3
    # an arch's crown: voussoirs 8 and 9 lean on each other, 7 under 8 and 10 under 9
    left, crown, right = (0.6, 0.0, 0.8), (1.0, 0.0, 0.0), (-0.6, 0.0, 0.8)
    assert len(set(joint_levels([(7, 8), (8, 9), (10, 9)], [left, crown, right]))) == 3


def _bed_joint(x0, y0, y1, z):
    """A bed joint 0.2 m wide in x from ``x0``, ``y0`` to ``y1``, at height ``z``."""
    return [(x0, y0, z), (x0 + 0.2, y0, z), (x0 + 0.2, y1, z), (x0, y1, z)]


def test_thrust_line_joins_levels_and_names_its_breaks(monkeypatch):
    """A column whose lowest bricks meet at the plane y = 0 (their joints only touch
    it), a joint beside the column and a joint with no normal force: one line through
    the column's three levels, the level of two joints at its joints' normal forces'
    weighted point, and each break drawn and named."""
    pairs = [(0, 1), (0, 2), (1, 3), (2, 3), (3, 4), (7, 8), (8, 9)]
    polygons = [_bed_joint(0, -0.2, 0, 0), _bed_joint(0, 0, 0.2, 0), _bed_joint(0, -0.1, 0, 0.1),
                _bed_joint(0, 0, 0.1, 0.1), _bed_joint(0, -0.1, 0.1, 0.2),
                _bed_joint(0, -0.1, 0.1, 0.3), _bed_joint(0, -0.1, 0.1, 0.4)]
    kind = [2, 2, 0, 0, 0, 0, 0]
    joints = make_interfaces(pairs, polygons, [(0, 0, 1)] * 7, kind)
    x = [0.05, 0.15, 0.1, 0.1, 0.25, 0.1, np.nan]
    point = np.column_stack([x, [-0.1, 0.1, -0.05, 0.05, 0, 0, np.nan], joints.centre[:, 2]])
    resultants = {"sigma": np.array([1.0, 3.0, 2.0, 2.0, 4.0, 1.0, 0.0]), "point": point}
    kept = []
    monkeypatch.setattr(thrust, "figure_files", lambda fig, dpi, render: kept.append(fig))
    section = ThrustSection(0.0, 2, (-1.0, 0.0), False, "y = 0 m")
    thrust.thrust_line_png(joints, resultants, section)
    ax = kept[0].axes[0]
    line = [ln for ln in ax.lines if ln.get_linestyle() == "-" and ln.get_marker() == "o"]
    assert len(line) == 1
    # the ground level's point: (0.05 * 1 + 0.15 * 3) / 4
    np.testing.assert_allclose(line[0].get_xydata(), [[0.125, 0], [0.1, 0.1], [0.25, 0.2]],
                               atol=1e-12)
    marks = {ln.get_label(): ln.get_xydata() for ln in ax.lines}
    alone = next(v for k, v in marks.items() if "no block joins it" in k)
    empty = next(v for k, v in marks.items() if "no normal force" in k)
    outside = next(v for k, v in marks.items() if "leaves the section" in k)
    np.testing.assert_allclose(alone, [[0.1, 0.3]], atol=1e-12)
    np.testing.assert_allclose(empty, [[0.1, 0.4]], atol=1e-12)  # the joint's middle
    np.testing.assert_allclose(outside, [[0.25, 0.2]], atol=1e-12)  # 0.05 m beyond its end
    legend = [t.get_text() for t in kept[0].legends[0].get_texts()]
    assert sum("no block joins it" in t or "no normal force" in t for t in legend) == 2
    title = ax.get_title()
    assert "5 levels" in title and "7 joints" in title and "1 joint off the column" in title
    assert "1 joint without force" in title and "1 outside" in title
    plt.close("all")


def test_thrust_line_of_an_arch_runs_through_every_joint(monkeypatch):
    params = validate(Params.of(scene="arch"))
    scene, model = build_model(params)
    result = solve(model, params, Timer())
    resultants = interface_resultants(model.interfaces, result.layout, result.x)
    kept = []
    monkeypatch.setattr(thrust, "figure_files", lambda fig, dpi, render: kept.append(fig))
    thrust.thrust_line_png(model.interfaces, resultants, scene.kind.thrust_section(scene))
    ax = kept[0].axes[0]
    line = [ln for ln in ax.lines if ln.get_linestyle() == "-" and ln.get_marker() == "o"]
    # one line, springing to springing: N voussoirs have N + 1 joints, left to right
    assert len(line) == 1 and len(line[0].get_xdata()) == params.geometry.arch_blocks + 1
    assert np.all(np.diff(line[0].get_xdata()) > 0)
    plt.close("all")


def test_the_azimuths_radius_starts_near_the_smallest_factor(figures):
    factors = [0.79, 0.80, 0.82, 0.81, 0.795, 0.80]
    collapse = SimpleNamespace(azimuths=[(30.0 * k, f) for k, f in enumerate(factors)],
                               azimuth_deg=0.0, load_factor=0.79, refined=())
    azimuths.azimuths_png(collapse)
    low, high = figures[0].ylim
    assert 0.7 < low < 0.79 and 0.82 < high < 0.85


def _sweep_figures(monkeypatch, swept, rows):
    """The summary figures of ``rows``, kept as drawn: ``{file name: figure}``."""
    from masonry.plots import sweep as sweep_figures

    kept, names = [], []

    def keep(fig, dpi, render):
        kept.append(fig)
        return {}

    monkeypatch.setattr(sweep_figures, "figure_files", keep)
    monkeypatch.setattr(sweep_figures, "as_files", lambda path, files: names.append(path) or {})
    sweep_figures.summary_figures(swept, rows, "study")
    return dict(zip(names, kept))


def _row(variant, status="computed", error="", **inputs):
    return {**inputs, "variant": variant, "status": status, "error": error,
            "feasible": None if status == "failed" else True,
            "moi_factor": None if status == "failed" else 0.0,
            "load_factor": None if status == "failed" else 0.5}


def test_sweep_plots_tell_every_swept_input_apart_and_name_why_a_variant_failed(
        monkeypatch):
    """A 2 x 2 x 2 study whose variants all have the same result, one failed: the
    legend lists every value of the other inputs, the series differ in colour and
    marker, and the failed variant is a cross at its value with its reason."""
    reason = "ParameterError: invalid parameter point_loads='x': expected a free block"
    rows = [_row(k, mu=mu, stretch=stretch, pattern=pattern)
            for k, (mu, stretch, pattern) in enumerate(
                (m, s, p) for m in (0.5, 0.7) for s in (0.8, 1.2)
                for p in ("herringbone", "none"))]
    rows[5] = _row(5, "failed", reason + "\nTraceback ...", **{
        k: rows[5][k] for k in ("mu", "stretch", "pattern")})
    figures = _sweep_figures(monkeypatch, ["mu", "stretch", "pattern"], rows)
    assert set(figures) == {f"{y}_{x}.png" for y in ("moi_factor", "load_factor")
                            for x in ("mu", "stretch", "pattern")}
    for fig in figures["moi_factor_mu.png"], figures["load_factor_mu.png"]:
        legend = [t.get_text() for t in fig.legends[0].get_texts()]
        assert {"stretch = 0.8", "stretch = 1.2", 'pattern = herringbone',
                "pattern = none"} <= set(legend)
        assert "failed (1): " + reason in [t.replace("\n", " ") for t in legend]
    fig = figures["moi_factor_mu.png"]
    top = fig.axes[0]
    series = [ln for ln in top.lines if ln.get_marker() != "X"]
    # four series (stretch x pattern), each told apart by colour and marker
    assert len({(tuple(ln.get_color()), ln.get_marker()) for ln in series}) == 4
    # where their points coincide, each ring is another size
    assert len({ln.get_markersize() for ln in series}) == 4
    crosses = [ln for ln in top.lines if ln.get_marker() == "X"]
    assert len(crosses) == 1 and crosses[0].get_xdata().tolist() == [0.7]
    assert any(t.get_text() == "1" for t in top.texts)
    strip = fig.axes[1]
    assert [t.get_text() for t in strip.get_yticklabels()] == ["failed", "infeasible",
                                                              "feasible"]
    plt.close("all")


def test_a_sampled_input_is_a_colour_scale_with_its_bar(monkeypatch):
    density = [1500.0 + 100 * k for k in range(10)]
    rows = [_row(k, mu=mu, density=d) for k, (mu, d) in enumerate(
        (m, d) for m in (0.5, 0.7) for d in density)]
    fig = _sweep_figures(monkeypatch, ["mu", "density"], rows)["moi_factor_mu.png"]
    bars = [ax for ax in fig.axes if ax.get_ylabel() == "density"]
    assert len(bars) == 1 and bars[0].get_ylim() == (1500.0, 2400.0)
    assert "not told apart" not in fig.axes[0].get_title()
    plt.close("all")
