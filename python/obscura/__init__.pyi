# Typed stub of the obscura package (python/obscura/__init__.py and its compiled half _obscura):
# what editors complete and type checkers read. docs/PYTHON.md describes the API.
import os
from typing import Any, Callable, Iterable, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike[str]]
Progress = Callable[[int, int, float], Any]
Float32Array = npt.NDArray[np.float32]
Vec3 = Tuple[float, float, float]
LightScale = Union[float, Tuple[float, float, float], Sequence[float]]
Method = Literal["obscurance", "pathtrace"]

class InputError(ValueError):
    """Bad input: a scene, photo or state file, an option or an edit (the message names it)."""

class DeviceError(RuntimeError):
    """The Vulkan device failed: none found, out of memory, device lost."""

class Scene:
    """A glTF 2.0 scene, opened once; renders and sessions made from it share it."""
    def __init__(self, path: str, light_groups: str = "node") -> None: ...
    @property
    def path(self) -> str: ...
    @property
    def light_groups(self) -> str: ...
    @property
    def lights(self) -> list[dict[str, Any]]:
        """name, type, emission, power, triangles of each light, in the renderer's order."""
    @property
    def light_names(self) -> list[str]: ...
    @property
    def objects(self) -> list[dict[str, Any]]:
        """name, triangles, bounds of each object (names for move and remove edits)."""
    @property
    def cameras(self) -> list[dict[str, Any]]: ...
    @property
    def bounds(self) -> Tuple[Vec3, Vec3]: ...
    @property
    def triangles(self) -> int: ...
    def info(self) -> dict[str, Any]: ...

class Result:
    """A finished frame on the host: AOVs, per-light layers and relighting as arrays."""
    @property
    def aovs(self) -> dict[str, Float32Array]:
        """AOV name -> float32 H x W x C view ('combined', 'direct', 'indirect', 'albedo', ...)."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def light_names(self) -> list[str]: ...
    @property
    def light_stack(self) -> Float32Array:
        """float32 L x H x W x 3: each light's contribution; they sum to aovs['combined']."""
    @property
    def emissions(self) -> dict[str, Vec3]: ...
    def relight(self, scales: Mapping[str, LightScale], aov: str = "combined") -> Float32Array:
        """The frame with each named light's emission multiplied by a float or an (r, g, b) triple;
        no ray. Equal to the sum of light_stack's layers with the same scales."""
    @property
    def display(self) -> Optional[npt.NDArray[np.uint8]]:
        """Tonemapped combined, uint8 H x W x 4 (None for a loaded state)."""
    @property
    def stats(self) -> dict[str, Any]: ...
    def save_state(self, dir: PathLike) -> None: ...

def render(
    scene: Union[Scene, PathLike],
    *,
    progress: Optional[Progress] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    camera: Optional[int] = None,
    method: Optional[Method] = None,
    aovs: Optional[Sequence[str]] = None,
    exposure: Optional[float] = None,
    denoise: bool = False,
    pt_correction: Optional[Union[int, Literal["auto"]]] = None,
    shadow_rays: Optional[int] = None,
    obs_rays: Optional[int] = None,
    emission_samples: Optional[Union[int, Literal["auto"]]] = None,
    max_depth: Optional[int] = None,
    rho: Optional[Literal["sqrt", "exp", "ao"]] = None,
    tau: Optional[float] = None,
    dmax: Optional[float] = None,
    sampling: Optional[Literal["systematic", "random"]] = None,
    no_bleed: bool = False,
    escapes: Optional[Literal["auto", "dark", "ambient"]] = None,
    ambient: Optional[str] = None,
    light_sampling: Optional[str] = None,
    shadow_sampling: Optional[str] = None,
    background: Optional[Sequence[float]] = None,
    light_groups: Optional[str] = None,
    device: Optional[str] = None,
    traversal: Optional[str] = None,
    validate: bool = False,
    **settings: Any,
) -> Result:
    """Renders a frame; the settings are `obscura render`'s options as keywords."""

def info(scene: Union[Scene, PathLike], light_groups: str = "node") -> dict[str, Any]: ...
def load_state(dir: PathLike) -> Result:
    """A relighting state (render --save-state, Result.save_state) as a Result."""
def read_image(path: PathLike) -> dict[str, Float32Array]: ...
def run_command(args: Sequence[str]) -> None:
    """Runs an obscura command in this process (errors raised, not an exit status)."""
def devices() -> list[dict[str, Any]]: ...
def release_devices() -> None: ...
def buffer_bytes_in_use() -> int: ...
def validation_messages() -> list[str]: ...

class Session:
    """A scene rendered once, then edited (the session of `relight --edits` and the window)."""
    def __init__(
        self,
        scene: Union[Scene, PathLike],
        *,
        spare_lights: int = 4,
        progress: Optional[Progress] = None,
        **settings: Any,
    ) -> None: ...
    def apply(self, edit: Mapping[str, Any]) -> dict[str, Any]:
        """One edit (an edits file's entry as a dict); its report (the line of edits.jsonl)."""
    def apply_all(self, edits: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]: ...
    def result(self) -> Result: ...
    def save_state(self, dir: PathLike) -> None:
        """The frame's relighting state with the edited emissions (for `obscura relight DIR`)."""
    @property
    def display(self) -> npt.NDArray[np.uint8]: ...
    @property
    def light_names(self) -> list[str]: ...
    @property
    def object_names(self) -> list[str]: ...
    @property
    def closed(self) -> bool: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Session": ...
    def __exit__(self, *args: Any) -> None: ...

class Recovery:
    folder: str
    reflectance: Float32Array
    confidence: Optional[Float32Array]
    filled: Optional[Float32Array]
    object: Optional[Float32Array]
    report: dict[str, Any]
    def __init__(self, folder: str) -> None: ...
    def state(self) -> Result: ...

def recover(scene: PathLike, photos: PathLike, output: PathLike, **options: Any) -> Recovery: ...
def remodel(
    recovered: Union[Recovery, PathLike],
    edits: Union[PathLike, Sequence[Mapping[str, Any]]],
    output: Optional[PathLike] = None,
    **options: Any,
) -> dict[str, Float32Array]: ...
