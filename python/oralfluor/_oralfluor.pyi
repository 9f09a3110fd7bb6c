"""Type stubs of oralfluor's compiled core (python/src). Every argument is checked as the CLI checks
its options; a bad value raises InputError naming the argument. Paths are str or os.PathLike;
integers may be numpy integers; arrays any numpy array (or nested lists) of numbers."""
import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]
ImageLike = Union["SpectralImage", Any]  # a SpectralImage or anything with a SpectralImage `.image` (RenderResult)
CameraLike = Union["Camera", PathLike, Dict[str, Any]]
Spectrum = Union[Tuple[Sequence[float], Sequence[float]], Dict[str, Sequence[float]]]

class InputError(ValueError):
    """Bad input: the message is the CLI's one line "<file>: <field>: <what>" (empty parts left out)."""
    file: str
    field: str
    reason: str

class SpectralImage:
    """Spectral radiance image: radiance (rows, cols, bands) in W sr^-1 m^-2 nm^-1 on the band centres
    `wavelengths`, optional fluorescence layer and per-pixel AOV planes, header attributes."""
    def __init__(self, radiance: npt.ArrayLike, wavelengths: npt.ArrayLike, fluorescence: Optional[npt.ArrayLike] = None,
                 aovs: Optional[Mapping[str, npt.ArrayLike]] = None, attributes: Optional[Mapping[str, str]] = None) -> None: ...
    @property
    def radiance(self) -> npt.NDArray[np.float32]:
        """float32 array (rows, cols, bands), W sr^-1 m^-2 nm^-1 (a read-only view; .copy() to edit)"""
    @property
    def wavelengths(self) -> npt.NDArray[np.float64]:
        """band centres in nm"""
    @property
    def band_lo(self) -> npt.NDArray[np.float64]:
        """lower band edges in nm"""
    @property
    def band_hi(self) -> npt.NDArray[np.float64]:
        """upper band edges in nm"""
    @property
    def fluorescence(self) -> Optional[npt.NDArray[np.float32]]:
        """the fluorescent part of the radiance (same shape, read-only view), or None"""
    @property
    def aovs(self) -> Dict[str, npt.NDArray[np.float32]]:
        """per-pixel planes (read-only views): material (index into the scene's materials, -1 none, -2 LED), u, v,
        depth, cos_view, irradiance"""
    @property
    def attributes(self) -> Dict[str, str]:
        """header strings"""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    def srgb(self, white_radiance: float = 1.0) -> npt.NDArray[np.float32]:
        """linear sRGB (rows, cols, 3) through CIE 1931, Y = 1 for a flat radiance of white_radiance"""

def read_exr(path: PathLike) -> SpectralImage:
    """read a spectral EXR (every S0 channel, the fluorescence layer, aov.* planes, header strings)"""
def write_exr(path: PathLike, image: ImageLike) -> None:
    """write a spectral EXR (an image or a render result) in the layout oralfluor render writes"""

class Camera:
    """a camera: lens, filter stack and sensor (docs/camera.md)"""
    def __init__(self, source: Union[PathLike, Dict[str, Any]], name: str = "<python camera>") -> None:
        """from a camera.json path, an ISETCam sensor .mat path, or a dict in the camera.json format"""
    @property
    def name(self) -> str: ...
    @property
    def cfa(self) -> str: ...
    def to_dict(self, lo_nm: float = 350.0, hi_nm: float = 830.0) -> Dict[str, Any]:
        """a self-contained camera.json document (spectra sampled every nm over [lo_nm, hi_nm])"""

class CameraResult:
    """what `oralfluor camera` computes: raw mosaic, expected electrons, metadata"""
    @property
    def raw(self) -> npt.NDArray[np.uint16]:
        """uint16 raw mosaic (rows, cols), DN including the black level (read-only view)"""
    @property
    def electrons(self) -> npt.NDArray[np.float32]:
        """expected photo-electrons (rows, cols, 3): what R, G and B pixels would collect, noise free (read-only view)"""
    @property
    def mosaic_electrons(self) -> npt.NDArray[np.float32]:
        """expected electrons of each pixel's own colour plus the dark electrons (electrons.exr 'mosaic'; read-only view)"""
    @property
    def dark_electrons(self) -> float: ...
    @property
    def metadata(self) -> Dict[str, Any]:
        """cfa_pattern, black_level_dn, white_level_dn, bit depth, gains, exposure, seed, ..."""
    @property
    def cfa(self) -> str: ...
    @property
    def black_level(self) -> float: ...
    @property
    def white_level(self) -> float: ...
    @property
    def summary(self) -> Dict[str, Any]: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def camera(self) -> Camera: ...
    def write(self, folder: PathLike) -> Dict[str, str]:
        """write raw.tiff, raw.json, raw.dng, electrons.exr and camera_preview.png as the CLI does"""

def simulate_camera(image: Union[ImageLike, PathLike], camera: CameraLike, seed: Optional[int] = None,
                    noise: Optional[bool] = None, threads: Optional[int] = None,
                    radiance_name: str = "<python image>") -> CameraResult:
    """run the camera model on a spectral image (a SpectralImage, a RenderResult or an EXR path) through a camera
    (a Camera, a camera.json or ISETCam sensor .mat path, or a dict); the GIL is released"""
def read_raw(path: PathLike) -> Dict[str, Any]:
    """read a raw.tiff written by `oralfluor camera` (with its raw.json): {'raw', 'metadata', 'sidecar'}"""

def chromaticity(raw: npt.ArrayLike, cfa: str, black: float, white: float, roi: Optional[Sequence[int]] = None,
                 mask: Optional[npt.ArrayLike] = None, include_saturated: bool = False) -> Dict[str, Any]:
    """r, g per 2x2 CFA cell of a raw mosaic in roi (x, y, w, h): mean, covariance, 95 % ellipse, and rg per cell"""
def fluorophores(grid: Sequence[float] = (350, 830, 5)) -> List[Dict[str, Any]]:
    """the shipped fluorophore library: name, description, citation, file, peak excitation and emission"""
def fluorophore_eem(name: str, grid: Sequence[float] = (350, 830, 5)) -> Dict[str, Any]:
    """a fluorophore's EEM on a grid (min, max, step nm): eem[emission, excitation] in photons per nm per photon,
    with emission_nm, excitation_nm and photon_albedo"""

def read_mat(path: PathLike) -> Dict[str, Any]:
    """every variable of a .mat file: structs as dicts, text as str, cells as lists, arrays as numpy"""
def write_mat(path: PathLike, variables: Mapping[str, Any]) -> None:
    """write a MAT 5 file: dicts become structs, str char arrays, lists of str cells, arrays/numbers double (float32 single)"""
def export_iset(image: ImageLike, path: PathLike, name: str = "", distance_m: Optional[float] = None,
                hfov_deg: Optional[float] = None, source: str = "<python image>") -> Dict[str, Any]:
    """write the image as an ISETCam scene struct (variable `scene`) to a .mat file; returns a summary"""
def export_iset_oi(image: ImageLike, camera: CameraLike, path: PathLike) -> Dict[str, Any]:
    """write the optical image the camera's lens, filters and optics stage form from the image as an ISETCam oi
    (variable `oi`: sensor-plane irradiance in photons s^-1 m^-2 nm^-1 on the sensor grid); returns a summary"""
def read_iset_scene(path: PathLike) -> SpectralImage:
    """an ISETCam scene .mat as a SpectralImage (W sr^-1 m^-2 nm^-1); an exported scene gives back its fluorescence
    layer, AOV planes and header strings"""
def import_iset_sensor(path: PathLike) -> Tuple[Dict[str, Any], List[str]]:
    """an ISETCam sensor .mat as (camera.json dict, notes)"""
def read_spectrum_file(path: PathLike) -> Dict[str, Any]:
    """a spectrum CSV or ISETCam .mat (wavelength, data): {'nm': array, 'columns': {name: array}}"""
def write_spectrum_mat(path: PathLike, nm: npt.ArrayLike, columns: Sequence[npt.ArrayLike],
                       names: Optional[Sequence[str]] = None, comment: str = "") -> None:
    """write an ISETCam spectral file (wavelength, data, filterNames, comment)"""
def diagnose(input: PathLike, model: PathLike, where: Optional[Union[str, Sequence[str]]] = None,
             groups: Optional[Union[str, Sequence[str]]] = None, z: Optional[float] = None,
             max_causes: Optional[int] = None, report_by: Optional[str] = None, out: Optional[PathLike] = None,
             fit_on: Optional[str] = None, predict: Optional[str] = None,
             shared_concentrations: Optional[Union[str, Sequence[str]]] = None, threads: Optional[int] = None,
             progress: Optional[Callable[[int, int, int], Optional[bool]]] = None) -> Dict[str, Any]:
    """run `oralfluor diagnose` on a folder or CSV with a model file; returns the JSON report as a dict (plus 'text');
    threads: worker threads (None: all cores); progress: callable(done, total, step) called about every 0.1 s with
    the candidate causes tried in cause step `step`, returning False stops; Ctrl-C stops it (KeyboardInterrupt)"""

def _read_json(path: PathLike) -> Any: ...
def _scene_info(doc: Any, name: str) -> Dict[str, Any]: ...
def _render(doc: Any, name: str, spp: Optional[int] = None, seed: Optional[int] = None, width: Optional[int] = None,
            height: Optional[int] = None, threads: Optional[int] = None, aovs: bool = True, fluorescence: bool = True,
            callback: Optional[Callable[[int, int], Optional[bool]]] = None) -> Tuple[SpectralImage, Dict[str, Any]]: ...
def _reference_lines(camera: Camera, led: Spectrum, reflectance: Optional[Spectrum] = None,
                     fluorophores: Optional[Sequence[str]] = None, concentrations: npt.ArrayLike = ...,
                     grid_step: float = 1.0, camera_range: Optional[Sequence[float]] = None, field_angle_deg: float = 0.0,
                     sensor_angle_deg: Optional[float] = None) -> Dict[str, Any]: ...
