"""The plain dome (docs/model.md 4.9): the herringbone dome's courses without pattern
bricks; and what small ``p`` does to the pattern (docs/model.md 4.3)."""

import json

import numpy as np
import pytest
from conftest import PRESETS, scene_of

from masonry.blocks import BLOCK_CLASSES
from masonry.dome.levels import Dimensions, level_table
from masonry.dome.pattern import build_pattern
from masonry.errors import ParameterError
from masonry.params import Params, from_preset, structure_id, validate
from masonry.pipeline import model_record
from masonry.tolerances import PATTERN_END_REPORTED
from masonry_cli.main import main

PATTERN = BLOCK_CLASSES.index("pattern")
U = 0.1  # the presets' unit, metres


def plain(preset, **overrides):
    return scene_of(preset, pattern="none", **overrides)


# ---------------------------------------------------------------------------- bricks
@pytest.mark.parametrize("preset", PRESETS)
def test_a_plain_dome_has_no_pattern_brick(preset):
    scene = plain(preset)
    assert not np.any(scene.blocks.block_class == PATTERN)
    assert len(scene.pattern) == 0
    record = model_record(scene, 2000.0)
    assert record["counts"]["pattern"] == 0 and record["pattern"]["lines"] == 0
    assert record["counts"]["regular"] > 0.75 * record["counts"]["bricks"]


@pytest.mark.parametrize("preset", PRESETS)
def test_a_plain_dome_lays_the_herringbone_domes_courses(preset):
    herringbone, scene = scene_of(preset), plain(preset)
    dims = Dimensions.of(scene.geometry)
    assert scene.levels.n_courses == herringbone.levels.n_courses
    for name in ("theta", "x", "y", "z", "gamma_reg"):
        np.testing.assert_array_equal(getattr(scene.levels, name),
                                      getattr(herringbone.levels, name), err_msg=name)
    # every course brick's inner edges lie on the intrados one unit apart: its bed joints
    # run through the contact points of its course, in both domes
    for dome in (scene, herringbone):
        blocks, classes = dome.blocks, dome.blocks.block_class
        bricks = np.flatnonzero((blocks.block_course > 0) & (classes != PATTERN))
        corners = blocks.vertices.reshape(-1, 8, 3)[bricks]
        bottom, top = corners[:, 0, [0, 2]], corners[:, 4, [0, 2]]  # inner edges (x, z)
        for point in (bottom, top):
            np.testing.assert_allclose((point[:, 0] / dims.a) ** 2
                                       + (point[:, 1] / dims.c) ** 2, 1.0, rtol=1e-9)
        np.testing.assert_allclose(np.hypot(*(top - bottom).T), U, rtol=1e-9)
    # ... and the two domes' bed joints per course are the same planes
    for k in range(1, scene.levels.n_courses + 1):
        planes = []
        for dome in (scene, herringbone):
            blocks = dome.blocks
            ids = np.flatnonzero((blocks.block_course == k) & (blocks.block_class != PATTERN))
            corners = blocks.vertices.reshape(-1, 8, 3)[ids]
            up = dome.block_up[ids]
            offset = np.einsum("ij,ij->i", up, corners[:, 4])  # top face: n . p
            planes.append((up, offset))
        (up, offset), (up_h, offset_h) = planes
        np.testing.assert_allclose(up, np.broadcast_to(up_h[0], up.shape), atol=1e-12)
        np.testing.assert_allclose(offset, offset_h[0], rtol=0, atol=1e-12)


def course_volumes(levels, n):
    """(L,) m^3: the volume of each course of a web, from its contact points alone: a
    rectangle two units deep and one unit high along the course's chord, swept between
    the corner planes ``y = +-x tan(pi/n)`` (its width at the rectangle's centroid)."""
    x, z = levels.x, levels.z
    gamma = np.arctan2(x[:-1] - x[1:], z[1:] - z[:-1])
    centroid_x = x[:-1] + U * np.cos(gamma) - U / 2 * np.sin(gamma)
    return (2 * U) * U * 2 * centroid_x * np.tan(np.pi / n)


@pytest.mark.parametrize("preset", PRESETS)
def test_a_plain_domes_bricks_fill_its_courses_exactly(preset):
    scene = plain(preset)
    blocks, levels = scene.blocks, scene.levels
    expected = course_volumes(levels, scene.geometry.n)
    per_course = np.bincount(blocks.block_course[1:], weights=blocks.block_volume[1:],
                             minlength=levels.n_courses + 1)[1:]
    np.testing.assert_allclose(per_course, expected, rtol=1e-12)


@pytest.mark.parametrize("preset", PRESETS)
def test_the_herringbone_dome_is_the_plain_dome_and_its_pattern_bricks_outer_halves(preset):
    # a pattern brick is 4 units deep where a course is 2: its outer half (depth 2 to 4
    # units, the two-course chord high, swept to its ends or the corner planes) is what
    # the pattern adds to the courses
    herringbone, scene = scene_of(preset), plain(preset)
    layout, levels, tan = herringbone.layout, herringbone.levels, np.tan(np.pi / scene.geometry.n)
    pattern = layout.klass == PATTERN
    k = layout.course[pattern]
    height, gamma = levels.pattern_height[k - 1], levels.gamma_pat[k - 1]
    centroid_x = levels.x[k - 1] + 3 * U * np.cos(gamma) - height / 2 * np.sin(gamma)
    y0 = np.where(layout.miter_left[pattern], -centroid_x * tan, layout.s0[pattern] * U)
    y1 = np.where(layout.miter_right[pattern], centroid_x * tan, layout.s1[pattern] * U)
    outer = np.sum(2 * U * height * (y1 - y0))
    total = herringbone.blocks.block_volume[1:].sum()
    # a pattern brick's inner half is straight along its two-course chord where the two
    # courses bend at the contact point between: slivers of under 1e-4 of the volume
    assert total - outer == pytest.approx(course_volumes(levels, scene.geometry.n).sum(),
                                          rel=1e-4)
    assert total - outer == pytest.approx(scene.blocks.block_volume[1:].sum(), rel=1e-4)


def repeated_joints(layout):
    """Per course, its joints (the ends of bricks inside the course, not the course's
    ends) within one unit of a joint of the course below, counted from the bricks."""
    repeats, joints = [], 0
    below = np.zeros(0)
    for k in range(1, layout.course.max() + 1):
        mine = (layout.course == k) & (layout.klass != PATTERN)
        ends = np.sort(np.concatenate([layout.s0[mine], layout.s1[mine]]))
        pattern = (layout.klass == PATTERN) & ((layout.course == k) | (layout.course == k - 1))
        cells = np.concatenate([layout.s0[pattern], layout.s1[pattern]])
        inner = ends[(ends > ends.min()) & (ends < ends.max())]
        here = np.unique(np.round(inner[~np.isin(np.round(inner, 9), np.round(cells, 9))],
                                  9))
        near = (np.abs(here[:, None] - below[None, :]).min(axis=1) < 1 - 1e-9
                if len(below) and len(here) else np.zeros(len(here), bool))
        repeats.append(int(near.sum()))
        joints += len(here)
        below = here
    return np.array(repeats), joints


@pytest.mark.parametrize("pattern", ("herringbone", "none"))
@pytest.mark.parametrize("preset", PRESETS)
def test_joints_are_staggered_in_both_domes(preset, pattern):
    layout = scene_of(preset, pattern=pattern).layout
    repeats, joints = repeated_joints(layout)
    assert joints > 100
    assert repeats.sum() <= 0.02 * joints
    np.testing.assert_array_equal(layout.repeated_joints, repeats)


def test_a_plain_course_is_running_bond_between_its_mitered_ends():
    layout = plain("1").layout
    for k in range(1, layout.course.max() + 1):
        row = layout.course == k
        s0, s1 = layout.s0[row], layout.s1[row]
        assert layout.miter_left[row][0] and layout.miter_right[row][-1]
        assert not layout.miter_left[row][1:].any() and not layout.miter_right[row][:-1].any()
        np.testing.assert_allclose(s0[1:], s1[:-1], atol=1e-12)  # edge to edge
        np.testing.assert_allclose(s0, -s1[::-1], atol=1e-12)  # mirror-symmetric


# ---------------------------------------------------------------------------- inputs
def test_the_pattern_is_named_in_the_structure_id_only_when_there_is_none():
    assert structure_id(from_preset("1")) == "dome0_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1"
    assert structure_id(from_preset("1", pattern="none")).endswith("_u0.1_patnone")
    assert structure_id(from_preset("1", min_fill=2.0, pattern="none")).endswith(
        "_u0.1_mf2_patnone")
    with pytest.raises(ParameterError, match="herringbone, none") as error:
        from_preset("1", pattern="plain")
    assert error.value.name == "pattern"
    with pytest.raises(ParameterError) as error:
        validate(Params.of(scene="wall", pattern="none"))
    assert error.value.name == "pattern"


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("r", (0, 1, 2, 3))
def test_one_pattern_brick_per_side_ends_every_corner_line_on_the_first_course(preset, r):
    # why p = 1 is refused: whatever the profile, the lines that leave the corners lay
    # no brick above the first course; with r = 1 no pattern is left above it
    def pattern_of(p):
        geometry = from_preset(preset, pattern="none", p=p, r=r).geometry
        return build_pattern(level_table(geometry).y[1:] / geometry.unit, p, r)

    one, two = pattern_of(1), pattern_of(2)
    corner_lines = (0, 2 * r + 1)  # the first and the last line leave the corners
    for line in corner_lines:
        assert one.course[one.line == line].tolist() == [1]
        assert two.course[two.line == line].max() > 1  # two bricks per side go on
    if r == 1:
        assert set(one.course) == {1}


@pytest.mark.parametrize("r", (0, 1, 4))
def test_p_1_is_refused_with_the_pattern_and_built_without_it(r):
    with pytest.raises(ParameterError, match="herringbone pattern") as error:
        from_preset("1", p=1, r=r)
    assert error.value.name == "p" and error.value.value == 1
    if r == 0:
        return  # too small a dome for its bricks either way (wedges), refused by p too
    scene = plain("1", p=1, r=r)
    assert scene.levels.n_courses >= 10 and not np.any(scene.blocks.block_class == PATTERN)


def test_p_1_on_the_command_line_gets_one_line_naming_it(tmp_path, capsys):
    assert main(["run", "--preset", "2", "--p", "1", "--out", str(tmp_path / "o")]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("masonry: error: --p 1: expected an integer >= 2 for the "
                           "herringbone pattern")
    assert "--pattern none" in line
    assert not (tmp_path / "o").exists()


def test_lines_that_end_far_below_the_top_are_reported(tmp_path, capsys):
    # preset 1 with two bricks per rhombus side: the corner lines end halfway up
    params = from_preset("1", p=2)
    scene = scene_of("1", p=2)
    top = scene.levels.n_courses
    last = {line: scene.pattern.course[scene.pattern.line == line].max()
            for line in np.unique(scene.pattern.line)}
    low = sorted(k for k in last.values() if k < PATTERN_END_REPORTED * (top - 1))
    assert low == [8, 8] and top == 17
    record = model_record(scene, params.analysis.density)
    assert sorted(k for k, _ in record["pattern"]["ended_far_below_top"]) == low
    assert main(["build", "--preset", "1", "--p", "2", "--no-plots", "--no-printable",
                 "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert ("note: 2 of 4 pattern lines end far below the top course 17, on course 8: "
            in out)
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.name.startswith(".")]
    saved = json.loads((folder / "run.json").read_text())["pattern"]
    assert saved["ended_far_below_top"] == record["pattern"]["ended_far_below_top"]
    # lines that end near the top, where the web has narrowed, are not reported
    assert model_record(scene_of("3"), 2000.0)["pattern"]["ended_far_below_top"] == []
    small = scene_of("1", p=3, r=0)  # two lines end on course 9 of 11
    assert small.pattern.ended[:, 0].tolist() == [9, 9] and small.levels.n_courses == 11
    assert model_record(small, 2000.0)["pattern"]["ended_far_below_top"] == []
    assert main(["build", "--preset", "3", "--no-plots", "--no-printable",
                 "--out", str(tmp_path)]) == 0
    assert "note:" not in capsys.readouterr().out


# ---------------------------------------------------------------------------- commands
@pytest.mark.slow
def test_build_writes_a_plain_dome(tmp_path, capsys):
    assert main(["build", "--preset", "1", "--pattern", "none", "--fast", "--no-printable",
                 "--out", str(tmp_path), "-q"]) == 0
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.name.startswith(".")]
    assert folder.name == "dome1_fast1_fricauto_s1_n8_r1_p10_c0.1_u0.1_patnone"
    assert (folder / "00_pattern.png").stat().st_size > 10_000
    text = (folder / "00_parameters.txt").read_text()
    assert "pattern = none" in text
    record = json.loads((folder / "run.json").read_text())
    assert record["params"]["pattern"] == "none" and record["counts"]["pattern"] == 0
    assert record["counts"]["courses"] == scene_of("1").levels.n_courses
    assert "0 pattern" in capsys.readouterr().out


def test_the_pattern_figure_says_there_is_none():
    scene = plain("1")
    assert "no pattern" in scene.kind.pattern_caption(scene.geometry)
    assert "no pattern" not in scene_of("1").kind.pattern_caption(scene_of("1").geometry)


def test_a_study_and_the_python_interface_take_the_pattern(tmp_path):
    import masonry
    from masonry.studies.study_file import load_study

    path = tmp_path / "study.toml"
    path.write_text('[base]\npreset = 1\n[grid]\npattern = ["herringbone", "none"]\n')
    study = load_study(path)
    assert [v["pattern"] for v in study.variants()] == ["herringbone", "none"]
    structure = masonry.build(preset="1", pattern="none")
    assert structure.id.endswith("_patnone")
    assert not np.any(structure.blocks.block_class == PATTERN)
    with pytest.raises(ParameterError):
        masonry.build(preset="1", pattern="plain")
