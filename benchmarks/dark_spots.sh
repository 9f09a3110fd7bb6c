#!/usr/bin/env bash
# Dark spot: lesion or blood? Renders scenes/dark_spot_{385,405,450}.json, passes each through the
# OralEye-like camera and compares the dysplastic lesion and the blood spot with the healthy tongue
# (`oralfluor chroma --roi-material`): intensity, r,g chromaticity, and separations in units of the
# healthy tongue's spread (Mahalanobis distance with the healthy cells' covariance).
# Usage: benchmarks/dark_spots.sh [build-dir] [out-dir] [width height spp]   (docs/layered-tissue.md)
set -euo pipefail
build=${1:-build}
out=${2:-out/dark_spots}
w=${3:-192}; h=${4:-144}; spp=${5:-48}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
for nm in 385 405 450; do
  d="$out/$nm"
  if [ ! -f "$d/cam/raw.tiff" ]; then
    "$build/oralfluor" render "$root/scenes/dark_spot_$nm.json" -o "$d" --width "$w" --height "$h" --spp "$spp"
    "$build/oralfluor" camera "$d/radiance.exr" --camera "$root/scenes/cameras/oraleye.json" -o "$d/cam" > /dev/null
  fi
  for m in tongue_healthy dysplasia blood_spot; do
    "$build/oralfluor" chroma "$d/cam/raw.tiff" --roi-material "$m" --name "chroma_$m" --json > "$d/chroma_$m.json"
  done
done
python3 - "$out" <<'PY'
import json, sys, math
out = sys.argv[1]
def stats(nm, m):
    s = json.load(open(f"{out}/{nm}/chroma_{m}.json"))["stats"]
    c = s["covariance"]
    return {"n": s["cells_used"], "r": s["mean"]["r"], "g": s["mean"]["g"], "I": sum(s["mean_rgb_dn"]),
            "cov": [[c["rr"], c["rg"]], [c["rg"], c["gg"]]]}
def mahal(a, b, cov):
    dr, dg = a["r"] - b["r"], a["g"] - b["g"]
    (p, q), (_, s) = cov
    det = p * s - q * q
    return math.sqrt(max(0.0, (s * dr * dr - 2 * q * dr * dg + p * dg * dg) / det))
print("| LED | region | cells | R+G+B (DN) | vs healthy | r | g | distance from healthy (healthy s.d.) |")
print("|---|---|---|---|---|---|---|---|")
for nm in (385, 405, 450):
    H = stats(nm, "tongue_healthy")
    rows = {m: stats(nm, m) for m in ("dysplasia", "blood_spot")}
    print(f"| {nm} nm | healthy tongue | {H['n']} | {H['I']:.1f} | 1 | {H['r']:.3f} +- {math.sqrt(H['cov'][0][0]):.3f} | {H['g']:.3f} +- {math.sqrt(H['cov'][1][1]):.3f} | - |")
    for m, S in rows.items():
        print(f"| {nm} nm | {m.replace('_', ' ')} | {S['n']} | {S['I']:.1f} | {S['I'] / H['I']:.2f} | {S['r']:.3f} | {S['g']:.3f} | {mahal(S, H, H['cov']):.2f} |")
    L, B = rows["dysplasia"], rows["blood_spot"]
    # Lesion against blood spot: the distance of their means in healthy-spread units, and in units
    # of the standard error of the two means (is the difference resolved by these cells?).
    se = [[(L["cov"][i][j] / L["n"] + B["cov"][i][j] / B["n"]) for j in range(2)] for i in range(2)]
    print(f"| {nm} nm | lesion vs blood spot | | | {L['I'] / B['I']:.2f} | {L['r'] - B['r']:+.3f} | {L['g'] - B['g']:+.3f} | "
          f"{mahal(L, B, H['cov']):.2f} (means {mahal(L, B, se):.1f} standard errors apart) |")
PY
# The picture in docs/layered-tissue.md: every 8x8-pixel cell of the three regions in (r, g), per LED.
/usr/bin/python3 - "$out" <<'PY'
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
out = sys.argv[1]
fig, axes = plt.subplots(1, 3, figsize=(12, 4.2), sharex=True, sharey=True)
style = {"tongue_healthy": ("healthy tongue", "0.6", 6), "dysplasia": ("dysplasia", "tab:blue", 18),
         "blood_spot": ("blood spot", "tab:red", 18)}
for ax, nm in zip(axes, (385, 405, 450)):
    for m, (label, colour, size) in style.items():
        rows = list(csv.DictReader(open(f"{out}/{nm}/cam/chroma_{m}_cells.csv")))
        r = [float(x["r"]) for x in rows]; g = [float(x["g"]) for x in rows]
        ax.scatter(r, g, s=size, c=colour, alpha=0.35 if m == "tongue_healthy" else 0.8, label=label, edgecolors="none")
        ax.plot(sum(r) / len(r), sum(g) / len(g), marker="X", ms=11, c=colour, mec="k")
    ax.set_title(f"{nm} nm LEDs, OralEye-like camera", fontsize=10)
    ax.set_xlabel("r = R / (R+G+B)")
axes[0].set_ylabel("g = G / (R+G+B)")
axes[0].legend(fontsize=8, loc="upper right")
fig.tight_layout()
fig.savefig(f"{out}/dark_spots.png", dpi=110)
print(f"wrote {out}/dark_spots.png")
PY

