"""oralfluor: a spectral path tracer and camera simulator for fluorescence imaging of the mouth.

The jobs of the ``oralfluor`` command line as Python calls on numpy arrays (docs/python.md)::

    import oralfluor as ofl
    scene = ofl.Scene("scenes/minimal.json")          # or ofl.Scene({...dict...})
    scene.set("/lights/0/spd/peak_nm", 385)           # change any field (JSON pointer)
    r = ofl.render(scene, spp=16, seed=1, progress=True)
    r.radiance            # float32 (rows, cols, bands), W sr^-1 m^-2 nm^-1
    r.wavelengths         # band centres, nm
    cam = ofl.Camera("scenes/cameras/oraleye.json")
    raw = ofl.simulate_camera(r.image, cam, seed=1)
    raw.raw               # uint16 mosaic; raw.electrons: expected electrons (rows, cols, 3)

Bad input raises ``oralfluor.InputError`` (a ValueError) whose message is the CLI's one line,
naming the file and the field (or the argument).
"""
import sys as _sys


def _explain_import_error(err):
    """An ImportError that says which Python the compiled core was built for, when it is not this one."""
    import glob
    import os
    here = os.path.dirname(os.path.abspath(__file__))
    built = sorted(os.path.basename(p) for p in glob.glob(os.path.join(here, "_oralfluor*.so")))
    try:
        from ._build_info import python_executable, python_version
        target = f"Python {python_version} ({python_executable})"
    except ImportError:
        target = " or ".join(built) or "no Python (no _oralfluor*.so next to this file)"
    this = f"Python {_sys.version.split()[0]} ({_sys.executable})"
    return ImportError(
        f"oralfluor's compiled core in {here} was built for {target}, and {this} cannot load it ({err}). "
        f"Run it with that Python, or build the module for this one: docs/python.md, 'Another Python'.")


try:
    from . import _oralfluor  # noqa: F401
except ImportError as _e:
    raise _explain_import_error(_e) from _e

from ._oralfluor import (  # noqa: F401  (the compiled core)
    Camera,
    CameraResult,
    InputError,
    SpectralImage,
    chromaticity,
    diagnose,
    export_iset,
    export_iset_oi,
    fluorophore_eem,
    fluorophores,
    import_iset_sensor,
    read_exr,
    read_iset_scene,
    read_mat,
    read_raw,
    read_spectrum_file,
    simulate_camera,
    write_exr,
    write_mat,
    write_spectrum_mat,
)
from .scene import Scene  # noqa: F401
from .jobs import RenderResult, reference_lines, render, roi_chromaticity  # noqa: F401

__all__ = [
    "Camera", "CameraResult", "InputError", "RenderResult", "Scene", "SpectralImage", "chromaticity",
    "diagnose", "export_iset", "export_iset_oi", "fluorophore_eem", "fluorophores", "import_iset_sensor", "read_exr",
    "read_iset_scene", "read_mat", "read_raw", "read_spectrum_file", "reference_lines", "render", "roi_chromaticity",
    "simulate_camera", "write_exr", "write_mat", "write_spectrum_mat",
]
