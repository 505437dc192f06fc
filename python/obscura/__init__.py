"""Obscura from Python: render, relight and edit scenes, with NumPy arrays.

Obscura renders glTF scenes with ray-traced obscurances on Vulkan (a GPU, or lavapipe on the CPU)
and keeps the light transport per light, so that a light edit costs no ray::

    import obscura
    r = obscura.render("scenes/cornell-box/cornell-box.gltf", width=128, spp=8)
    r.aovs["combined"]          # float32 H x W x 3 (also direct, indirect, albedo, depth, ...)
    r.light_names               # ['Light', ...]
    r.light_stack               # float32 L x H x W x 3, summing to combined
    r.relight({"Light": 2.0})   # combined with that light twice as bright: no ray

    with obscura.Session("scene.gltf", width=128, spare_lights=2) as s:
        report = s.apply({"add_light": {"type": "point", "name": "lamp", "position": [0, 1, 0],
                                        "intensity": 5}})
        frame = s.result()

Settings are the command line's options as keyword arguments (`obscura render --help`): width,
height, spp, seed, camera, method, rho, ambient, no_bleed=True for a flag, background=(r, g, b),
aovs=[...] for --aov. They are checked by the command line's own parser: a bad one raises
InputError with its message. Errors are obscura.InputError (a ValueError: bad files, options,
edits; the message names the file and element) and obscura.DeviceError (a RuntimeError).

The GIL is released while the device works. Renders share one Vulkan context per device choice
(its compiled kernels serve every later render); a Session holds device memory until close() or
the end of its `with` block. See docs/PYTHON.md.
"""

from __future__ import annotations

import json as _json
import os as _os
import tempfile as _tempfile
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

from . import _obscura
from ._obscura import (
    DeviceError,
    InputError,
    Result,
    Scene,
    buffer_bytes_in_use,
    devices,
    load_state,
    read_image,
    release_devices,
    run_command,
    validation_messages,
)

__all__ = [
    "DeviceError", "InputError", "Result", "Scene", "Session", "Recovery", "buffer_bytes_in_use", "devices",
    "info", "load_state", "read_image", "recover", "release_devices", "remodel", "render", "run_command",
    "validation_messages",
]

PathLike = Union[str, "_os.PathLike[str]"]
Progress = Callable[[int, int, float], Any]

# Keyword names that differ from their option's (--aov takes a list, so the keyword is plural).
_OPTION_NAMES = {"aovs": "aov"}


def _word(value: Any) -> str:
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, _os.PathLike):
        return _os.fspath(value)
    return str(value)


def _arguments(settings: Mapping[str, Any]) -> list:
    """The command line's words for keyword settings: width=64 -> --width 64, no_bleed=True ->
    --no-bleed (False and None leave the option out), background=(r, g, b) -> --background r g b."""
    words = []
    for key, value in settings.items():
        if value is None or value is False:
            continue
        option = "--" + _OPTION_NAMES.get(key, key).replace("_", "-")
        if value is True:
            words.append(option)
        elif isinstance(value, (list, tuple)):
            words.append(option)
            words.extend(_word(v) for v in value)
        else:
            words += [option, _word(value)]
    return words


def _scene(scene: Union[Scene, PathLike], settings: dict) -> Scene:
    light_groups = settings.pop("light_groups", None)
    if isinstance(scene, Scene):
        if light_groups is not None and light_groups != scene.light_groups:
            raise InputError(f"light_groups={light_groups!r}: the scene was opened with {scene.light_groups!r}; "
                             "open it again with obscura.Scene(path, light_groups=...)")
        return scene
    return Scene(_os.fspath(scene), light_groups or "node")


def render(scene: Union[Scene, PathLike], *, progress: Optional[Progress] = None, **settings: Any) -> Result:
    """Renders a frame and returns it as a Result (AOVs, light stack and relight() as arrays).

    `scene`: a path or an opened obscura.Scene. `settings`: the options of `obscura render` as
    keywords (width, height, spp, seed, camera, method, rho, tau, dmax, ambient, shadow_rays,
    obs_rays, max_depth, emission_samples, light_sampling, background=(r, g, b), aovs=[...],
    denoise=True, device, traversal, light_groups, ...). `progress(done, total, seconds)` is
    called as samples finish.
    """
    opened = _scene(scene, settings)
    return _obscura._render(opened, _arguments(settings), progress)


def info(scene: Union[Scene, PathLike], light_groups: str = "node") -> dict:
    """What `obscura info SCENE` lists: lights (name, type, emission, power), objects (name,
    triangles, bounds), cameras, bounds, triangles, materials, textures."""
    return _scene(scene, {"light_groups": light_groups} if not isinstance(scene, Scene) else {}).info()


class Session(_obscura.Session):
    """A scene rendered once, then edited: the edit session of `relight --edits` and the window.

    Session(scene, spare_lights=4, progress=None, **settings) renders the first frame with the
    settings of obscura.render. apply(edit) takes one entry of an edits file as a dict and returns
    its report (the line of edits.jsonl); result() is the frame now. Use it in a `with` block, or
    call close(), to free its device memory.
    """

    def __init__(self, scene: Union[Scene, PathLike], *, spare_lights: int = 4,
                 progress: Optional[Progress] = None, **settings: Any) -> None:
        opened = _scene(scene, settings)
        super().__init__(opened, _arguments(settings), spare_lights, progress)

    def apply_all(self, edits: Iterable[Mapping[str, Any]]) -> list:
        """Applies edits in order; their reports."""
        return [self.apply(dict(edit)) for edit in edits]


class Recovery:
    """What obscura.recover found: reflectance (H x W x 3), confidence (H x W x 1, the sum of the
    filtered K_i), filled (H x W x 1: 0 measured, 1 filled from visibility, 2 from the object's
    mean, 3 from the measured pixels of its surface nearby), object (H x W x 1, the object each pixel sees, -1 none), report (recover.json) and
    the folder, whose `state` sub-folder obscura.load_state reads."""

    def __init__(self, folder: str) -> None:
        self.folder = folder
        layers = read_image(_os.path.join(folder, "reflectance.exr"))
        self.reflectance = layers["rgb"]
        self.confidence = layers.get("confidence")
        self.filled = layers.get("filled")
        self.object = layers.get("object")
        with open(_os.path.join(folder, "recover.json")) as f:
            self.report = _json.load(f)

    def state(self) -> Result:
        """The photographed room's relighting state with the recovered albedo (lights shot0..)."""
        return load_state(_os.path.join(self.folder, "state"))

    def __repr__(self) -> str:
        h, w = self.reflectance.shape[:2]
        return f"<obscura.Recovery {w}x{h} in {self.folder!r}>"


def recover(scene: PathLike, photos: PathLike, output: PathLike, **options: Any) -> Recovery:
    """Recovers per-pixel reflectance from photographs, as `obscura recover SCENE --photos
    PHOTOS -o OUTPUT` does (its options as keywords: spp, obs_rays, indirect, iterations,
    gather_rays, ..., png=True, debug=True, truth=path). Writes the same folder and returns it
    read back as a Recovery."""
    run_command(["recover", _os.fspath(scene), "--photos", _os.fspath(photos), "-o", _os.fspath(output)]
                + _arguments(options))
    return Recovery(_os.fspath(output))


def _absolute_inserts(edits: Sequence[Mapping[str, Any]]) -> list:
    out = []
    for edit in edits:
        edit = dict(edit)
        if isinstance(edit.get("insert"), (str, _os.PathLike)):
            edit["insert"] = _os.path.abspath(_os.fspath(edit["insert"]))
        out.append(edit)
    return out


def remodel(recovered: Union[Recovery, PathLike], edits: Union[PathLike, Sequence[Mapping[str, Any]]],
            output: Optional[PathLike] = None, **options: Any) -> dict:
    """Relights and remodels a photographed room with its recovered reflectance, as `obscura
    remodel DIR --edits EDITS -o OUTPUT` does. `edits`: an edits file, or its list of dicts
    (inserted files relative to the working directory). Options as keywords (spp, seed,
    gather_rays, gather_smoothing, bounces, hidden_bounces). Returns the frame's layers as arrays: rgb (the
    relit radiance), reflectance, direct, indirect, synthesized; `output` (an .exr) keeps the
    file too."""
    folder = recovered.folder if isinstance(recovered, Recovery) else _os.fspath(recovered)
    if output is not None and not _os.fspath(output).lower().endswith(".exr"):
        raise InputError(f"{_os.fspath(output)}: remodel's output from Python is an .exr (its layers are returned); "
                         "for a PNG run obscura.run_command(['remodel', ...])")
    with _tempfile.TemporaryDirectory(prefix="obscura-remodel-") as temp:
        if isinstance(edits, (str, _os.PathLike)):
            edits_file = _os.fspath(edits)
        else:
            edits_file = _os.path.join(temp, "edits.json")
            with open(edits_file, "w") as f:
                _json.dump(_absolute_inserts(edits), f)
        exr = _os.fspath(output) if output is not None else _os.path.join(temp, "frame.exr")
        run_command(["remodel", folder, "--edits", edits_file, "-o", exr] + _arguments(options))
        return {name: array.copy() for name, array in read_image(exr).items()}
