"""The examples in python/examples run and say what the CLI says: figure5.py's lines are
`oralfluor chroma`'s reference lines for a render of the same scene and camera; led_sweep.py's
measured patch chromaticity lies where the reference construction predicts for each LED."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT, cli_json, run_cli, scene_path

EXAMPLES = os.path.join(ROOT, "python", "examples")


def run_example(name, *args):
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *map(str, args)], capture_output=True, text=True,
                       env=dict(os.environ, MPLBACKEND="Agg"))
    assert p.returncode == 0, p.stderr
    return p


def is_png(path):
    with open(path, "rb") as f:
        return f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_figure5_lines_match_oralfluor_chroma(tmp_path):
    run_example("figure5.py", "--out", tmp_path / "fig")
    ours = json.load(open(tmp_path / "fig" / "figure5.json"))
    assert is_png(tmp_path / "fig" / "figure5.png")
    # The CLI: a tiny render of the same scene (its LED and bands), the same camera, chroma's lines.
    run_cli("render", scene_path("oraleye_385.json"), "--spp", 1, "--width", 8, "--height", 6, "-o", tmp_path / "r")
    run_cli("camera", tmp_path / "r" / "radiance.exr", "--camera", scene_path("cameras", "oraleye.json"), "-o", tmp_path / "r")
    chroma = cli_json("chroma", tmp_path / "r" / "raw.tiff", "-o", tmp_path / "r")
    assert [l["fluorophore"] for l in ours["lines"]] == [l["fluorophore"] for l in chroma["lines"]]
    assert len(ours["lines"]) >= 6
    np.testing.assert_allclose(ours["tongue_rg"], chroma["reference"]["tongue_rg"], rtol=1e-12)
    for a, b in zip(ours["lines"], chroma["lines"]):
        np.testing.assert_allclose(a["concentration"], b["concentration"], rtol=1e-12, err_msg=a["fluorophore"])
        np.testing.assert_allclose(a["rg"], b["rg"], rtol=1e-12, atol=1e-15, err_msg=a["fluorophore"])
        assert a["visible"] == b["visible"]
    # The lines go somewhere: porphyrin toward red, FAD toward green.
    by = {l["fluorophore"]: l for l in ours["lines"]}
    assert by["protoporphyrin"]["pure_rg"][0] > ours["tongue_rg"][0] + 0.1
    assert by["FAD"]["pure_rg"][1] > ours["tongue_rg"][1] + 0.1


def test_led_sweep_means_follow_the_reference_construction(tmp_path):
    out = run_example("led_sweep.py", "--out", tmp_path, "--peaks", "370,415,460", "--size", 48, "--spp", 8)
    assert "wrote" in out.stdout and is_png(tmp_path / "led_sweep.png")
    points = json.load(open(tmp_path / "led_sweep.json"))
    assert [p["peak_nm"] for p in points] == [370, 415, 460]
    dev, blue, spread = [], [], []
    for p in points:
        n = p["stats"]["cells_used"]
        assert n == 24 * 24  # every 2x2 cell of the patch, none saturated
        cov = p["stats"]["covariance"]
        se = np.sqrt([cov["rr"] / n, cov["gg"] / n])
        mean = np.array([p["stats"]["mean"]["r"], p["stats"]["mean"]["g"]])
        dev.append(np.abs(mean - np.array(p["predicted_rg"])) - 4 * se)
        blue.append(1 - mean.sum())
        spread.append(p["stats"]["ellipse95"]["semi_axes"][0])
    # Far from the filter edge the patch sits where the on-axis reference construction puts it:
    # within noise (4 standard errors) plus 0.004 for 5 nm bands and the filter edge moving off axis.
    assert np.all(dev[0] < 0.004) and np.all(dev[1] < 0.004), dev
    # At 460 nm the LED leaks through the 475 nm long-pass: blue grows, and more so off axis, where the
    # interference edge moves to shorter wavelengths: the mean leaves the on-axis prediction and the
    # spread over the patch grows.
    assert blue[2] > blue[1] + 0.01
    assert np.max(dev[2]) > 0.004
    assert spread[2] > 1.1 * spread[1]


def test_iset_exchange_example(tmp_path):
    out = run_example("iset_exchange.py", "--out", tmp_path)
    assert is_png(tmp_path / "iset_exchange.png")
    import oralfluor as ofl
    back = ofl.read_iset_scene(str(tmp_path / "scene.mat"))
    assert back.shape == (72, 96, 35)
    if (tmp_path / "sensor.mat").exists():  # written by Octave with ISETCam's field layout
        cam, notes = ofl.import_iset_sensor(str(tmp_path / "sensor.mat"))
        s = cam["sensor"]
        assert s["cfa"] == "RGGB"
        assert s["full_well_e"] == pytest.approx(1 / 5e-5)          # voltageSwing / conversionGain
        assert s["system_gain_dn_per_e"] == pytest.approx(5e-5 * 1024)  # conversionGain / (swing / 2^bits)
        assert s["read_noise_e"] == pytest.approx(6e-4 / 5e-5)
        line = [l for l in out.stdout.splitlines() if l.startswith("Octave: photon sum")][0]
        octave_sum, python_sum = float(line.split()[3]), float(line.split()[5].rstrip(")"))
        assert octave_sum == pytest.approx(python_sum, rel=1e-5)
