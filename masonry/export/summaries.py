"""The text summaries of a run: ``00_parameters.txt`` and ``RBE/00_objective.txt``."""

from masonry.parameters import declarations, values
from masonry.rbe.solve import ACCURACY, LOAD_PATH
from masonry.tolerances import MECHANISM_MAIN, MOTION_TOL


def _line(name, value, note) -> str:
    value = f"{value:.6g}" if isinstance(value, float) else value
    return (f"{name:>14} = {value!s:<12} # {note}" if note else f"{name:>14} = {value}")


def _lines(part, shown, names) -> list:
    """One line per input of a declared ``part``: its value as shown, what it means."""
    docs = declarations(part)
    return [_line(name, shown[name], docs[name].doc) for name in names]


ANALYSIS_SHOWN = ("mu", "density", "friction")
"""The analysis inputs printed with their values (the friction model, the accuracy
preset and the solvers follow, as the run resolved them)."""

OUTPUTS_SHOWN = ("quick", "cad_offset", "print_size")


def parameters_text(params, structure_id: str) -> str:
    """``00_parameters.txt``: the structure id and the inputs of the scene that was run,
    with the values the run used (a default resolved, the accuracy preset and solvers it
    resolved to), each with what it means."""
    analysis, kind, outputs = params.analysis, params.kind, params.outputs
    preset = ACCURACY[analysis.accuracy]
    solvers = (analysis.solver if analysis.solver is not None
               else f"{preset.net_solver} (friction-net), {preset.plus_solver} (friction+)")
    shown = kind.shown(params.geometry)
    lines = [f"structure id: {structure_id}", "", _line("scene", kind.name, "")]
    lines += _lines(params.geometry, shown, shown)
    if len(kind.boundaries) > 1:
        lines += _lines(analysis, values(analysis), ("boundary",))
    cone = analysis.cone
    lines += ["", *_lines(analysis, values(analysis), ANALYSIS_SHOWN),
              _line("friction_cone", cone.name, cone.describe()),
              _line("contact_law", analysis.law_text(), ""),
              _line("accuracy", preset.name, f"solver preset; residual <= {preset.residual:g}"),
              _line("solver", solvers, "" if analysis.solver is None else "set by --solver"),
              ""]
    moved = kind.moved_for_cad
    lines += _lines(outputs, values(outputs),
                    [name for name in OUTPUTS_SHOWN if name != "cad_offset" or moved])
    return "\n".join(lines) + "\n"


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


def objective_text(result, centering=None) -> str:
    """``RBE/00_objective.txt``: the thesis's summary of a solve, each value with what it
    means, and the centering force (:class:`~masonry.rbe.centering.CenteringResult`)
    where the structure cannot stand."""
    d = result.to_dict()
    verdict = "feasible" if d["feasible"] else "infeasible"
    by_lp = d["solver"] == LOAD_PATH  # docs/model.md 6.6: the LP's point answers
    if by_lp:
        meaning = ("stands without tension: the load-path LP found forces within the "
                   "friction model that balance every block; no solver reached the "
                   "friction-net QP's optimum, so they are one equilibrium, not the "
                   "least-norm one")
    elif d["feasible"]:
        meaning = "stands without tension: the friction-net QP was solved to tolerance"
    else:
        meaning = "cannot stand without tension; friction+ measures how much it needs"
    whose = "; of these forces, above the QP's minimum" if by_lp else ""
    lines = [
        f"feasibility:        {verdict} ({meaning})",
        f"friction method:    friction-{d['friction']} (mu = {d['mu']:g}; the problem "
        "whose solution is reported)",
        f"friction model:     {result.cone.describe()}",
        f"contact law:        {result.contact_law}",
        f"objective:          {d['objective']:.6g} N^2 (1/2 x^T H x, weights: tension 1, "
        f"compression and friction 1e-3{whose})",
        f"MoI:                {d['moi']:.6g} N (sum of all vertex tensions: the QP's "
        "optimality measure, not a force anyone supplies)",
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
    if centering is not None:
        lines.append(_centering_text(centering))
    return "\n".join(lines) + "\n"


def _centering_text(centering) -> str:
    """The centering force's line of ``RBE/00_objective.txt`` (docs/model.md 6.10)."""
    if centering.total_N is None:
        return (f"centering force:    not solved ({centering.solver}: {centering.status})")
    return (f"centering force:    {centering.total_N:.6g} N ({centering.fraction:.6g} of the "
            f"weight): the least total force that supports at the blocks' centroids must "
            f"give, with no tension and the friction model above; {centering.held_count} "
            f"blocks need one (RBE/centering.csv; {centering.solver}, residual "
            f"{centering.residual_eq:.3g}, {centering.time_s:.3g} s)")


def collapse_text(result) -> str:
    """``collapse/00_collapse.txt``: the collapse load factor and its mechanism, readable
    (docs/model.md 6.8, 6.9), with the friction-law note when sliding takes part."""
    d = result.to_dict()
    factor = "none" if d["load_factor"] is None else f"{d['load_factor']:.6g}"
    live = d["live_load"]
    lines = [
        f"load factor:        {factor} ({d['status']})",
        f"dead load stands:   {d['dead_load_feasible']}",
        f"live load:          {live['kind']}, "
        + ", ".join(f"{k} {_readable(v)}" for k, v in live.items() if k != "kind"),
        f"azimuth:            {d['azimuth_deg']}" + (f" ({search_words(d)})"
                                                       if d.get("azimuths") else ""),
        f"mu:                 {d['mu']:g}",
        f"friction model:     {result.cone.describe()}",
        f"contact law:        {result.contact_law}",
        f"friction law:       {d['friction_law']}"
        + ("" if d["associated_factor"] is None
           else f" (associated factor {d['associated_factor']:.6g})"),
        f"mechanism:          {mechanism_words(d)}",
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


def search_words(record: dict) -> str:
    """How an azimuth search found its least factor (``record``:
    :meth:`CollapseResult.to_dict` after ``--lateral all``)."""
    refined = record.get("refined") or ()
    return (f"the least of {len(record['azimuths'])} azimuths"
            + (f" and {len(refined)} more solved between them at the corners of their bounds"
               if refined else ""))


def mechanism_words(record: dict) -> str:
    """The mechanism's joints in words, as ``00_collapse.txt`` and the command line say
    them (``record``: :meth:`CollapseResult.to_dict`)."""
    return (f"{record['main_hinges']} hinges, {record['main_sliding']} sliding joints "
            f"(opening or slipping by {MECHANISM_MAIN:.0%} of the largest or more; "
            f"{record['hinges']} and {record['sliding']} by {MOTION_TOL:.1%} of the largest "
            f"displacement or more)")


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
