"""`oralfluor view` in headless Chromium (Debian's, driven over the DevTools pipe, chromium_cdp.py):
the page loads from file:// with no error and asks for nothing but itself; a real mouse click on a
pixel shows the spectrum the EXR holds there (radiance and fluorescence, to float16 precision); a
dragged rectangle gives the region's mean, standard deviation and (r, g) chromaticity that numpy
computes from the EXR and from oralfluor's own sRGB conversion; two images share one cursor; the
camera's electrons.exr and raw.tiff show their channels; a decimated page shows block means."""
import json
import os

import numpy as np
import pytest

import oralfluor as ofl
from chromium_cdp import Browser
from conftest import run_cli, scene_path

HALF_REL = 2.0 ** -11  # float16 rounding of value / channel maximum


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("view")
    run_cli("render", scene_path("minimal.json"), "--spp", 2, "--seed", 3, "--width", 40, "--height", 30, "-o", d)
    run_cli("camera", d / "radiance.exr", "--camera", scene_path("cameras", "oraleye.json"), "--seed", 1, "-o", d / "cam")
    return d


@pytest.fixture(scope="module")
def browser():
    with Browser() as b:
        yield b


def open_view(browser, outputs, name, *files, extra=()):
    html = outputs / name
    p = run_cli("view", *files, "-o", html, *extra)
    assert "wrote" in p.stdout
    text = html.read_text()
    for external in ('src="http', 'href="http', "url(http", "@import", 'src="//'):
        assert external not in text
    page = browser.open(html.as_uri())
    assert page.evaluate("document.body.dataset.ready") == "1", page.errors
    return page


def panel_point(page, index, x, y):
    """CSS coordinates of the centre of image pixel (x, y) on panel `index`."""
    r = page.evaluate(f"(() => {{ const im = oflView.images[{index}], b = im.over.getBoundingClientRect();"
                      f" return [b.left, b.top, b.width, b.height, im.m.width, im.m.height]; }})()")
    return r[0] + (x + 0.5) * r[2] / r[4], r[1] + (y + 0.5) * r[3] / r[5]


def close(shown, expected, scale):
    """float16 of value / scale, decoded: within half an ulp of the value, or of the smallest normal."""
    shown, expected = np.asarray(shown, float), np.asarray(expected, float)
    tol = np.maximum(np.maximum(np.abs(expected) * HALF_REL, 6.2e-5 * np.asarray(scale)) * 1.01, 1e-30)
    return np.all(np.abs(shown - expected) <= tol), np.max(np.abs(shown - expected) / tol)


def test_click_shows_the_exr_spectrum_and_a_region_its_statistics(browser, outputs):
    img = ofl.read_exr(outputs / "radiance.exr")
    page = open_view(browser, outputs, "one.html", outputs / "radiance.exr")
    assert page.errors == []
    assert all(u.startswith(("file:", "data:")) for u in page.requests), page.requests
    scale = np.abs(img.radiance).max(axis=(0, 1))
    fscale = np.abs(img.fluorescence).max(axis=(0, 1))
    for x, y in [(25, 17), (3, 2)]:
        page.click(*panel_point(page, 0, x, y))
        row = json.loads(page.evaluate("document.getElementById('readout').dataset.rows"))[0]
        assert (row["x"], row["y"]) == (x, y)
        ok, worst = close(row["values"], img.radiance[y, x], scale)
        assert ok, worst
        ok, worst = close(row["fluorescence"], img.fluorescence[y, x], fscale)
        assert ok, worst
    assert img.radiance[17, 25].max() > 10 * img.radiance[17, 25].min() + 1e-12  # a spectrum with shape, not flat
    # A dragged rectangle from pixel (5, 4) to (20, 14): columns 5..20, rows 4..14 inclusive.
    page.drag(*panel_point(page, 0, 5, 4), *panel_point(page, 0, 20, 14))
    stats = json.loads(page.evaluate("document.getElementById('region').dataset.stats"))[0]
    x0, y0, w, h = stats["rect"]
    assert (x0, y0) == (5, 4) and 15 <= w <= 16 and 10 <= h <= 11
    block = img.radiance[y0:y0 + h, x0:x0 + w].reshape(-1, img.radiance.shape[2]).astype(float)
    assert stats["n"] == block.shape[0]
    np.testing.assert_allclose(stats["mean"], block.mean(axis=0), rtol=2 * HALF_REL, atol=1e-4 * scale.max())
    np.testing.assert_allclose(stats["std"], block.std(axis=0, ddof=1), rtol=0.01, atol=1e-4 * scale.max())
    rgb = img.srgb()[y0:y0 + h, x0:x0 + w].reshape(-1, 3).mean(axis=0)  # the module's CIE 1931 -> sRGB
    assert stats["colour"]["r"] == pytest.approx(rgb[0] / rgb.sum(), abs=2e-3)
    assert stats["colour"]["g"] == pytest.approx(rgb[1] / rgb.sum(), abs=2e-3)
    assert page.errors == []


def test_two_images_share_the_cursor_and_camera_outputs_show_their_channels(browser, outputs):
    shot = ofl.simulate_camera(outputs / "radiance.exr", scene_path("cameras", "oraleye.json"), noise=False)
    page = open_view(browser, outputs, "two.html", outputs / "radiance.exr", outputs / "cam" / "electrons.exr")
    page.mouse("mouseMoved", *panel_point(page, 0, 30, 12))  # hover over the left image only
    rows = json.loads(page.evaluate("document.getElementById('readout').dataset.rows"))
    assert [(r["image"], r["x"], r["y"]) for r in rows] == [(0, 30, 12), (1, 30, 12)]
    e = shot.electrons[12, 30]
    ok, worst = close(rows[1]["values"], e, shot.electrons.max(axis=(0, 1)))
    assert ok, worst
    assert rows[1]["r"] == pytest.approx(e[0] / e.sum(), abs=1e-3)
    # raw.tiff: one R, mean G, B per 2x2 cell, above black.
    raw = ofl.read_raw(outputs / "cam" / "raw.tiff")
    page = open_view(browser, outputs, "raw.html", outputs / "cam" / "raw.tiff")
    page.click(*panel_point(page, 0, 7, 5))
    row = json.loads(page.evaluate("document.getElementById('readout').dataset.rows"))[0]
    cell = raw["raw"][10:12, 14:16].astype(float) - raw["metadata"]["black_level_dn"]
    cfa = raw["metadata"]["cfa_pattern"]
    want = [np.mean([cell[k // 2, k % 2] for k in range(4) if cfa[k] == c]) for c in "RGB"]
    np.testing.assert_allclose(row["values"], want, rtol=HALF_REL * 1.01, atol=1e-9)
    assert page.errors == []


def test_a_decimated_page_shows_block_means(browser, outputs):
    img = ofl.read_exr(outputs / "radiance.exr")
    h, w, b = img.radiance.shape
    page = open_view(browser, outputs, "small.html", outputs / "radiance.exr", extra=("--max-values", (w * h * b) // 4))
    m = page.evaluate("oflView.images[0].m")
    assert m["k"] == 2 and any("2 x 2 pixel means" in n for n in m["notes"])
    page.click(*panel_point(page, 0, 13, 9))  # in the block of pixels 12..13 x 8..9
    row = json.loads(page.evaluate("document.getElementById('readout').dataset.rows"))[0]
    block = img.radiance[8:10, 12:14].astype(float).mean(axis=(0, 1))
    ok, worst = close(row["values"], block, np.abs(img.radiance).max(axis=(0, 1)))
    assert ok, worst


def test_bad_input_is_one_line_and_exit_2(outputs, tmp_path):
    (tmp_path / "x.exr").write_bytes(b"not an exr")
    p = run_cli("view", tmp_path / "x.exr", "-o", tmp_path / "v.html", check=False)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "x.exr" in p.stderr
    assert not (tmp_path / "v.html").exists()
    p = run_cli("view", outputs / "radiance.exr", outputs / "radiance.exr", outputs / "radiance.exr", "-o",
                tmp_path / "v.html", check=False)
    assert p.returncode == 2
