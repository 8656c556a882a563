"""Renders split over a Ray cluster: one image of N samples per pixel as tasks over disjoint
sample ranges of the same sequence, whose film sums add up to the one-process render.

    import envgi.distributed as ed
    img = ed.render("scenes/buddha.xml", spp=1024, parts=16, address="auto", res=512)

Ray schedules the tasks (``num_gpus=1`` each where the device is cuda, so a node with 8 GPUs
runs 8 at once) and retries a task whose worker dies (``max_retries``). The scene travels as a
path that every node reads (one machine, or a shared file system): a path is a few bytes, where
the object store would copy the scene's meshes and maps to every node at each call, and a
worker keeps the scene it loaded for the next share of it. On one machine, ``address=None``
starts Ray locally.

``study`` runs ``envgi study`` the same way: each (strategy, spp, seed) run is a task, the
reference is split into shares, and the results land in the same results.csv, results.json and
report.html as a local study's. The envgi command plans (checks the settings, makes the folder,
lists the runs not yet written) and, at the end, gathers; the tasks only render and measure.
"""

import json
import os
import subprocess
import tempfile
from pathlib import Path

import envgi

_loaded = {}  # (path, params) -> Scene, per worker process: loaded once, its BVH built once


def sample_ranges(spp, parts):
    """[s0, s1) ranges that tile [0, spp) in `parts` nearly equal shares, each with its index."""
    if spp <= 0 or parts <= 0:
        raise ValueError("spp and parts must be positive")
    parts = min(parts, spp)
    bounds = [spp * i // parts for i in range(parts + 1)]
    return [(i, bounds[i], bounds[i + 1]) for i in range(parts)]


def _render_share(path, params, spp, s0, s1, settings):
    key = (path, tuple(sorted(params.items())))
    scene = _loaded.get(key)
    if scene is None:
        scene = _loaded[key] = envgi.load_file(path, **params)
    share = envgi.render(scene, spp=spp, sample_range=(s0, s1), progress=False, **settings)
    del share["image"]
    return share


def merge_checked(spp, results):
    """The merged image of (index, s0, s1, share) results, after checking that they cover
    [0, spp) with each range exactly once: a retried task must never count twice."""
    seen = sorted((s0, s1, i) for i, s0, s1, _ in results)
    indices = [i for _, _, i in seen]
    if len(set(indices)) != len(indices):
        raise RuntimeError("a sample range was counted twice")
    at = 0
    for s0, s1, _ in seen:
        if s0 != at:
            raise RuntimeError(f"the samples {at}:{s0} are missing" if s0 > at else f"the samples {s0}:{at} overlap")
        at = s1
    if at != spp:
        raise RuntimeError(f"the samples {at}:{spp} are missing")
    return envgi.merge_shares([share for *_, share in results])


def _connect(address):
    """Joins the Ray cluster at address (None: starts Ray here), with a clear error where none answers."""
    import ray

    if ray.is_initialized():
        return ray
    if address and address != "auto":
        # Ray's own connect retries for minutes where nothing listens: a plain TCP connect first.
        import socket

        host, _, port = address.split("://")[-1].rpartition(":")
        try:
            socket.create_connection((host, int(port)), timeout=5).close()
        except (OSError, ValueError) as e:
            raise ConnectionError(f"no Ray cluster answers at {address}: {e}") from None
    try:
        ray.init(address=address, log_to_driver=False, include_dashboard=False)
    except (ConnectionError, RuntimeError) as e:
        raise ConnectionError(f"no Ray cluster answers at {address}: {str(e).splitlines()[0]}") from None
    return ray


def _require_gpus(ray, device):
    # A task asking for a GPU no node has would wait for ever: refused here instead.
    if device == "cuda" and ray.cluster_resources().get("GPU", 0) < 1:
        raise ValueError("device 'cuda': no node of the Ray cluster has a GPU")


def _task_error(e):
    """The error a task raised, as itself (a worker's FileNotFoundError stays one), not Ray's wrapper."""
    cause = getattr(e, "cause", None)
    return cause if isinstance(cause, Exception) else e


def _gather(ray, pending, on_result, progress, total=None, done=0):
    """Waits on pending {ref: info}, calling on_result(info, value) as each finishes, with one
    tqdm bar over all of them; a task's own error is raised as itself."""
    total = total or len(pending)
    bar = envgi._Bar(progress)
    try:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                info = pending.pop(ref)
                try:
                    value = ray.get(ref)
                except ray.exceptions.RayTaskError as e:
                    for other in pending:  # nothing more to wait for: what finished is kept
                        ray.cancel(other)
                    raise _task_error(e) from None
                on_result(info, value)
                done += 1
                if bar.callback():
                    bar.update_to(done / total)
    finally:
        bar.close()


def _task(ray, function, device, threads, max_retries):
    # A task renders with the CPUs it asks Ray for (threads, one by default), or one GPU.
    return ray.remote(num_cpus=max(1, threads), num_gpus=1 if device == "cuda" else 0,
                      max_retries=max_retries)(function)


def _render_shares(ray, scene_path, spp, parts, device, settings, max_retries, progress, params):
    _require_gpus(ray, device)
    if parts is None:
        parts = max(1, int(ray.cluster_resources().get("GPU" if device == "cuda" else "CPU", 1)))
    task = _task(ray, _render_share, device, settings["threads"], max_retries)
    pending = {}
    for i, s0, s1 in sample_ranges(spp, parts):
        pending[task.remote(str(scene_path), params, spp, s0, s1, settings)] = (i, s0, s1)
    results = []
    try:
        _gather(ray, pending, lambda info, share: results.append((*info, share)), progress)
    except Exception as e:
        # What finished is kept: (index, s0, s1, share) each, for merge_shares or a second try
        # at the ranges that are missing.
        e.finished_shares = results
        raise
    return merge_checked(spp, results)


def render(scene_path, spp, parts=None, address=None, device="cpu", integrator=None, strategy=None, seed=None,
           threads=1, max_retries=3, progress=True, **params):
    """Renders scene_path at spp samples a pixel as `parts` tasks on a Ray cluster (address:
    "auto", "HOST:PORT", or None to start Ray here) and returns the merged float32 image, equal
    to envgi.render's of the same settings up to float rounding. parts defaults to the cluster's
    CPUs (GPUs with device="cuda"); each task takes `threads` CPUs. Keyword arguments are the
    scene's parameters. Where a task fails, its error is raised with the shares that finished
    as its ``finished_shares``."""
    ray = _connect(address)
    settings = {"device": device, "integrator": integrator, "strategy": strategy, "seed": seed, "threads": threads}
    return _render_shares(ray, scene_path, spp, parts, device, settings, max_retries, progress, params)


def _study_run(path, params, run, settings, reference):
    """One study run: rendered, measured against the reference, its record (and image) returned."""
    key = (path, tuple(sorted(params.items())))
    scene = _loaded.get(key)
    if scene is None:
        scene = _loaded[key] = envgi.load_file(path, **params)
    image, st = envgi.render(scene, spp=run["spp"], strategy=run["strategy"], seed=run["render_seed"],
                             progress=False, stats=True, **settings)
    error = envgi.image_error(image, reference)
    record = {"strategy": run["strategy"], "spp": run["spp"], "time_budget": run["time_budget"], "seed": run["seed"],
              "seconds": st["seconds"], "rmse": error["rmse"], "relmse": error["relmse"],
              "worst_region_rmse": error["worst_region_rmse"], "device": st["device"],
              "mean_spp": st["mean_spp"] if st["mean_spp"] > 0 else float(run["spp"])}
    return record, image if run["image"] else None


def _write_atomically(path, write):
    """write(tmp) then a rename: a file is whole or absent, as the study's own are."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _plan(args):
    with tempfile.TemporaryDirectory() as d:
        plan = Path(d) / "plan.json"
        envgi._run_study_cli([*args, "--plan", str(plan)])
        return json.loads(plan.read_text())


def study(scene, output, address=None, strategies=None, spp=None, time=None, seeds=None, reference=None,
          reference_spp=None, integrator=None, device="cpu", noise_threshold=None, min_spp=None, threads=1,
          reference_parts=None, max_retries=3, progress=True, as_frame=False, **params):
    """``envgi study`` over a Ray cluster (address as render's): the reference as split shares,
    each run a task asking for one CPU (or one GPU with device="cuda"). Every finished run is
    written to output/runs at once, so a study stopped midway resumes from them; the results
    equal a local study's. The scene is read by path on every node (a shared path, as render's);
    the reference travels once through Ray's object store. Returns the records, as envgi.study."""
    if device not in ("auto", "cpu", "cuda"):
        raise ValueError(f"unknown device '{device}' (cpu, cuda, auto)")
    scene = os.path.abspath(scene)
    # The envgi command here only plans and gathers, on this machine, which need not have the
    # workers' GPUs: its device is the CPU's (study.json does not record the device).
    args = envgi._study_args(scene, output, strategies, spp, time, seeds, reference, reference_spp, integrator, "cpu",
                             params, noise_threshold, min_spp)
    plan = _plan(args)  # settings checked, the folder made: before any cluster is joined
    ray = _connect(address)
    if device == "auto":  # the cluster's GPUs where it has any
        device = "cuda" if ray.cluster_resources().get("GPU", 0) >= 1 else "cpu"
    _require_gpus(ray, device)
    settings = {"device": device, "integrator": plan.get("integrator") or (plan["reference"] or {}).get("integrator"),
                "threads": threads}
    if plan["reference"]:
        ref = plan["reference"]
        share_settings = {"device": device, "integrator": ref["integrator"], "strategy": ref["strategy"],
                          "seed": ref["seed"], "threads": threads}
        image = _render_shares(ray, scene, ref["spp"], reference_parts, device, share_settings, max_retries,
                               progress, params)
        _write_atomically(ref["path"], lambda tmp: envgi.write_image(str(tmp), image))
        plan = _plan(args)
        settings["integrator"] = plan["integrator"]
    adaptive = plan["adaptive_sampling"] or {}
    settings.update(noise_threshold=adaptive.get("noise_threshold", 0.0), min_spp=adaptive.get("min_spp", 16))
    reference_ref = ray.put(envgi.read_image(plan["reference_path"]))
    task = _task(ray, _study_run, device, threads, max_retries)

    def written(run, result):
        record, image = result
        if image is not None:  # the image first: a run counts as done once its record is there
            _write_atomically(run["exr"], lambda tmp: envgi.write_image(str(tmp), image))
        _write_atomically(run["json"], lambda tmp: tmp.write_text(json.dumps(record, indent=2)))

    total, done = plan["total"], plan["done"]
    while plan["runs"]:
        ready = [run for run in plan["runs"] if run["spp"] is not None]
        if not ready:
            raise RuntimeError("the study's plan made no progress: its time budgets wait on runs that are not done")
        pending = {task.remote(scene, params, run, settings, reference_ref): run for run in ready}
        _gather(ray, pending, written, progress, total=total, done=done)
        done += len(ready)
        plan = _plan(args)  # the time budgets' sample counts, from the runs just written
    envgi._run_study_cli(args)  # every run is written: this gathers them into results and report
    return envgi._study_records(output, as_frame)


def _main(argv):
    """python -m envgi.distributed --study JSON: what ``envgi study --ray`` runs."""
    import sys

    if len(argv) != 3 or argv[1] != "--study":
        print("usage: python -m envgi.distributed --study JSON (as envgi study --ray writes it)", file=sys.stderr)
        return 2
    spec = json.loads(argv[2])
    params = spec.pop("params")
    try:
        study(spec.pop("scene"), spec.pop("output"), **spec, **params)
    except (ValueError, OSError, RuntimeError) as e:  # ConnectionError and FileNotFoundError are OSErrors
        print(f"envgi: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(_main(sys.argv))
