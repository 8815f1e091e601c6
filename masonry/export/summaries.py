"""The text summaries of a run: ``00_parameters.txt`` and ``RBE/00_objective.txt``."""

from masonry.params import arch_radius, structure_id
from masonry.rbe.solve import ACCURACY, friction_model
from masonry.tolerances import MECHANISM_MAIN, MOTION_TOL

# the inputs of each scene, with their units, in the order they are printed
_GEOMETRY = {
    "section": (("stretch", "dome height / circumradius"), ("n", "walls of the dome"),
                ("r", "full rhombi across the section"),
                ("p", "pattern bricks per rhombus side"),
                ("cut", "fraction of the height cut off"), ("unit", "m, the brick unit"),
                ("min_fill", "units, shortest fill-in brick"),
                ("boundary", "what the section's end bricks bear on")),
    "wall": (("wall_length", "units"), ("wall_courses", "courses"),
             ("unit", "m, the brick unit")),
    "arch": (("arch_shape", ""), ("arch_blocks", "voussoirs"),
             ("arch_span", "m, of the centre line"),
             ("arch_rise", "m, of the centre line"),
             ("arch_thickness", "m"), ("arch_depth", "m, along y")),
    "assembly": (("assembly", "the imported model"),),
}
_GEOMETRY["dome"] = _GEOMETRY["section"][:-1]
_ANALYSIS = (("mu", "friction coefficient"), ("density", "kg/m^3"),
             ("friction", "net | plus | auto (net, then plus if infeasible)"))
_OUTPUT = (("fast", "one view, lower resolution"),
           ("cad_offset", "units the CAD files move each brick inward"),
           ("print_size", "mm, largest dimension of dome.3mf (None: no 3MF)"))
_BRICK_SCENES = ("section", "dome", "wall")
"""The scenes of bricks with an inward face, which the CAD offset moves (an arch's
voussoirs and an imported assembly's blocks stay where they are)."""


def _line(name, value, note) -> str:
    value = f"{value:.6g}" if isinstance(value, float) else value
    return (f"{name:>14} = {value!s:<12} # {note}" if note else f"{name:>14} = {value}")


def parameters_text(params) -> str:
    """``00_parameters.txt``: the structure id and the inputs of the scene that was run,
    with the values the run used (the accuracy preset and solvers it resolved to)."""
    preset = ACCURACY[params.solver_accuracy]
    solvers = (params.solver if params.solver is not None
               else f"{preset.net_solver} (friction-net), {preset.plus_solver} (friction+)")
    lines = [f"structure id: {structure_id(params)}", "", _line("scene", params.scene, "")]
    lines += [_line(name, _value(params, name), note)
              for name, note in _GEOMETRY.get(params.scene, ())]
    cone = friction_model(params.solver_accuracy, params.friction_cone)
    lines += ["", *(_line(name, getattr(params, name), note) for name, note in _ANALYSIS),
              _line("friction_cone", cone.name, cone.describe()),
              _line("accuracy", preset.name, f"solver preset; residual <= {preset.residual:g}"),
              _line("solver", solvers, "" if params.solver is None else "set by --solver"),
              ""]
    lines += [_line(name, getattr(params, name), note) for name, note in _OUTPUT
              if name != "cad_offset" or params.scene in _BRICK_SCENES]
    return "\n".join(lines) + "\n"


def _value(params, name):
    """A parameter's value as the run used it (an arch's default rise resolved)."""
    if name == "arch_rise" and params.arch_rise is None:
        return arch_radius(params.arch_shape, params.arch_span)[1]
    return getattr(params, name)


def lp_check_text(result) -> str:
    """What the independent LP check (HiGHS, friction-net) said, and what it means."""
    preset = ACCURACY.get(result.accuracy)
    verdict = "feasible" if result.feasible else "infeasible"
    if result.lp_feasible is None:
        if result.lp_time_s > 0:
            return "ran, inconclusive (time limit): the QP's verdict stands alone"
        if preset is not None and preset.lp_check == "infeasible" and result.feasible:
            return (f"not run in {preset.name}: it confirms infeasible verdicts only; a "
                    "feasible one rests on the recomputed residuals")
        return (f"not run in {result.accuracy}; the accurate preset runs it to confirm an "
                "infeasible verdict")
    agrees = result.lp_feasible == result.feasible
    return (f"the friction-net LP is {'feasible' if result.lp_feasible else 'infeasible'}: "
            + (f"confirms {verdict}" if agrees else f"CONTRADICTS the QP's {verdict}"))


def objective_text(result) -> str:
    """``RBE/00_objective.txt``: the thesis's summary of a solve, each value with what it
    means."""
    d = result.to_dict()
    verdict = "feasible" if d["feasible"] else "infeasible"
    meaning = ("stands without tension: the friction-net QP was solved to tolerance"
               if d["feasible"] else
               "cannot stand without tension; friction+ measures how much it needs")
    lines = [
        f"feasibility:        {verdict} ({meaning})",
        f"friction method:    friction-{d['friction']} (mu = {d['mu']:g}; the problem "
        "whose solution is reported)",
        f"friction model:     {result.cone.describe()}",
        f"objective:          {d['objective']:.6g} N^2 (1/2 x^T H x, weights: tension 1, "
        "compression and friction 1e-3)",
        f"MoI:                {d['moi']:.6g} N (sum of all vertex tensions)",
        f"MoI factor:         {d['moi_factor']:.6g} (MoI / weight)",
        f"weight:             {d['weight_N']:.6g} N",
        f"solver:             {d['solver']} ({d['status']}, {d['iterations']} iterations; "
        f"accuracy preset {d['accuracy']})",
        f"residual (eq):      {d['residual_eq']:.3g} (||A x + f||_inf / ||f||_inf, "
        f"accepted <= {_residual(d['accuracy'])})",
        f"friction violation: {d['friction_violation']:.3g} (largest, per reference "
        "weight)",
        f"LP check (HiGHS):   {lp_check_text(result)}",
        f"time:               {d['time_s']:.3g} s",
    ]
    return "\n".join(lines) + "\n"


def collapse_text(result) -> str:
    """``collapse/00_collapse.txt``: the collapse load factor and its mechanism, readable
    (SPEC 6.8-6.9), with the friction-law note when sliding takes part."""
    d = result.to_dict()
    factor = "none" if d["load_factor"] is None else f"{d['load_factor']:.6g}"
    live = d["live_load"]
    lines = [
        f"load factor:        {factor} ({d['status']})",
        f"dead load stands:   {d['dead_load_feasible']}",
        f"live load:          {live['kind']}, "
        + ", ".join(f"{k} {_readable(v)}" for k, v in live.items() if k != "kind"),
        f"azimuth:            {d['azimuth_deg']}",
        f"mu:                 {d['mu']:g}",
        f"friction model:     {result.cone.describe()}",
        f"friction law:       {d['friction_law']}"
        + ("" if d["associated_factor"] is None
           else f" (associated factor {d['associated_factor']:.6g})"),
        f"mechanism:          {d['main_hinges']} hinges, {d['main_sliding']} sliding joints "
        f"(opening or slipping by {MECHANISM_MAIN:.0%} of the largest or more)",
        f"joints that move:   {d['opening']} open ({d['hinges']} hinges), {d['sliding']} "
        f"slide (by {MOTION_TOL:.1%} of the largest displacement or more)",
        f"solver:             {d['solver']} ({d['iterations']} iterations)",
        f"residual (eq):      {d['residual']:.3g}",
        f"work balance:       {d['work_balance']:.3g}",
        f"time:               {d['time_s']:.3g} s",
    ]
    if d["note"]:
        lines.append(f"note:               {d['note']}")
    return "\n".join(lines) + "\n"


def _readable(value) -> str:
    """A number or a list of numbers to six significant digits; anything else as is."""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_readable(v) for v in value) + "]"
    return str(value)


def _residual(accuracy) -> str:
    preset = ACCURACY.get(accuracy)
    return "?" if preset is None else f"{preset.residual:g}"
