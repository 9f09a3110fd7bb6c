"""ISETCam exchange from Python and the CLI: the exported scene's photons are the radiance times
lambda / (h c); Octave (Debian's, as a stand-in for MATLAB) loads the .mat and finds the same
photon sum, size, wavelengths and geometry; a spectrum .mat works where a CSV does."""
import os
import shutil
import subprocess

import numpy as np
import pytest

import oralfluor as ofl
from conftest import cli_json, run_cli, scene_path

H, C = 6.62607015e-34, 299792458.0


@pytest.fixture(scope="module")
def render(tmp_path_factory):
    d = tmp_path_factory.mktemp("iset")
    run_cli("render", scene_path("minimal.json"), "--spp", 2, "--width", 30, "--height", 20, "-o", d)
    return d


def expected_photons(img):
    lam = img.wavelengths * 1e-9
    return (img.radiance.astype(np.float64) * (lam / (H * C))).astype(np.float32)


def test_python_and_cli_export_the_same_scene(render, tmp_path):
    img = ofl.read_exr(str(render / "radiance.exr"))
    py = ofl.export_iset(img, str(tmp_path / "py.mat"), name="radiance")
    cli = cli_json("export-iset", render / "radiance.exr", "-o", tmp_path / "cli.mat")
    photons = expected_photons(img)
    assert py["photon_sum"] == pytest.approx(photons.astype(np.float64).sum(), rel=1e-12)
    assert cli["photon_sum"] == py["photon_sum"]
    assert cli["distance_m"] == py["distance_m"] == pytest.approx(0.3, rel=1e-3)  # the patch is 0.3 m away
    # 18 degrees vertical over 20 rows, 30 columns: horizontal 2 atan(1.5 tan 9 deg).
    assert cli["hfov_deg"] == pytest.approx(2 * np.degrees(np.arctan(1.5 * np.tan(np.radians(9)))), rel=1e-9)
    back = ofl.read_iset_scene(str(tmp_path / "cli.mat"))
    np.testing.assert_allclose(back.radiance, img.radiance, rtol=3e-7)


@pytest.mark.skipif(shutil.which("octave-cli") is None, reason="octave-cli not installed (.ci/install-deps.sh installs it)")
def test_octave_loads_the_exported_scene(render, tmp_path):
    img = ofl.read_exr(str(render / "radiance.exr"))
    mat = tmp_path / "scene.mat"
    run_cli("export-iset", render / "radiance.exr", "-o", mat)
    script = (f"load('{mat}'); p = scene.data.photons; "
              "printf('%s|%s|%d %d %d|%.17g|%.17g|%.17g|%.17g|%s|%.17g\\n', scene.type, class(p), size(p, 1), size(p, 2), "
              "size(p, 3), sum(double(p(:))), scene.wAngular, scene.distance, scene.spectrum.wave(end), "
              "scene.illuminant.type, sum(double(scene.illuminant.data.photons)));")
    p = subprocess.run(["octave-cli", "--no-gui", "--norc", "--quiet", "--eval", script], capture_output=True, text=True,
                       env=dict(os.environ, HOME=str(tmp_path)))
    assert p.returncode == 0, p.stderr
    line = [l for l in p.stdout.splitlines() if "|" in l][-1]
    typ, cls, dims, psum, hfov, dist, wmax, iltype, ilsum = line.split("|")
    assert typ == "scene" and cls == "single" and iltype == "illuminant"
    assert dims == "20 30 97"  # rows x cols x wavelengths (default bands: the whole grid, 350-830 nm)
    assert float(psum) == pytest.approx(expected_photons(img).astype(np.float64).sum(), rel=1e-12)
    assert float(hfov) == pytest.approx(2 * np.degrees(np.arctan(np.tan(np.radians(9)) * 1.5)), rel=1e-9)
    assert float(dist) == pytest.approx(0.3, rel=1e-3)
    assert float(wmax) == 830
    assert float(ilsum) > 0


def test_spectrum_mat_stands_where_a_csv_does(tmp_path):
    table = ofl.read_spectrum_file(os.path.join(os.path.dirname(scene_path()), "assets", "sensors", "MT9V024_RGB.csv"))
    names = list(table["columns"])
    ofl.write_spectrum_mat(str(tmp_path / "qe.mat"), table["nm"], [table["columns"][n] for n in names], names, "MT9V024")
    back = ofl.read_spectrum_file(str(tmp_path / "qe.mat"))
    assert list(back["columns"]) == names
    for n in names:
        np.testing.assert_array_equal(back["columns"][n], table["columns"][n])
    # In a scene: the LED SPD as a .mat renders exactly like the same spectrum inline.
    nm = np.arange(370.0, 441.0, 1.0)
    spd = np.exp(-0.5 * ((nm - 405) / 6.0) ** 2)
    ofl.write_spectrum_mat(str(tmp_path / "led.mat"), nm, [spd])
    a = ofl.Scene(scene_path("minimal.json")).set("/lights/0/spd", str(tmp_path / "led.mat"))
    b = ofl.Scene(scene_path("minimal.json")).set("/lights/0/spd", {"type": "points", "points": [[float(x), float(y)] for x, y in zip(nm, spd)]})
    ra = ofl.render(a, spp=1, width=16, height=16)
    rb = ofl.render(b, spp=1, width=16, height=16)
    np.testing.assert_array_equal(ra.radiance, rb.radiance)
    # A .mat whose data has no column: the error names the file, the variable and the scene entry.
    ofl.write_spectrum_mat(str(tmp_path / "led2.mat"), nm, [])
    with pytest.raises(ofl.InputError, match=r'led2\.mat: variable "data": has no columns .*named by .*/lights/0/spd'):
        ofl.render(ofl.Scene(scene_path("minimal.json")).set("/lights/0/spd", str(tmp_path / "led2.mat")), spp=1)


def test_oi_through_the_sensor_qe_gives_the_camera_electrons(render, tmp_path):
    # The exported optical image is the irradiance oralfluor's sensor integrates: summed with the
    # sensor's QE, pixel area, fill factor, exposure and band widths (what ISETCam's sensorCompute
    # does with a bare sensor) it gives simulate_camera's expected electrons.
    img = ofl.read_exr(render / "radiance.exr")
    cam_file = scene_path("cameras", "oraleye.json")
    summary = ofl.export_iset_oi(img, cam_file, tmp_path / "oi.mat")
    cli = cli_json("export-iset", render / "radiance.exr", "--camera", cam_file, "-o", tmp_path / "cli_oi.mat")
    assert cli["photon_sum"] == summary["photon_sum"] and cli["kind"] == "oi"
    oi = ofl.read_mat(tmp_path / "oi.mat")["oi"]
    assert oi["type"] == "opticalimage" and oi["optics"]["model"] == "skip"
    photons = np.asarray(oi["data"]["photons"], dtype=np.float64)
    wave = np.ravel(oi["spectrum"]["wave"])
    np.testing.assert_array_equal(wave, img.wavelengths)
    assert photons.shape == img.radiance.shape
    # ISETCam's oi width 2 f tan(wAngular / 2) is one 6 um pixel per column.
    width = 2 * oi["optics"]["focalLength"] * np.tan(np.radians(oi["wAngular"]) / 2)
    assert width == pytest.approx(img.width * 6e-6, rel=1e-12)
    shot = ofl.simulate_camera(img, cam_file, noise=False)
    qe_file = ofl.read_spectrum_file(os.path.join(os.path.dirname(cam_file), "..", "..", "assets", "sensors", "MT9V024_RGB.csv"))
    dl = img.band_hi - img.band_lo
    k = (6e-6) ** 2 * 0.9 * shot.metadata["exposure_s"]
    for c, col in enumerate("rgb"):
        qe = np.interp(wave, qe_file["nm"], qe_file["columns"][col], left=0, right=0)
        e = k * (photons * (qe * dl)).sum(axis=2)
        ref = shot.electrons[..., c].astype(np.float64)
        # The oi holds band values: QE at the band centre times the band mean of T lambda stands for the
        # band integral of T QE lambda. Summed over the image that agrees to 0.5 %; pixel by pixel
        # to a few % where the filters' edges cross a band (how much depends on the pixel's spectrum).
        assert e.sum() == pytest.approx(ref.sum(), rel=5e-3), col
        lit = ref > 0.05 * ref.max()
        np.testing.assert_allclose(e[lit], ref[lit], rtol=0.05)
