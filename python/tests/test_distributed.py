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


def kill_node_later(port, seconds):
    """SIGKILLs the raylet of the worker node on `port` after `seconds`; returns its pids and a
    list that gets the time of the kill."""
    victim = subprocess.run(["pgrep", "-f", f"raylet.*node_manager_port={port}"], capture_output=True,
                            text=True).stdout.split()
    assert victim, f"the raylet of the worker node on port {port}"
    killed = []

    def kill():
        for p in victim:
            os.kill(int(p), signal.SIGKILL)
        killed.append(time.monotonic())

    threading.Timer(seconds, kill).start()
    return victim, killed


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
    # Killed while the shares run: its tasks fail and Ray runs them again elsewhere.
    victim, killed = kill_node_later(WORKER_PORTS[0], 0.5)
    split = ed.render(BUDDHA, spp=256, parts=16, address=cluster, progress=False, res=96)
    finished = time.monotonic()
    assert killed and killed[0] < finished, "the node died before the render ended"
    np.testing.assert_allclose(split, one, rtol=1e-5, atol=1e-6)
    for p in victim:  # the node is gone (or a zombie not yet reaped), not merely idle
        status = Path(f"/proc/{p}/status")
        assert not status.exists() or "State:\tZ" in status.read_text()


def test_bad_input_is_a_clear_error_not_a_hang(cluster, tmp_path):
    with pytest.raises(FileNotFoundError, match="no-such-scene.xml") as failed:
        ed.render(SOURCE / "no-such-scene.xml", spp=4, parts=2, progress=False)
    assert failed.value.finished_shares == []
    with pytest.raises(ValueError, match="no node of the Ray cluster has a GPU"):
        ed.render(BUDDHA, spp=4, parts=2, device="cuda", progress=False, res=8)
    # The driver plans on its own CPU whatever the workers' device: the cluster refuses it.
    with pytest.raises(ValueError, match="no node of the Ray cluster has a GPU"):
        ed.study(BUDDHA, tmp_path, address=cluster, device="cuda", progress=False, spp=[1], reference_spp=4, res=8)


STUDY = dict(strategies=["uniform", "importance", "points-8"], spp=[1, 4, 16], seeds=2, reference_spp=64,
             time=[0.01], res=32)


def rows(folder):
    """results.csv as {(strategy, spp or budget, seed): rmse to four digits}, each key once."""
    import csv

    out = {}
    with open(Path(folder) / "results.csv") as f:
        for r in csv.DictReader(f):
            key = (r["strategy"], r["time_budget"] if float(r["time_budget"]) > 0 else r["spp"], r["seed"])
            assert key not in out, f"{key} counted twice"
            out[key] = f"{float(r['rmse']):.4g}"
    return out


@pytest.fixture(scope="module")
def local_study(tmp_path_factory):
    folder = tmp_path_factory.mktemp("local")
    envgi.study(BUDDHA, folder, device="cpu", **STUDY)
    return rows(folder)


def equal_sample_rows(table):
    return {k: v for k, v in table.items() if "." not in k[1]}


def test_a_study_over_the_cluster_gives_the_local_table(cluster, local_study, tmp_path):
    records = envgi.study(BUDDHA, tmp_path, cluster=cluster, device="cpu", **STUDY)
    table = rows(tmp_path)
    assert len(records) == len(table) == 3 * 4 * 2
    assert equal_sample_rows(table) == equal_sample_rows(local_study)
    assert (tmp_path / "report.html").stat().st_size > 10_000 and (tmp_path / "study.json").exists()
    # Resumed: only the runs whose files are gone are rendered again, to the same numbers.
    gone = [tmp_path / "runs" / "uniform_spp4_seed1.json", tmp_path / "runs" / "points-8_spp16_seed0.json"]
    kept = tmp_path / "runs" / "importance_spp16_seed1.json"
    before = kept.stat().st_mtime_ns
    for f in gone:
        f.unlink()
    ed.study(BUDDHA, tmp_path, address=cluster, device="cpu", progress=False, **STUDY)
    assert all(f.exists() for f in gone) and kept.stat().st_mtime_ns == before
    assert rows(tmp_path) == table


def test_envgi_study_ray_is_the_same_study(cluster, local_study, tmp_path):
    cli = os.environ.get("ENVGI_CLI", "envgi")
    args = [cli, "study", str(BUDDHA), "-o", str(tmp_path), "--device", "cpu", "-q", "--ray", cluster,
            "--strategies", ",".join(STUDY["strategies"]), "--spp", "1,4,16", "--seeds", "2", "--time", "0.01",
            "--reference-spp", "64", "-D", "res=32"]
    done = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert equal_sample_rows(rows(tmp_path)) == equal_sample_rows(local_study)
    refused = subprocess.run([cli, "study", str(BUDDHA), "-o", str(tmp_path / "x"), "--ray", "127.0.0.1:9",
                              "-D", "res=8"], capture_output=True, text=True, timeout=300)
    assert refused.returncode == 1 and "no Ray cluster answers at 127.0.0.1:9" in refused.stderr
    assert not (tmp_path / "x" / "results.csv").exists()


def test_a_study_survives_a_killed_worker_node(cluster, local_study, tmp_path):
    # The reference (64 spp) takes most of a second: the node dies among the first runs.
    _, killed = kill_node_later(WORKER_PORTS[1], 1.0)
    # auto: the cluster's GPUs where it has any, its CPUs here.
    ed.study(BUDDHA, tmp_path, address=cluster, device="auto", progress=False, **STUDY)
    assert killed and killed[0] < time.monotonic()
    table = rows(tmp_path)  # rows() fails on a run counted twice
    assert len(table) == 3 * 4 * 2
    assert equal_sample_rows(table) == equal_sample_rows(local_study)
