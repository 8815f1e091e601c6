"""Parameter studies: many ordinary runs, serially or on a Dask cluster.

A study is a base of fixed inputs, a grid whose Cartesian product gives the variants, and
optionally random samples of some inputs. Every variant is an ordinary run of
:func:`masonry.pipeline.run` with its own run folder and ``run.json``, so a study is
resumable for free: a variant whose folder already holds a complete run of the same input
is reused, not recomputed, and variants that differ only in ``mu`` or the friction mode
share the cached geometry. A variant that fails is recorded with its error; the others go
on. The distributed engine is Dask (an optional extra); without it the study runs
serially.
"""

import csv
import dataclasses
import io
import itertools
import json
import logging
import math
import signal
import time
import traceback
import warnings
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from masonry.export._text import format_floats
from masonry.export.columns import COLUMNS, RUN_COLUMNS, column_names, summary_row
from masonry.export.csv import HEADERS, header
from masonry.errors import ParameterError
from masonry.mortars import LAYING_INPUTS, split_laying
from masonry.outputs import Outputs
from masonry.params import Params, geometry_key, names, validate
from masonry.pipeline import run, versions
from masonry.stages.records import (STAGE_SUMMARY_COLUMNS, STANDS_THROUGHOUT,
                                           stage_summary)
from masonry.stages.run import run_stages, stage_params
from masonry.runfolder import Publication, source_file
from masonry.forking import use_one_blas_thread
from masonry.optional import optional_import, raise_interrupt
from masonry.studies.workers import WORKER_LOG_LEVEL, quiet_shutdown

log = logging.getLogger(__name__)

SUMMARY_COLUMNS = column_names(RUN_COLUMNS)
"""Result columns of the summary (:data:`masonry.export.columns.RUN_COLUMNS`: their
sources in ``run.json``, types, units and meanings); the swept inputs come first. A study
of stages adds :data:`~masonry.stages.records.STAGE_SUMMARY_COLUMNS`."""

def measure(row: dict, column: str):
    """A result column of a variant's row as a number, for an optimisation: a boolean as
    0 or 1; a column of :data:`STANDS_THROUGHOUT` as infinity when every stage stands;
    None when the variant failed or the column is empty."""
    if row.get("status") == "failed":
        return None
    value = row.get(column)
    if value is not None:
        return float(value)
    stands = row.get("stages") is not None and row.get("stages_standing") == row["stages"]
    return math.inf if column in STANDS_THROUGHOUT and stands else None


def result_columns(study) -> list:
    """The summary's result columns for ``study`` (record keys): its columns after the
    swept inputs (:attr:`Study.columns`)."""
    return study.columns[len(study.swept):]


def measure_columns(study) -> list:
    """The result columns an optimisation may maximise, minimise or bound, as
    ``summary.csv`` names them (:func:`~masonry.export.csv.header`): every result column
    but the labels (the variant, its status and error, names) and ``constraints_met``."""
    labels = {"variant", "constraints_met",
              *(name for name, c in COLUMNS.items() if c.kind == "str")}
    return header([c for c in result_columns(study) if c not in labels])


def column_key(name: str) -> str:
    """The record key of a ``summary.csv`` column (``moi_N`` -> ``moi``)."""
    return {column: key for key, column in HEADERS.items()}.get(name, name)


STUDY_OUTPUTS = {"plots": False, "printable": False}
"""What every variant of a study writes unless the study's ``[outputs]`` says otherwise:
no figures (and so no ``dome.html``) and no printable body, the files a study of many
variants does not read."""

SAMPLE_DIGITS = 3
"""A float drawn from a ``[sample]`` range (a sweep's draw, an optimisation's trial) lies
on a grid of ``10^(floor(log10(high - low)) - SAMPLE_DIGITS)``: three digits finer than
the range's width (``[0.4, 1.0]``: steps of 0.0001), so run folders and tables name it
as a person would write it (``_mu0.7342``, not ``_mu0.7341906253``)."""


def sample_step(low: float, high: float) -> float:
    """The grid step of a float range (:data:`SAMPLE_DIGITS`); 0 for an empty range."""
    width = float(high) - float(low)
    return 10.0 ** (math.floor(math.log10(width)) - SAMPLE_DIGITS) if width > 0 else 0.0


def on_grid(value: float, low: float, high: float) -> float:
    """``value`` at the nearest point of its range's grid within ``[low, high]``, to 12
    significant digits (the sum's rounding dropped)."""
    step = sample_step(low, high)
    if step == 0:
        return float(low)
    count = math.floor((float(high) - float(low)) / step + 1e-9)
    k = min(max(round((value - low) / step), 0), count)
    return float(f"{low + k * step:.12g}")

@dataclass(frozen=True)
class Study:
    """A parameter study over a run's inputs (:func:`masonry.params.names`).

    Parameters
    ----------
    base : dict
        Fixed inputs (flat input names, as :meth:`masonry.params.Params.of` takes them).
    grid : dict of lists
        Inputs whose Cartesian product gives the variants.
    sample : dict of (low, high)
        Inputs drawn uniformly at random, ``count`` draws (integers where both bounds are
        integers), seeded by ``seed``; combined with every grid point.
    count, seed : int
    analyse : bool
        Whether each run solves.
    outputs : dict
        What each run writes: the outputs a study chooses for all its variants
        (:data:`~masonry.params.FILE_OUTPUTS`, as :class:`masonry.outputs.Outputs` takes
        them; :data:`STUDY_OUTPUTS` unless given: no plots, no printable body, and
        ``dome.html`` with the plots).
    stages : str or None
        Also a stage study of every variant (:func:`masonry.stages.run.run_stages`),
        laid by ``course``, ``brick`` or ``block``; its results add
        :data:`STAGE_SUMMARY_COLUMNS` to the summary. Its mortar by age
        (:data:`~masonry.mortars.LAYING_INPUTS`) is among the inputs of ``base``,
        ``grid`` and ``sample``.
    stages_course : int or None
        The course a brick plan lays brick by brick; None: every course (the whole
        construction).
    stages_order : str or None
        The laying order of a brick or block plan (its default when None).
    constraints : dict of (low, high)
        Bounds on result columns (record keys of :func:`measure_columns`) a variant must
        meet to count as a solution of an optimisation; a sweep reports them as
        ``constraints_met``.
    """

    base: dict
    grid: dict
    sample: dict = dataclasses.field(default_factory=dict)
    count: int = 0
    seed: int = 0
    analyse: bool = True
    outputs: dict = dataclasses.field(default_factory=lambda: dict(STUDY_OUTPUTS))
    stages: str | None = None
    stages_course: int | None = None
    stages_order: str | None = None
    constraints: dict = dataclasses.field(default_factory=dict)

    @property
    def swept(self) -> list:
        """Names of the inputs that vary, grid first."""
        return list(self.grid) + [k for k in self.sample if k not in self.grid]

    @property
    def columns(self) -> list:
        """The summary's columns: the swept inputs, :data:`SUMMARY_COLUMNS`,
        :data:`STAGE_SUMMARY_COLUMNS` for a study of stages, and ``constraints_met`` for
        a study with constraints (:meth:`meets`)."""
        return self.swept + list(SUMMARY_COLUMNS) + list(
            STAGE_SUMMARY_COLUMNS if self.stages else ()) + (
            ["constraints_met"] if self.constraints else [])

    def options(self) -> dict:
        """:func:`run_variant`'s keyword arguments: what each variant does and writes."""
        stages = None if self.stages is None else {
            "by": self.stages, "course": self.stages_course, "order": self.stages_order}
        return dict(analyse=self.analyse, outputs=self.outputs, stages=stages)

    @staticmethod
    def outputs_default() -> dict:
        """:data:`STUDY_OUTPUTS`, what a study writes unless its ``[outputs]`` says."""
        return dict(STUDY_OUTPUTS)

    def variants(self) -> list:
        """One dict of inputs per variant (base, then grid point, then sample).

        Returns
        -------
        list of dict
            The inputs of every variant: the grid's Cartesian product, each point
            combined with every one of the ``count`` seeded draws.

        Raises
        ------
        ParameterError
            For names that are no run's inputs, a grid entry that is not a
            non-empty list, or samples with ``count < 1``.
        """
        fields = {"scene", "fast", *names(), *(LAYING_INPUTS if self.stages else ())}
        unknown = (set(self.base) | set(self.grid) | set(self.sample)) - fields
        if unknown:
            raise ParameterError("study", sorted(unknown), "inputs named as run options")
        for name, values in self.grid.items():
            if not isinstance(values, list) or not values:
                raise ParameterError(f"grid.{name}", values, "a non-empty list")
        points = [dict(zip(self.grid, combo))
                  for combo in itertools.product(*self.grid.values())] or [{}]
        draws = [{}]
        if self.sample:
            if self.count < 1:
                raise ParameterError("sample.count", self.count, "an integer >= 1")
            rng = np.random.default_rng(self.seed)
            draws = []
            for _ in range(self.count):
                draw = {}
                for name, bounds in self.sample.items():
                    low, high = bounds
                    if isinstance(low, int) and isinstance(high, int):
                        draw[name] = int(rng.integers(low, high + 1))
                    else:
                        draw[name] = on_grid(rng.uniform(low, high), low, high)
                draws.append(draw)
        return [{**self.base, **point, **draw} for point in points for draw in draws]

    def violations(self, row: dict) -> dict:
        """How far a variant's result ``row`` lies outside each of :attr:`constraints`:
        column -> 0 when met, the distance to the nearer bound when not (in the column's
        unit), None when the column has no value (:func:`measure`: the variant failed or
        has no such value)."""
        out = {}
        for column, (low, high) in self.constraints.items():
            value = measure(row, column)
            out[column] = None if value is None else max(low - value, value - high, 0.0)
        return out

    def meets(self, row: dict) -> bool:
        """Whether a variant's result ``row`` meets every constraint (an empty column
        does not)."""
        return all(v == 0.0 for v in self.violations(row).values())


def run_variant(inputs: dict, out_root, analyse=True, outputs=None, stages=None) -> dict:
    """Run one variant (and its stage study); never raises: a failure becomes a row with
    its error.

    Parameters
    ----------
    inputs : dict
        The variant's inputs (flat names), and with ``stages`` its stage study's mortar
        by age (:func:`~masonry.mortars.split_laying`).
    out_root : str or Path
        The study's output root; the variant's run folder is named by its structure id.
    analyse : bool
        Whether the run solves (:func:`masonry.pipeline.run`).
    outputs : dict, optional
        What the run writes (:class:`masonry.outputs.Outputs`' inputs by name; None:
        :data:`STUDY_OUTPUTS`).
    stages : dict or None
        ``by``, ``course`` and ``order`` of a stage study of the variant
        (:func:`masonry.stages.run.run_stages`, in its own run folder; a section
        laid cyclic unless the inputs give a boundary, as ``masonry stages`` does).

    Returns
    -------
    dict
        ``status`` (``'computed'``, ``'reused'`` or ``'failed'``), ``error`` (str, empty
        unless failed), ``time_s`` (wall clock, s) and, for a run that did not fail, the
        result columns of :data:`SUMMARY_COLUMNS` (``moi`` and ``weight_N`` in N,
        ``objective`` in N^2, ``moi_factor`` and ``residual_eq`` dimensionless) and with
        ``stages`` those of :data:`STAGE_SUMMARY_COLUMNS` (``computed`` when the run or
        the stage study was).
    """
    use_one_blas_thread()  # in a Dask worker process too
    start = time.perf_counter()
    row = {"status": "failed", "error": ""}
    inputs, laying = split_laying(inputs)
    try:
        params = validate(Params.of(**{**STUDY_OUTPUTS, **(outputs or {}), **inputs}))
        record = run(params, out_root, analyse=analyse)
        staged = None if stages is None else run_stages(
            stage_params(params, "boundary" in inputs), out_root, **stages, **laying)
    except Exception as error:  # a variant's failure is data, not the study's end
        raise_interrupt(error)  # an interrupt an extension's loader made an ImportError
        row["error"] = f"{type(error).__name__}: {error}"
        log.debug("variant failed: %s", traceback.format_exc())
    else:
        reused = record.get("reused") and (staged is None or staged.get("reused"))
        row.update(status="reused" if reused else "computed", **run_summary(record))
        if staged is not None:
            row.update(stage_summary(staged))
    row["time_s"] = round(time.perf_counter() - start, 3)
    return row


def run_summary(record) -> dict:
    """The result columns of :data:`SUMMARY_COLUMNS` from a run's ``run.json`` record
    (see :func:`run_variant`), each where its row of
    :data:`masonry.export.columns.RUN_COLUMNS` says."""
    return summary_row(RUN_COLUMNS, record)


def run_after(previous, inputs: dict, out_root, **options) -> dict:
    """:func:`run_variant` once ``previous`` (the row of the variant that built the shared
    geometry) is done: Dask passes the finished result in, which orders the two.

    ``previous`` is not used otherwise; ``inputs``, ``out_root`` and ``options`` are
    :func:`run_variant`'s, and so is the returned row.
    """
    return run_variant(inputs, out_root, **options)


def geometry_group(inputs: dict) -> str:
    """Variants with the same group share their geometry and interfaces (the cache key).

    Parameters
    ----------
    inputs : dict
        A variant's inputs (flat names).

    Returns
    -------
    str
        JSON of the variant's geometric inputs; of all its inputs when they are not valid
        (such a variant is a group of its own and fails on its own).
    """
    try:
        return geometry_key(Params.of(**split_laying(inputs)[0]))
    except (TypeError, ValueError):  # an invalid variant: alone, to fail on its own
        return json.dumps(inputs, sort_keys=True, default=str)


def check_scheduler_address(address: str) -> None:
    """Refuse a Dask scheduler address that names no scheme Dask speaks or, for TCP and
    TLS, no host and port (:class:`~masonry.errors.ParameterError` named ``scheduler``),
    before any client starts."""
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import backends

    expected = "the address of a running Dask scheduler, e.g. tcp://127.0.0.1:8786"
    try:
        scheme, location = parse_address(str(address))
        if scheme in ("tcp", "tls"):
            parse_host_port(location)
    except (ValueError, TypeError) as error:
        raise ParameterError("scheduler", address, f"{expected} ({error})") from None
    if scheme not in backends:
        raise ParameterError("scheduler", address, f"{expected} (no protocol {scheme!r}: "
                             f"one of {', '.join(backends)})")


class Runner:
    """Where variants run: in this process, on a local Dask cluster or on a running Dask
    scheduler. A context manager: the cluster or client lives until the block ends.

    Parameters
    ----------
    out_root : str or Path
        Where every variant's run folder goes (a folder every worker reaches).
    options : dict
        :func:`run_variant`'s keyword arguments (:meth:`Study.options`).
    workers : int
        1 and no ``scheduler``: serially, in this process. More: on a Dask
        ``LocalCluster`` of ``workers`` single-threaded processes (which ignore Ctrl-C:
        this process stops them); :func:`masonry.studies.workers.local_workers` says
        how many.
    scheduler : str, optional
        The address of a running Dask scheduler (``tcp://host:port``), used instead of a
        local cluster. A worker lost while it runs a variant (killed, its machine gone) is
        no failure: the scheduler runs the variant again on another worker.

    Raises
    ------
    ParameterError
        Named ``scheduler`` (on entry) when no Dask scheduler answers at that address.
    """

    def __init__(self, out_root, options: dict, workers=1, scheduler=None):
        self.out_root, self.options = str(out_root), dict(options)
        self.workers, self.scheduler = workers, scheduler
        self.client = self.cluster = None

    def __enter__(self):
        if self.workers == 1 and self.scheduler is None:
            return self
        from dask.distributed import Client, LocalCluster

        if self.scheduler is None:
            # the scheduler's HTTP routes move to another port when 8787 is taken
            with _children_ignore_ctrl_c(), warnings.catch_warnings():
                warnings.filterwarnings("ignore", message="Port .* is already in use")
                self.cluster = LocalCluster(
                    n_workers=self.workers, threads_per_worker=1, processes=True,
                    host="127.0.0.1", dashboard_address=None,
                    silence_logs=WORKER_LOG_LEVEL)
        try:
            self.client = Client(self.cluster if self.cluster is not None
                                 else self.scheduler)
        except (OSError, ValueError, TypeError) as error:  # no scheduler there
            if self.cluster is not None:
                self.cluster.close()
                raise
            raise ParameterError("scheduler", self.scheduler, f"the address of a running "
                                 f"Dask scheduler ({error})") from None
        return self

    def __exit__(self, *exc):
        with quiet_shutdown():  # the client first: the cluster's end is then no surprise
            if self.client is not None:
                self.client.close()
            if self.cluster is not None:
                self.cluster.close()
        return False

    def map(self, variants: list):
        """Run ``variants`` (dicts of inputs); yield ``(index, row)`` as each finishes,
        ``row`` as :func:`run_variant` returns it (a variant whose workers all died is a
        failed row)."""
        if self.client is None:
            for i, inputs in enumerate(variants):
                yield i, run_variant(inputs, self.out_root, **self.options)
            return
        from dask.distributed import as_completed

        # the first variant of each geometry builds it; the others of its group wait for
        # it and reuse the cached geometry instead of building it again in parallel
        first, futures = {}, {}
        for i, inputs in enumerate(variants):
            key, group = f"variant-{i}-{time.time_ns()}", geometry_group(inputs)
            if group in first:
                future = self.client.submit(run_after, first[group], inputs, self.out_root,
                                            **self.options, key=key, pure=False)
            else:
                future = first[group] = self.client.submit(
                    run_variant, inputs, self.out_root, **self.options, key=key, pure=False)
            futures[future] = i
        for future in as_completed(futures):
            try:
                row = future.result()
            except Exception as error:  # the workers died (KilledWorker) or were lost
                row = {"status": "failed", "error": f"{type(error).__name__}: {error}",
                       "time_s": None}
            yield futures[future], row


def execute(study: Study, out_root, workers=1, scheduler=None):
    """Run every variant; yield ``(index, inputs, row)`` as each finishes.

    Parameters
    ----------
    study : Study
    out_root : str or Path
        Where every variant's run folder goes.
    workers, scheduler
        Where the variants run (:class:`Runner`).

    Yields
    ------
    index : int
        The variant's position in ``study.variants()``.
    inputs : dict
        Its inputs.
    row : dict
        :func:`run_variant`'s row; a variant whose worker dies is recorded as failed.

    Raises
    ------
    ParameterError
        When the study's inputs are not ``Params`` fields or its grid or sample is
        malformed (before any variant runs); named ``scheduler`` when no Dask scheduler
        answers at that address.
    """
    variants = study.variants()
    if scheduler is not None:
        check_scheduler_address(scheduler)
    with Runner(out_root, study.options(), workers, scheduler) as runner:
        for i, row in runner.map(variants):
            yield i, variants[i], row


@contextmanager
def _children_ignore_ctrl_c():
    """Processes started inside the block ignore SIGINT (an ignored signal stays ignored
    in a child): Ctrl-C in a terminal reaches every process of its group, and the worker
    processes would each print a traceback. This process alone gets it, and stops them
    as it unwinds."""
    try:
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the main thread: nothing to change
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def summary_rows(study: Study, results) -> list:
    """Rows of the summary table in variant order: swept inputs, then results.

    Parameters
    ----------
    study : Study
    results : iterable of (int, dict, dict)
        ``(index, inputs, row)`` as :func:`execute` yields them, in any order.

    Returns
    -------
    list of dict
        One dict per variant, keys ``study.columns``.
    """
    rows = []
    for i, inputs, row in sorted(results, key=lambda r: r[0]):
        if study.constraints:
            row = {**row, "constraints_met": study.meets(row)}
        rows.append({**{k: inputs.get(k) for k in study.swept}, "variant": i,
                     **{k: row.get(k) for k in result_columns(study) if k != "variant"}})
    return rows


def summary_csv(study: Study, rows, columns=None) -> bytes:
    """CSV (UTF-8 bytes) of :func:`summary_rows`: its columns (``study.columns``, or
    ``columns``), named with their units (:func:`~masonry.export.csv.header`); floats as
    every CSV of the project prints them (:func:`~masonry.export._text.format_floats`:
    12 digits, every digit of a sampled input and of its run folder's name), None as an
    empty cell."""
    columns = columns or study.columns
    texts = []
    for c in columns:
        values = [row.get(c) for row in rows]
        text = ["" if v is None else str(v) for v in values]
        floats = [i for i, v in enumerate(values) if isinstance(v, float)]
        if floats:
            for i, printed in zip(floats, format_floats([values[i] for i in floats])):
                text[i] = printed
        texts.append(text)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header(columns))
    writer.writerows(zip(*texts))
    return buf.getvalue().encode()


def summary_parquet(study: Study, rows):
    """Parquet bytes of :func:`summary_rows` (same columns as :func:`summary_csv`), or
    None when pyarrow is not installed."""
    pa, pq = optional_import("pyarrow"), optional_import("pyarrow.parquet")
    if pa is None or pq is None:
        return None
    columns = study.columns
    text_columns = [c.name for c in RUN_COLUMNS if c.kind == "str"]
    table = pa.table({HEADERS.get(c, c): [None if r.get(c) is None else str(r.get(c))
                          if c in text_columns
                          else r.get(c) for r in rows] for c in columns})
    buf = io.BytesIO()
    pq.write_table(table, buf)
    return buf.getvalue()


def summary_figures(study: Study, rows, label="") -> dict:
    """The study's summary plots (:func:`masonry.plots.sweep.summary_figures`, in the
    study's figure formats and resolution), titled with ``label`` (the study's name),
    its variants and its fixed inputs: ``{file name: bytes}``."""
    # matplotlib, imported only by the runs that draw
    from masonry.plots.common import Render
    from masonry.plots.sweep import summary_figures as figures

    failed = sum(r["status"] == "failed" for r in rows)
    fixed = _fixed_inputs(study)
    title = (f"{label + ': ' if label else ''}{len(rows) - failed} variants ({failed} "
             f"failed)" + (f"\nfixed: {fixed}" if fixed else ""))
    return figures(study.swept, rows, title, Render.of(Outputs(**study.outputs)))


def _fixed_inputs(study: Study) -> str:
    """The study's fixed inputs away from their defaults, for figure titles."""
    default = Params.of().inputs()
    text = ", ".join(f"{key} {value}" for key, value in study.base.items()
                     if key not in study.swept and default.get(key) != value)
    return text if len(text) <= 80 else text[:77] + "..."


def publish_summary(study: Study, rows, out_root, name: str, label="",
                    study_file=None) -> dict:
    """The study's folder ``out_root/name``: ``summary.csv``, ``summary.parquet`` (with
    pyarrow), the summary plots and ``run.json`` (with ``study_file``, the study's file
    if given: :func:`~masonry.runfolder.check_study_folder`), published by the run-folder protocol
    (:class:`masonry.runfolder.Publication`). It is always written again: it sums up this
    run's variants, and a variant that ran before is reused, so nothing it held is lost.

    Returns
    -------
    dict
        The study's record (``run.json``) and the folder's ``path``.
    """
    counts = {s: sum(r["status"] == s for r in rows) for s in ("computed", "reused", "failed")}
    identity = {"study": dataclasses.asdict(study)}
    record = {**identity, "complete": True, "outputs": {"plots": True}, "variants": counts,
              "versions": versions()}
    if study_file is not None:
        record["study_file"] = source_file(study_file)

    def write(folder):
        folder.write("summary.csv", summary_csv(study, rows))
        parquet = summary_parquet(study, rows)
        if parquet is not None:
            folder.write("summary.parquet", parquet)
        for figure_name, data in summary_figures(study, rows, label).items():
            folder.write(figure_name, data)
        folder.write_json("run.json", record)

    job = Publication(out_root, name, identity, record["outputs"], force=True)
    return {**record, "path": str(job.publish(write).target)}
