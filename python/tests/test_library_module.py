"""The fluorophore library as arrays (checked against the CLI's list and the EEM conventions) and
`diagnose` as a dict equal to the CLI's --json report."""
import json

import numpy as np
import pytest

import oralfluor as ofl
from conftest import ROOT, cli_json, scene_path


def test_fluorophore_library_matches_cli_and_eem_conventions():
    lib = ofl.fluorophores()
    cli = cli_json("fluorophores")
    assert [f["name"] for f in lib] == [f["name"] for f in cli]
    for a, b in zip(lib, cli):
        assert a["peak_excitation_nm"] == b["peak_excitation_nm"] and a["peak_emission_nm"] == b["peak_emission_nm"]
    for f in lib:
        e = ofl.fluorophore_eem(f["name"], grid=(350, 830, 5))
        m, em, ex = e["eem"], e["emission_nm"], e["excitation_nm"]
        assert m.shape == (len(em), len(ex)) == (97, 97)
        assert np.all(m >= 0)
        assert np.all(m[np.less_equal.outer(em, ex)] == 0), f["name"]  # Stokes: nothing at or below excitation
        albedo = m.sum(axis=0) * 5.0  # photons out per photon in, integrated over emission
        np.testing.assert_allclose(albedo, e["photon_albedo"], rtol=1e-12)
        assert albedo.max() <= 1 + 1e-9  # a photon in gives at most one photon out
        if json.load(open(f["file"])).get("normalise", True):
            # Normalised on the file's own axes to a peak albedo of 1 (keratin peaks below 350 nm: a grid
            # from 240 nm holds every peak); bin averaging onto 5 nm loses a little.
            wide = ofl.fluorophore_eem(f["name"], grid=(240, 840, 5))["photon_albedo"]
            assert wide.max() == pytest.approx(1.0, abs=0.03), f["name"]
        assert ex[np.argmax(albedo)] == f["peak_excitation_nm"]


def test_diagnose_returns_the_cli_report(tmp_path):
    args = (f"{ROOT}/assets/measurements/camera_example", "--model", scene_path("diagnose", "camera_example.json"))
    cli = cli_json("diagnose", *args)
    py = ofl.diagnose(args[0], args[2], out=str(tmp_path / "d"))
    assert py.pop("text").strip()
    files = py.pop("files")
    assert any(f.endswith("report.json") for f in files)
    job_py, job_cli = py.pop("job"), cli.pop("job")  # the jobs differ only in where files go
    assert job_py["input"] == job_cli["input"] and job_py["model"] == job_cli["model"]
    assert py == cli
    with pytest.raises(ofl.InputError, match=r"nope\.json: cannot open file"):
        ofl.diagnose(args[0], str(tmp_path / "nope.json"))
    # fit_on / predict reach the job as the CLI's --fit-on / --predict do (their checks fire).
    with pytest.raises(ofl.InputError, match=r"--predict.*needs --fit-on"):
        ofl.diagnose(args[0], args[2], predict="illuminant=5000K")
    with pytest.raises(ofl.InputError, match=r"--fit-on"):
        ofl.diagnose(args[0], args[2], fit_on="illuminant=3000K")
