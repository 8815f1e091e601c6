"""compas_assembly's 527-block dome (fixtures/compas/compas_assembly/dome_assembly.json):
its staggered courses overlap by design, refused by default and read with
``--overlap-tolerance``; and the overlap depth on boxes of known penetration."""

import json
from pathlib import Path

import numpy as np
import pytest

import masonry
from masonry.blocks import Blocks
from masonry.errors import ParameterError
from masonry.scenes.imported import read_blocks
from masonry.scenes.overlaps import overlapping_pairs
from masonry_cli.main import main

DOME = Path(__file__).parent.parent / "fixtures" / "compas" / "compas_assembly" / \
    "dome_assembly.json"
BLOCKS_PER_COURSE = 31
COURSES = 17


def _file_graph():
    """The dome's nodes and its own interfaces, per pair of node keys: the summed
    ``size`` (m^2) and the count (plain json)."""
    graph = json.loads(DOME.read_text())["data"]["graph"]["data"]
    interfaces = {}
    for u, neighbours in graph["edge"].items():
        for v, attributes in neighbours.items():
            sizes = [i["data"]["size"] for i in attributes.get("interfaces") or []]
            interfaces[frozenset((u, v))] = (sum(sizes), len(sizes))
    return graph["node"], interfaces


@pytest.fixture(scope="module")
def dome():
    return masonry.read(DOME, overlap_tolerance=0.02, mu=0.84)


def test_dome_refused_by_default_naming_the_option(tmp_path, capsys):
    code = main(["analyze", str(DOME), "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "dome_assembly.json" in err[0] and "992 pairs overlap" in err[0]
    assert "accept it with --overlap-tolerance 0.02" in err[0]
    assert not any(tmp_path.iterdir())


def test_dome_overlaps_are_its_staggered_bed_joints():
    # every block cuts into the two blocks of the next course that it straddles, and no
    # deeper than the sagitta r (1 - cos(pi / 31)) of its flat bed face, a chord of the
    # conical bed joint (r: the pair's largest horizontal radius); at least as deep as
    # the deepest corner of one inside the other's face planes
    blocks = read_blocks([DOME])
    pairs, depth = overlapping_pairs(blocks)
    assert len(pairs) == 2 * BLOCKS_PER_COURSE * (COURSES - 1)
    low = np.round(blocks.block_bounds[:, 0, 2], 3)
    courses = np.unique(low)
    assert len(courses) == COURSES
    course = np.searchsorted(courses, low)
    assert np.array_equal(np.abs(course[pairs[:, 0]] - course[pairs[:, 1]]),
                          np.ones(len(pairs), int))
    for (i, j), d in zip(pairs, depth):
        both = np.vstack([blocks.block_vertices(i), blocks.block_vertices(j)])
        sagitta = np.hypot(both[:, 0], both[:, 1]).max() * (1 - np.cos(np.pi / 31))
        corner = max(_corner_depth(blocks, i, j), _corner_depth(blocks, j, i))
        assert corner - 1e-12 <= d <= sagitta, (i, j)


def _corner_depth(blocks, i, j) -> float:
    """How deep the deepest vertex of block ``j`` lies inside block ``i`` (its distance
    to the nearest of ``i``'s face planes; negative when outside), metres."""
    faces = blocks.block_faces(i)
    distance = np.einsum("vfk,fk->vf", blocks.block_vertices(j)[:, None, :]
                         - blocks.face_centre[faces][None], blocks.face_normal[faces])
    return float((-distance).min(axis=1).max())


def test_dome_read_with_the_tolerance_has_the_files_blocks_and_interfaces(dome):
    nodes, interfaces = _file_graph()
    blocks = dome.blocks
    assert blocks.n_blocks == len(nodes) == BLOCKS_PER_COURSE * COURSES
    is_support = {k: bool(n.get("is_support")) for k, n in nodes.items()}
    assert int(blocks.block_is_support.sum()) == sum(is_support.values()) == 31
    key = [str(name)[len("node_"):] for name in blocks.block_name]
    found = {}
    for (i, j), area in zip(dome.interfaces.pair, dome.interfaces.area):
        pair = frozenset((key[i], key[j]))
        found[pair] = found.get(pair, 0.0) + area
    # the file's pairs but those of two supports (fixed: nothing to balance there)
    between_supports = {p for p in interfaces if all(is_support[k] for k in p)}
    assert len(between_supports) == BLOCKS_PER_COURSE
    assert set(found) == set(interfaces) - between_supports
    assert all(interfaces[p][1] == 1 for p in found)
    ours = np.array([found[p] for p in found])
    theirs = np.array([interfaces[p][0] for p in found])
    # bed joints a little larger: the staggered chord faces overlap by up to the sagitta
    np.testing.assert_allclose(ours, theirs, rtol=3e-3)
    assert dome.source["overlaps"]["pairs"] == 992
    assert 0.01 < dome.source["overlaps"]["fraction"] <= 0.02


def test_dome_stands_at_compas_cras_default_mu(dome):
    assert dome.solve().verdict == "feasible"


@pytest.mark.parametrize("value", [0.2, 0.0, float("nan"), True, "0.01"])
def test_overlap_tolerance_out_of_range_refused_before_reading(value):
    with pytest.raises(ParameterError, match="overlap_tolerance"):
        masonry.read("no-such-file.obj", support="a", overlap_tolerance=value)


def test_overlap_tolerance_option_one_line_exit_2(tmp_path, capsys):
    code = main(["analyze", "no-such-file.obj", "--support", "a", "--overlap-tolerance",
                 "0.5", "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--overlap-tolerance 0.5" in err[0]
    assert "0.1" in err[0]
    assert main(["stages", "--overlap-tolerance", "0.01", "--out", str(tmp_path)]) == 2
    assert "FILE" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("shift", [0.004, 0.02, 0.3])
def test_overlap_depth_of_boxes_is_the_penetration(shift):
    # a unit cube and a 2 m cube pushed into it by ``shift`` along x, offset in y and z
    # less than the contact: the shortest translation that parts them is ``shift``
    unit = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    corners = np.stack([unit, 2 * unit + [1 - shift, -0.4, -0.7]])
    blocks = Blocks.from_hexahedra(corners, block_class=[0, 0])
    pairs, depth = overlapping_pairs(blocks)
    assert pairs.tolist() == [[0, 1]]
    assert depth[0] == pytest.approx(shift, rel=1e-12, abs=1e-15)
    assert len(overlapping_pairs(blocks, 1.01 * shift / np.sqrt(3))[0]) == 0
