"""envgi.distributed on a real Ray cluster: a head and two worker nodes started here on
127.0.0.1 (ray start), one CPU each, torn down at the end. A split render equals the
one-process render to float rounding, and a worker node killed mid-render costs only a retry."""

import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import ray

import envgi
import envgi.distributed as ed

SOURCE = Path(os.environ.get("ENVGI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUDDHA = SOURCE / "scenes" / "buddha.xml"
PORT = 6389 + os.getpid() % 500
WORKER_PORTS = (PORT + 600, PORT + 700)  # each worker node's raylet, so that a test can kill one



@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    # A cluster on loopback, torn down at the end: no token (Ray's default asks the nodes to share
    # one, which a token left in ~/.ray by an earlier local Ray would not match).
    os.environ["RAY_AUTH_MODE"] = "disabled"
    ray_bin = Path(__import__("sys").executable).with_name("ray")
    temp = tmp_path_factory.mktemp("ray")
    common = ["--num-cpus=1", "--disable-usage-stats"]
    subprocess.run([str(ray_bin), "start", "--head", f"--port={PORT}", "--include-dashboard=false",
                    f"--temp-dir={temp}", *common], check=True, capture_output=True)
    try:
        for port in WORKER_PORTS:
            subprocess.run([str(ray_bin), "start", f"--address=127.0.0.1:{PORT}", f"--node-manager-port={port}",
                            *common], check=True, capture_output=True)
        ray.init(address=f"127.0.0.1:{PORT}", log_to_driver=False)
        yield f"127.0.0.1:{PORT}"
    finally:
        ray.shutdown()
        subprocess.run([str(ray_bin), "stop", "--force"], capture_output=True)


def test_sample_ranges_tile_the_samples():
    assert ed.sample_ranges(10, 4) == [(0, 0, 2), (1, 2, 5), (2, 5, 7), (3, 7, 10)]
    assert ed.sample_ranges(3, 8) == [(0, 0, 1), (1, 1, 2), (2, 2, 3)]
    share = {"sum": np.ones((1, 1, 3), np.float32), "weight": None, "samples": 1}
    with pytest.raises(RuntimeError, match="missing"):
        ed.merge_checked(3, [(0, 0, 1, share), (2, 2, 3, share)])
    with pytest.raises(RuntimeError, match="twice"):
        ed.merge_checked(2, [(0, 0, 1, share), (0, 0, 1, share), (1, 1, 2, share)])


def test_a_split_render_equals_the_one_process_render(cluster):
    assert len(ray.nodes()) == 3
    one = envgi.render(envgi.load_file(BUDDHA, res=32), spp=16, progress=False)
    split = ed.render(BUDDHA, spp=16, parts=4, address=cluster, progress=False, res=32)
    assert split.shape == one.shape
    np.testing.assert_allclose(split, one, rtol=1e-5, atol=1e-6)
    assert not np.array_equal(split, np.zeros_like(split))


def test_a_killed_worker_node_costs_a_retry_not_a_sample(cluster):
    one = envgi.render(envgi.load_file(BUDDHA, res=96), spp=256, progress=False)
    victim = subprocess.run(["pgrep", "-f", f"raylet.*node_manager_port={WORKER_PORTS[0]}"], capture_output=True,
                            text=True).stdout.split()
    assert victim, "the worker node's raylet"
    # Killed while the shares run: its tasks fail and Ray runs them again elsewhere.
    killed = []

    def kill():
        for p in victim:
            os.kill(int(p), signal.SIGKILL)
        killed.append(time.monotonic())

    threading.Timer(0.5, kill).start()
    split = ed.render(BUDDHA, spp=256, parts=16, address=cluster, progress=False, res=96)
    finished = time.monotonic()
    assert killed and killed[0] < finished, "the node died before the render ended"
    np.testing.assert_allclose(split, one, rtol=1e-5, atol=1e-6)
    for p in victim:  # the node is gone (or a zombie not yet reaped), not merely idle
        status = Path(f"/proc/{p}/status")
        assert not status.exists() or "State:\tZ" in status.read_text()
