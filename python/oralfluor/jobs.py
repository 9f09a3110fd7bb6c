"""render, reference lines and ROI chromaticity: the Python side of the compiled calls."""
import sys
import time
import warnings

from . import _oralfluor
from .scene import Scene, _error


class RenderResult:
    """A finished (or interrupted) render: ``image`` (SpectralImage) and ``stats`` (dict).

    ``radiance``, ``wavelengths``, ``fluorescence`` and ``aovs`` are the image's. ``interrupted`` is
    True when Ctrl-C or the progress callback stopped it: the image then holds ``spp`` completed
    samples per pixel (``stats["spp"]``), exactly what a render with that many samples gives.
    """

    def __init__(self, image, stats):
        self.image, self.stats = image, stats

    radiance = property(lambda self: self.image.radiance)
    wavelengths = property(lambda self: self.image.wavelengths)
    fluorescence = property(lambda self: self.image.fluorescence)
    aovs = property(lambda self: self.image.aovs)
    interrupted = property(lambda self: bool(self.stats["interrupted"]))
    spp = property(lambda self: self.stats["spp"])

    def __repr__(self):
        h, w, b = self.image.shape
        return f"<oralfluor.RenderResult {h}x{w}x{b}, {self.spp} spp{' (interrupted)' if self.interrupted else ''}>"


class _TextBar:
    """A progress bar on stderr (also readable in logs: one line per 10 % when not a terminal)."""

    def __init__(self, stream=None):
        self.stream = stream or sys.stderr
        self.start = time.monotonic()
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.last_decile = -1

    def __call__(self, done, total):
        f = min(1.0, done / total) if total else 1.0
        el = time.monotonic() - self.start
        left = el * (1 - f) / f if f > 0 else 0
        line = f"render [{'#' * int(30 * f):.<30}] {100 * f:5.1f}%  {el:.0f}s elapsed, {left:.0f}s left"
        if self.tty:
            self.stream.write("\r" + line + ("\n" if f >= 1 else ""))
        elif int(10 * f) > self.last_decile:
            self.last_decile = int(10 * f)
            self.stream.write(line + "\n")
        self.stream.flush()
        return True


def render(scene, spp=None, seed=None, width=None, height=None, threads=None, progress=None, aovs=True,
           fluorescence=True):
    """Renders a scene (a Scene, a scene file path or a dict) and returns a RenderResult.

    spp, seed, width, height override the scene (as the CLI's --spp, --seed, --width, --height);
    threads: worker threads (None: all cores; the image is the same for any number).
    progress: True for a bar on stderr, or a callable(done, total) called about every 0.2 s with
    camera samples done and requested; returning False stops after the current pass.
    The GIL is released while rendering; Ctrl-C stops the render after the current pass and the
    samples finished so far are returned (``result.interrupted`` is True, with a warning).
    """
    if not isinstance(scene, Scene):
        scene = Scene(scene)
    callback = _TextBar() if progress is True else (None if progress is None or progress is False else progress)
    image, stats = _oralfluor._render(scene.doc, scene.file, spp=spp, seed=seed, width=width, height=height,
                                      threads=threads, aovs=aovs, fluorescence=fluorescence, callback=callback)
    result = RenderResult(image, stats)
    if result.interrupted:
        warnings.warn(f"render interrupted: {stats['spp']} of {stats['spp_requested']} samples per pixel finished",
                      RuntimeWarning, stacklevel=2)
    return result


def reference_lines(camera, led, reflectance=None, fluorophores=None, concentrations=None, grid_step=1.0,
                    camera_range=None, field_angle_deg=0.0, sensor_angle_deg=None):
    """Figure 5 of the OralEye paper: for each fluorophore, the (r, g) chromaticity this camera records
    from tissue with the given reflectance (default: the shipped tongue reflectance) plus an increasing
    concentration of the fluorophore, under the LED spectrum ``led`` ((nm, values) or a Scene's
    ``excitation_spd()``; only its shape matters). The same computation as ``oralfluor chroma``'s
    reference lines (docs/camera.md).

    camera_range: (lo, hi) nm the radiance covered (the camera sees nothing outside), default all;
    field_angle_deg: angle of incidence on front filters (sensor_angle_deg at the sensor, default equal).
    Returns {"lines": [{"fluorophore", "concentration", "rg", "pure_rg", "balance_concentration",
    "visible"}, ...], "tongue_rg": [r, g]}.
    """
    if not isinstance(camera, _oralfluor.Camera):
        camera = _oralfluor.Camera(camera)  # a path or a dict (InputError naming "source" otherwise)
    if isinstance(led, Scene):
        led = led.excitation_spd()
    return _oralfluor._reference_lines(camera, led, reflectance, fluorophores,
                                       [] if concentrations is None else concentrations, grid_step, camera_range,
                                       field_angle_deg, sensor_angle_deg)


def roi_chromaticity(camera_result, roi=None, mask=None, include_saturated=False):
    """ROI statistics of a CameraResult (or a dict from read_raw, or a raw.tiff path): r, g per 2x2
    cell, mean, covariance and 95 % ellipse, as ``oralfluor chroma`` computes them.
    roi = (x, y, w, h) in pixels, default the image; mask: a boolean array of the mosaic's shape."""
    if isinstance(camera_result, str) or hasattr(camera_result, "__fspath__"):
        camera_result = _oralfluor.read_raw(camera_result)
    if isinstance(camera_result, dict):
        if not {"raw", "metadata"} <= camera_result.keys():
            raise _error("camera_result", "expected a CameraResult, a dict from read_raw or a raw.tiff path")
        raw, meta = camera_result["raw"], camera_result["metadata"]
        cfa, black, white = meta["cfa_pattern"], meta["black_level_dn"], meta["white_level_dn"]
    elif isinstance(camera_result, _oralfluor.CameraResult):
        raw, cfa = camera_result.raw, camera_result.cfa
        black, white = camera_result.black_level, camera_result.white_level
    else:
        raise _error("camera_result", "expected a CameraResult, a dict from read_raw or a raw.tiff path, got "
                     + type(camera_result).__name__)
    return _oralfluor.chromaticity(raw, cfa, black, white, roi=roi, mask=mask, include_saturated=include_saturated)
