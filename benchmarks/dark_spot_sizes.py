"""Tables and pictures of benchmarks/dark_spot_sizes.sh (docs/layered-tissue.md, "Lesion size").

For each render <out>/<nm>/<transport>/d<d>/radiance.exr: the OralEye-like camera
(scenes/cameras/oraleye.json, with its noise) through the Python module, then (r, g) per 2x2 Bayer
cell (oralfluor.roi_chromaticity, as `oralfluor chroma` computes it) over three masks made from
the render's own AOVs: the lesion (aov.material = dysplasia), the blood spot (blood_spot), and the
healthy tongue in a ring 1-6 mm outside each disc's edge (surface points from aov.depth along each
camera ray). Writes <out>/sizes.md, <out>/sizes.png (contrast and lesion-vs-blood distance against
the diameter) and <out>/edge_profile.png (fluorescence against the distance from each disc's centre).
"""
import json
import math
import sys

import numpy as np

import oralfluor as ofl

out, root = sys.argv[1], sys.argv[2]
LEDS = (385, 405, 450)
DIAMETERS = (1, 2, 3, 5, 10)
TRANSPORTS = ("spatial", "table")
CAMERA = f"{root}/scenes/cameras/oraleye.json"


def surface_points(scene, img):
    """World position of the surface each pixel sees (pinhole camera, aov.depth = distance along the ray)."""
    cam = scene["camera"]
    pos, look, up = (np.array(cam[k], float) for k in ("position", "look_at", "up"))
    fwd = (look - pos) / np.linalg.norm(look - pos)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    H, W = img.height, img.width
    th = math.tan(math.radians(cam["fov_deg"] / 2))
    ys, xs = np.mgrid[0:H, 0:W]
    sx, sy = ((xs + 0.5) / W * 2 - 1) * th * W / H, (1 - (ys + 0.5) / H * 2) * th
    d = fwd + sx[..., None] * right + sy[..., None] * upv
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return pos + d * np.asarray(img.aovs["depth"])[..., None]


def masks(scene, img):
    names = json.loads(img.attributes["oralfluor.materials"])
    mat = np.asarray(img.aovs["material"])
    P = surface_points(scene, img)
    out = {}
    healthy = mat == names.index("tongue_healthy")
    for r in scene["materials"]["tongue"]["regions"]:
        name, c, rad = r["material"], np.array(r["sphere"]["center_m"]), r["sphere"]["radius_mm"] / 1000
        out[name] = mat == names.index(name)
        dist = np.linalg.norm(P - c, axis=-1)
        out["healthy_" + name] = healthy & (dist > rad + 0.001) & (dist < rad + 0.006)
    return out


def stats(cam, mask):
    try:
        s = ofl.roi_chromaticity(cam, mask=mask)
    except ofl.InputError:  # the region holds no complete 2x2 cell
        return None
    if s.get("cells_used", 0) < 3:
        return None
    c = s["covariance"]
    return {"n": s["cells_used"], "r": s["mean"]["r"], "g": s["mean"]["g"], "I": sum(s["mean_rgb_dn"]),
            "cov": [[c["rr"], c["rg"]], [c["rg"], c["gg"]]]}


def mahal(a, b, cov):
    dr, dg = a["r"] - b["r"], a["g"] - b["g"]
    (p, q), (_, s) = cov
    det = p * s - q * q
    return math.sqrt(max(0.0, (s * dr * dr - 2 * q * dr * dg + p * dg * dg) / det)) if det > 0 else float("nan")


def measure(nm, t, d):
    folder = f"{out}/{nm}/{t}/d{d}"
    try:
        scene = json.load(open(f"{folder}/scene.json"))
        img = ofl.read_exr(f"{folder}/radiance.exr")
    except (OSError, ValueError, ofl.InputError):
        return None
    cam = ofl.simulate_camera(img, CAMERA, seed=7)
    m = masks(scene, img)
    L, B = stats(cam, m["dysplasia"]), stats(cam, m["blood_spot"])
    HL, HB = stats(cam, m["healthy_dysplasia"]), stats(cam, m["healthy_blood_spot"])
    if not (L and B and HL and HB):
        return {"cells": (L["n"] if L else 0, B["n"] if B else 0)}
    healthy_cov = [[(HL["cov"][i][j] + HB["cov"][i][j]) / 2 for j in range(2)] for i in range(2)]
    se = [[L["cov"][i][j] / L["n"] + B["cov"][i][j] / B["n"] for j in range(2)] for i in range(2)]
    dist, apart = mahal(L, B, healthy_cov), mahal(L, B, se)
    return {"cells": (L["n"], B["n"]), "lesion": L["I"] / HL["I"], "blood": B["I"] / HB["I"],
            "dr": L["r"] - B["r"], "dg": L["g"] - B["g"], "dist": dist, "apart": apart,
            "told": apart >= 3.0 and dist >= 1.0}


rows = {(nm, t, d): measure(nm, t, d) for nm in LEDS for t in TRANSPORTS for d in DIAMETERS}

md = ["| LED | transport | diameter | cells (lesion, blood) | lesion / healthy | blood spot / healthy | "
      "lesion - blood (r, g) | distance (healthy s.d.) | means apart (s.e.) | told apart |",
      "|---|---|---|---|---|---|---|---|---|---|"]
for nm in LEDS:
    for t in TRANSPORTS:
        for d in DIAMETERS:
            r = rows[(nm, t, d)]
            if r is None or "lesion" not in r:
                cells = f"{r['cells'][0]}, {r['cells'][1]}: too few" if r else "not rendered"
                md.append(f"| {nm} nm | {t} | {d} mm | {cells} | | | | | | |")
                continue
            md.append(f"| {nm} nm | {t} | {d} mm | {r['cells'][0]}, {r['cells'][1]} | {r['lesion']:.2f} | {r['blood']:.2f} | "
                      f"{r['dr']:+.3f}, {r['dg']:+.3f} | {r['dist']:.2f} | {r['apart']:.1f} | {'yes' if r['told'] else 'no'} |")
md.append("")
md.append("| LED | smallest diameter told apart, spatial | position-free |")
md.append("|---|---|---|")
for nm in LEDS:
    best = {}
    for t in TRANSPORTS:
        told = [d for d in DIAMETERS if rows[(nm, t, d)] and rows[(nm, t, d)].get("told")]
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
        ds = [d for d in DIAMETERS if rows[(nm, t, d)] and "lesion" in rows[(nm, t, d)]]
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

# Fluorescence across the edges: mean fluorescence (480-700 nm) of the tongue against the distance on
# the surface from each disc's centre, in 0.25 mm rings, over healthy tongue's 6-12 mm away (a radial
# profile: pixel noise averages out along each ring; 405 nm, both transports).
fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
edges = np.arange(0.0, 12.01, 0.25)
for ax, spot in zip(axes, ("dysplasia", "blood_spot")):
    for d, c in zip((2, 5, 10), ("tab:orange", "tab:green", "tab:blue")):
        for t, ls in (("spatial", "-"), ("table", ":")):
            folder = f"{out}/405/{t}/d{d}"
            try:
                scene = json.load(open(f"{folder}/scene.json"))
                img = ofl.read_exr(f"{folder}/radiance.exr")
            except (OSError, ValueError, ofl.InputError):
                continue
            wl = np.asarray(img.wavelengths)
            fl = np.asarray(img.fluorescence)[..., (wl >= 480) & (wl <= 700)].sum(-1)
            names = json.loads(img.attributes["oralfluor.materials"])
            mat = np.asarray(img.aovs["material"])
            tongue = np.isin(mat, [names.index(n) for n in ("tongue_healthy", "dysplasia", "blood_spot")])
            region = next(r for r in scene["materials"]["tongue"]["regions"] if r["material"] == spot)
            dist = np.linalg.norm(surface_points(scene, img) - np.array(region["sphere"]["center_m"]), axis=-1) * 1000
            ref = fl[tongue & (dist > 6) & (dist < 12)].mean()
            prof = [fl[tongue & (dist >= lo) & (dist < hi)].mean() / ref if (tongue & (dist >= lo) & (dist < hi)).any() else np.nan
                    for lo, hi in zip(edges[:-1], edges[1:])]
            ax.plot((edges[:-1] + edges[1:]) / 2, prof, ls, c=c, label=f"{d} mm, {t}")
            ax.axvline(d / 2, c=c, lw=0.6, alpha=0.5)
    ax.set_title(f"405 nm: fluorescence around the {spot.replace('_', ' ')} (vertical lines: the disc's edge)", fontsize=9)
    ax.set_xlabel("distance from the disc's centre on the tongue (mm)")
    ax.set_ylabel("fluorescence 480-700 nm / healthy tongue 6-12 mm away")
    ax.axhline(1.0, c="0.5", lw=0.6)
    ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/edge_profile.png", dpi=110)
print(f"wrote {out}/sizes.md, {out}/sizes.png, {out}/edge_profile.png")
