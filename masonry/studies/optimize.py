"""Optimisation over a study's inputs: Optuna proposes variants, the sweep runs them.

The search space is the study's (:class:`masonry.studies.sweep.Study`): every ``grid``
list is a choice (categorical), every ``sample`` range ``(low, high)`` an integer range
where both ends are integers, else a float range on the sweep's grid
(:func:`~masonry.studies.sweep.sample_step`). Each trial is one sweep variant, run
by the sweep's :class:`~masonry.studies.sweep.Runner` (serially, on a local Dask cluster
or on a scheduler) into its own run folder, so a variant run before, by a sweep or an
earlier trial, is reused. Its objective values are summary columns of its row
(:func:`~masonry.studies.sweep.measure_columns`), and the study's ``constraints`` bound
others (Optuna's constraint values: the distance outside each bound).

Trials are asked in batches of a fixed size and each batch is told before the next one
is asked, and the sampler of batch ``k`` is seeded from ``(seed, k)``: the trials are a
function of the study, the seed and the batch size only, whether the batch runs serially
or on many workers, and whatever order its variants finish in. The trials live in an
Optuna journal file (:class:`optuna.storages.JournalStorage`) beside the study's
folder: an interrupted optimisation run again keeps its finished trials and runs the
unfinished ones again with their inputs.
"""

import hashlib
import json
import logging
import warnings
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from masonry.errors import MasonryError, ParameterError
from masonry.runfolder import alone, source_file

log = logging.getLogger(__name__)

DIRECTIONS = ("maximize", "minimize")
REPEATS = 100
"""Proposals in a row of variants already tried after which an optimisation stops: its
sampler has converged, or the search space holds no other variant."""

SAMPLERS = ("tpe", "random")
"""Optuna's tree-structured Parzen estimator (integer, float and categorical inputs, one
or more objectives, constraints; its first 10 trials are random) or random search."""


@dataclass(frozen=True)
class Search:
    """An optimisation: a study's search space, the columns to optimise and how.

    Parameters
    ----------
    study : masonry.studies.sweep.Study
        Fixed inputs (``base``), choices (``grid``), ranges (``sample``) and bounds on
        result columns (``constraints``).
    objectives : tuple of (str, str)
        ``(column, direction)`` pairs, ``direction`` one of :data:`DIRECTIONS`; more
        than one: a multi-objective search for the Pareto front.
    trials : int
        How many trials to finish in all, each a variant not tried before (those of an
        earlier, interrupted run count).
    seed : int
        Seeds the sampler.
    batch : int
        Trials asked at once and run side by side (on a cluster, about its workers).
    sampler : str
        One of :data:`SAMPLERS`.
    """

    study: object  # masonry.studies.sweep.Study: imported with the pipeline, when it runs
    objectives: tuple
    trials: int = 20
    seed: int = 0
    batch: int = 4
    sampler: str = "tpe"

    @property
    def inputs(self) -> list:
        """The searched inputs: the grid's choices, then the sampled ranges."""
        return self.study.swept

    def checked(self) -> "Search":
        """This search, refused if it cannot run (before any work), its objectives named
        by record key (``moi_N`` in ``summary.csv`` is ``moi``).

        Raises
        ------
        ParameterError
            Named ``maximize`` (or ``minimize``) for a missing objective, a column that
            is no number of the summary (as ``summary.csv`` names it) or a column given
            twice; ``trials``, ``batch``, ``seed`` or ``sampler`` out of range; ``study`` for a
            study without search space or with a choice that is not a number, string or
            boolean.
        """
        from masonry.studies.sweep import column_key, measure_columns

        if not self.objectives:
            raise ParameterError("maximize", None, "--maximize COLUMN or --minimize "
                                 "COLUMN: a result column of the summary to optimise")
        columns = measure_columns(self.study)
        seen = set()
        for column, direction in self.objectives:
            if direction not in DIRECTIONS:
                raise ParameterError("direction", direction, f"one of {DIRECTIONS}")
            if column not in columns:
                raise ParameterError(direction, column, "a result column of the summary "
                                     f"that is a number, one of {', '.join(columns)}")
            if column in seen:
                raise ParameterError(direction, column, "each column once")
            seen.add(column)
        for name, value, ok, expected in (
                ("trials", self.trials, self.trials >= 1, "an integer >= 1"),
                ("batch", self.batch, self.batch >= 1, "an integer >= 1"),
                ("seed", self.seed, isinstance(self.seed, int) and self.seed >= 0,
                 "an integer >= 0"),
                ("sampler", self.sampler, self.sampler in SAMPLERS,
                 f"one of {', '.join(SAMPLERS)}")):
            if not ok:
                raise ParameterError(name, value, expected)
        if not self.inputs:
            raise ParameterError("study", "no [grid] or [sample]", "a study with a search "
                                 "space: [grid] lists of choices or [sample] [low, high] "
                                 "ranges")
        for name, values in self.study.grid.items():
            bad = [v for v in values if not isinstance(v, (bool, int, float, str))]
            if bad:
                raise ParameterError(f"grid.{name}", bad[0], "choices an optimisation can "
                                     "make: numbers, strings or booleans")
        return replace(self, objectives=tuple((column_key(c), d)
                                              for c, d in self.objectives))

    def identity(self) -> dict:
        """What makes the trials: the study's inputs and constraints, the objectives,
        seed, batch and sampler (not the number of trials: asking for more continues)."""
        study = {k: v for k, v in asdict(self.study).items()
                 if k not in ("count", "plots", "printable", "html", "figure_format", "dpi",
                              "html_plotly")}
        return {"study": study, "objectives": [list(o) for o in self.objectives],
                "seed": self.seed, "batch": self.batch, "sampler": self.sampler}

    def journal_name(self, label: str) -> str:
        """The Optuna study's name in the journal: ``label`` and a digest of
        :meth:`identity` (a changed study starts afresh beside the old one)."""
        text = json.dumps(self.identity(), sort_keys=True, default=str)
        return f"{label}-{hashlib.sha256(text.encode()).hexdigest()[:12]}"

    def inputs_of(self, trial) -> dict:
        """A trial's inputs as its variant runs them: floats to ten significant digits,
        as a sweep's draws (its run folder's name and the table show every digit)."""
        return {name: float(f"{value:.10g}") if isinstance(value, float) else value
                for name, value in ((k, trial.params.get(k)) for k in self.inputs)}

    def estimated_bricks(self) -> list:
        """Every trial's estimated blocks, for choosing where the trials run
        (:func:`masonry.studies.workers.local_workers`): each that of the variant at
        every choice's first and every range's lower end."""
        from masonry.studies.workers import estimated_bricks

        first = {**self.study.base, **{k: v[0] for k, v in self.study.grid.items()},
                 **{k: low for k, (low, high) in self.study.sample.items()}}
        trials = min(self.trials, self.size() or self.trials)
        return [estimated_bricks(first)] * trials

    def size(self):
        """How many variants the search space holds, or None when a range is of floats."""
        if any(not (isinstance(lo, int) and isinstance(hi, int))
               for k, (lo, hi) in self.study.sample.items() if k not in self.study.grid):
            return None
        return int(np.prod([len(v) for v in self.study.grid.values()]
                           + [hi - lo + 1 for k, (lo, hi) in self.study.sample.items()
                              if k not in self.study.grid]))

    def distributions(self) -> dict:
        """Optuna's distribution of every searched input."""
        from optuna.distributions import (CategoricalDistribution, FloatDistribution,
                                          IntDistribution)

        from masonry.studies.sweep import on_grid, sample_step

        out = {name: CategoricalDistribution(values)
               for name, values in self.study.grid.items()}
        for name, (low, high) in self.study.sample.items():
            if name in out:
                continue
            if isinstance(low, int) and isinstance(high, int):
                out[name] = IntDistribution(low, high)
            else:  # on the sweep's grid (names as a person writes them)
                out[name] = FloatDistribution(float(low), on_grid(high, low, high),
                                              step=sample_step(low, high))
        return out


def _quiet_optuna():
    """Optuna's per-trial log lines and its experimental-feature warnings off: the
    command line shows its own progress."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)


def _sampler(search: Search, k: int):
    """The sampler of batch ``k``: seeded from ``(seed, k)``, so a resumed optimisation
    asks what an uninterrupted one would."""
    import optuna

    seed = int(np.random.SeedSequence([search.seed, k]).generate_state(1)[0])
    if search.sampler == "random":
        return optuna.samplers.RandomSampler(seed=seed)
    return optuna.samplers.TPESampler(seed=seed)


def open_study(search: Search, journal, label: str):
    """The Optuna study of ``search`` in the journal file ``journal`` (created or
    resumed). Trials an interrupted run left unfinished are closed as failed (without a
    row) and queued again with their inputs.

    Returns
    -------
    optuna.Study

    Raises
    ------
    MasonryError
        ``journal`` is not an Optuna journal (corrupt, another file).
    """
    import optuna
    from optuna.storages import JournalStorage
    from optuna.storages.journal import JournalFileBackend
    from optuna.trial import TrialState

    _quiet_optuna()
    try:
        _check_entries(journal)
        storage = JournalStorage(JournalFileBackend(str(journal)))
        storage.get_all_studies()  # replayed through before anything is written to it
        study = optuna.create_study(
            study_name=search.journal_name(label), storage=storage, load_if_exists=True,
            directions=[direction for _, direction in search.objectives])
    except (ValueError, KeyError, TypeError, IndexError, AssertionError) as error:
        # JSON, UTF-8 or a log entry Optuna cannot replay: not a journal it wrote
        raise MasonryError(f"{journal}: expected the Optuna journal of an optimisation "
                           f"({type(error).__name__}: {_first_line(error)}); move it "
                           f"away to start again") from None
    for trial in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        study.tell(trial.number, state=TrialState.FAIL)
        study.enqueue_trial(trial.params)
        log.info("trial %d was not finished: queued again", trial.number)
    return study


def _check_entries(journal):
    """Raise ValueError unless every whole line of ``journal`` (if it exists) is a JSON
    object: Optuna takes a last line that is not one for a write cut short, and would
    append after it, leaving a journal that no run can read again."""
    try:
        with open(journal, "rb") as f:
            for line in f:
                if line.endswith(b"\n") and not isinstance(json.loads(line), dict):
                    raise ValueError(f"a line that is no log entry: {line[:40]!r}")
    except FileNotFoundError:
        return


def _first_line(error) -> str:
    lines = str(error).strip().splitlines()
    return lines[0] if lines else "unreadable"


def evaluated(study) -> list:
    """The trials that ran a variant, in the order they were asked (FrozenTrials with a
    ``row`` user attribute)."""
    return [t for t in study.get_trials(deepcopy=False) if "row" in t.user_attrs]


def optimise(search: Search, out_root, journal, label, workers=1, scheduler=None,
             progress=None):
    """Run the trials ``search`` still needs; returns the trials table.

    Parameters
    ----------
    search : Search
        Checked (:meth:`Search.checked`).
    out_root : str or Path
        Where the variants' run folders go.
    journal : str or Path
        The Optuna journal file (created, or resumed when it holds this search).
    label : str
        The study's name (its file's stem).
    workers, scheduler
        Where the variants run (:class:`~masonry.studies.sweep.Runner`).
    progress : callable, optional
        ``progress(done, total, failed)`` after each trial.

    Returns
    -------
    list of dict
        :func:`trial_rows`.
    """
    from optuna.trial import TrialState

    from masonry.studies.sweep import Runner, check_scheduler_address

    if scheduler is not None:
        check_scheduler_address(scheduler)
    options = search.study.options()
    # the workers first: a scheduler that does not answer is refused before the journal
    with Runner(out_root, options, workers, scheduler) as runner, alone(journal):
        study = open_study(search, journal, label)
        done = evaluated(study)
        failed = sum(t.state == TrialState.FAIL for t in done)
        while len(done) < min(search.trials, search.size() or search.trials):
            size = min(search.batch - len(done) % search.batch, search.trials - len(done))
            study.sampler = _sampler(search, len(done) // search.batch)
            asked = _ask_new(study, search, size)
            if not asked:
                log.warning("stopped after %d trials: the sampler proposed only variants "
                            "already tried, %d times in a row", len(done), REPEATS)
                break
            variants = [{**search.study.base, **search.inputs_of(trial)} for trial in asked]
            for j, row in runner.map(variants):
                failed += _tell(study, search, asked[j], row) == TrialState.FAIL
                done = evaluated(study)
                if progress is not None:
                    progress(len(done), search.trials, failed)
    return trial_rows(search, study)


def _key(search: Search, trial) -> str:
    return json.dumps(search.inputs_of(trial), sort_keys=True)


def _ask_new(study, search: Search, size: int) -> list:
    """Ask up to ``size`` trials of variants not tried yet. A proposal of a variant
    already tried is told that variant's values at once (failed when it failed or is
    still running) and does not count; after :data:`REPEATS` of them in a row, fewer
    trials (or none) are returned."""
    from optuna.trial import TrialState

    tried = {_key(search, t): t for t in evaluated(study)}
    asked, repeats = [], 0
    while len(asked) < size and repeats < REPEATS:
        trial = study.ask(search.distributions())
        key = _key(search, trial)
        if key not in tried:
            asked.append(trial)
            tried[key], repeats = trial, 0
            continue
        repeats += 1
        earlier = tried[key]
        trial.set_user_attr("repeat_of", earlier.number)
        if getattr(earlier, "state", None) == TrialState.COMPLETE:
            for column, violation in search.study.violations(
                    earlier.user_attrs["row"]).items():
                trial.set_constraint(column, 1.0 if violation is None else violation)
            study.tell(trial, earlier.values)
        else:
            study.tell(trial, state=TrialState.FAIL)
    return asked


def _tell(study, search: Search, trial, row: dict):
    """Record a variant's row on its trial and finish it: complete with the objective
    columns' values (and constraint values), failed when the variant failed or an
    objective column is empty. Returns the trial's state."""
    from optuna.trial import TrialState

    from masonry.studies.sweep import measure, result_columns

    keep = {k: row.get(k) for k in result_columns(search.study) if k != "variant"}
    trial.set_user_attr("row", keep)
    for column, violation in search.study.violations(row).items():
        trial.set_constraint(column, 1.0 if violation is None else violation)
    values = [measure(row, column) for column, _ in search.objectives]
    if None in values:
        study.tell(trial, state=TrialState.FAIL)
        return TrialState.FAIL
    study.tell(trial, values)
    return TrialState.COMPLETE


def trial_rows(search: Search, study) -> list:
    """The trials table: one row per trial that ran a variant, in the order asked.

    Returns
    -------
    list of dict
        ``trial`` (0, 1, ...), the searched inputs, the variant's result columns
        (:func:`~masonry.studies.sweep.result_columns`), ``constraints_met`` (True
        without constraints) and ``best``: the first trial of the best value among those
        that meet the constraints (one objective) or of each point of the Pareto front
        (several).
    """
    rows = []
    for i, trial in enumerate(evaluated(study)):
        row = trial.user_attrs["row"]
        rows.append({"trial": i, **search.inputs_of(trial),
                     **row, "constraints_met": search.study.meets(row), "best": False})
    for i in best_trials(search, rows):
        rows[i]["best"] = True
    return rows


def _values(search: Search, row: dict):
    """A row's objective values, each turned so that larger is better; None when the
    variant failed, an objective is empty or a constraint is not met."""
    from masonry.studies.sweep import measure

    values = [measure(row, column) for column, _ in search.objectives]
    if not row["constraints_met"] or None in values:
        return None
    return np.array([v if d == "maximize" else -v
                     for v, (_, d) in zip(values, search.objectives)])


def best_trials(search: Search, rows) -> list:
    """Indices of :func:`trial_rows`' best rows (see there); empty when no trial gave a
    value that meets the constraints."""
    scored = [(i, v) for i, v in ((i, _values(search, r)) for i, r in enumerate(rows))
              if v is not None]
    if not scored:
        return []
    best, seen = [], []
    for i, v in scored:
        dominated = any(np.all(w >= v) and np.any(w > v) for _, w in scored)
        if not dominated and not any(np.array_equal(v, w) for w in seen):
            best.append(i)
            seen.append(v)
    return best


def best_folders(rows, out_root) -> list:
    """The run folders of the best trials (:func:`best_trials`)."""
    return [str(Path(out_root) / r["structure_id"]) for r in rows if r["best"]]


def draw_best(search: Search, rows, out_root) -> list:
    """Run every best trial's variant again with plots (and the printable body the
    study asks for): its run folder grows by them, its results are reused.

    Returns
    -------
    list of dict
        :func:`~masonry.studies.sweep.run_variant`'s rows.
    """
    from masonry.studies.sweep import run_variant

    options = search.study.options()
    options["outputs"] = {**options["outputs"], "plots": True}
    out = []
    for row in (r for r in rows if r["best"]):
        inputs = {**search.study.base, **{k: row[k] for k in search.inputs}}
        out.append(run_variant(inputs, out_root, **options))
    return out


def trial_columns(search: Search) -> list:
    """The columns of ``trials.csv``: ``trial``, the searched inputs, the result columns,
    ``constraints_met`` and ``best``."""
    from masonry.studies.sweep import result_columns

    results = [c for c in result_columns(search.study) if c not in ("variant",
                                                                     "constraints_met")]
    return ["trial", *search.inputs, *results, "constraints_met", "best"]


def publish_trials(search: Search, rows, out_root, name: str, journal, label="",
                   study_file=None) -> dict:
    """The optimisation's folder ``out_root/name``: ``trials.csv``, ``convergence.png``
    and ``run.json`` (the search, the trials' counts, the best trials with their inputs,
    values and run folders, the journal's path, the study's file if given:
    :func:`~masonry.runfolder.check_study_folder`), published by the run-folder
    protocol and always written again (it sums up every trial of the journal).

    Returns
    -------
    dict
        The record (``run.json``) and the folder's ``path``.
    """
    import optuna

    from masonry.pipeline import versions
    from masonry.plots.convergence import convergence_png
    from masonry.runfolder import Publication
    from masonry.studies.sweep import measure, summary_csv

    counts = {s: sum(r["status"] == s for r in rows) for s in ("computed", "reused",
                                                               "failed")}
    best = [{"trial": r["trial"], "inputs": {k: r[k] for k in search.inputs},
             "values": {c: r[c] for c, _ in search.objectives},
             "run_folder": str(Path(out_root) / r["structure_id"])}
            for r in rows if r["best"]]
    identity = {"optimisation": search.identity()}
    record = {**identity, "complete": True, "outputs": {"plots": True},
              "trials": {"asked": search.trials, "finished": len(rows), **counts,
                         "constraints_met": sum(bool(r["constraints_met"]) for r in rows)},
              "best": best, "journal": str(journal),
              "versions": {**versions(), "optuna": optuna.__version__}}
    if study_file is not None:
        record["study_file"] = source_file(study_file)

    def write(folder):
        folder.write("trials.csv", summary_csv(search.study, rows, trial_columns(search)))
        folder.write("convergence.png", convergence_png(rows, search.objectives, measure,
                                                        label))
        folder.write_json("run.json", record)

    job = Publication(out_root, name, identity, record["outputs"], force=True)
    return {**record, "path": str(job.publish(write).target)}
