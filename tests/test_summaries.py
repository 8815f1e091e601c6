"""The text summaries say what each value means and list only the scene's inputs."""

from test_rbe import MU, cantilever, stack

from masonry.export.summaries import lp_check_text, objective_text, parameters_text
from masonry.params import Params, from_preset, structure_id, validate
from masonry.rbe.solve import solve_rbe


def parameters(params):
    return parameters_text(params, structure_id(params))


def names(text):
    return {line.split("=")[0].strip() for line in text.splitlines() if " = " in line}


def test_parameters_list_the_scene_that_ran_and_the_values_it_used():
    arch = names(parameters(validate(Params.of(scene="arch"))))
    assert {"arch_blocks", "arch_thickness", "mu", "accuracy", "solver"} <= arch
    assert not arch & {"stretch", "n", "wall_length", "boundary"}
    assert "cad_offset" not in arch  # voussoirs are not moved inward
    section = parameters(from_preset("1"))
    assert {"stretch", "n", "boundary", "cad_offset"} <= names(section)
    assert not names(section) & {"arch_blocks", "wall_courses"}
    # the preset the run used, not the unset option (None)
    assert "accuracy = balanced" in " ".join(section.split())
    assert "accuracy = fast" in " ".join(parameters(from_preset("1", fast=True)).split())
    assert "None" not in section.split("solver")[1].splitlines()[0]


def test_lp_check_line_says_what_was_checked():
    blocks, interfaces = stack(2)
    balanced = solve_rbe(blocks, interfaces, mu=MU)
    assert lp_check_text(balanced).startswith("not run in balanced")
    checked = solve_rbe(blocks, interfaces, mu=MU, lp_check=True)
    assert lp_check_text(checked) == "the friction-net LP is feasible: confirms feasible"
    blocks, interfaces = cantilever()
    accurate = solve_rbe(blocks, interfaces, mu=MU, accuracy="accurate")
    assert not accurate.feasible
    assert lp_check_text(accurate) == "the friction-net LP is infeasible: confirms infeasible"
    text = objective_text(accurate)
    assert "None" not in text and "MoI factor" in text and "infeasible (" in text
