"""Tables and pictures of benchmarks/dark_spot_sizes.sh (docs/layered-tissue.md, "Lesion size").

Reads <out>/<nm>/<transport>/d<d>/chroma_<material>.json (oralfluor chroma --json) and the radiance
EXRs; writes <out>/sizes.md, <out>/sizes.png (contrast and lesion-vs-blood distance against the
diameter) and <out>/edge_profile.png (fluorescence across the lesion's edge).
"""
import json
import math
import sys

import numpy as np

out, root = sys.argv[1], sys.argv[2]
LEDS = (385, 405, 450)
DIAMETERS = (1, 2, 3, 5, 10)
TRANSPORTS = ("spatial", "table")


def stats(nm, transport, d, material):
    try:
        s = json.load(open(f"{out}/{nm}/{transport}/d{d}/chroma_{material}.json"))["stats"]
    except (OSError, KeyError, ValueError):
        return None
    if not s.get("cells_used"):
        return None
    c = s["covariance"]
    return {"n": s["cells_used"], "r": s["mean"]["r"], "g": s["mean"]["g"], "I": sum(s["mean_rgb_dn"]),
            "cov": [[c["rr"], c["rg"]], [c["rg"], c["gg"]]]}


def mahal(a, b, cov):
    dr, dg = a["r"] - b["r"], a["g"] - b["g"]
    (p, q), (_, s) = cov
    det = p * s - q * q
    return math.sqrt(max(0.0, (s * dr * dr - 2 * q * dr * dg + p * dg * dg) / det)) if det > 0 else float("nan")


rows = {}
for nm in LEDS:
    for t in TRANSPORTS:
        for d in DIAMETERS:
            H, L, B = (stats(nm, t, d, m) for m in ("tongue_healthy", "dysplasia", "blood_spot"))
            if not (H and L and B):
                rows[(nm, t, d)] = None
                continue
            se = [[L["cov"][i][j] / L["n"] + B["cov"][i][j] / B["n"] for j in range(2)] for i in range(2)]
            dist, apart = mahal(L, B, H["cov"]), mahal(L, B, se)
            rows[(nm, t, d)] = {"cells": (L["n"], B["n"]), "lesion": L["I"] / H["I"], "blood": B["I"] / H["I"],
                                "dr": L["r"] - B["r"], "dg": L["g"] - B["g"], "dist": dist, "apart": apart,
                                "told": apart >= 3.0 and dist >= 1.0}

md = ["| LED | transport | diameter | cells (lesion, blood) | lesion / healthy | blood spot / healthy | "
      "lesion - blood (r, g) | distance (healthy s.d.) | means apart (s.e.) | told apart |",
      "|---|---|---|---|---|---|---|---|---|---|"]
for nm in LEDS:
    for t in TRANSPORTS:
        for d in DIAMETERS:
            r = rows[(nm, t, d)]
            if r is None:
                md.append(f"| {nm} nm | {t} | {d} mm | too few cells | | | | | | |")
                continue
            md.append(f"| {nm} nm | {t} | {d} mm | {r['cells'][0]}, {r['cells'][1]} | {r['lesion']:.2f} | {r['blood']:.2f} | "
                      f"{r['dr']:+.3f}, {r['dg']:+.3f} | {r['dist']:.2f} | {r['apart']:.1f} | {'yes' if r['told'] else 'no'} |")
md.append("")
md.append("| LED | smallest diameter told apart, spatial | position-free |")
md.append("|---|---|---|")
for nm in LEDS:
    best = {}
    for t in TRANSPORTS:
        told = [d for d in DIAMETERS if rows[(nm, t, d)] and rows[(nm, t, d)]["told"]]
        best[t] = f"{min(told)} mm" if told else "none of 1-10 mm"
    md.append(f"| {nm} nm | {best['spatial']} | {best['table']} |")
open(f"{out}/sizes.md", "w").write("\n".join(md) + "\n")
print("\n".join(md))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
colours = {385: "tab:purple", 405: "tab:blue", 450: "tab:cyan"}
for nm in LEDS:
    for t, ls in (("spatial", "-"), ("table", ":")):
        ds = [d for d in DIAMETERS if rows[(nm, t, d)]]
        if not ds:
            continue
        axes[0].plot(ds, [rows[(nm, t, d)]["lesion"] for d in ds], ls, marker="o", c=colours[nm], label=f"{nm} nm lesion, {t}")
        axes[0].plot(ds, [rows[(nm, t, d)]["blood"] for d in ds], ls, marker="s", c=colours[nm], alpha=0.6)
        axes[1].plot(ds, [rows[(nm, t, d)]["dist"] for d in ds], ls, marker="o", c=colours[nm], label=f"{nm} nm, {t}")
axes[0].set_xscale("log")
axes[0].set_xlabel("diameter (mm)")
axes[0].set_ylabel("intensity R+G+B / healthy tongue (circles lesion, squares blood spot)")
axes[0].legend(fontsize=7)
axes[1].set_xscale("log")
axes[1].axhline(1.0, c="0.5", lw=0.8)
axes[1].set_xlabel("diameter (mm)")
axes[1].set_ylabel("lesion vs blood spot, (r, g) distance in healthy s.d.")
axes[1].legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/sizes.png", dpi=110)

# Fluorescence across the lesion's edge: the image row through the lesion's centre.
import oralfluor as ofl  # noqa: E402

scene = json.load(open(f"{root}/scenes/dark_spot_spatial_405.json"))
cam = scene["camera"]
centre = np.array(scene["materials"]["tongue"]["regions"][0]["sphere"]["center_m"])
pos, look, up = np.array(cam["position"]), np.array(cam["look_at"]), np.array(cam["up"])
fwd = (look - pos) / np.linalg.norm(look - pos)
right = np.cross(fwd, up)
right /= np.linalg.norm(right)
upv = np.cross(right, fwd)
fig, axes = plt.subplots(1, 2, figsize=(11, 4))
for ax, d in zip(axes, (2, 5)):
    for t, ls in (("spatial", "-"), ("table", ":")):
        try:
            img = ofl.read_exr(f"{out}/405/{t}/d{d}/radiance.exr")
        except Exception:
            continue
        fl = np.asarray(img.fluorescence)
        wl = np.asarray(img.wavelengths)
        H, W = fl.shape[:2]
        v = centre - pos
        th = math.tan(math.radians(cam["fov_deg"] / 2))
        x = (np.dot(v, right) / np.dot(v, fwd) / (th * W / H) + 1) / 2 * W
        y = (1 - np.dot(v, upv) / np.dot(v, fwd) / th) / 2 * H
        row = fl[int(round(y)), :, (wl >= 480) & (wl <= 700)].sum(-1)
        xs = np.arange(W) - x
        sel = np.abs(xs) < 60
        ax.plot(xs[sel], row[sel], ls, label=t)
    ax.set_title(f"405 nm, lesion of {d} mm: fluorescence 480-700 nm along the image row through its centre", fontsize=8)
    ax.set_xlabel("pixels from the lesion's centre (about 0.15 mm each)")
    ax.set_ylabel("fluorescence radiance (W sr^-1 m^-2 nm^-1, summed over bands)")
    ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/edge_profile.png", dpi=110)
print(f"wrote {out}/sizes.md, {out}/sizes.png, {out}/edge_profile.png")
