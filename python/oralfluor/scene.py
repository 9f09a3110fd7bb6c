"""Scene documents: a scene file or a Python dict, edited field by field before rendering."""
import copy
import os

from . import _oralfluor


def _pointer_tokens(pointer):
    if pointer in ("", "/"):
        return []
    if not pointer.startswith("/"):
        raise _oralfluor.InputError(f"<python scene>: {pointer}: a JSON pointer starts with /")
    return [t.replace("~1", "/").replace("~0", "~") for t in pointer[1:].split("/")]


class Scene:
    """A scene document (the JSON of docs/scene-format.md) with the name errors report.

    ``Scene("scenes/x.json")`` reads a file; relative data paths resolve against its folder and
    error messages name it. ``Scene(dict, base_dir=...)`` takes a document built in Python;
    relative paths resolve against ``base_dir`` (default: the current folder).
    """

    def __init__(self, source, base_dir=None):
        if isinstance(source, Scene):
            self.doc, self.file = copy.deepcopy(source.doc), source.file
        elif isinstance(source, dict):
            self.doc = copy.deepcopy(source)
            self.file = os.path.join(os.path.abspath(base_dir or os.getcwd()), "<python scene>")
        else:
            self.file = os.fspath(source)
            self.doc = _oralfluor._read_json(self.file)  # the CLI's reader: the same error text

    def copy(self):
        return Scene(self)

    def get(self, pointer):
        """The value at a JSON pointer, e.g. ``scene.get("/integrator/spp")``."""
        node = self.doc
        for t in _pointer_tokens(pointer):
            node = node[int(t)] if isinstance(node, list) else node[t]
        return node

    def set(self, pointer, value):
        """Sets the value at a JSON pointer (creating the last member); returns self."""
        tokens = _pointer_tokens(pointer)
        if not tokens:
            raise _oralfluor.InputError(f"{self.file}: {pointer}: cannot replace the whole document")
        node = self.doc
        for t in tokens[:-1]:
            node = node[int(t)] if isinstance(node, list) else node.setdefault(t, {})
        last = tokens[-1]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
        return self

    def info(self):
        """Loads the scene (every field checked as the renderer does) and summarises it: size, spp,
        seed, wavelength grid, output bands, materials, LED excitation spectrum."""
        return _oralfluor._scene_info(self.doc, self.file)

    def excitation_spd(self):
        """Summed on-axis spectral intensity of the LEDs on the transport grid:
        ``{"nm": [...], "W_per_sr_nm": [...]}`` (what a render records as oralfluor.excitation_spd)."""
        return self.info()["excitation_spd"]

    def band_range(self):
        """(lowest, highest) wavelength the output bands cover, nm."""
        i = self.info()
        half = 0.5 * i["band_step_nm"]
        return (i["bands_nm"][0] - half, i["bands_nm"][-1] + half)

    def __repr__(self):
        return f"<oralfluor.Scene {self.file}>"
