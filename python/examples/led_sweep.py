#!/usr/bin/env python3
"""Sweep an LED parameter in a loop: the peak wavelength of the excitation LED, from deep violet up
toward the camera's 475 nm long-pass edge. For each LED: render a patch of tongue tissue with FAD (lit
obliquely, so the light falls off across it), run the OralEye-like camera with noise, and measure
the chromaticity over the whole patch: its mean and its spread (95 % ellipse), next to what the
reference-line construction predicts for that LED. Plots with matplotlib.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/led_sweep.py --out out/led_sweep
"""
import argparse
import json
import os

import numpy as np

import oralfluor as ofl

ROOT = os.environ.get("OFL_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def patch_scene(size_px, spp):
    """A 20 cm patch of tongue tissue (shipped reflectance + FAD) under one LED 10 cm away, off axis.
    Output bands 345-750 nm cover the LED, so excitation light leaking through the filter is counted."""
    return ofl.Scene({
        "format": "oralfluor-scene", "version": 1,
        "integrator": {"spp": spp, "seed": 1,
                       "wavelengths": {"min_nm": 340, "max_nm": 780, "step_nm": 5},
                       "output_bands": {"min_nm": 345, "max_nm": 750, "step_nm": 5}},
        "camera": {"position": [0, 0, 0.3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 18,
                   "resolution": [size_px, size_px]},
        "materials": {"tongue": {"type": "fluorescent",
                                 "reflectance": os.path.join(ROOT, "assets/spectra/tissue/tongue_reflectance.csv"),
                                 "fluorophores": [{"name": "FAD", "concentration": 0.05}]}},
        "geometry": [{"type": "quad", "center": [0, 0, 0], "u": [0.2, 0, 0], "v": [0, 0.2, 0], "material": "tongue"}],
        "lights": [{"spd": {"type": "gaussian", "peak_nm": 385, "fwhm_nm": 12}, "radiant_intensity_W_sr": 0.12,
                    "profile": {"half_angle_deg": 30}, "position": [0.06, 0, 0.1], "target": [0, 0, 0]}],
    })


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/led_sweep")
    ap.add_argument("--peaks", default="370,385,400,415,430,445,460", help="LED peak wavelengths, nm")
    ap.add_argument("--size", type=int, default=64, help="image size in pixels")
    ap.add_argument("--spp", type=int, default=16)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    camera = ofl.Camera(os.path.join(ROOT, "scenes/cameras/oraleye.json"))
    tongue = ofl.read_spectrum_file(os.path.join(ROOT, "assets/spectra/tissue/tongue_reflectance.csv"))
    reflectance = (tongue["nm"], tongue["columns"]["reflectance"])
    scene = patch_scene(args.size, args.spp)
    points = []
    for peak in [float(p) for p in args.peaks.split(",")]:
        scene.set("/lights/0/spd/peak_nm", peak)                      # the swept parameter
        r = ofl.render(scene, progress=False)
        shot = ofl.simulate_camera(r.image, camera, seed=1)
        stats = ofl.roi_chromaticity(shot)                            # the whole patch
        led = scene.excitation_spd()
        band_lo, band_hi = r.image.band_lo[0], r.image.band_hi[-1]
        pred = ofl.reference_lines(camera, led, reflectance=reflectance, fluorophores=["FAD"],
                                   concentrations=[0.0, 0.05], camera_range=(band_lo, band_hi))
        points.append({"peak_nm": peak, "stats": {k: stats[k] for k in ("mean", "covariance", "ellipse95", "cells_used")},
                       "predicted_rg": pred["lines"][0]["rg"][1], "tongue_rg": pred["tongue_rg"],
                       "mean_electrons": shot.summary["channels"]})
        a, b = stats["ellipse95"]["semi_axes"]
        print(f"LED {peak:5.1f} nm: mean r,g = ({stats['mean']['r']:.4f}, {stats['mean']['g']:.4f}), "
              f"predicted ({pred['lines'][0]['rg'][1][0]:.4f}, {pred['lines'][0]['rg'][1][1]:.4f}), "
              f"95 % ellipse {a:.4f} x {b:.4f}")
    with open(os.path.join(args.out, "led_sweep.json"), "w") as f:
        json.dump(points, f, indent=1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from oralfluor.plot import plot_ellipse
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.6))
    colours = plt.cm.viridis(np.linspace(0, 0.9, len(points)))
    for p, c in zip(points, colours):
        plot_ellipse(ax1, p["stats"], colour=c, label=f"{p['peak_nm']:.0f} nm")
        ax1.plot(*p["predicted_rg"], "x", color=c, ms=9)
    ax1.set_xlabel("r")
    ax1.set_ylabel("g")
    ax1.set_title("patch chromaticity (95 % ellipse, + mean; x predicted)")
    ax1.legend(fontsize=8, title="LED peak")
    ax1.grid(True, lw=0.3)
    peaks = [p["peak_nm"] for p in points]
    ax2.plot(peaks, [p["stats"]["ellipse95"]["semi_axes"][0] for p in points], "o-", label="major semi-axis")
    ax2.plot(peaks, [p["stats"]["ellipse95"]["semi_axes"][1] for p in points], "s-", label="minor semi-axis")
    ax2.set_xlabel("LED peak wavelength (nm)")
    ax2.set_ylabel("chromaticity spread over the patch")
    ax2.set_title("spread of r,g (shot and read noise, light fall-off)")
    ax2.grid(True, lw=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "led_sweep.png"), dpi=110)
    print("wrote", os.path.join(args.out, "led_sweep.png"))


if __name__ == "__main__":
    main()
