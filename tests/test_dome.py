"""Dome mode: boundary conditions of a section against the full dome (docs/model.md 6.4)."""

import functools

import numpy as np
import pytest
from conftest import PRESETS, support_force

from masonry.blocks import BLOCK_CLASSES
from masonry.rbe.boundary import analysis_model
from masonry.interfaces import INTERFACE_KINDS
from masonry.params import from_preset
from masonry.scenes import build
from masonry.rbe.solve import solve_rbe

BOUNDARY, SUPPORT = INTERFACE_KINDS.index("boundary"), INTERFACE_KINDS.index("support")
PATTERN = BLOCK_CLASSES.index("pattern")

# small domes for the symmetry test: (n, p, r), unit 0.1, preset 1's stretch and cut;
# the smallest whose course wedges stay under max_gap_angle (9.5, 9.5, 8.8 degrees)
SMALL = {3: (3, 3, 1), 4: (4, 3, 1), 8: (8, 3, 0)}


@functools.lru_cache(maxsize=None)
def analysed(friction="auto", lp_check=False, **params):
    p = from_preset("1", **params)
    scene = build(p)
    model = analysis_model(scene, p.analysis.boundary)
    result = solve_rbe(model.blocks, model.interfaces, mu=p.analysis.mu, friction=friction,
                       lp_check=lp_check, side_block=model.side_block,
                       side_rotation=model.side_rotation)
    return scene, model, result


@pytest.mark.parametrize("n, pattern", [(n, "herringbone") for n in sorted(SMALL)]
                         + [(4, "none"), (8, "none")])
def test_cyclic_section_equals_full_dome(n, pattern):
    n, p, r = SMALL[n]
    plain = {} if pattern == "herringbone" else {"pattern": pattern}  # the cache's key
    section, cyclic, part = analysed(n=n, p=p, r=r, boundary="cyclic", **plain)
    _, dome, whole = analysed(n=n, p=p, r=r, scene="dome", **plain)
    assert (section.layout.klass == PATTERN).any() == (pattern == "herringbone")
    assert whole.friction == part.friction and whole.feasible == part.feasible
    assert whole.objective == pytest.approx(n * part.objective, rel=1e-6)
    assert whole.moi == pytest.approx(n * part.moi, rel=1e-5, abs=1e-6 * whole.weight_N)
    assert whole.weight_N == pytest.approx(n * part.weight_N, rel=1e-12)

    # the interfaces of web 0 and of its corner with web 1 in both models, keyed by their
    # blocks in the section's numbering: (web-0 block, block or source of the image)
    count = section.blocks.n_blocks
    left = np.concatenate([[False], section.layout.miter_left])
    source = np.concatenate([np.arange(count), np.flatnonzero(left)])

    def keyed(pairs, is_other_web, to_section):
        out = {}
        for k, (a, b) in enumerate(pairs):
            if is_other_web[k, 0]:  # the neighbour is main: web 0's brick is side 1
                out[(b, to_section(a), True)] = (k, -1.0)
            elif is_other_web[k, 1]:
                out[(a, to_section(b), True)] = (k, 1.0)
            else:
                out[(a, b, False)] = (k, 1.0)
        return out

    ours = keyed(cyclic.interfaces.pair, cyclic.interfaces.pair >= count, lambda i: source[i])
    web = dome.blocks.block_web[dome.interfaces.pair]
    near = (web[:, 0] == 0) & np.isin(web[:, 1], [0, 1]) | (web[:, 1] == 0) & (web[:, 0] == 1)
    theirs = keyed(dome.interfaces.pair[near], web[near] == 1, lambda i: i % count)
    theirs = {key: (np.flatnonzero(near)[k], sign) for key, (k, sign) in theirs.items()}
    assert ours.keys() == theirs.keys()
    keys = sorted(ours)
    k_part, s_part = np.array([ours[key] for key in keys]).T
    k_whole, s_whole = np.array([theirs[key] for key in keys]).T
    fp, fw = part.per_interface(), whole.per_interface()
    scale = np.abs(fp["compression"]).max()
    for name in ("compression", "tension", "normal", "t1", "t2", "friction"):
        mine = fp[name][k_part.astype(int)]
        other = fw[name][k_whole.astype(int)]
        if name == "t1":  # a flipped normal flips t1 = z x n (t2 = n x t1 stays)
            mine, other = mine * s_part, other * s_whole
        # Clarabel's gap tolerance 1e-10 on the scaled problem: forces agree to 1e-6
        np.testing.assert_allclose(other, mine, atol=1e-6 * scale, err_msg=name)


def test_full_dome_corners_meet_face_to_face():
    scene, model, _ = analysed(n=8, p=3, r=0, scene="dome")
    blocks, itf = model.blocks, model.interfaces
    corner = np.flatnonzero(itf.kind == BOUNDARY)
    assert len(corner) > 0
    # each corner interface is a whole mitered end face of the brick it belongs to
    end_face = [blocks.face_area[np.flatnonzero(blocks.face_block == a)].tolist()
                for a in itf.pair[corner, 0]]
    for area, faces in zip(itf.area[corner], end_face):
        assert min(abs(np.array(faces) / area - 1)) < 1e-9
    # and every corner plane (webs k and k + 1) holds the same number of interfaces
    webs = np.sort(model.blocks.block_web[itf.pair[corner]], axis=1)
    plane = np.where(webs[:, 1] - webs[:, 0] == 1, webs[:, 0], webs[:, 1])
    assert len(set(np.bincount(plane, minlength=8))) == 1


def test_full_dome_support_reaction_equals_weight():
    scene, model, result = analysed(n=6, p=4, r=0, scene="dome", friction="plus")
    itf = model.interfaces
    forces = result.per_interface()
    ground = itf.kind == SUPPORT
    total = support_force(itf, forces, ground)
    np.testing.assert_allclose(total, [0, 0, result.weight_N], atol=1e-6 * result.weight_N)
    assert result.residual_eq <= 1e-5


@pytest.mark.parametrize("preset", PRESETS)
def test_thesis_x2_structures_are_feasible_in_cyclic_mode(preset):
    """Thesis table 4.1: structures 1.2, 2.2, 3.2 (dome mode, friction-net) feasible."""
    p = from_preset(preset, boundary="cyclic")
    scene = build(p)
    model = analysis_model(scene, p.analysis.boundary)
    result = solve_rbe(model.blocks, model.interfaces, friction="net", lp_check=False,
                       side_block=model.side_block, side_rotation=model.side_rotation)
    assert result.feasible
    assert result.residual_eq <= 1e-5 and result.friction_violation <= 1e-5
    assert model.boundary_count > 0


def test_rigid_boundary_adds_both_corners():
    _, rigid, _ = analysed(n=8, p=3, r=0, boundary="rigid", friction="plus")
    _, cyclic, _ = analysed(n=8, p=3, r=0, boundary="cyclic", friction="plus")
    assert rigid.boundary_count == 2 * cyclic.boundary_count
    assert rigid.side_block is None  # the neighbours are supports


def test_a_dome_too_small_for_its_bricks_is_refused():
    from masonry.params import ParameterError

    with pytest.raises(ParameterError, match="wedges of up to"):
        build(from_preset("1", n=6, p=2, r=0))


def test_structures_table_rows_and_formats():
    from masonry.studies.structures import ROWS, structures_table, table_csv, table_markdown

    rows = structures_table(rows=[r for r in ROWS if r[0] == "3.2 rigid"])
    (row,) = rows
    assert row["feasible"] is True and row["boundary"] == "rigid"
    assert row["moi_factor"] < 1e-5 and row["residual_eq"] <= 1e-5
    csv_lines = table_csv(rows).decode().splitlines()
    assert csv_lines[0].startswith("structure,preset,scene,boundary")
    assert csv_lines[1].startswith("3.2 rigid,3,section,rigid")
    markdown = table_markdown(rows)
    assert "| 3 |  | feasible, MoI factor" in markdown
