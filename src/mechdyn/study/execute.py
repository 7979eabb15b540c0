"""Running a study: batches of variants in this process, in local worker processes
(the default) or on a Dask distributed cluster, results written as they come."""

from __future__ import annotations

import contextlib
import functools
import math
import os
import signal
import sys
import uuid
from pathlib import Path

import numpy as np

from .. import progress as _progress
from ..errors import ModelError
from .batch import batch_reason, batched
from .evaluate import Task, evaluate_batch, order_variants
from .output import StudyOutput, order_columns
from .parameters import BaseModel, Parameter, to_shown

__all__ = ["run_study", "variant_table", "batches_of", "MAX_BATCH", "MAX_BATCHED"]

#: default largest batch (task) of variants analysed one by one
MAX_BATCH = 50
#: default largest batch of variants analysed as one (:mod:`.batch`): its probes and
#: compiled kernels are shared by more variants
MAX_BATCHED = 2000
#: longest wait (s) for a batch before the study's process looks at its signals again
_WAIT = 0.25


def variant_table(base: BaseModel, variants):
    """(parameters, values (n, d) SI, ids (n,)) of a design table (:func:`~.designs.design`)
    or a mapping of model-file path to SI values."""
    import pandas as pd

    if not isinstance(variants, pd.DataFrame):
        variants = pd.DataFrame({k: np.atleast_1d(np.asarray(v, float))
                                 for k, v in dict(variants).items()})
    params = variants.attrs.get("parameters")
    if not params or [p.path for p in params] != list(variants.columns):
        params = [base.parameter(c) for c in variants.columns]
    return tuple(params), variants.to_numpy(dtype=float), np.arange(len(variants))


def batches_of(ids: np.ndarray, values: np.ndarray, size: int) -> list[list]:
    """The variants in batches of ``size``: lists of (id, values tuple)."""
    items = [(int(i), tuple(float(x) for x in v)) for i, v in zip(ids, values, strict=True)]
    return [items[k:k + size] for k in range(0, len(items), size)]


def _check_resume(done_df, params: tuple[Parameter, ...], values, ids) -> None:
    """Refuse to resume an output written by a different design."""
    pos = {int(i): k for k, i in enumerate(ids)}
    for p, col in zip(params, values.T, strict=True):
        if p.column not in done_df:
            raise ModelError(f"--resume: the output has no column {p.column!r}: it was written "
                             f"by another study")
        for vid, got in zip(done_df["variant"], done_df[p.column], strict=True):
            k = pos.get(int(vid))
            want = to_shown(col[k], p.kind) if k is not None else np.nan
            if k is None or not math.isclose(float(got), want, rel_tol=1e-9, abs_tol=1e-12):
                raise ModelError(f"--resume: variant {int(vid)} of the output has "
                                 f"{p.column} = {got}, not {want}: the output was written by "
                                 f"another study (other ranges, samples or seed)")


def _bar(total: int, initial: int, progress):
    if progress is False:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, unit="variant", file=sys.stderr, desc="study",
                delay=0.0 if progress else _progress.PROGRESS_AFTER)


#: the signals that stop a study: Ctrl-C and SIGTERM
_STOP = (signal.SIGINT, signal.SIGTERM)


def _quiet_worker() -> None:
    """Signals of a local worker process: Ctrl-C ignored (the study's process stops them
    all), SIGTERM the system's default, which ends the worker at once wherever it is (a
    Python handler inherited from the parent, such as the command line's, would raise
    in the middle of the pool's own locking, or never run while the worker waits on a
    lock); then the signals blocked while it was started (:func:`_start_pool`) are let
    through."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOP)


def _start_pool(workers: int):
    """A pool of ``workers`` processes whose signals are :func:`_quiet_worker`'s from
    their first instruction: SIGINT and SIGTERM are blocked in this thread while the
    pool forks its workers and starts its threads (which keep them blocked, so that
    this process's handlers run in its main thread only)."""
    import multiprocessing

    if not hasattr(signal, "pthread_sigmask"):
        return multiprocessing.Pool(workers, initializer=_quiet_worker)
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP)
    try:
        return multiprocessing.Pool(workers, initializer=_quiet_worker)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextlib.contextmanager
def _signals_held():
    """SIGINT and SIGTERM held while the block runs (the pool is stopped, the table
    gathered), then the first one that came is raised again for this process's own
    handler; a no-op outside the main thread."""
    got: list[int] = []
    try:
        previous = {s: signal.signal(s, lambda signum, frame: got.append(signum))
                    for s in _STOP}
    except ValueError:  # not the main thread: signals cannot be handled here
        yield
        return
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if got:
            signal.raise_signal(got[0])


def _local(task, batches, workers: int):
    """Results of the batches as they finish, in this process (workers <= 1) or in a
    pool of worker processes: closed and joined when every batch is done, terminated
    (pending batches dropped, running ones stopped) when the study is interrupted or
    the generator closed early; joined either way."""
    if workers <= 1:
        for b in batches:
            yield evaluate_batch(task, b)
        return
    import multiprocessing

    pool = _start_pool(workers)
    done = False
    try:
        results = pool.imap_unordered(functools.partial(evaluate_batch, task), batches)
        while True:
            try:  # in short waits: a signal is acted on within _WAIT s
                rows = results.next(timeout=_WAIT)
            except multiprocessing.TimeoutError:
                continue
            except StopIteration:
                break
            yield rows
        done = True
    finally:
        if done:  # the workers leave by the pool's sentinel: no signal sent
            pool.close()
        else:
            pool.terminate()
        pool.join()


def _dask(task, batches, client, retries: int):
    """Results of the batches as they finish on a Dask cluster (each task one batch;
    a batch lost with its worker is run again, up to ``retries`` times)."""
    from distributed import as_completed

    # the task (a few kB: the model document, the parameters, the analysis) goes with
    # every batch: scattered data lost with a worker could not be recomputed
    tag = uuid.uuid4().hex[:12]
    futures = [client.submit(evaluate_batch, task, b, key=f"mechdyn-study-{tag}-{k}",
                             retries=retries, pure=False) for k, b in enumerate(batches)]
    try:
        for f in as_completed(futures):
            yield f.result()
    finally:
        client.cancel(futures)


def _one_by_one(base: BaseModel, analysis) -> str:
    """Why the study's variants are analysed one by one rather than as batches ("" when
    the base model and the analysis allow batches)."""
    if not batched(analysis):
        return batch_reason(analysis, []) or ""
    try:
        model = base.compile({})
    except Exception:  # noqa: BLE001 - the variants' rows say what is wrong
        return ""
    return batch_reason(analysis, [model]) or ""


def run_study(model, variants, analysis, *, output: str | Path | None = None,
              client=None, workers: int | None = None, batch_size: int | None = None,
              resume: bool = False, progress: bool | None = None, order: bool = True,
              retries: int = 3):
    """Analyse every variant of a design; one table row per variant.

    Parameters
    ----------
    model : str, Path or BaseModel
        The model file (or bundled example name) the variants change.
    variants : pandas.DataFrame or mapping
        The design (:func:`~mechdyn.study.designs.design`), or model-file path -> SI
        values (all of one length).
    analysis : callable
        One of :mod:`mechdyn.study.analyses` (``analysis(model, warm) -> Outcome``).
    output : str or Path, optional
        ``.parquet`` or ``.csv``: each batch is written as it finishes (parts beside the
        file), the whole table at the end, and also when the study is interrupted.
    client : distributed.Client, optional
        Run the batches on this Dask cluster instead of local processes.
    workers : int, optional
        Local worker processes (default ``os.cpu_count()``; 1: in this process); with
        ``client``, sets the batch size only (default the cluster's workers).
    batch_size : int, optional
        Variants per batch (task); default about four batches per worker, at most
        :data:`MAX_BATCH` (:data:`MAX_BATCHED` for an analysis of variants as one batch,
        :func:`~mechdyn.study.batch.batched`).
    resume : bool
        Keep what ``output`` already holds and analyse only the other variants (the
        design must be the same); otherwise an existing output is replaced.
    progress : bool, optional
        A progress bar on stderr: always, never, or (None) after 2 s.
    order : bool
        Analyse the variants in nearest-neighbour order so that each starts from the
        previous one's poses (the table is still sorted by variant); for an analysis of
        variants as one batch, sorted by their parameters, so that each batch spans a
        small box.
    retries : int
        Dask: times a batch is run again when its worker is lost.

    Returns
    -------
    pandas.DataFrame
        One row per variant, sorted by ``variant`` (the design's row index): the
        parameters (columns with units, angles in deg), the figures, ``status``,
        ``message``, ``evaluated`` (``batch``: analysed as one batch of variants,
        :mod:`~mechdyn.study.batch`; ``loop``: on its own), ``seconds``;
        ``attrs["analysed"]``: the variants analysed in this call (the others were
        resumed); ``attrs["one_by_one"]``: why the analysis or the model does not allow
        batches ("" when they do).

    Raises
    ------
    ModelError
        Unknown parameter paths, an output of another type, or resuming an output of
        another study.
    KeyboardInterrupt
        After writing what was done to ``output``.

    Examples
    --------
    >>> from mechdyn.study.analyses import KinetostaticExtremes
    >>> df = run_study("slider_crank", {"bodies.rod.mass": [1.0, 2.0]},
    ...                KinetostaticExtremes("1000 rpm", steps=24), workers=1, progress=False)
    >>> df[["variant", "bodies.rod.mass_kg", "status"]].values.tolist()
    [[0, 1.0, 'success'], [1, 2.0, 'success']]
    """
    import pandas as pd

    base = model if isinstance(model, BaseModel) else BaseModel(model)
    params, values, ids = variant_table(base, variants)
    out = None if output is None else StudyOutput(output)
    done: set[int] = set()
    if out is not None:
        if resume:
            prev = out.existing()
            if prev is not None:
                _check_resume(prev, params, values, ids)
                done = {int(v) for v in prev["variant"]}
        else:
            out.clear()
    todo = np.array([k for k, i in enumerate(ids) if int(i) not in done], int)
    if order and len(todo) > 1 and batched(analysis):  # slabs along the first parameter
        todo = todo[np.lexsort(values[todo].T[::-1])]
    elif order and len(todo) > 1:
        todo = todo[order_variants(values[todo])]
    if workers is None:
        workers = len(client.scheduler_info()["workers"]) if client is not None else \
            (os.cpu_count() or 1)
    workers = max(1, int(workers))
    if batch_size is None:  # about four batches per worker; larger ones when batched
        most = MAX_BATCHED if batched(analysis) else MAX_BATCH
        batch_size = max(1, min(most, math.ceil(len(todo) / max(1, 4 * workers))))
    batches = batches_of(ids[todo], values[todo], int(batch_size))
    base.structure_known(params)  # once, here: the answer travels with the task
    task = Task(base, params, analysis)
    rows: list[dict] = []
    bar = _bar(len(ids), len(ids) - len(todo), progress)
    results = _dask(task, batches, client, retries) if client is not None else \
        _local(task, batches, min(workers, len(batches)))
    try:
        for batch_rows in results:
            rows.extend(batch_rows)
            if out is not None:
                out.append(batch_rows)
            if bar is not None:
                bar.update(len(batch_rows))
    finally:
        with _signals_held():  # a second Ctrl-C or a SIGTERM waits for the table
            results.close()
            if bar is not None:
                bar.close()
            if out is not None:
                table = out.finish()
    if out is None:
        table = pd.DataFrame(rows)
        if len(table):
            table = order_columns(table.sort_values("variant").reset_index(drop=True))
    table.attrs["model"] = base.spec
    table.attrs["analysis"] = getattr(analysis, "name", type(analysis).__name__)
    table.attrs["analysed"] = len(rows)  # in this call (the others were resumed)
    table.attrs["one_by_one"] = _one_by_one(base, analysis)
    return table
