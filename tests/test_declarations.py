"""Every declared input of the analysis and the outputs is a command line option and a
study file's key, made from its declaration; a run's record of what it wrote is what its
folder holds."""

import json

import pytest

from masonry.outputs import Outputs
from masonry.parameters import declarations, defaults
from masonry.params import FILE_OUTPUTS, Params, option_of
from masonry.rbe.settings import Analysis
from masonry.studies.study_file import load_study
from masonry_cli import run as run_command
from masonry_cli.main import main
from masonry_cli.options import Parser, given_inputs

FIELDS = [(part, name) for part in (Analysis, Outputs) for name in declarations(part)]


def _other_value(part, name):
    """A valid value of a declared field other than its default, from its declaration."""
    declaration, default = declarations(part)[name], defaults(part)[name]
    if declaration.kind == "bool":
        return default is not True
    if declaration.choices:
        return next(choice for choice in declaration.choices if choice != default)
    if name == "friction_cone":
        return "polygon:16"
    if name == "figure_format":
        return ("pdf",)
    value = declaration.low + (declaration.high - declaration.low) / 4
    return round(value) if declaration.kind == "int" else value


def _run_parser():
    parser = Parser(prog="masonry")
    run_command.register(parser.add_subparsers())
    return parser._subparsers._group_actions[0].choices["run"]


def _tokens(parser, name, value) -> list:
    """The command line that gives ``value`` to input ``name``, as the parser declares
    its option (a switch: the option whose constant is the value)."""
    actions = [a for a in parser._actions if a.dest == name and a.option_strings]
    assert actions, f"no option of masonry run sets {name}"
    if isinstance(value, bool):
        (action,) = [a for a in actions if a.const is value]
        return [action.option_strings[0]]
    (action,) = actions
    text = ",".join(value) if isinstance(value, tuple) else str(value)
    return [action.option_strings[0], text]


@pytest.mark.parametrize("part, name", FIELDS, ids=[name for _, name in FIELDS])
def test_every_declared_input_is_an_option_that_gives_its_value(part, name):
    parser, value = _run_parser(), _other_value(part, name)
    args = parser.parse_args(_tokens(parser, name, value))
    assert Params.of(**given_inputs(args)).inputs()[name] == value
    # the option the user types is the one the study file and the errors name
    option = next(a for a in parser._actions if a.dest == name).option_strings[0]
    assert option in (f"--{option_of(name)}", f"--no-{option_of(name)}")


@pytest.mark.parametrize("name", ["plots", "printable", "html"])
def test_a_switch_has_both_ways_where_its_default_is_not_one(name):
    parser = _run_parser()
    off = parser.parse_args([f"--no-{name}"])
    assert getattr(off, name) is False
    if defaults(Outputs)[name] is None:  # optional: --name turns it on
        assert getattr(parser.parse_args([f"--{name}"]), name) is True
    assert getattr(parser.parse_args([]), name) is None  # not given: the default's


def _toml(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return f'"{value}"' if isinstance(value, str) else repr(value)


@pytest.mark.parametrize("part, name", FIELDS, ids=[name for _, name in FIELDS])
def test_every_declared_input_is_a_study_key_that_gives_its_value(tmp_path, part, name):
    value = _other_value(part, name)
    base = ('boundary = "free"\nlateral = 0\n' if name == "friction_law" else "")
    if name in FILE_OUTPUTS:  # chosen once for every variant (a 3MF of the printable body)
        beside = "printable = true\n" if name == "print_size" else ""
        text = (f"[base]\n{base}[grid]\nn = [6, 8]\n[outputs]\n{beside}"
                f"{name} = {_toml(value)}\n")
    else:
        text = f"[base]\n{base}{option_of(name)} = {_toml(value)}\n[grid]\nn = [6, 8]\n"
    path = tmp_path / "study.toml"
    path.write_text(text)
    study = load_study(path)
    given = study.outputs if name in FILE_OUTPUTS else study.variants()[0]
    assert given[name] == value
    if name in FILE_OUTPUTS:  # and the other tables refuse it, naming [outputs]
        path.write_text(f"[base]\n{option_of(name)} = {_toml(value)}\n")
        with pytest.raises(Exception, match=r"\[outputs\] table chooses it"):
            load_study(path)


def test_a_study_refuses_a_print_size_without_the_printable_body(tmp_path, capsys):
    """A study writes no printable body unless asked, so a print size alone would write
    no 3MF: refused in one line naming the file and key, exit 2, as ``masonry run``
    refuses ``--print-size`` beside ``--no-printable``."""
    path = tmp_path / "study.toml"
    path.write_text("[grid]\nn = [6, 8]\n[outputs]\nprint_size = 100\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "o")]) == 2
    line = capsys.readouterr().err.strip()
    assert line.count("\n") == 0 and "outputs.print_size = 100" in line
    assert "printable = true" in line and not (tmp_path / "o").exists()


def test_the_record_of_written_outputs_is_what_the_folder_holds(tmp_path):
    out = tmp_path / "o"
    assert main(["run", "--scene", "arch", "--blocks", "8", "--fast", "--no-printable",
                 "--no-html", "--figure-format", "svg", "--out", str(out), "-q"]) == 0
    (folder,) = out.glob("arch_*")
    record = json.loads((folder / "run.json").read_text())
    held = {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}
    outputs = record["outputs"]
    assert outputs["plots"] is True and outputs["printable"] is False
    assert outputs["html"] is False and "dome.html" not in held
    assert not held & {"dome.stl", "dome.obj", "dome.3mf"}
    assert outputs["3dm"] is ("bricks.3dm" in held)
    figures = {p for p in held if p.endswith((".png", ".svg", ".pdf"))}
    assert figures and figures == set(record["figures"]["files"])
    assert all(p.endswith(".svg") for p in figures)
    coordinates = record["coordinates"]
    listed = {*coordinates["model"], *coordinates["moved_inward"]}
    assert listed <= held
    assert {"locations.csv", "bricks.obj", "interfaces.csv", "RBE/forces.csv"} <= listed


def test_every_written_output_switch_has_its_exporters():
    from masonry.export import EXPORTERS
    from masonry.outputs import WRITTEN_OUTPUTS

    switches = {exporter.output for exporter in EXPORTERS} - {""}
    # the switches of Outputs that say whether files are written, and rhino3dm's 3dm
    assert switches & set(declarations(Outputs)) == set(WRITTEN_OUTPUTS)
    assert switches - set(declarations(Outputs)) == {"3dm"}
