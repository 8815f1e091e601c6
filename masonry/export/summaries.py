"""The text summaries of a run: ``00_parameters.txt`` and ``RBE/00_objective.txt``."""

import dataclasses

from masonry.params import structure_id


def parameters_text(params) -> str:
    """``00_parameters.txt``: the structure id and every input, readable."""
    lines = [f"structure id: {structure_id(params)}", ""]
    lines += [f"{f.name:>12} = {getattr(params, f.name)}" for f in dataclasses.fields(params)]
    return "\n".join(lines) + "\n"


def objective_text(result) -> str:
    """``RBE/00_objective.txt``: the thesis's summary of a solve, readable."""
    d = result.to_dict()
    verdict = "feasible" if d["feasible"] else "infeasible"
    lines = [
        f"feasibility:        {verdict}",
        f"friction method:    friction-{d['friction']} (mu = {d['mu']:g})",
        f"objective:          {d['objective']:.6g} N^2",
        f"MoI:                {d['moi']:.6g} N",
        f"MoI factor:         {d['moi_factor']:.6g}",
        f"weight:             {d['weight_N']:.6g} N",
        f"solver:             {d['solver']} ({d['status']}, {d['iterations']} iterations)",
        f"residual (eq):      {d['residual_eq']:.3g}",
        f"friction violation: {d['friction_violation']:.3g}",
        f"LP check (HiGHS):   {d['lp_feasible']}",
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
        + ", ".join(f"{k} {v}" for k, v in live.items() if k != "kind"),
        f"azimuth:            {d['azimuth_deg']}",
        f"mu:                 {d['mu']:g}",
        f"mechanism:          {d['opening']} interfaces open ({d['hinges']} hinges), "
        f"{d['sliding']} slide",
        f"solver:             {d['solver']} ({d['iterations']} iterations)",
        f"residual (eq):      {d['residual']:.3g}",
        f"work balance:       {d['work_balance']:.3g}",
        f"time:               {d['time_s']:.3g} s",
    ]
    if d["note"]:
        lines.append(f"note:               {d['note']}")
    return "\n".join(lines) + "\n"
