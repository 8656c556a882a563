"""envgi from Python: load a Mitsuba 3 scene once, render it many times into NumPy arrays.

    import envgi
    scene = envgi.load_file("scenes/buddha.xml", res=128)
    img = envgi.render(scene, spp=16, strategy="importance")   # float32 (H, W, 3)

The names follow Mitsuba 3's where the idea is the same (``load_file``, ``load_string``,
``render``). A render releases the GIL, stops at Ctrl-C with ``KeyboardInterrupt``, and reuses
the scene's acceleration structure from one call to the next.
"""

import json
import os
import shutil
import subprocess
from pathlib import Path

from . import _envgi
from ._envgi import EnvironmentMap, Scene, image_error, read_image, set_log_level, write_image

__all__ = ["EnvironmentMap", "Scene", "image_error", "load_file", "load_string", "merge_shares", "read_image", "render",
           "set_log_level", "study", "write_image"]


def load_file(path, **params):
    """Loads a scene from Mitsuba 3 XML. Keyword arguments set its ``<default>`` parameters
    (the CLI's ``-D name=value``). Raises FileNotFoundError or ValueError ("FILE:LINE: what")."""
    return _envgi.load_file(str(path), **params)


def load_string(xml, **params):
    """Loads a scene from XML text; relative file names are read from the working folder."""
    return _envgi.load_string(xml, **params)


class _Bar:
    """A tqdm bar in per cent, where tqdm is installed."""

    def __init__(self, enabled):
        self._bar = None
        if not enabled:
            return
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return
        self._bar = tqdm(total=100, unit="%", desc="envgi", leave=False)

    def update_to(self, fraction):
        self._bar.update(max(0, int(100 * fraction) - self._bar.n))

    def callback(self):
        return self.update_to if self._bar is not None else None

    def close(self):
        if self._bar is not None:
            self._bar.close()


def render(scene, spp=None, integrator=None, strategy=None, seed=None, device="auto", time_limit=None, threads=0,
           progress=True, sample_range=None, noise_threshold=0.0, min_spp=16, stats=False):
    """Renders ``scene`` and returns its image as a float32 array (height, width, 3) that
    Python owns (NumPy's buffer protocol, ``__array__`` and ``__dlpack__``).

    spp, integrator, strategy and seed override the scene's for this call only; the next call
    starts from the scene's own. device is "auto" (a GPU where there is one and the
    integrator runs there), "cpu" or "cuda". time_limit: seconds, after which the render stops
    with the passes done. threads: CPU threads (0: every core). progress: a tqdm bar where tqdm
    is installed. noise_threshold > 0 samples adaptively, as ``envgi render --noise-threshold``:
    every pixel takes min_spp samples, then stops once its noise is below the threshold.
    stats=True returns (result, stats), stats a dict of the render's own "seconds" (without
    loading or building), "spp", "mean_spp" (samples a pixel, on average) and "device".

    sample_range=(s0, s1) renders samples [s0, s1) of the spp-sample render only (path and
    direct), and returns that share's film as a dict: "sum" (H, W, 3), "weight" (the filter's
    weights summed, or None where each sample weighs one), "samples" (s1 - s0) and "image" (the
    share's own mean). Shares that cover [0, spp) add up with merge_shares to the one render's
    image, to float rounding.
    """
    bar = _Bar(progress)
    try:
        return _envgi.render(scene, spp, integrator, strategy, seed, device, float(time_limit or 0.0), int(threads),
                             bar.callback(), None if sample_range is None else tuple(int(s) for s in sample_range),
                             float(noise_threshold), int(min_spp), bool(stats))
    finally:
        bar.close()


def merge_shares(shares):
    """The image of shares of one render (render(..., sample_range=...)): their sums added, then
    divided by the samples (or the filter's weights) as the renderer's own film does."""
    import numpy as np

    shares = list(shares)
    if not shares:
        raise ValueError("merge_shares: no shares")
    total = np.zeros_like(shares[0]["sum"])
    for share in shares:
        total += share["sum"]
    count = np.float32(max(sum(share["samples"] for share in shares), 1))
    if shares[0]["weight"] is None:
        return total / count
    weight = np.zeros_like(shares[0]["weight"])
    for share in shares:
        weight += share["weight"]
    # A weighted mean where the weights reach a quarter of the count, the plain mean elsewhere.
    divisor = np.where(weight > np.float32(0.25) * count, weight, count).astype(np.float32)
    return total / divisor[..., None]


def _cli():
    """The envgi command: $ENVGI_CLI, the build's own beside build/python, or one on PATH."""
    given = os.environ.get("ENVGI_CLI")
    if given:
        return given
    beside = Path(__file__).resolve().parents[2] / "bin" / "envgi"
    if beside.is_file():
        return str(beside)
    found = shutil.which("envgi")
    if found:
        return found
    raise FileNotFoundError("the envgi command was not found: set ENVGI_CLI, or put envgi on PATH")


def _study_args(scene, output, strategies, spp, time, seeds, reference, reference_spp, integrator, device, params,
                noise_threshold=None, min_spp=None, threads=None):
    """The ``envgi study`` command line of study()'s arguments."""
    args = [_cli(), "study", str(scene), "-o", str(output), "-q", "--device", device]

    def listed(option, values):
        if values is not None:
            args.extend([option, ",".join(str(v) for v in values)])

    listed("--strategies", strategies)
    listed("--spp", spp)
    listed("--time", time)
    for option, value in (("--seeds", seeds), ("--reference", reference), ("--reference-spp", reference_spp),
                          ("--integrator", integrator), ("--noise-threshold", noise_threshold),
                          ("--min-spp", min_spp), ("--threads", threads)):
        if value is not None:
            args.extend([option, str(value)])
    for name, value in params.items():
        args.extend(["-D", f"{name}={str(value).lower() if isinstance(value, bool) else value}"])
    return args


def _run_study_cli(args):
    done = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        message = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}"
        raise ValueError(message.removeprefix("envgi: error: "))


def _study_records(output, as_frame):
    records = json.loads((Path(output) / "results.json").read_text())["runs"]
    if as_frame:
        import pandas
        return pandas.DataFrame.from_records(records)
    return records


def study(scene, output, strategies=None, spp=None, time=None, seeds=None, reference=None, reference_spp=None,
          integrator=None, device="auto", as_frame=False, cluster=None, **params):
    """Runs ``envgi study`` (docs/study.md) with the CLI's arguments: lists for strategies, spp
    and time; keyword arguments for the scene's parameters. It writes output/results.csv,
    results.json and report.html, resumes from the runs already in output, and returns the
    results as a list of records, or as a pandas DataFrame with as_frame=True.

    cluster: a Ray address ("auto", "HOST:PORT", or "local" to start Ray here) runs each run,
    and the reference's shares, as Ray tasks (envgi.distributed.study): the same files result."""
    if cluster is not None:
        from . import distributed

        return distributed.study(scene, output, address=None if cluster == "local" else cluster,
                                 strategies=strategies, spp=spp, time=time, seeds=seeds, reference=reference,
                                 reference_spp=reference_spp, integrator=integrator, device=device,
                                 as_frame=as_frame, **params)
    _run_study_cli(_study_args(scene, output, strategies, spp, time, seeds, reference, reference_spp, integrator,
                               device, params))
    return _study_records(output, as_frame)
