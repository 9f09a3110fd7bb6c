"""Fuzzing of the Python entry points' argument conversion: random calls whose arguments are drawn
from a pool of awkward values (wrong types, out-of-range and huge integers, NaN, numpy scalars and
arrays of every shape, paths that do not exist, objects of the wrong class). The contract: every
call either succeeds or raises oralfluor.InputError; any other exception, or a crash of the
interpreter, is a finding.

    python3 python/tests/fuzz_arguments.py --minutes 10 [--seed N] [--out findings.json]

runs a campaign: batches of calls in child interpreters (a crash ends only the batch, and the call
that crashed is reported), printing the count of calls and findings. A finding is kept as a
regression in fuzz_regressions.json (replayed by test_fuzz_arguments.py) once it is fixed.
A case is (entry point, {argument: pool key}), so it can be written down and replayed.
"""
import argparse
import json
import math
import os
import pathlib
import random
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.environ.get("OFL_SOURCE_DIR", os.path.join(HERE, "..", "..")))
# The files the calls may name live in a scratch copy of scenes/ and assets/ (make_pool), and calls
# run in a scratch folder: a writer handed a scene's name, or a short string, as its output must
# not write into the source tree.
MINIMAL = CAMERA = None


def make_pool(ofl, np, tmp):
    """Pool key -> a fresh value. Valid values are cheap (tiny images, small integers). Copies the
    scenes and assets into `tmp` and points MINIMAL and CAMERA there."""
    global MINIMAL, CAMERA
    for name in ("scenes", "assets"):
        if not os.path.exists(os.path.join(tmp, name)):
            shutil.copytree(os.path.join(ROOT, name), os.path.join(tmp, name))
    MINIMAL = os.path.join(tmp, "scenes", "minimal.json")
    CAMERA = os.path.join(tmp, "scenes", "cameras", "oraleye.json")
    readme = os.path.join(tmp, "README.md")
    shutil.copy(os.path.join(ROOT, "README.md"), readme)
    tiny_scene = ofl.Scene(MINIMAL).set("/camera/resolution", [6, 4]).set("/integrator/spp", 1)
    state = {}

    def render():
        if "r" not in state:
            state["r"] = ofl.render(tiny_scene, threads=1)
        return state["r"]

    def shot():
        if "s" not in state:
            state["s"] = ofl.simulate_camera(render(), CAMERA, seed=1, threads=1)
        return state["s"]

    return {
        "none": lambda: None, "zero": lambda: 0, "one": lambda: 1, "two": lambda: 2, "minus1": lambda: -1,
        "int31": lambda: 2 ** 31, "int63": lambda: 2 ** 63, "int64": lambda: 2 ** 64, "neg63": lambda: -2 ** 63,
        "big": lambda: 10 ** 30, "half": lambda: 0.5, "float2": lambda: 2.0, "nan": lambda: math.nan,
        "inf": lambda: math.inf, "ninf": lambda: -math.inf, "true": lambda: True, "false": lambda: False,
        "str8": lambda: "8", "empty_str": lambda: "", "long_str": lambda: "x" * 500, "nul_str": lambda: "a\0b",
        "bytes": lambda: b"scene", "empty_list": lambda: [], "list2": lambda: [1, 2], "list3": lambda: [350, 830, 5],
        "tiny_grid": lambda: [350, 830, 0.001], "list4": lambda: (0, 0, 2, 2), "list_str": lambda: ["a", "b"],
        "nested": lambda: [[1, 2], [3]], "dict": lambda: {}, "dict_bad": lambda: {"a": object()},
        "object": lambda: object(), "func": lambda: (lambda *a: None), "func_false": lambda: (lambda *a: False),
        "func_raise": lambda: (lambda *a: 1 / 0),
        "np_int": lambda: np.int64(3), "np_uint_big": lambda: np.uint64(2 ** 63), "np_f32_nan": lambda: np.float32("nan"),
        "np_bool": lambda: np.bool_(True), "np_empty": lambda: np.array([]), "np_2x2": lambda: np.zeros((2, 2)),
        "np_2x2x2": lambda: np.zeros((2, 2, 2)), "np_4": lambda: np.array([0, 0, 2, 2]), "np_obj": lambda: np.array([object()]),
        "np_u16": lambda: np.full((4, 6), 100, np.uint16), "np_f64_3d": lambda: np.random.default_rng(0).random((3, 4, 5)),
        "np_str": lambda: np.array(["a", "b"]), "np_0d": lambda: np.array(5), "np_huge_shape": lambda: np.zeros((0, 100000, 0)),
        "path_missing": lambda: pathlib.Path("/nonexistent/x.exr"), "path_dir": lambda: pathlib.Path(tmp),
        "path_minimal": lambda: pathlib.Path(MINIMAL), "str_minimal": lambda: MINIMAL, "str_camera": lambda: CAMERA,
        "path_out": lambda: pathlib.Path(tmp) / "out.bin", "str_out_mat": lambda: os.path.join(tmp, "o.mat"),
        "str_out_exr": lambda: os.path.join(tmp, "o.exr"), "path_out_dir": lambda: pathlib.Path(tmp) / "outdir",
        "readme": lambda: readme,
        "image": lambda: render().image, "result": render, "shot": shot, "camera": lambda: ofl.Camera(CAMERA),
        "scene": lambda: ofl.Scene(tiny_scene), "camera_dict": lambda: {"sensor": {"cfa": "RGGB"}},
        "spectrum": lambda: ([380, 390, 400], [0, 1, 0]), "spectrum_dict": lambda: {"nm": [380, 400], "values": [1, 1]},
        "pointer": lambda: "/integrator/spp", "bad_pointer": lambda: "integrator", "cfa": lambda: "RGGB",
    }


# Entry point -> (callable factory, required arguments, optional arguments). Every required
# argument is drawn (Python's own TypeError for a missing one is not the module's to prevent);
# each optional one is drawn or left at its default.
def entries(ofl):
    import numpy as np
    return {
        "render": (lambda: ofl.render, ["scene"], ["spp", "seed", "width", "height", "threads", "progress", "aovs"]),
        "simulate_camera": (lambda: ofl.simulate_camera, ["image", "camera"], ["seed", "noise", "threads"]),
        "chromaticity": (lambda: ofl.chromaticity, ["raw", "cfa", "black", "white"], ["roi", "mask", "include_saturated"]),
        "roi_chromaticity": (lambda: ofl.roi_chromaticity, ["camera_result"], ["roi", "mask", "include_saturated"]),
        "SpectralImage": (lambda: ofl.SpectralImage, ["radiance", "wavelengths"], ["fluorescence", "aovs", "attributes"]),
        "SpectralImage.srgb": (lambda: ofl.SpectralImage(np.ones((2, 3, 4)), [400, 500, 600, 700]).srgb, [], ["white_radiance"]),
        "read_exr": (lambda: ofl.read_exr, ["path"], []), "read_raw": (lambda: ofl.read_raw, ["path"], []),
        "read_mat": (lambda: ofl.read_mat, ["path"], []), "read_iset_scene": (lambda: ofl.read_iset_scene, ["path"], []),
        "import_iset_sensor": (lambda: ofl.import_iset_sensor, ["path"], []),
        "read_spectrum_file": (lambda: ofl.read_spectrum_file, ["path"], []),
        "write_exr": (lambda: ofl.write_exr, ["path", "image"], []),
        "export_iset": (lambda: ofl.export_iset, ["image", "path"], ["distance_m", "hfov_deg"]),
        "export_iset_oi": (lambda: ofl.export_iset_oi, ["image", "camera", "path"], []),
        "write_mat": (lambda: ofl.write_mat, ["path", "variables"], []),
        "write_spectrum_mat": (lambda: ofl.write_spectrum_mat, ["path", "nm", "columns"], ["names"]),
        "fluorophores": (lambda: ofl.fluorophores, [], ["grid"]),
        "fluorophore_eem": (lambda: ofl.fluorophore_eem, ["name"], ["grid"]),
        "Scene": (lambda: ofl.Scene, ["source"], ["base_dir"]),
        "Scene.set": (lambda: ofl.Scene(MINIMAL).set, ["pointer", "value"], []),
        "Scene.get": (lambda: ofl.Scene(MINIMAL).get, ["pointer"], []),
        "Camera": (lambda: ofl.Camera, ["source"], []),
        "Camera.to_dict": (lambda: ofl.Camera(CAMERA).to_dict, [], ["lo_nm", "hi_nm"]),
        "reference_lines": (lambda: ofl.reference_lines, ["camera", "led"], ["concentrations", "grid_step", "camera_range",
                                                                            "field_angle_deg"]),
        "diagnose": (lambda: ofl.diagnose, ["input", "model"], ["where", "z", "max_causes", "threads", "progress"]),
        "CameraResult.write": (None, ["folder"], []),  # bound to the pool's camera result in run_case
    }


def random_case(rng, table, pool_keys):
    entry = rng.choice(sorted(table))
    _, required, optional = table[entry]
    chosen = {a: rng.choice(pool_keys) for a in required}
    chosen.update({a: rng.choice(pool_keys) for a in optional if rng.random() < 0.6})
    return [entry, chosen]


def run_case(ofl, pool, table, case):
    """Runs one case; returns None when the contract holds, else a one-line description."""
    entry, chosen = case
    factory = table[entry][0]
    try:
        fn = pool["shot"]().write if entry == "CameraResult.write" else factory()
        kwargs = {a: pool[k]() for a, k in chosen.items()}
        fn(**kwargs)
    except ofl.InputError:
        return None
    except KeyboardInterrupt:
        if entry == "diagnose" and chosen.get("progress") == "func_false":
            return None  # a progress callback that returns False stops diagnose: documented
        return "KeyboardInterrupt"
    except BaseException as e:  # noqa: BLE001 - everything else is a finding
        return f"{type(e).__name__}: {str(e).splitlines()[0][:200] if str(e) else ''}"
    return None


def child(args):
    """Runs `args.count` random cases from `args.seed`, logging each before it runs (for crashes)."""
    import numpy as np
    import oralfluor as ofl
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)  # relative output names ("8", "RGGB") land in the scratch folder
        pool, table = make_pool(ofl, np, tmp), entries(ofl)
        keys = sorted(pool)
        with open(args.log, "w") as log:
            for _ in range(args.count):
                case = random_case(rng, table, keys)
                log.write(json.dumps(case) + "\n")
                log.flush()
                problem = run_case(ofl, pool, table, case)
                if problem:
                    log.write(json.dumps({"finding": case, "what": problem}) + "\n")
                    log.flush()


def campaign(args):
    end = time.monotonic() + 60 * args.minutes
    findings, calls, batch = [], 0, 0
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "log")
        while time.monotonic() < end:
            seed = args.seed * 1_000_003 + batch
            batch += 1
            p = subprocess.run([sys.executable, __file__, "--child", "--seed", str(seed), "--count", str(args.batch),
                                "--log", log], capture_output=True, text=True, timeout=600)
            lines = [json.loads(x) for x in open(log)] if os.path.exists(log) else []
            calls += sum(1 for x in lines if isinstance(x, list))
            findings += [x for x in lines if isinstance(x, dict)]
            if p.returncode != 0:
                last = [x for x in lines if isinstance(x, list)]
                findings.append({"finding": last[-1] if last else None, "what": f"child exited {p.returncode}: "
                                 + (p.stderr.strip().splitlines() or [""])[-1][:200]})
    unique = {json.dumps(f["finding"]): f for f in findings}
    print(f"{calls} calls in {batch} batches, {len(findings)} findings ({len(unique)} distinct)")
    for f in unique.values():
        print(json.dumps(f))
    if args.out:
        json.dump(list(unique.values()), open(args.out, "w"), indent=1)
    return 1 if unique else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=10)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--batch", type=int, default=400)
    ap.add_argument("--out")
    ap.add_argument("--child", action="store_true")
    ap.add_argument("--count", type=int)
    ap.add_argument("--log")
    args = ap.parse_args()
    if args.child:
        child(args)
        return 0
    return campaign(args)


if __name__ == "__main__":
    sys.exit(main())
