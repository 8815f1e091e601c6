"""Interfaces of the dome section (docs/model.md 5 on the model of docs/model.md 4)."""

import functools

import numpy as np
import pytest
from conftest import PRESETS, scene_of
from scipy.spatial import cKDTree

from masonry.blocks import BLOCK_CLASSES
from masonry.interfaces import INTERFACE_KINDS, detect

PATTERN = BLOCK_CLASSES.index("pattern")
HORIZONTAL, VERTICAL, SUPPORT = (INTERFACE_KINDS.index(k)
                                 for k in ("horizontal", "vertical", "support"))


@functools.lru_cache(maxsize=None)
def interfaces_of(preset):
    scene = scene_of(preset)
    return detect(scene.blocks, up=scene.block_up)


@pytest.mark.parametrize("preset", PRESETS)
def test_nothing_floats(preset):
    blocks, itf = scene_of(preset).blocks, interfaces_of(preset)
    bed = np.isin(itf.kind, [HORIZONTAL, SUPPORT])
    # the main block of a bed joint is the lower one: every free brick is 'other' once
    supported = np.zeros(blocks.n_blocks, bool)
    supported[itf.pair[bed, 1]] = True
    assert np.all(supported | blocks.block_is_support)
    # and every bed joint's normal points up along the upper brick's course
    up = scene_of(preset).block_up[itf.pair[bed, 1]]
    assert np.all(np.einsum("ij,ij->i", itf.normal[bed], up) > np.cos(np.radians(10)))


@pytest.mark.parametrize("preset", PRESETS)
def test_pattern_bricks_meet_their_neighbours_on_both_courses(preset):
    scene, itf = scene_of(preset), interfaces_of(preset)
    blocks = scene.blocks
    course = blocks.block_course
    top = course + (blocks.block_class == PATTERN)  # the last course a brick spans
    for b in np.flatnonzero(blocks.block_class == PATTERN):
        side = (itf.kind == VERTICAL) & (itf.pair == b).any(axis=1)
        other = np.where(itf.pair[side, 0] == b, itf.pair[side, 1], itf.pair[side, 0])
        for c in (course[b], course[b] + 1):
            assert np.any((course[other] <= c) & (top[other] >= c)), (b, c)
        below = (itf.pair[:, 1] == b) & np.isin(itf.kind, [HORIZONTAL, SUPPORT])
        assert below.any()


@pytest.mark.parametrize("preset", PRESETS)
def test_interfaces_are_mirror_symmetric(preset):
    itf = interfaces_of(preset)
    mirrored = itf.centre * [1, -1, 1]
    distance, twin = cKDTree(itf.centre).query(mirrored)
    assert distance.max() < 1e-9
    np.testing.assert_allclose(itf.area[twin], itf.area, rtol=1e-9)
    np.testing.assert_array_equal(itf.kind[twin], itf.kind)
    counts = itf.counts()
    assert counts["horizontal"] > counts["support"] > 0 and counts["vertical"] > 0


def test_rigid_motion_keeps_the_dome_interfaces():
    scene = scene_of("1")
    rng = np.random.default_rng(7)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    motion = np.eye(4)
    motion[:3, :3] = q * np.sign(np.linalg.det(q))
    motion[:3, 3] = rng.normal(size=3) * 10
    moved = scene.blocks.transformed(motion)
    before = interfaces_of("1")
    after = detect(moved, up=scene.block_up @ motion[:3, :3].T)
    assert after.counts() == before.counts()
    key = lambda itf: sorted(zip(map(tuple, np.sort(itf.pair, axis=1)), itf.area))  # noqa: E731
    for (pair_a, area_a), (pair_b, area_b) in zip(key(before), key(after)):
        assert pair_a == pair_b
        assert area_b == pytest.approx(area_a, rel=1e-9)


@pytest.mark.parametrize("preset", PRESETS)
def test_ground_contacts_cover_the_first_course(preset):
    scene, itf = scene_of(preset), interfaces_of(preset)
    blocks = scene.blocks
    ground = itf.kind == SUPPORT
    first = np.flatnonzero(blocks.block_course == 1)
    assert set(itf.pair[ground, 1]) == set(first)
    # every first-course brick stands on the ground with its whole bottom face
    bottom = blocks.face_area[6 * first + 4]
    np.testing.assert_allclose(np.sort(itf.area[ground]), np.sort(bottom), rtol=1e-9)
