"""Construction stages (docs/model.md 4.7): stage models filtered from the whole structure's, and
their verdicts against book stacking, an arch laid without centering and the full dome."""

import csv
import json

import numpy as np
import pytest
from test_collapse import column
from test_interfaces import box_corners

from masonry import forking
from masonry.blocks import BLOCK_CLASSES, Blocks
from masonry.export.obj import blocks_obj
from masonry.interfaces import detect
from masonry.params import ParameterError, Params, from_preset, validate
from masonry.rbe.boundary import Model, analysis_model, restrict
from masonry.rbe.solve import RBEProblem
from masonry.scenes import build
from masonry.stages.analysis import analyse_stage, analyse_stages, loose_blocks
from masonry.stages.plans import (NOT_LAID, StagePlan, block_plan, brick_plan, course_plan,
                                   make_plan)
from masonry_cli.main import main

PATTERN = BLOCK_CLASSES.index("pattern")
SMALL_DOME = dict(n=4, p=3, r=1)  # test_dome's smallest 4-sided dome (unit 0.1)


# ---------------------------------------------------------------------- book stacking
def stack(offsets, width=1.0, height=0.2):
    """Blocks of ``width`` stacked on a wide ground slab, block ``i`` shifted by
    ``offsets[i]`` along x from the one below (block 0 centred on the slab)."""
    centre = np.cumsum(np.concatenate([[0.0], offsets]))
    corners = [box_corners([-3, -0.5, -height], [3, 0.5, 0])]
    corners += [box_corners([c - width / 2, -0.5, i * height], [c + width / 2, 0.5,
                                                                 (i + 1) * height])
                for i, c in enumerate(centre)]
    blocks = Blocks.from_hexahedra(np.array(corners), ["ground"] + ["block"] *
                                   len(centre))
    return blocks, centre


def stands_by_statics(centre, width=1.0):
    """Per stage k (the lowest k blocks): whether every top part's centroid lies over
    the block below it (book stacking; the slab is wider than any block)."""
    verdicts = []
    for k in range(1, len(centre) + 1):
        top = [centre[j:k].mean() for j in range(1, k)]  # parts on blocks j-1, j >= 1
        verdicts.append(all(abs(c - centre[j - 1]) <= width / 2
                            for j, c in zip(range(1, k), top)))
    return verdicts


def stage_verdicts(blocks, order="z", mu=0.7):
    params = validate(Params.of(mu=mu))
    model = Model(blocks, detect(blocks))
    plan = block_plan(blocks, order)
    return plan, analyse_stages(model, params, plan)


def test_harmonic_stack_stands_at_every_stage():
    # 95 % of the harmonic overhangs: b/2 over the block below at the top, then b/4,
    # b/6, ... (laid bottom up, so the smallest first); the whole stack overhangs
    # 0.95 (1/2 + 1/4 + ... + 1/12) b = 1.16 b, beyond the slab's block
    n = 6
    offsets = 0.95 / (2 * np.arange(n - 1, 0, -1))
    blocks, centre = stack(offsets)
    assert centre[-1] + 0.5 > 1.1  # the top block lies wholly beyond the bottom one
    assert all(stands_by_statics(centre))
    plan, rows = stage_verdicts(blocks)
    assert plan.n_stages == n
    assert [r["feasible"] for r in rows] == [True] * n
    assert all(r["moi_factor"] == pytest.approx(0, abs=1e-6) for r in rows)


@pytest.mark.parametrize("offsets, first_failing", [
    (np.full(5, 0.3), 4),   # blocks 2-4 together tip over block 1: (0.3+0.6+0.9)/3 > 0.5
    (np.full(5, 0.55), 2),  # the second block alone tips
    (1.05 / (2 * np.arange(5, 0, -1)), 6),  # 5 % beyond harmonic: the top block tips
])
def test_overhanging_stack_fails_at_the_stage_statics_says(offsets, first_failing):
    n = len(offsets) + 1
    blocks, centre = stack(offsets)
    expected = stands_by_statics(centre)
    assert expected.index(False) + 1 == first_failing
    plan, rows = stage_verdicts(blocks, order="names")
    assert [r["feasible"] for r in rows] == expected
    assert [r["bricks"] for r in rows] == list(range(1, n + 1))
    failing = rows[first_failing - 1]
    assert failing["moi"] > 1e-3 * 9.81 * 2000 * 0.2  # tension of a real mechanism, N
    assert failing["held"] and failing["centering_N"] > 0  # somebody must hold a block
    assert all(r["centering_N"] == 0 for r in rows[:first_failing - 1])


@pytest.mark.skipif(not forking.can_fork(), reason="the stages share the cores by fork")
def test_stages_on_two_cores_fail_where_statics_says(two_processes):
    """Every second stage in a forked process (forking.two_at_once, forced on this small
    model): the verdicts of book stacking, in stage order."""
    blocks, centre = stack(np.full(5, 0.3))
    plan, rows = stage_verdicts(blocks, order="names")
    assert len(two_processes) == 1
    assert [r["stage"] for r in rows] == list(range(1, 7))
    assert [r["feasible"] for r in rows] == stands_by_statics(centre)
    assert [r["feasible"] for r in rows].index(False) == 3


# ---------------------------------------------------------------------- arch
def voussoirs(radius, thickness, count, k):
    """Areas (k,) and centroids (k, 2) of the lowest ``k`` voussoirs of the right half of
    a semicircular arch centred at the origin (straight joints and faces, as built), the
    springing at ``(radius, 0)``."""
    inner, outer = radius - thickness / 2, radius + thickness / 2
    step = np.pi / count
    area, centroid = [], []
    for i in range(k):
        a, b = i * step, (i + 1) * step
        x, y = np.array([[inner * np.cos(a), inner * np.sin(a)],
                         [outer * np.cos(a), outer * np.sin(a)],
                         [outer * np.cos(b), outer * np.sin(b)],
                         [inner * np.cos(b), inner * np.sin(b)]]).T
        x1, y1 = np.roll(x, -1), np.roll(y, -1)
        cross = x * y1 - x1 * y
        area.append(cross.sum() / 2)
        centroid.append([((x + x1) * cross).sum(), ((y + y1) * cross).sum()]
                        / (3 * cross.sum()))
    return np.array(area), np.array(centroid)


def half_arch_stands(radius, thickness, count, mu):
    """Per stage k = 1..count/2 - 1 (k voussoirs on each springing, not yet closed):
    whether a half arch stands. Each part above a joint carries only its own weight, so
    the vertical through its centroid must cross the joint, and the joint's slope must
    not exceed the friction angle."""
    inner, outer = radius - thickness / 2, radius + thickness / 2
    step = np.pi / count
    area, centroid = voussoirs(radius, thickness, count, count // 2)
    verdicts = []
    for k in range(1, count // 2):
        ok = True
        for j in range(k):  # joint j at angle j step above the springing
            x = (area[j:k] * centroid[j:k, 0]).sum() / area[j:k].sum()
            phi = j * step
            ok &= inner * np.cos(phi) <= x <= outer * np.cos(phi) and np.tan(phi) <= mu
        verdicts.append(bool(ok))
    return verdicts


def half_arch_held(radius, thickness, count, k, hinge, mu):
    """The least force at the voussoirs' centroids that holds a half arch of ``k``
    voussoirs whose part above joint ``hinge`` tips inwards about the joint's intrados
    edge P, as a fraction of the half arch's weight, and that force ((2,), the arch's
    plane, per unit weight of the half arch).

    Virtual work: the part turning about P by d theta, its weight does ``W_part e d
    theta`` (``e`` the horizontal distance of its centroid inside P), a force ``s_i`` at
    a centroid ``c_i`` at most ``||s_i|| |c_i - P| d theta``, and the opening joint
    none: ``sum ||s_i|| >= W_part e / max |c_i - P|``, reached by a force on the top
    voussoir (the farthest from P) perpendicular to ``c_k - P``. The force is
    admissible: with it, the load on the part above every joint crosses the joint
    within its thickness and within the friction angle (asserted here), so it is the
    least."""
    inner, outer = radius - thickness / 2, radius + thickness / 2
    step = np.pi / count
    area, centroid = voussoirs(radius, thickness, count, k)
    hinge_point = inner * np.array([np.cos(hinge * step), np.sin(hinge * step)])
    part = slice(hinge, k)
    x = (area[part] * centroid[part, 0]).sum() / area[part].sum()
    moment = area[part].sum() * (hinge_point[0] - x)
    arm = centroid[k - 1] - hinge_point
    lever = np.linalg.norm(arm)
    force = moment / lever * np.array([arm[1], -arm[0]]) / lever  # turns it back out
    for j in range(k):  # statics of every joint with the force on the top voussoir
        load = np.array([force[0], force[1] - area[j:].sum()])
        moment_o = (-(area[j:] * centroid[j:, 0]).sum()
                    + centroid[k - 1, 0] * force[1] - centroid[k - 1, 1] * force[0])
        along = np.array([np.cos(j * step), np.sin(j * step)])  # the joint, outwards
        crossing = moment_o / (along[0] * load[1] - along[1] * load[0])
        assert inner - 1e-9 <= crossing <= outer + 1e-9
        normal = np.array([-along[1], along[0]])                 # up the arch
        assert abs(load @ along) <= mu * -(load @ normal)
    return moment / lever / area.sum(), force / area.sum()


def test_arch_laid_without_centering_fails_before_closure_and_stands_closed():
    """The default arch: semicircular, 16 voussoirs, span 10 m, t = 0.6 m: t/R = 0.12,
    above Milankovitch's 0.1075, so the closed arch stands. Laid in pairs from the
    springings, stage 3 is the first that fails: the two upper voussoirs of each half
    tip inwards about joint 1's intrados edge; the centering force holds them by the top
    voussoir of each half (:func:`half_arch_held`)."""
    params = validate(Params.of(scene="arch"))
    scene = build(params)
    plan = make_plan(scene, "block", "z")
    assert plan.n_stages == 8  # one voussoir on each side per stage
    rows = analyse_stages(analysis_model(scene, "free"), params, plan)
    mu = params.analysis.mu
    expected = half_arch_stands(5.0, 0.6, 16, mu)
    assert expected[:2] == [True, True] and not expected[2]  # statics: third pair tips
    assert [r["feasible"] for r in rows[:-1]] == expected
    assert rows[-1]["feasible"] and rows[-1]["bricks"] == 16
    assert [r["centering_N"] for r in rows[:2] + rows[-1:]] == [0.0] * 3
    fraction, force = half_arch_held(5.0, 0.6, 16, 3, 1, mu)
    third = rows[2]
    assert third["centering_fraction"] == pytest.approx(fraction, abs=1e-6 / 6)
    names = scene.blocks.block_name
    held = {str(names[block]): vector for block, vector, _ in third["held"]}
    assert set(held) == {"v002", "v013"}  # the top voussoir of each half
    half_weight = third["centering_N"] / fraction / 2
    # the right half in the xz-plane; the left one its mirror image
    assert held["v002"][[0, 2]] == pytest.approx(force * half_weight,
                                                 abs=1e-3 * half_weight / 3)
    assert held["v013"][[0, 2]] == pytest.approx(force * [-1, 1] * half_weight,
                                                 abs=1e-3 * half_weight / 3)


# ---------------------------------------------------------------------- domes
def dome_stage(scene_kind, plan_of, stage):
    params = from_preset("1", **SMALL_DOME, **scene_kind)
    scene = build(params)
    plan = plan_of(scene)
    model = analysis_model(scene, params.analysis.boundary)
    part = restrict(model, plan.is_present(stage))
    return scene, plan, part, analyse_stage(model, params, plan, stage)


@pytest.mark.parametrize("plan_of, stage", [
    (lambda scene: course_plan(scene.blocks), 5),
    (lambda scene: brick_plan(scene, 4, "pattern-first"), 2),
])
def test_cyclic_section_stage_equals_full_dome_stage(plan_of, stage):
    n = SMALL_DOME["n"]
    section, plan, part, ours = dome_stage(dict(boundary="cyclic"), plan_of, stage)
    dome, whole_plan, whole_part, whole = dome_stage(dict(scene="dome"), plan_of, stage)
    assert whole_plan.n_stages == plan.n_stages
    assert whole["bricks"] == n * ours["bricks"]
    assert whole_part.interfaces.counts()["horizontal"] == \
        n * part.interfaces.counts()["horizontal"]
    assert whole["feasible"] == ours["feasible"]
    # one web's share of the whole dome's solution: the objective is strictly convex, the
    # stage symmetric, so the unique solution is symmetric (docs/model.md 6.4)
    params = from_preset("1", **SMALL_DOME)
    results = []
    for model in (part, whole_part):
        problem = RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                             side_rotation=model.side_rotation)
        results.append(problem.solve(mu=params.analysis.mu, lp_check=False))
    assert results[1].weight_N == pytest.approx(n * results[0].weight_N, rel=1e-12)
    assert results[1].objective == pytest.approx(n * results[0].objective, rel=1e-5)


def test_stage_model_keeps_only_interfaces_of_laid_blocks():
    scene = build(from_preset("1", **SMALL_DOME, boundary="cyclic"))
    model = analysis_model(scene, "cyclic")
    plan = course_plan(scene.blocks)
    source = model.block_source
    for stage in (1, 3, plan.n_stages):
        present = plan.is_present(stage)
        part = restrict(model, present)
        # every interface of the whole model between two present blocks (a support or
        # an image of a laid brick), and no other
        is_kept = present[source] | (scene.blocks.block_is_support[source]
                                     & (source == np.arange(len(source))))
        expected = is_kept[model.interfaces.pair].all(axis=1).sum()
        assert len(part.interfaces) == expected
        assert (present[part.block_source]).all()
        centres = np.sort(part.interfaces.centre, axis=0)
        whole = model.interfaces.centre[is_kept[model.interfaces.pair].all(axis=1)]
        np.testing.assert_allclose(centres, np.sort(whole, axis=0), atol=0)
    assert len(restrict(model, plan.is_present(plan.n_stages)).interfaces) == \
        len(model.interfaces)


def test_course_plan_lays_every_brick_once_in_course_order():
    scene = build(from_preset("1", **SMALL_DOME, boundary="cyclic"))
    plan = course_plan(scene.blocks)
    free = ~scene.blocks.block_is_support
    assert (plan.block_stage[free] == scene.blocks.block_course[free]).all()
    bricks = [int((plan.is_present(k) & free).sum()) for k in range(1, plan.n_stages + 1)]
    assert np.all(np.diff(bricks) > 0) and bricks[-1] == free.sum()


@pytest.mark.parametrize("order", ["pattern-first", "along"])
def test_brick_orders(order):
    scene = build(from_preset("1", **SMALL_DOME, boundary="cyclic"))
    layout = scene.layout
    courses = [k for k in range(2, layout.course.max())
               if ((layout.course == k) & (layout.klass == PATTERN)).any()]
    course = courses[0]
    plan = brick_plan(scene, course, order)
    stage = plan.block_stage[1:]  # the section's layout bricks (block 0: the slab)
    on = layout.course == course
    assert (stage[layout.course < course] == 0).all()
    assert (stage[layout.course > course] == NOT_LAID).all()
    assert sorted(stage[on]) == list(range(1, on.sum() + 1))
    sequence = np.flatnonzero(on)[np.argsort(stage[on])]
    if order == "along":
        assert np.all(np.diff(layout.s0[sequence]) > 0)
        return
    # the pattern bricks of the course first, then every brick beside one already there
    patterns = int((layout.klass[on] == PATTERN).sum())
    assert (layout.klass[sequence[:patterns]] == PATTERN).all()
    there = (layout.course == course - 1) & (layout.klass == PATTERN)
    occupants = np.flatnonzero(on | there)
    occupants = occupants[np.argsort(layout.s0[occupants])]
    is_there = there.copy()
    for brick in sequence:
        if layout.klass[brick] != PATTERN:
            i = int(np.flatnonzero(occupants == brick)[0])
            beside = occupants[max(i - 1, 0): i + 2]
            assert is_there[beside].any(), f"brick {brick} laid beside nothing"
        is_there[brick] = True


def test_course_stages_need_courses():
    with pytest.raises(ParameterError, match="parameter by="):
        course_plan(build(validate(Params.of(scene="arch"))).blocks)


# ---------------------------------------------------------------------- command line
def test_stages_command_writes_its_own_folder_reproducibly(tmp_path, capsys):
    args = ["stages", "--preset", "1", *[f"--{k}={v}" for k, v in SMALL_DOME.items()],
            "--fast", "--no-plots", "--out", str(tmp_path), "-q"]
    assert main(["run", *args[1:]]) == 0  # a run of the same dome, beside the stages
    assert main(args) == 0
    folders = sorted(p.name for p in tmp_path.iterdir()
                     if p.is_dir() and not p.name.startswith("."))
    # run and stages both model the section as cyclic unless told otherwise
    assert len(folders) == 2 and folders[1] == folders[0] + "_stages_course"
    folder = tmp_path / folders[1]
    with open(folder / "stages.csv") as f:
        rows = list(csv.DictReader(f))
    record = json.loads((folder / "run.json").read_text())
    assert record["complete"] and record["stages"]["count"] == len(rows)
    assert [int(r["stage"]) for r in rows] == list(range(1, len(rows) + 1))
    bricks = [int(r["bricks"]) for r in rows]
    assert np.all(np.diff(bricks) > 0) and bricks[-1] == record["counts"]["bricks"]
    assert all(r["load_factor"] == "" for r in rows)  # no lateral load
    assert main([*args, "--force"]) == 0
    with open(folder / "stages.csv") as f:
        again = list(csv.DictReader(f))
    keep = ("stage", "course", "bricks", "feasible", "moi_N", "moi_factor")
    assert [{k: r[k] for k in keep} for r in again] == [{k: r[k] for k in keep}
                                                        for r in rows]


def test_friction_net_stages_name_the_first_stage_that_needs_support(tmp_path, capsys):
    # friction-net measures no MoI, and the report names the stage without one. The
    # plain sector's top course laid along starts with a brick alone on a bed steeper
    # than atan(0.7)
    args = ["stages", "--scene", "sector", "--radius", "10.3923", "--p", "5", "--cut",
            "0.3", "--pattern", "none", "--by", "brick", "--course", "8", "--order",
            "along", "--friction", "net", "--fast", "--no-plots", "--out", str(tmp_path)]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "first stage that needs support: 1 (32 bricks)" in out


@pytest.mark.parametrize("args, option", [
    (["--preset", "1", "--by", "brick", "--course", "99"], "--course"),
    (["--preset", "1", "--by", "block", "--course", "3"], "--course"),
    (["--preset", "1", "--by", "course", "--order", "along"], "--order"),
    (["--scene", "arch", "--by", "course"], "--by"),
    (["--preset", "1", "--scene", "arch"], "--scene"),
])
def test_bad_stage_options_get_one_line_and_write_nothing(tmp_path, capsys, args, option):
    out = tmp_path / "out"
    assert main(["stages", *args, "--out", str(out), "-q"]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and option in error
    assert not out.exists()


@pytest.mark.parametrize("order", ["names", "z"])
def test_imported_stack_laid_by_names_or_height(tmp_path, capsys, order):
    # the stack of 0.3 b overhangs, as an OBJ file: block names b0001 ... b0006 bottom
    # up, so both orders lay it bottom up and stage 4 is the first to need support
    blocks, centre = stack(np.full(5, 0.3))
    path = tmp_path / "stack.obj"
    path.write_bytes(blocks_obj(blocks))
    assert main(["stages", str(path), "--support", "*ground*", "--order", order,
                 "--no-plots", "--out", str(tmp_path / "out"), "-q"]) == 0
    (folder,) = (tmp_path / "out").glob(f"*_stages_{order}")
    with open(folder / "stages.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["feasible"] == "True" for r in rows] == stands_by_statics(centre)
    record = json.loads((folder / "run.json").read_text())
    first = record["stages"]["first_unsupported"]
    assert first["stage"] == 4 and len(first["laid"]) == 1
    assert first["laid"][0] == str(blocks.block_name[4])  # the fourth above the slab
    # the top block is held (tests/test_centering.py): 0.3 / sqrt(0.41) of its weight
    brick = 2000.0 * 9.81 * blocks.block_volume[4]
    assert first["centering_N"] == pytest.approx(0.3 / np.sqrt(0.41) * brick, rel=1e-6)
    assert [h["name"] for h in first["held"]] == [str(blocks.block_name[4])]
    with open(folder / "first_unsupported" / "held.csv") as f:
        (held,) = list(csv.DictReader(f))
    assert held["name"] == first["held"][0]["name"] and held["course"] == ""
    assert float(held["support_N"]) == pytest.approx(first["centering_N"], rel=1e-6)
    assert np.hypot(float(held["force_x_N"]), float(held["force_z_N"])) == pytest.approx(
        float(held["support_N"]), rel=1e-6)
    printed = capsys.readouterr().out
    assert "first stage that needs support: 4" in printed
    assert "centering force: supports must give" in printed
    # the wall time, not the stages' solves summed
    wall = record["stages"]["wall_s"]
    assert f"{len(rows)} stages solved in {wall:.3g} s" in printed
    assert wall == record["timings_s"]["stages"]


def test_first_unsupported_stage_is_drawn_with_its_new_block_outlined(tmp_path):
    # the 0.3 b stack again, with plots: stage 4's views must show the magenta outline
    # of the block laid at that stage in every view (2D elevations and the 3D angle)
    import matplotlib.image

    from masonry.plots import OUTLINE_COLOUR
    from masonry.plots.common import views_of

    blocks, _ = stack(np.full(5, 0.3))
    path = tmp_path / "stack.obj"
    path.write_bytes(blocks_obj(blocks))
    assert main(["stages", str(path), "--support", "*ground*", "--out",
                 str(tmp_path / "out"), "-q"]) == 0
    (folder,) = (tmp_path / "out").glob("*_stages_z")
    magenta = np.array(matplotlib.colors.to_rgb(OUTLINE_COLOUR))
    views = sorted((folder / "first_unsupported").glob("*.png"))
    # the views of the model's extent: the slab 6 m long in x seen end on from the
    # front (x) is left out
    assert [v.name for v in views] == ["01_angle.png", "03_top.png", "04_side.png"]
    assert [f"{view}.png" for view in views_of(blocks.bounds)] == [v.name for v in views]
    for view in views:
        pixels = matplotlib.image.imread(view)[..., :3]
        assert (np.abs(pixels - magenta).max(axis=-1) < 0.05).sum() > 50, view.name
    assert (folder / "stages.png").stat().st_size > 10_000


# ---------------------------------------------------------------- stage load factors
def test_lateral_load_factor_of_each_stage_matches_statics():
    # a block b wide and h high on the slab tips about its edge at lambda = b / h (mu
    # 0.7 > b/h: no sliding first). Stage 2, a second identical block centred on it: the
    # two tip together about the bottom block's edge when lambda 2W h (their loads at
    # h/2 and 3h/2) reaches 2W b/2, lambda = b / (2 h), before the top block tips alone
    # (b / h) or either joint slides (mu)
    b, h = 0.2, 0.4
    blocks, _ = stack([0.0], width=b, height=h)
    params = validate(Params.of(mu=0.7, lateral=0.0))
    model = Model(blocks, detect(blocks))
    plan = block_plan(blocks, "z")
    rows = analyse_stages(model, params, plan)
    assert [r["feasible"] for r in rows] == [True, True]
    assert rows[0]["load_factor"] == pytest.approx(b / h, abs=1e-6)
    assert rows[1]["load_factor"] == pytest.approx(b / (2 * h), abs=1e-6)


def test_lateral_load_factor_of_a_stage_that_slides():
    # mu 0.3 < b/h = 0.5: the single block slides at lambda = mu
    blocks, _ = stack([], width=0.2, height=0.4)
    params = validate(Params.of(mu=0.3, lateral=180.0))
    rows = analyse_stages(Model(blocks, detect(blocks)), params, block_plan(blocks, "z"))
    assert rows[0]["load_factor"] == pytest.approx(0.3, abs=1e-6)


def test_a_block_laid_before_the_one_under_it_is_loose_and_has_no_moi():
    """A column laid top block first: at stage 1 the top blocks touch nothing that joins
    them to the ground (no equilibrium, even with tension: no solve, no MoI); at stage 2
    the column stands."""
    model = column(3, (0.2, 0.2, 0.1))
    plan = StagePlan(np.array([0, 2, 1, 1]), np.array([0, 0]), by="block", order="names")
    params = validate(Params.of(scene="wall"))
    first, second = (analyse_stage(model, params, plan, k) for k in (1, 2))
    assert first["loose"] == 2 and first["loose_blocks"] == [2, 3]
    assert not first["feasible"] and first["moi"] is None
    # nothing holds them but a support: their whole weight (shared between them as the
    # solver likes: the one below may carry both)
    weight = 2000.0 * 9.81 * model.blocks.block_volume[[2, 3]].sum()
    assert first["centering_N"] == pytest.approx(weight, rel=1e-6)
    assert {block for block, _, _ in first["held"]} <= {2, 3}
    assert second["loose"] == 0 and second["feasible"]


@pytest.mark.parametrize("boundary", ["cyclic", "rigid"])
def test_a_sections_end_brick_laid_alone_is_loose_and_course_stages_are_not(boundary):
    """A cyclic neighbour's images are the section's own bricks: a top end brick laid
    alone touches nothing that joins it to the ground, its copies in the other webs
    included (a rigid neighbour's images are supports: they may hold it). Every brick of
    the first courses is joined to the ground, through the images too."""
    scene = build(from_preset("3", scene="section", boundary=boundary, p=4))
    model = analysis_model(scene, boundary)
    count = scene.blocks.n_blocks
    ends = np.unique(model.block_source[count:])  # the bricks with an image
    top = ends[np.argmax(scene.blocks.block_course[ends])]
    alone = np.zeros(count, bool)
    alone[top] = True
    if boundary == "cyclic":
        assert loose_blocks(restrict(model, alone)).tolist() == [top]
    plan = course_plan(scene.blocks)
    for stage in (1, 2, 3):
        assert len(loose_blocks(restrict(model, plan.is_present(stage)))) == 0


def test_stages_csv_names_what_each_stage_lays(tmp_path):
    """A block plan's rows say which blocks each stage lays (an arch rises from both
    springings at once), with floats as every CSV prints them."""
    assert main(["stages", "--scene", "arch", "--no-plots", "--out", str(tmp_path),
                 "-q"]) == 0
    (folder,) = tmp_path.glob("arch_*_stages_z")
    with open(folder / "stages.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["laid"] for r in rows[:2]] == ["v000 v015", "v001 v014"]
    assert all(r["moi_N"] == "" or "." in r["moi_N"] or "e" in r["moi_N"] for r in rows)


# ---------------------------------------------------------------------- the whole construction
def test_whole_brick_plan_lays_every_course_brick_by_brick():
    scene = build(from_preset("1", **SMALL_DOME, boundary="cyclic"))
    courses = course_plan(scene.blocks)
    for order in ("pattern-first", "along"):
        plan = make_plan(scene, "brick", order)
        free = ~scene.blocks.block_is_support
        # one brick of the section per stage, every brick once, courses bottom to top
        assert sorted(plan.block_stage[free]) == list(range(1, free.sum() + 1))
        assert np.all(np.diff(plan.stage_course) >= 0)
        assert (plan.stage_course[plan.block_stage[free] - 1]
                == scene.blocks.block_course[free]).all()
        # within a course, the order of the course's own brick plan; its last stage is
        # the course stage
        for course in (1, 3):
            alone = brick_plan(scene, course, order)
            on = scene.blocks.block_course == course
            assert (np.argsort(plan.block_stage[on]) == np.argsort(alone.block_stage[on])).all()
            last = np.flatnonzero(plan.stage_course == course)[-1] + 1
            assert (plan.is_present(last) == courses.is_present(course)).all()
        assert plan.tag == f"brick_{order}"


@pytest.mark.parametrize("mu, order", [(0.7, "pattern-first"), (0.4, "along")])
@pytest.mark.slow
def test_stages_solved_in_sequence_equal_stages_solved_alone(mu, order):
    # every brick stage of a small dome, each from the last one's work (warm starts,
    # the whole model's matrices and ordering, the local certificate) and each alone:
    # the same verdicts, and the measure of infeasibility within the acceptance
    # tolerance (the QP's unique minimiser, both accepted at residual 1e-5)
    params = validate(from_preset("1", **SMALL_DOME, boundary="cyclic", mu=mu))
    scene = build(params)
    model = analysis_model(scene, "cyclic")
    plan = make_plan(scene, "brick", order)
    warm = analyse_stages(model, params, plan)
    cold = analyse_stages(model, params, plan, reuse=False)
    assert [r["feasible"] for r in warm] == [r["feasible"] for r in cold]
    assert sum(not r["feasible"] for r in cold) >= 4  # the certificate is exercised
    weight = max(r["moi"] / r["moi_factor"] for r in cold if r["moi"])
    for ours, alone in zip(warm, cold):
        assert (ours["moi"] is None) == (alone["moi"] is None)
        if alone["moi"] is not None:
            assert ours["moi"] == pytest.approx(alone["moi"], abs=1e-6 * weight)
        assert ours["centering_N"] == pytest.approx(alone["centering_N"], abs=1e-6 * weight)
        # the least adhesion: the same program on the whole model's matrices and alone
        assert ours["adhesion_kPa"] == pytest.approx(alone["adhesion_kPa"], rel=1e-5)
    assert max(r["adhesion_kPa"] for r in cold) > 0



def test_adhesion_bench_times_the_stages_masonry_stages_solves(tmp_path, capsys):
    """Course 8 of the small dome at mu 0.4, laid along: the bench's stages that need
    adhesion are those `analyse_stages` finds standing on no dry joints, and its largest
    least adhesion is theirs (rel 1e-5); a course below 1 is refused by name."""
    from masonry_benchmarks.stages_bench import adhesion_bench, adhesion_markdown

    params = validate(from_preset("1", **SMALL_DOME, boundary="cyclic", mu=0.4))
    (row,) = adhesion_bench({"small dome": params}, 8, orders=("along",))
    scene = build(params)
    rows = analyse_stages(analysis_model(scene, "cyclic"), params,
                          make_plan(scene, "brick", "along", 8))
    assert row["stages"] == len(rows) and row["needing"] == sum(not r["feasible"] for r in rows)
    assert row["needing"] >= 1 and row["rbe_s"] > 0 and row["ratio_median"] > 0
    assert row["adhesion_max_kPa"] == pytest.approx(max(r["adhesion_kPa"] for r in rows),
                                                    rel=1e-5)
    assert "| small dome | 8 | along |" in adhesion_markdown([row])
    assert main(["bench", "--adhesion-course", "0", "--out", str(tmp_path / "x")]) == 2
    assert "--adhesion-course 0" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()

def test_stages_bench_rows_and_its_refusal(tmp_path, capsys):
    from masonry_benchmarks.stages_bench import stages_bench, stages_markdown

    params = validate(from_preset("1", **SMALL_DOME, boundary="cyclic"))
    rows = stages_bench({"small dome": params}, orders=("along",), repeats=1)
    (row,) = rows
    assert row["stages"] == make_plan(build(params), "brick", "along").n_stages
    assert row["same_verdicts"] and row["moi_factor_diff"] < 1e-6
    assert row["sequence_runs"] == pytest.approx(row["sequence_s"] / row["run_s"])
    assert "| small dome | along |" in stages_markdown(rows)
    assert main(["bench", "--stages", "--collapse", "--out", str(tmp_path / "x")]) == 2
    assert "one bench at a time" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
