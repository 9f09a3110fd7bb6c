#!/usr/bin/env python3
"""Hand a render to ISETCam and bring an ISETCam sensor back, from Python.

1. Render a small fluorescent patch and export it as an ISETCam scene (scene.mat: photons, wave,
   wAngular, distance, the LED illuminant), the file ISETCam's sceneGet/oiCompute/sensorCompute take.
2. Write an ISETCam sensor .mat the way sensorCreate lays it out (pixel, color.filterSpectra,
   cfa.pattern, noise in volts) from the shipped MT9V024 QE, and use it as an oralfluor camera.
3. If Octave is installed, load scene.mat there and compare its photon sum with Python's.
Plots the exported photons at three wavelengths and the raw image through the imported sensor.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/iset_exchange.py --out out/iset
"""
import argparse
import os
import shutil
import subprocess

import numpy as np

import oralfluor as ofl

ROOT = os.environ.get("OFL_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/iset")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # 1. Render and export.
    scene = ofl.Scene(os.path.join(ROOT, "scenes", "minimal.json"))
    scene.set("/camera/resolution", [96, 72]).set("/integrator/output_bands", {"min_nm": 380, "max_nm": 720, "step_nm": 10})
    r = ofl.render(scene, spp=16)
    summary = ofl.export_iset(r.image, os.path.join(args.out, "scene.mat"), name="oralfluor patch")
    print(f"scene.mat: {r.image.height} x {r.image.width} x {len(r.wavelengths)} photons, wAngular "
          f"{summary['hfov_deg']:.2f} deg, distance {summary['distance_m']:.3f} m, photon sum {summary['photon_sum']:.6g}")
    for w in summary["warnings"]:
        print("warning:", w)

    # 2. An ISETCam sensor: the spectral QE as an ISETCam colour-filter file, then a sensor struct.
    qe = ofl.read_spectrum_file(os.path.join(ROOT, "assets", "sensors", "MT9V024_RGB.csv"))
    names = list(qe["columns"])
    qe_mat = os.path.join(args.out, "MT9V024_qe.mat")
    ofl.write_spectrum_mat(qe_mat, qe["nm"], [qe["columns"][n] for n in names], names, "MT9V024 RGB QE (ISETCam)")
    camera_doc = {"name": "MT9V024 from an ISETCam colour-filter file",
                  "lens": {"f_number": 2.4}, "filters": [{"type": "longpass", "edge_nm": 475, "width_nm": 8, "od": 4}],
                  "sensor": {"pixel_pitch_um": 6.0, "cfa": "RGGB", "qe": {"file": qe_mat},
                             "exposure_s": 0.02, "system_gain_dn_per_e": 0.05, "full_well_e": 20000, "bit_depth": 10}}
    sensor_mat = os.path.join(args.out, "sensor.mat")
    octave = shutil.which("octave-cli")
    if octave:  # an ISETCam sensor struct written by Octave, field names as sensorCreate makes them
        script = (f"d = load('{qe_mat}'); s.name = 'MT9V024 (Octave)'; s.type = 'sensor'; "
                  "s.spectrum.wave = d.wavelength; s.color.filterSpectra = d.data; s.color.filterNames = d.filterNames; "
                  "s.color.irFilter = ones(size(d.wavelength)); s.cfa.pattern = [1 2; 2 3]; "
                  "s.pixel.width = 6e-6; s.pixel.height = 6e-6; s.pixel.widthGap = 0; s.pixel.heightGap = 0; "
                  "s.pixel.pdWidth = 5.5e-6; s.pixel.pdHeight = 5.5e-6; s.pixel.conversionGain = 5e-5; "
                  "s.pixel.voltageSwing = 1; s.pixel.darkVoltage = 5e-4; s.pixel.readNoise = 6e-4; "
                  "s.pixel.spectralQE = ones(size(d.wavelength)); s.sigmaGainFPN = 1; s.sigmaOffsetFPN = 4e-4; "
                  "s.analogGain = 1; s.analogOffset = 0; s.quantization.method = 'linear'; s.quantization.bits = 10; "
                  "s.integrationTime = 0.02; s.AE = 0; s.noiseFlag = 2; s.rows = 72; s.cols = 96; "
                  f"sensor = s; save('-v7', '{sensor_mat}', 'sensor');")
        subprocess.run([octave, "--no-gui", "--norc", "--quiet", "--eval", script], check=True, capture_output=True,
                       env=dict(os.environ, HOME=args.out))
        camera = ofl.Camera(sensor_mat)  # an ISETCam sensor .mat is a camera file
        cam_doc, notes = ofl.import_iset_sensor(sensor_mat)
        for n in notes:
            print("note:", n)
    else:
        camera = ofl.Camera(camera_doc)
    shot = ofl.simulate_camera(r.image, camera, seed=1)
    print(f"camera '{camera.name}': mean DN above black {float(shot.raw.mean()) - shot.black_level:.1f}")

    # 3. Octave reads the scene back.
    if octave:
        p = subprocess.run([octave, "--no-gui", "--norc", "--quiet", "--eval",
                            f"load('{os.path.join(args.out, 'scene.mat')}'); printf('%.17g\\n', sum(double(scene.data.photons(:))));"],
                           capture_output=True, text=True, env=dict(os.environ, HOME=args.out))
        print(f"Octave: photon sum {float(p.stdout.split()[-1]):.6g} (Python {summary['photon_sum']:.6g})")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    back = ofl.read_iset_scene(os.path.join(args.out, "scene.mat"))
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.4))
    for ax, nm in zip(axes[:3], (450, 530, 630)):
        b = int(np.argmin(abs(back.wavelengths - nm)))
        photons = back.radiance[:, :, b] * back.wavelengths[b] * 1e-9 / (6.62607015e-34 * 299792458.0)
        im = ax.imshow(photons, cmap="magma")
        ax.set_title(f"scene.data.photons at {back.wavelengths[b]:.0f} nm", fontsize=9)
        ax.axis("off")
        fig.colorbar(im, ax=ax, fraction=0.046, label="photons s$^{-1}$ sr$^{-1}$ m$^{-2}$ nm$^{-1}$")
    axes[3].imshow(shot.raw, cmap="gray")
    axes[3].set_title(f"raw mosaic through\n'{camera.name}'", fontsize=9)
    axes[3].axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "iset_exchange.png"), dpi=100)
    print("wrote", os.path.join(args.out, "iset_exchange.png"))


if __name__ == "__main__":
    main()
