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
"""

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


def render(scene_path, spp, parts=None, address=None, device="cpu", integrator=None, strategy=None, seed=None,
           max_retries=3, progress=True, **params):
    """Renders scene_path at spp samples a pixel as `parts` tasks on a Ray cluster (address:
    "auto", "HOST:PORT", or None to start Ray here) and returns the merged float32 image, equal
    to envgi.render's of the same settings up to float rounding. Keyword arguments are the
    scene's parameters."""
    import ray

    if not ray.is_initialized():
        ray.init(address=address, log_to_driver=False, include_dashboard=False)
    if parts is None:
        parts = max(1, int(ray.cluster_resources().get("GPU" if device == "cuda" else "CPU", 1)))
    settings = {"device": device, "integrator": integrator, "strategy": strategy, "seed": seed}
    task = ray.remote(num_cpus=1, num_gpus=1 if device == "cuda" else 0, max_retries=max_retries)(_render_share)
    pending = {}
    for i, s0, s1 in sample_ranges(spp, parts):
        ref = task.remote(str(scene_path), params, spp, s0, s1, settings)
        pending[ref] = (i, s0, s1)
    bar = envgi._Bar(progress)
    results = []
    try:
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                i, s0, s1 = pending.pop(ref)
                results.append((i, s0, s1, ray.get(ref)))
                if bar.callback():
                    bar.update_to(len(results) / (len(results) + len(pending)))
    finally:
        bar.close()
    return merge_checked(spp, results)
