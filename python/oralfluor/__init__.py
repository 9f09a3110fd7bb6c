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
naming the file and the field.
"""
from ._oralfluor import (  # noqa: F401  (the compiled core)
    Camera,
    CameraResult,
    InputError,
    SpectralImage,
    chromaticity,
    diagnose,
    export_iset,
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
    "diagnose", "export_iset", "fluorophore_eem", "fluorophores", "import_iset_sensor", "read_exr",
    "read_iset_scene", "read_mat", "read_raw", "read_spectrum_file", "reference_lines", "render", "roi_chromaticity",
    "simulate_camera", "write_exr", "write_mat", "write_spectrum_mat",
]
