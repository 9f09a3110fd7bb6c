"""Edge profiles of the blood-spot discs: volume walk, spatial transport, position-free table and the
3D Monte Carlo (its radiance along the normal, the reference, and its light within 37 degrees of the
normal, the reference before 2026-11-27), per ring, 440-460 nm and 540-580 nm.

Usage: python3 benchmarks/volume_edges.py RUNS_DIR OUT.png
RUNS_DIR holds `oralfluor bench <case> --json` results named <case>.json (benchmarks/lesion_results.sh
keeps them in benchmarks/results.d/lesion_runs): volume_lesion_blood_spot_<a> and
spatial_lesion_blood_spot_<a> for a = 1mm and 5mm.
"""
import json
import os
import sys

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(runs, out):
    sizes = ["1mm", "5mm"]
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharey=True)
    for col, a in enumerate(sizes):
        vol = json.load(open(os.path.join(runs, f"volume_lesion_blood_spot_{a}.json")))["extra"]
        sp_path = os.path.join(runs, f"spatial_lesion_blood_spot_{a}.json")
        sp = json.load(open(sp_path))["extra"] if os.path.exists(sp_path) else None
        edges = vol["ring_edges_mm"]
        mid = [0.5 * (edges[k] + edges[k + 1]) for k in range(len(edges) - 1)]
        for row, (b, name) in enumerate([(0, "440-460 nm"), (1, "540-580 nm")]):
            ax = axes[row][col]
            mc = vol["forward_mc"]
            ax.errorbar(mid, mc["contrast"][b], yerr=mc["se"][b], fmt="o", color="black", ms=3, label="Monte Carlo, along the normal")
            if "within_37_degrees" in mc:
                w = mc["within_37_degrees"]
                ax.errorbar(mid, w["contrast"][b], yerr=w["se"][b], fmt="s", color="gray", mfc="none", ms=3,
                            label="Monte Carlo, within 37 deg")
            ax.errorbar(mid, vol["volume"]["contrast"][b], yerr=vol["volume"]["se"][b], fmt="-", color="tab:red", label="volume walk")
            if sp is not None:
                ax.plot(mid, sp["spatial"]["contrast"][b], "-", color="tab:blue", label="spatial")
            ax.plot(mid, vol["position_free"]["contrast"][b], ":", color="tab:green", label="position-free")
            ax.axvline(float(a[:-2]), color="k", lw=0.5)
            ax.set_title(f"blood spot, radius {a[:-2]} mm, {name}")
            ax.set_xlabel("distance from the centre (mm)")
            if col == 0:
                ax.set_ylabel("reflectance / healthy")
            if row == 0 and col == 0:
                ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
