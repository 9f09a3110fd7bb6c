"""Every Python entry point checks its arguments as the CLI checks its options: a bad value raises
oralfluor.InputError naming the argument (never a crash, an abort inside Embree, an all-zero image
or a raw pybind11 TypeError that prints the whole scene); numpy scalars and arrays stand wherever a
number or a list does; paths are str or pathlib.Path everywhere; a render result stands where an
image does; arrays are read-only views, not copies; diagnose takes threads and a progress callback
and stops on Ctrl-C; importing the module into another Python says which Python it was built for."""
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import threading

import numpy as np
import pytest

import oralfluor as ofl
from conftest import ROOT, run_cli, scene_path

MINIMAL = scene_path("minimal.json")
CAMERA = scene_path("cameras", "oraleye.json")


def tiny(**kw):
    args = dict(spp=1, seed=1, width=8, height=6, threads=1)
    args.update(kw)
    return ofl.render(MINIMAL, **args)


@pytest.mark.parametrize("arg, value, message", [
    ("width", 0, "width: value 0 not in range 1 to 16384"),        # was SIGFPE
    ("height", 0, "height: value 0 not in range 1 to 16384"),      # was an Embree assertion abort
    ("width", -4, "width: value -4 not in range 1 to 16384"),      # was a negative byte count
    ("width", 16385, "width: value 16385 not in range 1 to 16384"),
    ("spp", 0, "spp: value 0 not in range 1 to 16777216"),          # was an all-zero image
    ("spp", -3, "spp: value -3 not in range 1 to 16777216"),
    ("spp", "8", "spp: expected an integer in range 1 to 16777216, got str '8'"),
    ("spp", 2.5, "spp: expected an integer"),
    ("spp", True, "spp: expected an integer"),
    ("seed", -1, "seed: value -1 not in range 0 to 18446744073709551615"),
    ("seed", 2 ** 64, "seed: value 18446744073709551616 not in range 0 to 18446744073709551615"),
    ("seed", "7", "seed: expected an integer"),
    ("threads", -1, "threads: value -1 not in range 0 to 1024"),
    ("threads", 5000, "threads: value 5000 not in range 0 to 1024"),
    ("aovs", "yes", "aovs: expected True or False, got str"),
    ("progress", 5, "progress: expected True, False, None or a callable"),
])
def test_render_arguments_are_checked_as_the_cli_checks_them(arg, value, message):
    with pytest.raises(ofl.InputError) as e:
        tiny(**{arg: value})
    assert str(e.value).startswith(message), str(e.value)
    assert e.value.field == arg
    assert len(str(e.value)) < 200 and "\n" not in str(e.value)  # one line, not the scene dict


def test_cli_answers_the_same_ranges():
    # The bounds above are the CLI's own (the two sides must not drift apart).
    assert "0 not in range 1 to 16384" in run_cli("render", MINIMAL, "--width", 0, check=False).stderr
    assert "0 not in range 1 to 16777216" in run_cli("render", MINIMAL, "--spp", 0, check=False).stderr
    assert "5000 not in range 0 to 1024" in run_cli("--threads", 5000, "fluorophores", check=False).stderr


def test_numpy_scalars_and_paths_stand_for_numbers_and_names(tmp_path):
    ref = tiny()
    a = ofl.render(pathlib.Path(MINIMAL), spp=np.int64(1), seed=np.uint64(1), width=np.int32(8), height=np.int16(6),
                   threads=np.int64(1))
    np.testing.assert_array_equal(a.radiance, ref.radiance)
    # numpy values inside a scene document (a sweep over np.arange), as the same plain numbers.
    scene = ofl.Scene(MINIMAL).set("/integrator/spp", np.int64(1)).set("/camera/resolution", np.array([8, 6]))
    scene.set("/lights/0/spd/peak_nm", np.float64(450.0))
    plain = ofl.Scene(MINIMAL).set("/integrator/spp", 1).set("/camera/resolution", [8, 6]).set("/lights/0/spd/peak_nm", 450.0)
    np.testing.assert_array_equal(ofl.render(scene, seed=1).radiance, ofl.render(plain, seed=1).radiance)
    with pytest.raises(ofl.InputError, match=r"cannot be written as JSON: a object \(<object object") as e:
        ofl.render(ofl.Scene(MINIMAL).set("/integrator/spp", object()))
    assert "Traceback" not in str(e.value)
    # Paths as pathlib.Path, a render result where an image is expected.
    exr = tmp_path / "r.exr"
    ofl.write_exr(exr, ref)
    back = ofl.read_exr(exr)
    np.testing.assert_array_equal(back.radiance, ref.radiance)
    shot = ofl.simulate_camera(ref, CAMERA, seed=np.int64(3))          # a RenderResult and a camera path
    same = ofl.simulate_camera(exr, ofl.Camera(pathlib.Path(CAMERA)), seed=3)  # an EXR path and a Camera
    np.testing.assert_array_equal(shot.raw, same.raw)
    files = shot.write(tmp_path / "cam")
    assert ofl.read_raw(pathlib.Path(files["raw_tiff"]))["raw"].shape == (6, 8)
    stats = ofl.roi_chromaticity(pathlib.Path(files["raw_tiff"]), roi=np.array([0, 0, 8, 6]))
    assert stats["cells_used"] == 12


@pytest.mark.parametrize("call, message", [
    (lambda s: ofl.roi_chromaticity(s, roi=(0, 0, 9, 6)), "roi: value 9 not in range 1 to 8"),
    (lambda s: ofl.roi_chromaticity(s, roi=(0, 0, 1, 1)), "roi: holds no complete 2x2 CFA cell"),
    (lambda s: ofl.roi_chromaticity(s, roi=(-1, 0, 2, 2)), "roi: value -1 not in range 0 to 7"),
    (lambda s: ofl.roi_chromaticity(s, roi="0,0,2,2"), "roi: expected (x, y, w, h)"),
    (lambda s: ofl.roi_chromaticity(s, roi=(0, 0, 2)), "roi: expected four integers"),
    (lambda s: ofl.roi_chromaticity(s, mask=np.ones((2, 2), bool)), "mask: expected an array of the raw mosaic's shape"),
    (lambda s: ofl.roi_chromaticity(42), "camera_result: expected a CameraResult"),
    (lambda s: ofl.simulate_camera(s, CAMERA), "image: expected a SpectralImage (or a RenderResult), got CameraResult"),
    (lambda s: ofl.simulate_camera(tiny(), 42), "camera: expected a Camera, a camera file name or a camera dict"),
    (lambda s: ofl.simulate_camera(tiny(), CAMERA, noise="off"), "noise: expected True or False"),
    (lambda s: ofl.read_exr(42), "path: expected a file name (str or pathlib.Path), got int"),
    (lambda s: ofl.chromaticity(s.raw, "RGBW", 64, 1023), 'cfa: unknown CFA pattern "RGBW"'),
    (lambda s: ofl.chromaticity(s.raw, "RGGB", 64, 10), "white: must be above black"),
    (lambda s: ofl.fluorophores(grid=(350, 830)), "grid: expected three numbers"),
    (lambda s: ofl.fluorophore_eem("FAD", grid=(350, 830, 0)), "grid: value 0 not in range"),
    (lambda s: ofl.SpectralImage(np.zeros((2, 2)), [500]), "radiance: expected an array of shape (rows, cols, bands)"),
    (lambda s: ofl.SpectralImage(np.zeros((2, 2, 2)), [600, 500]), "wavelengths: must increase"),
    (lambda s: ofl.SpectralImage(np.full((1, 1, 1), np.nan), [500]), "radiance: holds NaN"),
    (lambda s: ofl.export_iset(tiny(), "x.mat", hfov_deg=0), "hfov_deg: value 0 not in range"),
    (lambda s: ofl.write_spectrum_mat("x.mat", [400, 500], [[1, 2, 3]]), "columns: each column needs as many values as nm"),
    (lambda s: ofl.diagnose(ROOT, ROOT, threads=-2), "threads: value -2 not in range 0 to 1024"),
    (lambda s: ofl.Scene(42), "scene: expected a Scene, a scene file name"),
    (lambda s: ofl.Scene(MINIMAL).get("/nope/0"), "/nope/0: no such field in the scene"),
    (lambda s: ofl.reference_lines(CAMERA, ([385, 390], [1, 1]), concentrations=[-1]), "concentrations: values must be >= 0"),
])
def test_other_entry_points_name_the_bad_argument(call, message):
    shot = ofl.simulate_camera(tiny(), CAMERA, seed=1)
    with pytest.raises(ofl.InputError) as e:
        call(shot)
    assert message in str(e.value), str(e.value)


def test_arrays_are_read_only_views_not_copies():
    r = tiny()
    a, b = r.radiance, r.radiance
    assert np.shares_memory(a, b) and np.shares_memory(r.image.radiance, a)
    assert not a.flags.writeable
    with pytest.raises(ValueError):
        a[0, 0, 0] = 1.0
    assert np.shares_memory(r.fluorescence, r.fluorescence) and np.shares_memory(r.aovs["depth"], r.aovs["depth"])
    shot = ofl.simulate_camera(r, CAMERA, seed=1)
    assert np.shares_memory(shot.raw, shot.raw) and np.shares_memory(shot.electrons, shot.electrons)
    assert not shot.mosaic_electrons.flags.writeable
    view = r.radiance
    del r  # the array keeps the image alive
    assert float(view.sum()) == pytest.approx(float(tiny().radiance.sum()))
    copy = view.copy()
    copy[0, 0, 0] = 5
    assert copy.flags.writeable


DIAGNOSE = (os.path.join(ROOT, "assets", "measurements", "camera_example"), scene_path("diagnose", "camera_example.json"))


def test_diagnose_takes_threads_and_reports_progress_and_stops():
    calls = []
    one = ofl.diagnose(*DIAGNOSE, threads=1, progress=lambda d, t, s: calls.append((d, t, s)))
    two = ofl.diagnose(*DIAGNOSE, threads=np.int64(2))
    one.pop("text"), two.pop("text")
    assert one == two  # the same report at any thread count
    steps = [c for c in calls if c[1] > 0]
    assert steps and all(0 < d <= t for d, t, _ in steps) and {s for _, _, s in steps} == {1, 2}
    # A callback that says stop ends the run with KeyboardInterrupt once the candidates in flight finish.
    seen = []
    with pytest.raises(KeyboardInterrupt, match="progress callback"):
        ofl.diagnose(*DIAGNOSE, threads=1, progress=lambda d, t, s: seen.append(d) or d < 1)
    assert seen and seen[-1] >= 1


def test_diagnose_stops_on_ctrl_c():
    seen, sent = [], []

    def progress(done, total, step):
        seen.append(step)
        if done >= 1 and not sent:
            sent.append(True)
            os.kill(os.getpid(), signal.SIGINT)  # what Ctrl-C sends
        return True

    with pytest.raises(KeyboardInterrupt):
        ofl.diagnose(*DIAGNOSE, threads=1, progress=progress)
    assert sent and max(seen) == 1  # stopped in the first cause step (a whole run goes on to later steps)
    full = []
    ofl.diagnose(*DIAGNOSE, threads=2, progress=lambda d, t, s: full.append(s))
    assert max(full) > 1


def test_another_python_is_told_which_python_the_module_is_for(tmp_path):
    # A copy of the package whose compiled core carries another interpreter's tag, as a module built
    # for Python 3.11 looks to Python 3.12: the import must name both.
    pkg = pathlib.Path(ofl.__file__).parent
    dst = tmp_path / "oralfluor"
    shutil.copytree(pkg, dst, ignore=shutil.ignore_patterns("__pycache__"))
    for so in dst.glob("_oralfluor*.so"):
        so.rename(dst / "_oralfluor.cpython-39-x86_64-linux-gnu.so")
    p = subprocess.run([sys.executable, "-c", "import oralfluor"], cwd=tmp_path, capture_output=True, text=True,
                       env=dict(os.environ, PYTHONPATH=str(tmp_path)))
    assert p.returncode != 0
    last = p.stderr.strip().splitlines()[-1]
    assert "was built for" in last and f"Python {sys.version.split()[0]}" in last and "Another Python" in last, last


def test_text_that_is_not_utf8_reads_without_a_decode_error(tmp_path):
    # A spectrum CSV whose header has a Latin-1 byte (a campaign's finding: UnicodeDecodeError).
    (tmp_path / "latin1.csv").write_bytes(b"wavelength_nm,\xb5W per nm\n400,1\n500,2\n")
    t = ofl.read_spectrum_file(tmp_path / "latin1.csv")
    assert list(t["columns"]) == ["\ufffdW per nm"]
    np.testing.assert_array_equal(t["columns"]["\ufffdW per nm"], [1, 2])
    img = ofl.SpectralImage(np.ones((1, 1, 1)), [500], attributes={"note": "ok"})
    ofl.write_exr(tmp_path / "a.exr", img)
    assert ofl.read_exr(tmp_path / "a.exr").attributes["note"] == "ok"
