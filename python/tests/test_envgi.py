"""import envgi: renders equal the CLI's, settings are per call, errors are Python's, Ctrl-C
stops a render, the GIL is free while it runs, and the map's draws follow their density."""

import _thread
import os
import subprocess
import sys
import threading
import time
import types
from pathlib import Path

import numpy as np
import pytest

import envgi

SOURCE = Path(os.environ.get("ENVGI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUDDHA = SOURCE / "scenes" / "buddha.xml"
GRACE = SOURCE / "scenes" / "envmaps" / "grace_latlong.hdr"


@pytest.fixture(scope="module")
def buddha():
    return envgi.load_file(BUDDHA, res=32)


def test_render_is_a_float32_array_python_owns(buddha):
    img = envgi.render(buddha, spp=4, progress=False)
    assert img.dtype == np.float32
    assert img.shape == (buddha.height, buddha.width, 3) == (32, 32, 3)
    assert img.flags["C_CONTIGUOUS"] and img.flags["OWNDATA"] is False  # held by its capsule
    assert np.isfinite(img).all() and img.mean() > 0.01
    # NumPy's protocols, DLPack's among them, share the pixels without a copy.
    assert np.shares_memory(np.from_dlpack(img), img)
    assert memoryview(img).shape == (32, 32, 3)


def test_render_equals_the_cli_to_the_bit(buddha, tmp_path):
    out = tmp_path / "cli.exr"
    subprocess.run([os.environ["ENVGI_CLI"], "render", str(BUDDHA), "-D", "res=32", "--spp", "8", "--seed", "3",
                    "-o", str(out), "-q"], check=True)
    cli = envgi.read_image(str(out))
    img = envgi.render(buddha, spp=8, seed=3, progress=False)
    assert np.array_equal(cli, img)


def test_settings_hold_for_one_call_and_the_scene_is_reused(buddha):
    own = (buddha.integrator, buddha.strategy)
    assert own == ("direct", "product")
    first = envgi.render(buddha, spp=2, progress=False)
    assert buddha.accel_built
    uniform = envgi.render(buddha, spp=2, strategy="uniform", progress=False)
    path = envgi.render(buddha, spp=2, integrator="path", progress=False)
    points = envgi.render(buddha, spp=2, strategy="points", progress=False)  # the collapsed map, made for it
    assert (buddha.integrator, buddha.strategy) == own
    for other in (uniform, path, points):
        assert not np.array_equal(first, other)
    # Back to the scene's own settings: the same image to the bit.
    assert np.array_equal(first, envgi.render(buddha, spp=2, progress=False))
    # The same estimator in expectation: the two strategies agree on the image's mean.
    many = envgi.render(buddha, spp=64, progress=False).mean()
    assert abs(envgi.render(buddha, spp=64, strategy="uniform", progress=False).mean() / many - 1) < 0.05


def test_load_string_and_parameters():
    xml = BUDDHA.read_text().replace('value="meshes/', f'value="{SOURCE}/scenes/meshes/').replace(
        'value="envmaps/', f'value="{SOURCE}/scenes/envmaps/')
    scene = envgi.load_string(xml, res=16, spp=2)
    assert (scene.width, scene.height, scene.spp) == (16, 16, 2)
    assert envgi.render(scene, progress=False).shape == (16, 16, 3)


def test_errors_are_python_exceptions_with_the_clis_line(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        envgi.load_file(tmp_path / "missing.xml")
    with pytest.raises(ValueError, match=r"<string>:1: .*version"):
        envgi.load_string("<scene/>")
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <integrator type="path">\n    <integer name="max_dept" value="3"/>\n'
                   '  </integrator>\n</scene>\n')
    with pytest.raises(ValueError, match=r"bad.xml:3: .*max_depth"):
        envgi.load_file(bad)
    scene = envgi.load_file(BUDDHA, res=8)
    with pytest.raises(ValueError, match="spp must be positive"):
        envgi.render(scene, spp=0, progress=False)
    with pytest.raises(ValueError, match="unknown device 'gpu'"):
        envgi.render(scene, device="gpu", progress=False)
    with pytest.raises(ValueError, match="strateg"):
        envgi.render(scene, strategy="importnce", progress=False)
    assert scene.strategy == "product"  # a refused override leaves the scene as it was
    with pytest.raises(ValueError):
        envgi.set_log_level("loud")


def test_ctrl_c_stops_a_render_with_keyboard_interrupt():
    scene = envgi.load_file(BUDDHA, res=64)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        envgi.render(scene, spp=1 << 20, time_limit=20, progress=False)  # ends anyway if Ctrl-C is lost
    assert time.monotonic() - start < 10.0
    # The scene renders again afterwards.
    assert envgi.render(scene, spp=1, progress=False).shape == (64, 64, 3)


def test_the_gil_is_free_while_rendering(buddha):
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    envgi.render(envgi.load_file(BUDDHA, res=64), spp=32, progress=False)
    done.set()
    t.join()
    assert len(ticks) > 20


def test_progress_goes_to_tqdm_where_it_is_installed(buddha, monkeypatch):
    seen = []

    class FakeBar:
        def __init__(self, total, **kwargs):
            self.n, self.total = 0, total

        def update(self, k):
            self.n += k
            seen.append(self.n)

        def close(self):
            seen.append("closed")

    auto = types.ModuleType("tqdm.auto")
    auto.tqdm = FakeBar
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", auto)
    envgi.render(buddha, spp=2)
    assert seen[-2:] == [100, "closed"]
    seen.clear()
    envgi.render(buddha, spp=2, progress=False)
    assert seen == []


def test_environment_map_draws_follow_their_density():
    env = envgi.EnvironmentMap(str(GRACE))
    assert (env.width, env.height) == (1024, 512)
    n = 20000
    for strategy in ("importance", "uniform", "cosine", "product"):
        dirs, pdfs = env.sample(n, strategy=strategy, seed=1)
        assert dirs.shape == (n, 3) and pdfs.shape == (n,)
        np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0, atol=1e-5)
        # pdf() finds each direction's pixel again from the direction: one in thousands lands
        # across a pixel's edge by float rounding (the fuzz target allows the same).
        agree = np.isclose(env.pdf(dirs, strategy=strategy), pdfs, rtol=1e-4, atol=0)
        assert agree.mean() > 0.999, strategy
    # The map's power by importance sampling and by uniform sampling: one integral, two
    # unbiased estimates that agree within their standard errors.
    estimates = []
    for strategy in ("importance", "uniform"):
        dirs, pdfs = env.sample(n, strategy=strategy, seed=2)
        lum = env.eval(dirs) @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
        w = lum / pdfs
        estimates.append((w.mean(), w.std() / np.sqrt(n)))
    (a, sa), (b, sb) = estimates
    assert abs(a - b) < 4 * np.hypot(sa, sb)
    assert sa < sb / 3  # importance sampling is the better estimator of the two
    with pytest.raises(ValueError):
        env.sample(10, strategy="nonsense")
    with pytest.raises(FileNotFoundError):
        envgi.EnvironmentMap("nowhere.hdr")


def test_images_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    img = rng.random((5, 7, 3), dtype=np.float32)
    for ext in ("exr", "pfm"):
        envgi.write_image(str(tmp_path / f"x.{ext}"), img)
        np.testing.assert_array_equal(envgi.read_image(str(tmp_path / f"x.{ext}")), img)
    with pytest.raises(ValueError, match="shape"):
        envgi.write_image(str(tmp_path / "y.exr"), np.zeros((4, 4)))


def test_study_runs_the_clis_study_and_returns_its_records(tmp_path):
    kwargs = dict(strategies=["uniform", "importance"], spp=[1, 4], seeds=1, reference_spp=16, res=16)
    records = envgi.study(BUDDHA, tmp_path / "s", **kwargs)
    assert sorted((r["strategy"], r["spp"]) for r in records) == [("importance", 1), ("importance", 4),
                                                                   ("uniform", 1), ("uniform", 4)]
    assert all(r["rmse"] > 0 for r in records)
    assert (tmp_path / "s" / "report.html").is_file()
    # Run again, it resumes: every run is read back, none rendered, and the table is the same.
    assert envgi.study(BUDDHA, tmp_path / "s", **kwargs) == records
    with pytest.raises(ValueError, match="strateg"):
        envgi.study(BUDDHA, tmp_path / "t", strategies=["importnce"], res=16)


def test_camera_and_environment_change_without_a_new_bvh():
    scene = envgi.load_file(BUDDHA, res=32)
    first = envgi.render(scene, spp=4, progress=False)
    scene.set_camera((0.0, 1.5, 4.0), (0.0, 0.0, 0.0))
    moved = envgi.render(scene, spp=4, progress=False)
    assert not np.allclose(moved, first)
    # The scene file's own lookat again: the first image to the bit, on the BVH built for it.
    scene.set_camera((0.0, 0.1, 4.4), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    assert scene.accel_built
    assert np.array_equal(envgi.render(scene, spp=4, progress=False), first)
    # The map twice as bright lights the scene twice as brightly (it is the only light); turned
    # a full circle it is where it was; turned a quarter it lights the Buddha otherwise.
    scene.set_environment(scale=2.0)
    np.testing.assert_allclose(envgi.render(scene, spp=4, progress=False), 2 * first, rtol=1e-5, atol=1e-6)
    scene.set_environment(rotation=360.0)
    np.testing.assert_allclose(envgi.render(scene, spp=4, progress=False), first, rtol=1e-3, atol=1e-3)
    scene.set_environment(rotation=90.0)
    assert not np.allclose(envgi.render(scene, spp=4, progress=False), first, rtol=0.05)
    with pytest.raises(ValueError, match="same point"):
        scene.set_camera((0.0, 0.0, 1.0), (0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="scale"):
        scene.set_environment(scale=-1.0)


def test_shares_of_a_render_add_up_to_it():
    scene = envgi.load_file(BUDDHA, res=24)
    whole = envgi.render(scene, spp=8, progress=False)
    a = envgi.render(scene, spp=8, sample_range=(0, 3), progress=False)
    b = envgi.render(scene, spp=8, sample_range=(3, 8), progress=False)
    assert (a["samples"], b["samples"]) == (3, 5) and a["weight"] is None
    np.testing.assert_allclose(envgi.merge_shares([a, b]), whole, rtol=1e-5, atol=1e-6)
    # Each share's own image is the mean of its samples.
    np.testing.assert_allclose((3 * a["image"] + 5 * b["image"]) / 8, whole, rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="renders as a whole"):
        envgi.render(scene, spp=8, sample_range=(0, 4), integrator="sppm", progress=False)
    with pytest.raises(ValueError, match="not a range"):
        envgi.render(scene, spp=8, sample_range=(4, 12), progress=False)
