"""Options shared by the subcommands, and their translation into ``Params``."""

import argparse
import math
import shlex

from masonry.errors import ParameterError
from masonry.outputs import Outputs
from masonry.parameters import declarations, defaults, read_toml
from masonry.params import (PRESETS, Params, applies, from_preset, load, names, option_of,
                            section_default, validate)
from masonry.rbe.collapse_result import VERDICTS
from masonry.rbe.settings import Analysis
from masonry.scenes import KINDS, kind_of, memory_estimate
from masonry.tolerances import INTERPENETRATION_REL, MAX_BRICKS, OVERLAP_TOLERANCE_RANGE

MATERIAL_OPTIONS = ("mu", "friction_cone", "density", "cohesion_kpa", "tensile_kpa",
                    "head_joint_ratio", "support_joint_ratio", "adhesion_tension_ratio")
"""The analysis's inputs of the material (``masonry arch-thickness`` takes these only)."""
SOLVER_OPTIONS = ("friction", "accuracy", "solver")
"""The analysis's inputs of the solve; ``boundary`` and ``friction_law`` have groups of
their own (a section's, a live load's)."""
FIGURE_OPTIONS = ("figure_format", "dpi")
"""The outputs' inputs of the figures' files (``masonry stages`` takes these only)."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2."""

    def error(self, message):
        self.exit(2, f"masonry: error: {' '.join(message.split())}\n")


def option_names(parser) -> dict:
    """A parser's destinations -> the long option a user types (``arch_blocks`` ->
    ``--blocks``)."""
    names = {}
    for action in parser._actions:
        longs = [o for o in action.option_strings if o.startswith("--")]
        if longs:
            names.setdefault(action.dest, longs[0])
        elif not action.option_strings:  # a positional argument: its metavar
            names.setdefault(action.dest, action.metavar or action.dest.upper())
    return names


def describe_error(error, args) -> str:
    """One line about a refused input, naming it as the user gave it: the option and
    value typed, or the key and value of the file it came from, or the preset or default
    it came from (and then the options the user gave that it depends on)."""
    if not isinstance(error, ParameterError):
        return " ".join(str(error).split())
    name, value, expected = error.name, error.value, " ".join(str(error.expected).split())
    options = getattr(args, "option_names", {})
    option = options.get(name, f"--{name.replace('_', '-')}")
    if error.where:  # a file's key, its value as the file writes it
        text = str(value).lower() if isinstance(value, bool) else repr(value)
        return f"{error.where}: {name} = {text}: expected {expected}"
    if not option.startswith("--"):  # a positional argument: its value says it
        return f"{_typed(value)}: expected {expected}"
    typed = getattr(args, "typed", {})
    if value is None and not _given(args, name):  # an option missing beside another
        return f"{option}: expected {expected}"
    if value is True and option not in typed:  # a flag given where it does not apply
        return f"{option}: expected {expected}"
    if name not in names() or _given(args, name):
        return f"{option} {typed.get(option, _typed(value))}: expected {expected}"
    given = [r for r in error.related if _given(args, r)]
    origin = (f"from --params {args.params}" if getattr(args, "params", None) else
              f"from --preset {args.preset}" if getattr(args, "preset", None) else
              "the default")
    subject = f"{option} {_typed(value)} ({origin})"
    if given:
        typed_options = [options.get(r, r) for r in given]
        these = ", ".join(f"{o} {typed.get(o, _typed(getattr(args, r)))}"
                          for o, r in zip(typed_options, given))
        subject = f"{these} with {subject}"
    return f"{subject}: expected {expected}"


def typed_values(argv) -> dict:
    """``--option`` -> the value as typed on the command line (the last one given), so an
    error line repeats ``1e-9`` rather than Python's ``1e-09``."""
    typed = {}
    for i, token in enumerate(argv):
        if not token.startswith("--"):
            continue
        if "=" in token:
            option, value = token.split("=", 1)
        elif i + 1 < len(argv) and not _is_option(argv[i + 1]):
            option, value = token, argv[i + 1]
        else:  # a flag
            continue
        typed[option] = shlex.quote(value)
    return typed


def _given(args, name) -> bool:
    return getattr(args, name, None) is not None


def _is_option(token) -> bool:
    """``--out``, ``-q``; not ``-90`` (a value)."""
    if not token.startswith("-"):
        return False
    try:
        float(token)
    except ValueError:
        return True
    return False


def _typed(value) -> str:
    if isinstance(value, float) and math.isfinite(value) and value == int(value):
        return f"{value:g}"
    return shlex.quote(str(value)) if isinstance(value, str) else str(value)


def add_model_options(parser):
    g = parser.add_argument_group("model")
    g.add_argument("--preset", choices=list(PRESETS),
                   help="a thesis structure (1 spherical, 2 stretched, 3 compressed) or the "
                        "validation wall; explicit options below override it (default: "
                        "preset 1's dome)")
    g.add_argument("--params", metavar="FILE",
                   help="parameters from a TOML file (inputs named as these options, "
                        "as in fixtures/presets); "
                        "options given next to it override it")
    built = {name: kind for name, kind in KINDS.items() if kind.from_parameters}
    g.add_argument("--scene", choices=list(built),
                   help="; ".join(f"{name}: {kind.summary}" for name, kind in built.items()))
    g.add_argument("--fast", action="store_true", default=None,
                   help="the fast accuracy preset and quick figures (one view, lower "
                        "resolution)")
    memory = memory_estimate(MAX_BRICKS, Analysis().accuracy) / 2**30
    g.add_argument("--max-bricks", dest="max_bricks", type=int, default=MAX_BRICKS,
                   metavar="N", help=f"refuse a model estimated above N blocks before "
                                     f"building it (default {MAX_BRICKS}, about "
                                     f"{memory:.0f} GiB to solve one that stands)")
    add_scene_options(parser)


def add_scene_options(parser, kinds=None, skip=()):
    """One option per declared geometry input of the scene kinds (``kinds``: names; all
    built from parameters by default), grouped by geometry, from the declarations
    (:mod:`masonry.parameters`): a new scene's inputs are options without a line here."""
    groups = {}
    for name, kind in KINDS.items():
        if kind.from_parameters and (kinds is None or name in kinds):
            groups.setdefault(kind.geometry, []).append(name)
    added = set(skip)
    for geometry, scenes in groups.items():
        g = parser.add_argument_group(f"{' and '.join(scenes)} scene"
                                      f"{'s' if len(scenes) > 1 else ''}")
        names = [name for name in declarations(geometry) if name not in added]
        added.update(names)
        add_declared_options(g, geometry, names, groups)


def add_declared_options(group, part, names, groups=None):
    """The options of the declared fields ``names`` of ``part`` (a declared dataclass:
    a scene's geometry, :class:`Analysis`, :class:`Outputs`), each from its declaration
    (:class:`masonry.parameters.Declaration`): ``--name`` with dashes (or its
    ``option``), typed by its kind, its values' name its ``metavar`` (else the option's,
    upper case), its help its ``help`` (else what it is, its range and default); a
    switch (a boolean) is ``--name`` when it defaults to false, ``--no-name`` when it
    defaults to true, both when it is optional. ``groups``: geometry -> the scenes that
    share it, for a scene option's help. A new declared field is an option without a
    line here."""
    for name in names:
        declaration = declarations(part)[name]
        option = declaration.option or f"--{name.replace('_', '-')}"
        if declaration.kind == "bool":
            default = defaults(part)[name]
            if default is not True:
                group.add_argument(option, dest=name, action="store_true", default=None,
                                   help=declaration.help.replace("%", "%%"))
            if default is not False:
                group.add_argument(f"--no-{option[2:]}", dest=name, action="store_false",
                                   default=None,
                                   help=declaration.off_help.replace("%", "%%"))
            continue
        metavar = declaration.metavar or (None if declaration.choices else
                                          option[2:].replace("-", "_").upper())
        group.add_argument(option, dest=name, choices=declaration.choices,
                           type={"int": int, "float": float}.get(declaration.kind, str),
                           action="append" if declaration.repeat else None,
                           metavar=metavar,
                           help=_declared_help(name, declaration, part, groups or {}))


def _declared_help(name, declaration, part, groups) -> str:
    """An option's help from its declaration: what it is, the values it takes, its
    default (and the values of the presets of its scenes), and the other scenes that
    take it."""
    if declaration.help:
        text = declaration.help
    else:
        values = "" if declaration.choices else \
            (declaration.expected or declaration._expected()).split(" (")[0] + "; "
        text = f"{declaration.doc} ({values}default {_text(defaults(part)[name])}"
        presets = [key for key, inputs in PRESETS.items() if name in inputs
                   and kind_of(inputs.get("scene", "section")).geometry is part]
        if len(presets) > 1:
            text += (f"; presets {' / '.join(presets)}: "
                     f"{' / '.join(_text(PRESETS[k][name]) for k in presets)}")
        text += ")"
    others = [scene for geometry, scenes in groups.items() if geometry is not part
              and name in declarations(geometry) for scene in scenes]
    if others:
        text += f"; also the {', '.join(others)} scenes"
    return text.replace("%", "%%")


def _text(value) -> str:
    return "none" if value is None else f"{value:g}" if isinstance(value, float) else str(value)


def add_overlap_option(group):
    low, high = OVERLAP_TOLERANCE_RANGE
    group.add_argument("--overlap-tolerance", dest="overlap_tolerance", type=float,
                       metavar="REL", help="accept blocks that interpenetrate by up to this "
                       f"fraction of the smaller one's size ({low:g} to {high:g}; default "
                       f"{INTERPENETRATION_REL:g}): for models that overlap by design")


def add_analysis_options(parser, boundary=True):
    """Friction, density and solver options; ``boundary`` adds a section's boundary."""
    g = parser.add_argument_group("analysis")
    add_material_options(g)
    add_declared_options(g, Analysis, SOLVER_OPTIONS)
    if boundary:
        add_boundary_options(g)


def add_boundary_options(g):
    """``--boundary`` and ``--dome``: what a section's end bricks bear on."""
    add_declared_options(g, Analysis, ("boundary",))
    g.add_argument("--dome", action="store_true",
                   help="dome mode, the default of a section: --boundary cyclic")


def add_live_load_options(parser):
    """The live loads of a collapse load factor (docs/model.md 6.8); at most one per run."""
    g = parser.add_argument_group(
        "live load: compute the collapse load factor lambda and its mechanism")
    g.add_argument("--lateral", metavar="AZIMUTH|all",
                   help="horizontal body force lambda x each block's weight, at AZIMUTH "
                        "degrees from +x toward +y; 'all' searches 24 azimuths and the "
                        "dome's symmetry directions for the worst and refines it "
                        "between them (where its bound's corners lie, to 1e-7 of "
                        "lambda, 1e-4 when fast; not on a cyclic section: use --scene "
                        "dome)")
    g.add_argument(f"--{option_of('point_loads')}", dest="point_loads", action="append",
                   metavar="NAME_OR_PATTERN:FX,FY,FZ",
                   help="force in newtons at the centre of the top face of every block "
                        "the name or fnmatch pattern matches (repeatable)")
    g.add_argument("--crown-load", dest="crown_load", type=float, metavar="NEWTONS",
                   help="domes: a downward load on the top course, shared by brick top "
                        "area (a lantern; a section carries its 1/n share)")
    add_declared_options(g, Analysis, ("friction_law",))


def collapse_summary(record, report) -> int:
    """The lines about the collapse load factor of a run record; returns the exit code:
    3 when the factor asked for has no verdict (:data:`~masonry.rbe.collapse_result.
    VERDICTS`), else 0."""
    from masonry.export.summaries import mechanism_words, search_words  # when reporting

    c = record["collapse"]
    live = c["live_load"]
    what = (f"lateral at {c['azimuth_deg']:.6g} deg" if live["kind"] == "lateral"
            and c["azimuth_deg"] is not None else f"{live['kind']} load")
    if live["kind"] == "point":
        what += f" on {live['blocks']} block{'s' * (live['blocks'] != 1)}"
    if c.get("azimuths"):
        what += f" ({search_words(c)})"
    if c["friction_law"] != "associated" and c["associated_factor"] is not None:
        what += (f", {c['friction_law']} friction (associated: "
                 f"{c['associated_factor']:.4g})")
    if c["load_factor"] is None:
        decided = c["status"] in VERDICTS
        report(f"collapse: no load factor ({c['status']}), {what}"
               + ("" if decided else f"; {c['solver']} stopped without a verdict"))
        if c["note"]:
            report(f"note: {c['note']}")
        return 0 if decided else 3
    report(f"collapse: lambda = {c['load_factor']:.4g} for the {what}; mechanism: "
           f"{mechanism_words(c)}; {c['solver']} {c['time_s']:.3g} s (collapse/00_collapse.txt)")
    if c.get("solved_on") == "whole, the half rejected":
        report("note: the mirror half's collapse forces failed their check on the whole, so "
               "the whole model was solved (run.json: collapse.solved_on)")
    if c["note"]:
        report(f"note: {c['note']}")
    return 0


def add_material_options(group):
    """The material's options (:data:`MATERIAL_OPTIONS`), with their ranges and
    defaults."""
    add_declared_options(group, Analysis, MATERIAL_OPTIONS)


def add_output_options(parser):
    g = parser.add_argument_group("output")
    g.add_argument("--out", default="exports", metavar="DIR",
                   help="output root; the run folder is DIR/<structure id> (default exports)")
    add_declared_options(g, Outputs, [name for name in declarations(Outputs)
                                      if name not in FIGURE_OPTIONS])
    add_figure_options(g)
    g.add_argument("--force", action="store_true",
                   help="recompute even if the run folder holds this input's results")
    add_verbosity(g)


def add_figure_options(group):
    """``--figure-format`` and ``--dpi``: the files every figure is written as."""
    add_declared_options(group, Outputs, FIGURE_OPTIONS)


def add_verbosity(parser):
    """``-q`` (only warnings and errors) and ``-v`` (progress and solver choices even
    when the output is redirected); by default progress shows on a terminal only."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("-q", "--quiet", action="store_true",
                       help="no progress messages: the results (on stdout), warnings and "
                            "errors only")
    group.add_argument("-v", "--verbose", action="store_true",
                       help="progress and the solvers' choices (fallbacks), also when "
                            "the output is redirected")


def given_inputs(args) -> dict:
    """The inputs (flat names, :func:`masonry.params.names`) the user gave as options."""
    known = {"scene", "fast", *names()}
    given = {k: v for k, v in vars(args).items() if k in known and v is not None}
    if getattr(args, "dome", False):
        given.setdefault("boundary", "cyclic")
    return given


def params_from_args(args, laying=False) -> Params:
    """Preset or file first, then every option the user gave; validated. Options that do
    not apply to the resulting scene are refused (:func:`masonry.params.applies`). A
    section whose boundary neither an option nor the file gives is cyclic: it stands for
    the whole dome, the question a run answers first. ``laying``: a stage study's, whose
    file's ``[mortar]`` may give the mortar by age (:func:`masonry.params.load`)."""
    given = given_inputs(args)
    scene = given.get("scene")
    if args.params is None and args.preset:
        # a preset's inputs are its scene's: another scene would take none of them
        scenes = ((PRESETS[args.preset]["scene"],) if "scene" in PRESETS[args.preset]
                  else ("section", "dome"))
        if given.get("scene", scenes[0]) not in scenes:
            raise ParameterError("scene", given["scene"], f"{' or '.join(scenes)} with "
                                 f"--preset {args.preset} (leave --preset out for another "
                                 f"scene)")
        scene = scene or scenes[0]
    if args.params is None:
        _refuse_inapplicable(given, kind_of(scene or "section"))
    if getattr(args, "dome", False) and (scene or "section") != "section":
        raise ParameterError("dome", True, f"an option of a section, not of this "
                                           f"{scene} scene")
    if args.params is not None:
        params = load(args.params, laying=laying, **given)
        _refuse_inapplicable(given, params.kind)
    elif args.preset:
        params = from_preset(args.preset, **given)
    elif scene in PRESETS:  # a scene whose inputs default to a preset of its name
        params = from_preset(scene, **given)
    else:
        params = validate(Params.of(**given))
    params = section_default(params, "boundary" in given or _file_names(args, "boundary"))
    check_print_size(args, params)
    return params


def _file_names(args, name) -> bool:
    """Whether the ``--params`` file (if any) gives the input ``name``."""
    if args.params is None:
        return False
    data = read_toml(args.params, "params")
    return name in data.get("params", data)


def _refuse_inapplicable(given, kind):
    """Refuse an option that does not apply to scenes of ``kind``."""
    for name, value in given.items():
        if name in ("scene", "fast") or applies(name, kind):
            continue
        scenes = [k.name for k in KINDS.values() if applies(name, k)]
        raise ParameterError(name, value, f"an option of the {' or '.join(scenes)} "
                                          f"scene, not of this {kind.name} scene")


def check_print_size(args, params: Params):
    """Refuse ``--print-size`` beside ``--no-printable``: the 3MF is the printable body."""
    size = params.outputs.print_size
    if size is not None and not params.outputs.printable:
        raise ParameterError("print_size", size,
                             "no --no-printable beside it (dome.3mf is the printable body "
                             "at that size)")


def summary(record, report):
    """The lines every subcommand prints about the model it wrote."""
    counts = record["counts"]
    interfaces = sum(counts.get("interfaces", {}).values())
    state = "up to date, reused" if record.get("reused") else "written"
    what = (f"{counts['bricks']} blocks" if kind_of(record["scene"]).block_word == "blocks" else
            f"{counts['bricks']} bricks ({counts['regular']} regular, {counts['pattern']} "
            f"pattern, {counts['fill_in']} fill-in) in {counts['courses']} courses")
    report(f"{record['structure_id']}: {what}, {interfaces} interfaces, "
           f"weight {record['weight_N']:.4g} N")
    pattern_note(record, report)
    figures_note(record, report)
    report(f"{state}: {record['path']}")


def figures_note(record, report):
    """The line naming the figures a run left out because they would show nothing (an
    all-zero tension, solver noise, one web's outline in a whole dome's frame)."""
    skipped = (record.get("figures") or {}).get("skipped") or {}
    if skipped:
        report(f"figures left out, nothing to show: {', '.join(skipped)} (why: run.json "
               f"figures.skipped)")


def pattern_note(record, report):
    """The line about pattern lines that end far below the top (docs/model.md 4.3), when
    a dome's did."""
    pattern = record.get("pattern") or {}
    ended = pattern.get("ended_far_below_top") or []
    if ended:
        courses = sorted({int(course) for course, _ in ended})
        report(f"note: {len(ended)} of {pattern['lines']} pattern lines end far below the "
               f"top course {record['counts']['courses']}, on course"
               f"{'s' if len(courses) > 1 else ''} {', '.join(map(str, courses))}: "
               f"{pattern['ended_why']} (run.json: pattern.ended)")


def _verdict(rbe) -> str:
    """The verdict of a record written without one: a friction+ result always has a
    finite MoI, so one without is a solve that stopped short."""
    if rbe.get("friction") == "plus" and _missing(rbe.get("moi")):
        return "not solved"
    return "feasible" if rbe["feasible"] else "infeasible"


def _number(value) -> str:
    """A residual for a report line: two digits, or 'none' without one."""
    return "none" if _missing(value) else f"{value:.2g}"


def _missing(value) -> bool:
    """A number a record does not have: None (read from run.json) or NaN."""
    return value is None or (isinstance(value, float) and not math.isfinite(value))


def centering_line(total_N, fraction, held, count, where) -> str:
    """The line about a centering force (docs/model.md 6.10): its total, its fraction of
    the weight, how many blocks need a support and the largest of them (``held``: dicts
    with ``name`` and ``support_N``, largest first), and the file that lists them."""
    if total_N is None:
        return "centering force: not solved (the support program found no optimum)"
    largest = ", ".join(f"{h['name']} ({h['support_N']:.3g} N)" for h in held[:3])
    return (f"centering force: supports must give {total_N:.4g} N ({fraction:.3g} of the "
            f"weight) to {count} block{'' if count == 1 else 's'} at their centroids; the "
            f"largest {largest} ({where})")


def adhesion_line(adhesion) -> str:
    """The line about the least adhesion (docs/model.md 6.12) of a record's ``adhesion``:
    ``a*``, the cohesion and tensile strength it stands for, and the joints that use most
    (``joints``: dicts with ``blocks`` and ``adhesion_kPa``, most first)."""
    if adhesion["a_kPa"] is None:
        return f"least adhesion: none found ({adhesion['reason']})"
    a, ratio = adhesion["a_kPa"], adhesion["ratio"]
    if a == 0:
        return "least adhesion: 0 kPa, the structure stands with dry joints"
    joints = ", ".join(f"{' | '.join(j['blocks'])} ({j['adhesion_kPa']:.3g} kPa)"
                       for j in adhesion["joints"])
    return (f"least adhesion: mortar must hold {a:.4g} kPa (c = {a:.4g}, t_c = {ratio:g} x "
            f"{a:.4g} kPa) for it to stand without centering; the joints that need most: "
            f"{joints} (RBE/adhesion.csv)")


def verdict_meaning(record, verdict) -> str:
    """The line saying what an RBE verdict means for the scene and boundary that ran."""
    rbe = record["rbe"]
    subject = kind_of(record["scene"]).verdict_subject(record["params"].get("boundary"))
    if verdict == "feasible":
        return (f"meaning: {subject} stands under its own weight: compression, and friction "
                f"within mu {rbe['mu']:g}, at its joints balance every block without tension")
    line = (f"meaning: {subject} cannot stand under its own weight: it would need tension "
            f"at its joints, which masonry does not carry")
    if _missing(rbe["moi"]):
        return line
    return line + ("; the MoI sums that tension over every joint's vertices (N), the MoI "
                   "factor divides it by the weight")


def rbe_summary(record, report) -> int:
    """The lines about the rigid block equilibrium of a run record; returns the exit code:
    3 when the equilibrium was not solved (no verdict), else 0."""
    rbe = record["rbe"]
    verdict = rbe.get("verdict") or _verdict(rbe)
    if verdict == "not solved":
        report(f"RBE: not solved (friction-{rbe['friction']}, mu {rbe['mu']:g}): "
               f"{rbe['solver']} stopped with status {rbe.get('status')!r}, residual "
               f"{_number(rbe['residual_eq'])}; no verdict")
        return 3
    if verdict == "infeasible" and rbe["friction"] == "plus" and _missing(rbe["moi"]):
        # friction-net has no equilibrium, and friction+ was not solved: no MoI
        report(f"RBE: infeasible (friction-net has no equilibrium, mu {rbe['mu']:g}); MoI "
               f"not computed: {rbe['solver']} stopped with status {rbe.get('status')!r} "
               f"on friction-{rbe['friction']}, residual {_number(rbe['residual_eq'])}")
        return 3
    model = rbe.get("friction_model", "square")  # records written before the models
    moi = ("no MoI (friction-net has none)" if _missing(rbe["moi"]) else
           f"MoI {rbe['moi']:.4g} N, MoI factor {rbe['moi_factor']:.4g}")
    report(f"RBE: {verdict} (friction-{rbe['friction']}, mu {rbe['mu']:g}, friction model "
           f"{model}), {moi}, residual {_number(rbe['residual_eq'])}, {rbe['solver']} "
           f"{rbe['time_s']:.3g} s")
    report(verdict_meaning(record, verdict))
    if rbe.get("solved_on") == "whole, the half rejected":
        report("note: the mirror half's forces failed their check on the whole, so the "
               "whole model was solved (run.json: rbe.solved_on)")
    if verdict == "feasible" and rbe["friction"] == "plus" and not _missing(rbe["moi"]) \
            and rbe["moi"] > 0:
        report("note: the MoI is the tension of the friction+ optimum (thesis 3.3.3), "
               "which trades compression for some tension; friction-net shows that none is "
               "needed")
    if model == "square":
        report("note: the square friction model is the thesis's pyramid: up to 41 % more "
               "friction than Coulomb's cone where joints slide diagonally to their axes, "
               "so this verdict depends on how the model is turned")
    centering = record.get("centering")
    if centering is not None:
        report(centering_line(centering["total_N"], centering["fraction"], centering["held"],
                              centering["held_count"], "RBE/centering.csv"))
    adhesion = record.get("adhesion")
    if adhesion is not None:
        report(adhesion_line(adhesion))
    if verdict == "infeasible" and record["params"].get("friction") == "net":
        report("friction-net has no equilibrium for this structure, so it has no measure "
               "of infeasibility: --friction auto (or plus) gives its MoI and forces")
    return 0
