"""`oralfluor view` on a large cube: how long Chromium takes to open the page, and the README's
screenshot of the viewer.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/view_load.py build/oralfluor out/view_bench [--screenshot docs/images/view/view.png]

1. A 640 x 480 x 87 cube (a synthetic spectral image with a fluorescence layer and a material
   plane, written with oralfluor.write_exr) through `oralfluor view` at the default --max-values,
   opened 3 times in headless Chromium (fresh tab each time): the page's own clock when it is ready
   (performance.now(), from navigation start) and the wall time to the load event, page size.
2. With --screenshot: the OralEye-like 385 nm mouth scene (320 x 240, 16 spp) and its camera
   electrons side by side, materials overlaid, a pixel on the tongue hovered and a region dragged,
   captured as PNG.
"""
import argparse
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "python", "tests"))
import oralfluor as ofl  # noqa: E402
from chromium_cdp import Browser  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def synthetic_cube(path, h=480, w=640, bands=87):
    rng = np.random.default_rng(1)
    wl = np.linspace(400, 830, bands)
    yy, xx = np.mgrid[0:h, 0:w]
    base = (0.2 + 0.8 * xx[..., None] / w) * np.exp(-((wl - 450 - 200 * yy[..., None] / h) / 60) ** 2)
    radiance = (1e-3 * base * (1 + 0.05 * rng.standard_normal((h, w, bands)))).astype(np.float32).clip(0)
    fluo = (0.3 * radiance * (wl > 500)).astype(np.float32)
    material = ((xx // 160) + 4 * (yy // 240)).astype(np.float32)
    ofl.write_exr(path, ofl.SpectralImage(radiance, wl, fluorescence=fluo, aovs={"material": material},
                                          attributes={"oralfluor.materials": '["a","b","c","d","e","f","g","h"]'}))


def load_times(browser, html, n=3):
    out = []
    for _ in range(n):
        t = time.monotonic()
        page = browser.open("file://" + os.path.abspath(html))
        wall = time.monotonic() - t
        assert page.evaluate("document.body.dataset.ready") == "1", page.errors
        out.append((float(page.evaluate("document.body.dataset.loadMs")), wall * 1000, page.errors))
        page.close()
    return out


def screenshot(binary, out, png):
    run = lambda *a: subprocess.run([binary, *map(str, a)], check=True, capture_output=True)  # noqa: E731
    run("render", os.path.join(ROOT, "scenes", "oraleye_385.json"), "--spp", 16, "--width", 320, "--height", 240, "-o", out)
    run("camera", os.path.join(out, "radiance.exr"), "--camera", os.path.join(ROOT, "scenes", "cameras", "oraleye.json"),
        "--noise", "off", "-o", os.path.join(out, "cam"))
    html = os.path.join(out, "both.html")
    run("view", os.path.join(out, "radiance.exr"), os.path.join(out, "cam", "electrons.exr"), "-o", html)
    with Browser(width=1520, height=600) as b:
        page = b.open("file://" + os.path.abspath(html))
        page.evaluate("document.getElementById('overlay').click(); document.getElementById('logy').click()")
        r = page.evaluate("(() => { const b = oflView.images[0].over.getBoundingClientRect(); return [b.left, b.top, b.width, b.height]; })()")
        at = lambda u, v: (r[0] + u * r[2], r[1] + v * r[3])  # noqa: E731
        page.drag(*at(0.44, 0.62), *at(0.56, 0.72))
        page.mouse("mouseMoved", *at(0.50, 0.55))
        assert page.errors == [], page.errors
        open(png, "wb").write(page.screenshot())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("out")
    ap.add_argument("--screenshot")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    exr, html = os.path.join(a.out, "cube.exr"), os.path.join(a.out, "cube.html")
    synthetic_cube(exr)
    t = time.monotonic()
    p = subprocess.run([a.binary, "view", exr, "-o", html], check=True, capture_output=True, text=True)
    print(f"oralfluor view: {time.monotonic() - t:.2f} s: {p.stdout.strip()}")
    with Browser() as b:
        for ready_ms, wall_ms, errors in load_times(b, html):
            print(f"Chromium: page ready at {ready_ms:.0f} ms (performance.now), load event after {wall_ms:.0f} ms, "
                  f"{len(errors)} errors")
    if a.screenshot:
        screenshot(a.binary, a.out, a.screenshot)
        print("wrote", a.screenshot)


if __name__ == "__main__":
    main()
