"""The camera from Python equals the CLI's: the same raw mosaic (read back from raw.tiff with
Pillow, independently of oralfluor's reader) and the same summary numbers; a camera dict equals
its file; ROI chromaticity equals `oralfluor chroma`."""
import json
import os

import numpy as np
import pytest

import oralfluor as ofl
from conftest import cli_json, run_cli, scene_path

CAMERA = scene_path("cameras", "oraleye.json")


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    d = tmp_path_factory.mktemp("cam")
    run_cli("render", scene_path("minimal.json"), "--spp", 2, "--seed", 5, "--width", 48, "--height", 36, "-o", d)
    return d


def test_raw_equals_cli_raw_tiff(rendered):
    out = rendered / "cli"
    summary = cli_json("camera", rendered / "radiance.exr", "--camera", CAMERA, "--seed", 11, "-o", out)
    img = ofl.read_exr(str(rendered / "radiance.exr"))
    shot = ofl.simulate_camera(img, ofl.Camera(CAMERA), seed=11, threads=2)
    from PIL import Image  # Debian's python3-pil (a dependency of python3-matplotlib)
    tiff = np.array(Image.open(out / "raw.tiff"))
    assert tiff.dtype == np.uint16 and tiff.shape == (36, 48)
    assert shot.raw.max() > shot.black_level + 10  # signal above black, not a dark frame
    np.testing.assert_array_equal(shot.raw, tiff)
    np.testing.assert_array_equal(shot.raw, ofl.read_raw(str(out / "raw.tiff"))["raw"])
    for c in "RGB":
        assert shot.summary["channels"][c] == summary["channels"][c]
    # Different seed, different noise: the comparison above can fail.
    other = ofl.simulate_camera(img, ofl.Camera(CAMERA), seed=12)
    assert not np.array_equal(other.raw, shot.raw)


def test_expected_electrons_match_the_cli_means(rendered):
    summary = cli_json("camera", rendered / "radiance.exr", "--camera", CAMERA, "--noise", "off", "-o", rendered / "nf")
    shot = ofl.simulate_camera(ofl.read_exr(str(rendered / "radiance.exr")), ofl.Camera(CAMERA), noise=False)
    e = shot.mosaic_electrons.astype(np.float64)
    cfa = shot.cfa
    ys, xs = np.mgrid[0:e.shape[0], 0:e.shape[1]]
    colour = np.array([[cfa[0], cfa[1]], [cfa[2], cfa[3]]])[ys % 2, xs % 2]
    for c in "RGB":
        assert e[colour == c].mean() == pytest.approx(summary["channels"][c]["mean_expected_electrons"], rel=1e-6)
        # The per-channel planes hold each colour's electrons; at the pixel's own colour they equal the mosaic.
        k = "RGB".index(c)
        np.testing.assert_allclose(shot.electrons[..., k][colour == c] + shot.dark_electrons, e[colour == c], rtol=1e-6)


def test_camera_from_dict_equals_file(rendered):
    img = ofl.read_exr(str(rendered / "radiance.exr"))
    doc = json.load(open(CAMERA))
    doc["sensor"]["qe"]["file"] = os.path.join(os.path.dirname(CAMERA), doc["sensor"]["qe"]["file"])
    a = ofl.simulate_camera(img, ofl.Camera(doc), seed=4)
    b = ofl.simulate_camera(img, ofl.Camera(CAMERA), seed=4)
    np.testing.assert_array_equal(a.raw, b.raw)
    doc["sensor"]["exposure_s"] *= 2
    brighter = ofl.simulate_camera(img, ofl.Camera(doc), seed=4, noise=False)
    dimmer = ofl.simulate_camera(img, ofl.Camera(CAMERA), seed=4, noise=False)
    assert brighter.electrons.mean() == pytest.approx(2 * dimmer.electrons.mean(), rel=1e-6)
    doc["sensor"]["cfa"] = "RGBW"
    with pytest.raises(ofl.InputError, match=r"/sensor/cfa"):
        ofl.Camera(doc)


def test_roi_chromaticity_equals_cli_chroma(rendered):
    out = rendered / "chroma"
    cli_json("camera", rendered / "radiance.exr", "--camera", CAMERA, "--seed", 2, "-o", out)
    chroma = cli_json("chroma", out / "raw.tiff", "--roi", "8,6,24,20", "-o", out)
    stats = ofl.roi_chromaticity(ofl.read_raw(str(out / "raw.tiff")), roi=(8, 6, 24, 20))
    assert stats["cells_used"] == chroma["stats"]["cells_used"] > 0
    assert stats["mean"] == chroma["stats"]["mean"]
    assert stats["covariance"] == chroma["stats"]["covariance"]
    assert stats["rg"].shape == (stats["cells_used"], 2)
    assert stats["rg"][:, 0].mean() == pytest.approx(stats["mean"]["r"], rel=1e-12)
