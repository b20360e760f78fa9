"""emaki: stylize 3D animation by example (type stub for the pybind11 module).

The docstrings (help(emaki.synthesize), ...) give each argument's range and default.
"""

import os
import pathlib
from typing import Callable, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

Array = npt.NDArray[Union[np.uint8, np.uint16, np.float32]]
PathLike = Union[str, os.PathLike[str]]
DType = Union[str, type, np.dtype]
Guide = Union[Tuple[Array, Array], Tuple[Array, Array, Optional[float]]]
Vec3 = Tuple[float, float, float]

class Error(Exception):
    """Base of emaki's errors."""

    subject: str  # the argument, file or key the error is about
    message: str  # the text without the subject

class InputError(Error, ValueError):
    """A bad argument: value out of range, wrong dtype / shape / size, non-finite value."""

class FileError(Error, OSError):
    """A file that cannot be read, decoded or written."""

    filename: str

@overload
def synthesize(
    style: Array,
    guides: Sequence[Guide],
    mask: Optional[Array] = None,
    *,
    style_weight: Optional[float] = None,
    uniformity: float = 3500.0,
    patch_size: int = 5,
    pyramid_levels: Optional[int] = None,
    search_vote_iters: Optional[int] = None,
    patch_match_iters: Optional[int] = None,
    extra_pass_3x3: bool = False,
    vote: Literal["weighted", "plain"] = "weighted",
    seed: int = 1,
    threads: int = 0,
    nnf: Literal[False] = False,
    error: Literal[False] = False,
    dtype: Optional[DType] = None,
    progress: Optional[Callable[[dict], object]] = None,
) -> Array: ...
@overload
def synthesize(
    style: Array,
    guides: Sequence[Guide],
    mask: Optional[Array] = None,
    *,
    style_weight: Optional[float] = None,
    uniformity: float = 3500.0,
    patch_size: int = 5,
    pyramid_levels: Optional[int] = None,
    search_vote_iters: Optional[int] = None,
    patch_match_iters: Optional[int] = None,
    extra_pass_3x3: bool = False,
    vote: Literal["weighted", "plain"] = "weighted",
    seed: int = 1,
    threads: int = 0,
    nnf: bool = False,
    error: bool = False,
    dtype: Optional[DType] = None,
    progress: Optional[Callable[[dict], object]] = None,
) -> Union[Array, Tuple[Array, ...]]: ...
# One channel is HxW, any other count HxWxC, for every function (in and out).
def read_image(path: PathLike, channels: Optional[Sequence[str]] = None) -> Array: ...
def write_image(
    path: PathLike,
    image: Array,
    *,
    channels: Optional[Sequence[str]] = None,
    depth: Optional[Union[Literal["8", "16", "half", "float", 8, 16]]] = None,
) -> None: ...
def image_channels(path: PathLike) -> list[str]: ...
def convert_colorspace(
    image: Array, src: str, dst: str, config: Optional[PathLike] = None
) -> Array: ...
def render(
    scene: PathLike,
    frame: int = 0,
    size: Tuple[int, int] = (640, 360),
    *,
    frames: Optional[Tuple[int, int]] = None,
    clip: Optional[str] = None,
    fps: float = 24.0,
    start: float = 0.0,
    loop: bool = False,
    aa: int = 2,
    outline_width: float = 1.5,
    camera: Optional[Vec3] = None,
    target: Optional[Vec3] = None,
    azimuth: float = 30.0,
    elevation: float = 15.0,
    distance: float = 0.0,
    fov: float = 40.0,
    gltf_camera: Optional[int] = None,
    light: Vec3 = (-1.0, 1.0, 1.0),
    light_world: bool = False,
    softness: float = 2.0,
    ground: bool = True,
    threads: int = 0,
    allow_outside_paths: bool = False,
) -> dict[str, npt.NDArray[np.float32]]: ...
def template(
    size: Tuple[int, int] = (1024, 768),
    *,
    sphere: Optional[Vec3] = None,
    elevation: float = 10.0,
    horizon: Optional[float] = None,
    fov: float = 30.0,
    light: Vec3 = (-1.0, 1.0, 1.0),
    softness: float = 2.0,
    ground: bool = True,
    aa: int = 3,
    outline_width: float = 1.5,
    threads: int = 0,
) -> dict[str, npt.NDArray[np.float32]]: ...

class Shot:
    """A shot file's settings, checked (docs/shot_file.md); the shot API of `emaki run`."""
    def __init__(self, path: PathLike) -> None: ...  # the same as Shot.load(path)
    @staticmethod
    def load(path: PathLike) -> "Shot": ...
    @staticmethod
    def from_dict(d: Mapping[str, object], path: PathLike = "shot.toml") -> "Shot": ...
    @property
    def path(self) -> pathlib.Path: ...
    @property
    def frames(self) -> Tuple[int, int]: ...
    @property
    def size(self) -> Tuple[int, int]: ...
    @property
    def layers(self) -> list[str]: ...
    @property
    def output_folder(self) -> pathlib.Path: ...
    def run(
        self,
        *,
        frames: Union[None, int, Tuple[int, int]] = None,
        layers: Optional[Sequence[str]] = None,
        force: bool = False,
        previews: bool = True,
        threads: Optional[int] = None,
        progress: Optional[Callable[[dict], object]] = None,
        max_memory_mb: Optional[int] = None,
        one_layer_at_a_time: bool = False,
    ) -> dict: ...
    def composite(
        self,
        *,
        frames: Union[None, int, Tuple[int, int]] = None,
        previews: bool = True,
        threads: Optional[int] = None,
        max_memory_mb: Optional[int] = None,
    ) -> int: ...
    def flicker(
        self, layer: str, *, frames: Union[None, int, Tuple[int, int]] = None, maps: bool = False
    ) -> dict: ...
    def plan(self, *, chunk: int = 8, threads: int = 1, emaki: str = "emaki") -> dict: ...

class Viewer:
    url: str
    port: int
    def stop(self) -> None: ...
    def __enter__(self) -> "Viewer": ...
    def __exit__(self, *args: object) -> None: ...

def view(
    folder: Union[str, os.PathLike],
    folder_b: Union[None, str, os.PathLike] = None,
    *,
    port: int = 0,
    bind: str = "127.0.0.1",
) -> Viewer: ...

pass_names: list[str]  # the passes render() and template() return, in channel order
pass_channels: dict[str, list[str]]  # their EXR channel names: {'normal': ['normal.X', ...], ...}

