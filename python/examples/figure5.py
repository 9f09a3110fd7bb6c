#!/usr/bin/env python3
"""Figure 5 of the OralEye paper (Farrell et al.) from Python: the chromaticity each fluorophore
adds to tongue tissue under the 385 nm light of scenes/oraleye_385.json, seen through the
OralEye-like camera (scenes/cameras/oraleye.json). The same lines `oralfluor chroma` draws.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/figure5.py --out out/figure5
"""
import argparse
import json
import os

import oralfluor as ofl

ROOT = os.environ.get("OFL_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/figure5", help="output folder")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # The figure in four lines: the scene's LED, the camera, the lines over the bands a render covers.
    scene = ofl.Scene(os.path.join(ROOT, "scenes", "oraleye_385.json"))
    camera = ofl.Camera(os.path.join(ROOT, "scenes", "cameras", "oraleye.json"))
    ref = ofl.reference_lines(camera, scene.excitation_spd(), camera_range=scene.band_range())

    with open(os.path.join(args.out, "figure5.json"), "w") as f:
        json.dump(ref, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from oralfluor.plot import plot_reference_lines
    fig, ax = plt.subplots(figsize=(6, 5.5))
    plot_reference_lines(ax, ref)
    ax.set_title("tongue + fluorophore, 385 nm LEDs, OralEye-like camera", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "figure5.png"), dpi=120)
    for line in ref["lines"]:
        print(f"{line['fluorophore']:16s} tongue ({line['rg'][0][0]:.4f}, {line['rg'][0][1]:.4f}) -> "
              f"pure ({line['pure_rg'][0]:.4f}, {line['pure_rg'][1]:.4f})")
    print("wrote", os.path.join(args.out, "figure5.png"))


if __name__ == "__main__":
    main()
