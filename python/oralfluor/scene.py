"""Scene documents: a scene file or a Python dict, edited field by field before rendering."""
import copy
import os

from . import _oralfluor


def _error(field, reason, file=""):
    """An InputError as the compiled core raises it: message "<file>: <field>: <reason>" (empty
    parts left out), with the parts as attributes."""
    e = _oralfluor.InputError(": ".join(p for p in (file, field, reason) if p))
    e.file, e.field, e.reason = file, field, reason
    return e


def _pointer_tokens(pointer):
    if not isinstance(pointer, str):
        raise _error("pointer", f"expected a JSON pointer such as \"/integrator/spp\", got {type(pointer).__name__}")
    if pointer in ("", "/"):
        return []
    if not pointer.startswith("/"):
        raise _error(pointer, "a JSON pointer starts with /", "<python scene>")
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
            if base_dir is not None and not isinstance(base_dir, str) and not hasattr(base_dir, "__fspath__"):
                raise _error("base_dir", f"expected a folder name (str or pathlib.Path), got {type(base_dir).__name__}")
            self.file = os.path.join(os.path.abspath(base_dir or os.getcwd()), "<python scene>")
        elif isinstance(source, str) or hasattr(source, "__fspath__"):
            self.file = os.fspath(source)
            self.doc = _oralfluor._read_json(self.file)  # the CLI's reader: the same error text
            if not isinstance(self.doc, dict):
                raise _error("", "expected a JSON object (a scene document)", self.file)
        else:
            raise _error("scene", "expected a Scene, a scene file name (str or pathlib.Path) or a dict, got "
                         + type(source).__name__)

    def copy(self):
        return Scene(self)

    def get(self, pointer):
        """The value at a JSON pointer, e.g. ``scene.get("/integrator/spp")``."""
        node = self.doc
        for t in _pointer_tokens(pointer):
            try:
                node = node[int(t)] if isinstance(node, list) else node[t]
            except (KeyError, IndexError, ValueError, TypeError):
                raise _error(pointer, "no such field in the scene", self.file) from None
        return node

    def set(self, pointer, value):
        """Sets the value at a JSON pointer (creating the last member); returns self."""
        tokens = _pointer_tokens(pointer)
        if not tokens:
            raise _oralfluor.InputError(f"{self.file}: {pointer}: cannot replace the whole document")
        node = self.doc
        try:
            for t in tokens[:-1]:
                node = node[int(t)] if isinstance(node, list) else node.setdefault(t, {})
            last = tokens[-1]
            if isinstance(node, list):
                node[int(last)] = value
            elif isinstance(node, dict):
                node[last] = value
            else:
                raise TypeError
        except (IndexError, ValueError, TypeError, AttributeError):
            raise _error(pointer, "no such place in the scene (a missing list item or a field inside a value)",
                         self.file) from None
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
