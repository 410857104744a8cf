"""polydg.batch: a pipeline over many inputs, on threads or on a Dask cluster.

Each input is one task that runs the library's runPipelineInput() (the same code as
``polydg run``): it writes DIR/<stem>/ through a staging folder renamed at the end, and its
report.json; a failing input is reported and never stops or spoils the others.
"""

import concurrent.futures
import json
import os

from . import _polydg


def _pipeline_text(pipeline):
    """(JSON text, name for messages, folder relative inputs are resolved against)."""
    if isinstance(pipeline, (str, os.PathLike)):
        path = os.path.abspath(os.fspath(pipeline))
        try:
            with open(path, encoding="utf-8") as f:
                return f.read(), os.fspath(pipeline), os.path.dirname(path)
        except OSError as e:
            raise _polydg.Error(f"{os.fspath(pipeline)}: cannot open the pipeline file ({e.strerror})") from None
    if isinstance(pipeline, list):
        pipeline = {"steps": pipeline}
    if not isinstance(pipeline, dict):
        raise _polydg.Error("batch(): the pipeline must be a file name, a dict or a list of steps")
    try:
        return json.dumps(pipeline), "pipeline", os.getcwd()
    except (TypeError, ValueError) as e:
        raise _polydg.Error(f"pipeline: not representable as JSON ({e})") from None


def _worker_threads():
    """The threads of the Dask worker running this task (0 outside a worker: no limit)."""
    try:
        from distributed import get_worker

        return int(get_worker().nthreads)
    except (ImportError, ValueError, AttributeError):
        return 0


def _run_one(text, name, base, path, stem, out):
    """One input, as a task: never raises (a failure is the input's report)."""
    try:
        from polydg import _polydg as core  # on a Dask worker: its own import

        return core.run_input(text, name, base, path, stem, out, threads=_worker_threads())
    except Exception as e:  # the folder could not be written, or the module is missing
        return {"input": path, "status": "failed", "error": str(e), "steps": []}


def batch(pipeline, inputs=None, out=None, client=None, jobs=None):
    """Runs a pipeline over many inputs (``polydg run``), locally or on a Dask cluster.

    pipeline: a pipeline file (the JSON of ``polydg run``), the same document as a dict, or a
    list of steps.
    inputs: surface files or .vtu meshes (default: the pipeline's "inputs").
    out: the output folder; each input gets out/<stem>/ with its outputs and report.json
    (default for a pipeline file: PIPELINE-out beside it).
    client: a dask.distributed.Client: each input is a task on its workers, which must import
    polydg and see the inputs and `out` at the same paths (a shared file system). None runs
    the inputs on `jobs` threads here (default: the number of CPUs).

    Returns one dict per input, in input order: the input's report.json (input, status "ok" or
    "failed", error, elements, volume, time_s, steps). Raises ``Error`` before running anything
    for an invalid pipeline, no inputs, or an input inside a folder the run would replace.
    """
    text, name, base = _pipeline_text(pipeline)
    pipeline_inputs = _polydg.check_pipeline(text, name, base)
    if inputs is None:
        inputs = pipeline_inputs
    inputs = [os.path.abspath(os.fspath(i)) for i in inputs]
    if not inputs:
        raise _polydg.Error(f"{name}: no inputs; give them in the pipeline or as `inputs`")
    if out is None:
        if not isinstance(pipeline, (str, os.PathLike)):
            raise _polydg.Error("batch(): give `out`, the output folder")
        out = os.path.splitext(os.fspath(pipeline))[0] + "-out"
    out = os.path.abspath(os.fspath(out))
    stems = _polydg.unique_stems(inputs)
    _polydg.refuse_inputs_in_outputs(inputs, stems, out)
    os.makedirs(out, exist_ok=True)

    tasks = list(zip(inputs, stems))
    if client is None:
        workers = jobs or os.cpu_count() or 1
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(_run_one, text, name, base, i, s, out) for i, s in tasks]
            return [f.result() for f in futures]

    futures = [client.submit(_run_one, text, name, base, i, s, out, pure=False)
               for i, s in tasks]
    results = []
    for (path, _), future in zip(tasks, futures):
        try:
            results.append(future.result())
        except Exception as e:  # the task was lost (its worker died) or could not be sent
            results.append({"input": path, "status": "failed",
                            "error": f"dask: {type(e).__name__}: {e}", "steps": []})
    return results
