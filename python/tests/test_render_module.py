"""The Python render equals the CLI's, bit for bit: same scene, seed and spp give the same cube,
fluorescence layer and AOV planes as radiance.exr; any thread count; a scene built or edited in
Python equals the CLI on the same document written to a file; Ctrl-C returns what finished."""
import json
import os
import signal

import numpy as np
import pytest

import oralfluor as ofl
from conftest import run_cli, scene_path


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


def assert_same_image(py_img, exr_img):
    assert py_img.shape == exr_img.shape
    np.testing.assert_array_equal(py_img.wavelengths, exr_img.wavelengths)
    np.testing.assert_array_equal(bits(py_img.radiance), bits(exr_img.radiance))
    assert (py_img.fluorescence is None) == (exr_img.fluorescence is None)
    if py_img.fluorescence is not None:
        np.testing.assert_array_equal(bits(py_img.fluorescence), bits(exr_img.fluorescence))
    assert sorted(py_img.aovs) == sorted(exr_img.aovs)
    for k in py_img.aovs:
        np.testing.assert_array_equal(bits(py_img.aovs[k]), bits(exr_img.aovs[k]), err_msg=k)


def test_cube_equals_cli_exr_bit_for_bit(tmp_path):
    scene = scene_path("minimal.json")
    run_cli("render", scene, "--spp", 4, "--seed", 7, "--width", 40, "--height", 30, "-o", tmp_path)
    exr = ofl.read_exr(str(tmp_path / "radiance.exr"))
    r = ofl.render(scene, spp=4, seed=7, width=40, height=30, threads=2)
    assert r.radiance.shape == (30, 40, 97)  # default bands: the whole grid, 350-830 nm every 5 nm
    assert r.radiance.max() > 0 and r.fluorescence.max() > 0  # a lit fluorescent patch, not an empty image
    assert_same_image(r.image, exr)
    assert r.image.attributes["oralfluor.excitation_spd"] == exr.attributes["oralfluor.excitation_spd"]
    assert r.stats["spp"] == 4 and not r.interrupted


def test_same_image_with_any_thread_count():
    a = ofl.render(scene_path("minimal.json"), spp=3, seed=2, width=24, height=20, threads=1)
    b = ofl.render(scene_path("minimal.json"), spp=3, seed=2, width=24, height=20, threads=2)
    np.testing.assert_array_equal(bits(a.radiance), bits(b.radiance))


def test_edited_dict_scene_equals_cli_on_the_written_document(tmp_path):
    scene = ofl.Scene(scene_path("minimal.json"))
    scene.set("/lights/0/spd/peak_nm", 385).set("/materials/patch/fluorophores/0/name", "protoporphyrin")
    scene.set("/camera/resolution", [20, 16]).set("/integrator/spp", 2)
    built = ofl.Scene(scene.doc, base_dir=os.path.dirname(scene.file))  # the same document as a plain dict
    doc_file = tmp_path / "edited.json"
    doc_file.write_text(json.dumps(scene.doc))
    run_cli("render", doc_file, "-o", tmp_path / "out")
    r = ofl.render(built)
    assert_same_image(r.image, ofl.read_exr(str(tmp_path / "out" / "radiance.exr")))
    # The edit took effect: protoporphyrin emits near 635 nm, FAD (the file's) does not.
    wl = r.wavelengths
    fl = r.fluorescence.mean(axis=(0, 1))
    assert fl[np.argmin(abs(wl - 630))] > 3 * fl[np.argmin(abs(wl - 530))]


def test_progress_callback_sees_every_sample_and_can_stop():
    calls = []

    def progress(done, total):
        calls.append((done, total))
        return True

    r = ofl.render(scene_path("minimal.json"), spp=8, width=32, height=32, progress=progress)
    assert calls and calls[-1] == (8 * 32 * 32, 8 * 32 * 32)
    assert all(d1 <= d2 for (d1, _), (d2, _) in zip(calls, calls[1:]))
    with pytest.warns(RuntimeWarning, match="interrupted"):
        stopped = ofl.render(scene_path("minimal.json"), spp=64, width=32, height=32, progress=lambda d, t: False)
    assert stopped.interrupted and stopped.spp < 64


def test_ctrl_c_returns_what_finished(recwarn):
    sent = []

    def interrupt_once(done, total):
        if not sent:
            sent.append(done)
            os.kill(os.getpid(), signal.SIGINT)  # as Ctrl-C does: Python's handler runs in the callback
        return True

    r = ofl.render(scene_path("minimal.json"), spp=256, seed=3, width=32, height=24, progress=interrupt_once)
    assert r.interrupted and 1 <= r.spp < 256
    assert any("interrupted" in str(w.message) for w in recwarn)
    # What finished is exactly a render with that many samples.
    full = ofl.render(scene_path("minimal.json"), spp=r.spp, seed=3, width=32, height=24)
    np.testing.assert_array_equal(bits(r.radiance), bits(full.radiance))


def test_exceptions_carry_the_cli_message(tmp_path):
    bad = tmp_path / "bad.json"
    doc = json.load(open(scene_path("minimal.json")))
    doc["lights"][0]["profile"]["half_angle_deg"] = -5
    bad.write_text(json.dumps(doc))
    cli = run_cli("render", bad, "-o", tmp_path / "o", check=False)
    assert cli.returncode == 2
    with pytest.raises(ofl.InputError) as e:
        ofl.render(str(bad))
    assert isinstance(e.value, ValueError)
    assert "error: " + str(e.value) == cli.stderr.strip().splitlines()[-1]
    assert e.value.file == str(bad) and e.value.field.startswith("/lights/0/profile")
    with pytest.raises(ofl.InputError) as e2:
        ofl.read_exr(str(tmp_path / "missing.exr"))
    assert "missing.exr" in str(e2.value)
    missing = ofl.Scene(doc)
    del missing.doc["camera"]
    with pytest.raises(ofl.InputError, match=r"<python scene>: /camera: missing required field"):
        ofl.render(missing)


def test_exr_round_trip_through_python(tmp_path):
    rng = np.random.default_rng(1)
    cube = rng.random((5, 7, 4), dtype=np.float32)
    img = ofl.SpectralImage(cube, [450, 500, 550, 600], fluorescence=cube * 0.5, aovs={"depth": cube[:, :, 0]},
                            attributes={"oralfluor.seed": "9"})
    ofl.write_exr(str(tmp_path / "x.exr"), img)
    back = ofl.read_exr(str(tmp_path / "x.exr"))
    np.testing.assert_array_equal(back.radiance, cube)
    np.testing.assert_array_equal(back.fluorescence, cube * 0.5)
    np.testing.assert_array_equal(back.aovs["depth"], cube[:, :, 0])
    assert back.attributes["oralfluor.seed"] == "9"
    with pytest.raises(ofl.InputError, match="wavelengths"):
        ofl.SpectralImage(cube, [450, 500, 550])


def test_render_releases_the_gil():
    import threading
    import time
    done, ticks = threading.Event(), []

    def ticker():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.002)

    t = threading.Thread(target=ticker)
    t.start()
    time.sleep(0.01)
    start = len(ticks)
    r = ofl.render(scene_path("minimal.json"), spp=256, width=64, height=64)
    done.set()
    t.join()
    # Another Python thread kept running while the render held no GIL (about one tick per 2 ms).
    assert r.stats["render_seconds"] > 0.1
    assert len(ticks) - start > 0.25 * r.stats["render_seconds"] / 0.002
