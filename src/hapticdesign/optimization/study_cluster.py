"""A study's generations evaluated on a Dask cluster (``optimize --scheduler``).

Each generation's designs are cut into contiguous chunks, a few per worker, and sent with the study
itself (its text and its device file's text, so a worker needs no file of the caller's machine); each
worker binds the study once (:func:`~hapticdesign.optimization.study_evaluation.bind_study`, kept per
study fingerprint) and answers its chunks. The answers are gathered in the designs' order, so a run on a
cluster gives the same numbers as a run in one process.
"""

from __future__ import annotations

import math

from hapticdesign.optimization.study_evaluation import BoundStudy, bind_study
from hapticdesign.optimization.study_file import Study
from hapticdesign.optimization.study_run import Answer, Evaluator

CHUNKS_PER_WORKER = 4

_BOUND: dict[str, BoundStudy] = {}


def evaluate_chunk(study: Study, chunk: list[dict[str, float]]) -> list[Answer]:
    """Answers for ``chunk`` on a worker (the study bound once per worker process)."""
    bound = _BOUND.get(study.fingerprint)
    if bound is None:
        bound = _BOUND[study.fingerprint] = bind_study(study)
    return bound.evaluate(chunk)


def cluster_evaluator(client, study: Study) -> Evaluator:
    """An evaluator that answers each batch on the workers of the Dask ``client``."""

    def evaluate(batch: list[dict[str, float]]) -> list[Answer]:
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        size = max(1, math.ceil(len(batch) / (CHUNKS_PER_WORKER * workers)))
        chunks = [batch[k:k + size] for k in range(0, len(batch), size)]
        futures = client.map(evaluate_chunk, [study] * len(chunks), chunks, pure=False)
        return [answer for answers in client.gather(futures) for answer in answers]

    return evaluate
