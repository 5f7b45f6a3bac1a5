"""The Rust core (pyo3 bindings). Use the package's public API instead.

The bindings only convert: they check types (TypeError naming the argument),
borrow C-contiguous arrays and release the GIL; every value is checked by
the core (ValueError, its message starting with the argument's name;
softshadow.TooLargeError, a ValueError and a MemoryError, before
allocating). A panic in the core (a bug) raises RuntimeError and leaves the
module usable.
"""

import inspect
from typing import Any, ClassVar, Literal, final

import numpy as np
import numpy.typing as npt
from typing_extensions import disjoint_base

# What `from softshadow._core import *` gives (the module's `__all__`, made
# from the core's table): the method configs, in the table's order, and
# their parts. `softshadow.methods` exports them. This list, `_Ran` and the
# classes of the configs with a keyword form are written by
# `python -m softshadow.experiments.method_stubs`.
# <all:start>
__all__ = [
    "Ssm",
    "Bitmask",
    "Exact",
    "PCSS",
    "Smoothies",
    "ShadowMapping",
    "Auto",
    "ConstantBias",
    "SlopeScaleBias",
    "LinearDepthBias",
    "BackFaces",
    "MidpointBias",
    "PCF",
    "LiSPSM",
    "EyeSpaceBlur",
]
# <all:end>

__version__: str
ENV_THREADS: str

#: (center, normal, up, size)
_Vec3 = tuple[float, float, float]
# A rectangle (center, normal, up, size); a sun (direction, up, angular_size);
# a sun with its map's orthographic space (..., depth_origin, depth_range).
_Light = (
    tuple[_Vec3, _Vec3, _Vec3, tuple[float, float]]
    | tuple[_Vec3, _Vec3, tuple[float, float]]
    | tuple[_Vec3, _Vec3, tuple[float, float], _Vec3, float]
    | tuple[_Vec3, _Vec3, float]
    | tuple[_Vec3, float]
)
_Resolution = int | tuple[int, int]
# A grey value or RGB channels.
_Color = float | list[float] | tuple[float, ...]

@disjoint_base
class _KeywordConfig:
    """The base of the method configs made from the core's table of
    methods: options keyword-only, compared and hashed by value, picklable."""

    __signature__: ClassVar[inspect.Signature]
    @property
    def name(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

# <keyword-configs:start>
# Written by python -m softshadow.experiments.method_stubs: do not edit.

@final
class Ssm(_KeywordConfig):
    """Soft shadow maps (Atty et al. 2005) as published: micro-patches of the occluder maps
    back-projected onto the light, their occlusions summed."""

    def __new__(
        cls,
        *,
        passes: int | None = None,
        occluder_resolution: _Resolution | None = None,
        hierarchy: bool | None = None,
        precision: Literal["f32", "f64", "f16", "f16-batched"] | None = None,
    ) -> Ssm: ...
    @property
    def passes(self) -> int | None: ...
    @property
    def occluder_resolution(self) -> tuple[int, int] | None: ...
    @property
    def hierarchy(self) -> bool | None: ...
    @property
    def precision(self) -> Literal["f32", "f64", "f16", "f16-batched"]: ...

@final
class Bitmask(_KeywordConfig):
    """The same micro-patches marking the light samples they hide in a bit mask per receiver,
    merged by OR (Schwarz & Stamminger 2007)."""

    def __new__(
        cls,
        *,
        samples: int | None = None,
        passes: int | None = None,
        occluder_resolution: _Resolution | None = None,
        hierarchy: bool | None = None,
        gaps: Literal["closed", "open"] | None = None,
    ) -> Bitmask: ...
    @property
    def samples(self) -> int: ...
    @property
    def passes(self) -> int | None: ...
    @property
    def occluder_resolution(self) -> tuple[int, int] | None: ...
    @property
    def hierarchy(self) -> bool | None: ...
    @property
    def gaps(self) -> Literal["closed", "open"]: ...

@final
class Exact(_KeywordConfig):
    """Ray casting against the occluder triangles (a BVH) with stratified light samples,
    jittered deterministically: converges to the true visibility."""

    def __new__(
        cls,
        *,
        samples: int | None = None,
        probe: int | None = None,
        engine: Literal["rays", "masks"] | None = None,
    ) -> Exact: ...
    @property
    def samples(self) -> int: ...
    @property
    def probe(self) -> int | None: ...
    @property
    def engine(self) -> Literal["rays", "masks"] | None: ...

@final
class PCSS(_KeywordConfig):
    """Percentage-closer soft shadows (Fernando 2005), what real-time engines ship: a blocker
    search on the shadow map, the penumbra estimated from the mean blocker depth, a box PCF of
    that width."""

    def __new__(
        cls,
        *,
        max_taps: int | None = None,
        occluder_resolution: _Resolution | None = None,
    ) -> PCSS: ...
    @property
    def max_taps(self) -> int: ...
    @property
    def occluder_resolution(self) -> tuple[int, int] | None: ...

@final
class Smoothies(_KeywordConfig):
    """Fake soft shadows (Chan & Durand 2003): the hard shadow map's umbra and an outer penumbra
    from smoothies on the occluders' silhouette edges, their alpha remapped by 1/(1 - b/r)."""

    def __new__(
        cls,
        *,
        width: float | None = None,
        falloff: Literal["linear", "sine"] | None = None,
        filter: Literal["bilinear"] | None = None,
        occluder_resolution: _Resolution | None = None,
    ) -> Smoothies: ...
    @property
    def width(self) -> float: ...
    @property
    def falloff(self) -> Literal["linear", "sine"]: ...
    @property
    def filter(self) -> Literal["bilinear"]: ...
    @property
    def occluder_resolution(self) -> tuple[int, int] | None: ...

# <keyword-configs:end>

@final
class ConstantBias:
    """A constant depth offset, in depth steps of a 24-bit buffer (2^-24 of the map's depth range)."""

    def __new__(cls, *, constant: float) -> ConstantBias: ...
    @property
    def constant(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class SlopeScaleBias:
    """glPolygonOffset on the z-buffer's own depth."""

    def __new__(cls, *, constant: float | None = None, slope: float | None = None) -> SlopeScaleBias: ...
    @property
    def constant(self) -> float: ...
    @property
    def slope(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class LinearDepthBias:
    """The same offset on a linear depth distribution."""

    def __new__(cls, *, constant: float | None = None, slope: float | None = None) -> LinearDepthBias: ...
    @property
    def constant(self) -> float: ...
    @property
    def slope(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class BackFaces:
    """Only faces turned away from the light are written."""

    def __new__(cls) -> BackFaces: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class MidpointBias:
    """Woo's midpoint between the nearest and second nearest surface."""

    def __new__(cls) -> MidpointBias: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class PCF:
    """Percentage-closer filtering: size x size bilinear taps one texel apart."""

    def __new__(cls, *, size: int | None = None) -> PCF: ...
    @property
    def size(self) -> int: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class LiSPSM:
    """Light-space perspective shadow maps (directional lights)."""

    def __new__(cls, *, n: float | None = None, vector: str | None = None) -> LiSPSM: ...
    @property
    def n(self) -> float | None: ...
    @property
    def vector(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class EyeSpaceBlur:
    """The depth-dependent eye-space blur of the shadow image."""

    def __new__(cls, *, iterations: int | None = None, radius: float | None = None) -> EyeSpaceBlur: ...
    @property
    def iterations(self) -> int: ...
    @property
    def radius(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

_Bias = ConstantBias | SlopeScaleBias | LinearDepthBias | BackFaces | MidpointBias

@final
class ShadowMapping:
    """Scherzer 2005's practical shadow mapping (the eye view)."""

    def __new__(
        cls,
        *,
        resolution: _Resolution | None = None,
        bias: _Bias | None = None,
        filter: PCF | None = None,
        warp: LiSPSM | None = None,
        focus: bool | None = None,
        blur: EyeSpaceBlur | None = None,
    ) -> ShadowMapping: ...
    @property
    def name(self) -> str: ...
    @property
    def resolution(self) -> tuple[int, int]: ...
    @property
    def bias(self) -> _Bias: ...
    @property
    def filter(self) -> PCF | None: ...
    @property
    def warp(self) -> LiSPSM | None: ...
    @property
    def focus(self) -> bool: ...
    @property
    def blur(self) -> EyeSpaceBlur | None: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

@final
class Auto:
    """The rule ``method="auto"`` names (an ``Ssm`` when run), or with a
    target (``error=`` or ``time=``) the plan made from the scene."""

    def __new__(cls, *, error: float | None = None, time: float | None = None) -> Auto: ...
    @property
    def name(self) -> str: ...
    @property
    def error(self) -> float | None: ...
    @property
    def time(self) -> float | None: ...
    def to_dict(self) -> dict[str, Any]: ...
    def rule(self, resolution: _Resolution) -> Ssm:
        """The ``Ssm`` the rule picks for an output resolution, from meshes."""
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...

# The configs a result says ran (every method's, resolved: never Auto), and
# what a call takes.
# <ran:start>
_Ran = Ssm | Bitmask | Exact | PCSS | Smoothies | ShadowMapping
# <ran:end>
_MethodArg = str | _Ran | Auto

@final
class RectLight:
    """A rectangular area light (conventions in src/geom/light.rs)."""

    def __new__(
        cls,
        center: npt.ArrayLike,
        normal: npt.ArrayLike,
        up: npt.ArrayLike,
        size: float | npt.ArrayLike | None = None,
        *,
        radiance: _Color | npt.ArrayLike | None = None,
    ) -> RectLight: ...
    @classmethod
    def canonical(cls, size: float | npt.ArrayLike) -> RectLight:
        """Center at the origin, n = +z, v = +y: the frame of depth-map input."""
    @property
    def center(self) -> tuple[float, float, float]: ...
    @property
    def normal(self) -> tuple[float, float, float]: ...
    @property
    def up(self) -> tuple[float, float, float]: ...
    @property
    def size(self) -> tuple[float, float]: ...
    @property
    def radiance(self) -> tuple[float, float, float]: ...
    @property
    def u(self) -> npt.NDArray[np.float64]: ...
    @property
    def v(self) -> npt.NDArray[np.float64]: ...
    @property
    def n(self) -> npt.NDArray[np.float64]: ...
    @property
    def area(self) -> float: ...
    def corners(self) -> npt.NDArray[np.float64]:
        """The four corners (4, 3): (-u,-v), (+u,-v), (+u,+v), (-u,+v)."""
    def irradiance_at(self, points: npt.ArrayLike, normals: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The unshadowed irradiance (N, 3), RGB, in closed form."""
    def _core_args(self) -> tuple[_Vec3, _Vec3, _Vec3, tuple[float, float]]: ...
    def _emission(self) -> tuple[float, float, float]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __getnewargs_ex__(self) -> tuple[tuple[Any, ...], dict[str, Any]]: ...

@final
class DiskLight:
    """A disk-shaped area light (conventions in src/geom/light.rs)."""

    def __new__(
        cls,
        center: npt.ArrayLike,
        normal: npt.ArrayLike,
        radius: float,
        *,
        radiance: _Color | npt.ArrayLike | None = None,
    ) -> DiskLight: ...
    @property
    def center(self) -> tuple[float, float, float]: ...
    @property
    def normal(self) -> tuple[float, float, float]: ...
    @property
    def radius(self) -> float: ...
    @property
    def radiance(self) -> tuple[float, float, float]: ...
    @property
    def u(self) -> npt.NDArray[np.float64]: ...
    @property
    def v(self) -> npt.NDArray[np.float64]: ...
    @property
    def n(self) -> npt.NDArray[np.float64]: ...
    @property
    def area(self) -> float: ...
    def irradiance_at(self, points: npt.ArrayLike, normals: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The unshadowed irradiance (N, 3), RGB: the disk's form factor."""
    def _core_args(self) -> tuple[_Vec3, _Vec3, float]: ...
    def _emission(self) -> tuple[float, float, float]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __getnewargs_ex__(self) -> tuple[tuple[Any, ...], dict[str, Any]]: ...

@final
class SphereLight:
    """A spherical area light (conventions in src/geom/sphere_light.rs)."""

    def __new__(
        cls,
        center: npt.ArrayLike,
        radius: float,
        *,
        radiance: _Color | npt.ArrayLike | None = None,
    ) -> SphereLight: ...
    @property
    def center(self) -> tuple[float, float, float]: ...
    @property
    def radius(self) -> float: ...
    @property
    def radiance(self) -> tuple[float, float, float]: ...
    @property
    def area(self) -> float: ...
    def irradiance_at(self, points: npt.ArrayLike, normals: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The unshadowed irradiance (N, 3), RGB: the visible cap's form factor."""
    def _core_args(self) -> tuple[_Vec3, float]: ...
    def _emission(self) -> tuple[float, float, float]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __getnewargs_ex__(self) -> tuple[tuple[Any, ...], dict[str, Any]]: ...

@final
class DirectionalLight:
    """A directional light, the sun (conventions in src/geom/sun.rs)."""

    def __new__(
        cls,
        direction: npt.ArrayLike,
        up: npt.ArrayLike,
        angular_size: float | npt.ArrayLike | None = None,
        *,
        irradiance: _Color | npt.ArrayLike | None = None,
    ) -> DirectionalLight: ...
    @property
    def direction(self) -> tuple[float, float, float]: ...
    @property
    def up(self) -> tuple[float, float, float]: ...
    @property
    def angular_size(self) -> tuple[float, float]: ...
    @property
    def irradiance(self) -> tuple[float, float, float]: ...
    @property
    def u(self) -> npt.NDArray[np.float64]: ...
    @property
    def v(self) -> npt.NDArray[np.float64]: ...
    @property
    def n(self) -> npt.NDArray[np.float64]: ...
    def irradiance_at(self, points: npt.ArrayLike, normals: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The unshadowed irradiance (N, 3), RGB: irradiance * max(0, n . s)."""
    def _core_args(self) -> tuple[_Vec3, _Vec3, tuple[float, float]]: ...
    def _emission(self) -> tuple[float, float, float]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __getnewargs_ex__(self) -> tuple[tuple[Any, ...], dict[str, Any]]: ...

@final
class Camera:
    """A pinhole camera (conventions in src/geom/camera.rs)."""

    def __new__(
        cls,
        K: npt.ArrayLike,
        world_from_camera: npt.ArrayLike,
        *,
        resolution: _Resolution,
    ) -> Camera: ...
    @staticmethod
    def from_intrinsics(K: npt.ArrayLike, world_from_camera: npt.ArrayLike, *, resolution: _Resolution) -> Camera:
        """OpenCV's K (no skew, fx == fy) and a rigid world_from_camera."""
    @staticmethod
    def look_at(
        *,
        eye: tuple[float, float, float] | npt.ArrayLike,
        target: tuple[float, float, float] | npt.ArrayLike,
        up: tuple[float, float, float] | npt.ArrayLike,
        fov_y: float,
        resolution: _Resolution,
    ) -> Camera:
        """Mitsuba's perspective sensor with fov_axis="y"; fov_y in degrees."""
    @property
    def eye(self) -> tuple[float, float, float]: ...
    @property
    def forward(self) -> tuple[float, float, float]: ...
    @property
    def right(self) -> tuple[float, float, float]: ...
    @property
    def up(self) -> tuple[float, float, float]: ...
    @property
    def fov_y(self) -> float: ...
    @property
    def resolution(self) -> tuple[int, int]: ...
    @property
    def K(self) -> npt.NDArray[np.float64]: ...
    @property
    def world_from_camera(self) -> npt.NDArray[np.float64]: ...
    def to_opencv(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def to_mitsuba(self) -> dict[str, Any]: ...
    def ray_directions(self) -> npt.NDArray[np.float64]:
        """Unit directions through every pixel centre, (H, W, 3)."""
    def __getnewargs_ex__(self) -> tuple[tuple[Any, ...], dict[str, Any]]: ...

@final
class OptionInfo:
    """One option of a method's config."""

    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str:
        """ "int", "one_of", "bool", "choice" or "resolution"."""
    @property
    def default(self) -> Any:
        """The default; None where it is resolved when the config runs."""
    @property
    def default_doc(self) -> str: ...
    @property
    def doc(self) -> str: ...
    @property
    def min(self) -> int | None: ...
    @property
    def max(self) -> int | None: ...
    @property
    def choices(self) -> list[Any] | None: ...
    @property
    def restricted_on(self) -> dict[str, list[Any]]:
        """Backends that accept only some values: {backend: [values]}."""

@final
class MethodInfo:
    """One method: its config class, options, backends and what it reads."""

    @property
    def name(self) -> str: ...
    @property
    def config(self) -> type[_Ran] | type[Auto]: ...
    @property
    def summary(self) -> str: ...
    @property
    def reads(self) -> list[str]: ...
    @property
    def backends(self) -> list[str]: ...
    @property
    def options(self) -> dict[str, OptionInfo]: ...

@final
class MeshShadowResult:
    """A shadow map of meshes and the light-view maps it came from."""

    @property
    def visibility(self) -> npt.NDArray[np.float32]: ...
    @property
    def receiver_depth(self) -> npt.NDArray[np.float32]: ...
    @property
    def occluder_depth(self) -> npt.NDArray[np.float32] | None: ...
    @property
    def occluder_depth_back(self) -> npt.NDArray[np.float32] | None: ...
    @property
    def occluder_depth_middle(self) -> list[npt.NDArray[np.float32]]: ...
    @property
    def extent(self) -> tuple[float, float]: ...
    @property
    def depth_origin(self) -> tuple[float, float, float] | None: ...
    @property
    def depth_range(self) -> float | None: ...
    @property
    def timings(self) -> dict[str, float]: ...
    @property
    def method(self) -> _Ran: ...
    @property
    def backend(self) -> str: ...
    @property
    def threads(self) -> int: ...
    @property
    def plan(self) -> list[tuple[str, bool, str]] | None: ...
    @property
    def planned_method(self) -> _Ran | None: ...
    @property
    def error_estimate(self) -> ErrorEstimate | None: ...

@final
class EyeResult:
    """An image: visibility, G-buffer, light-view maps, and what ran it."""

    @property
    def visibility(self) -> npt.NDArray[np.float32]: ...
    @property
    def shaded(self) -> npt.NDArray[np.float32]: ...
    @property
    def unshadowed(self) -> npt.NDArray[np.float32]: ...
    @property
    def albedo(self) -> npt.NDArray[np.float32]: ...
    @property
    def depth(self) -> npt.NDArray[np.float32]: ...
    @property
    def position(self) -> npt.NDArray[np.float64]: ...
    @property
    def normal(self) -> npt.NDArray[np.float32]: ...
    @property
    def mesh_id(self) -> npt.NDArray[np.int32]: ...
    @property
    def shadow_maps(self) -> list[npt.NDArray[np.float32]]: ...
    @property
    def map_extent(self) -> tuple[float, float] | None: ...
    @property
    def depth_origin(self) -> tuple[float, float, float] | None: ...
    @property
    def depth_range(self) -> float | None: ...
    @property
    def timings(self) -> dict[str, float]: ...
    @property
    def method(self) -> _Ran: ...
    @property
    def backend(self) -> str: ...
    @property
    def threads(self) -> int: ...
    @property
    def plan(self) -> list[tuple[str, bool, str]] | None: ...
    @property
    def planned_method(self) -> _Ran | None: ...
    @property
    def error_estimate(self) -> ErrorEstimate | None: ...

@final
class ErrorEstimate:
    """A result's error estimated from exact rays at a random subset of its
    pixels: the mean |V - V_ref| over the pixels the exact rays find in
    shadow, with a 95% confidence interval (docs/accuracy.md)."""

    @property
    def error(self) -> float:
        """The estimated error over the shadowed pixels."""
    @property
    def interval(self) -> tuple[float, float]:
        """The 95% confidence interval ``(low, high)``; ``(0.0, 1.0)`` when
        no traced pixel is in shadow."""
    @property
    def traced(self) -> int:
        """Pixels traced with exact rays."""
    @property
    def shadowed(self) -> int:
        """Of those, the pixels the exact rays found in shadow."""
    @property
    def samples(self) -> int:
        """Light samples per traced pixel."""
    @property
    def seconds(self) -> float:
        """Seconds the estimate took."""

def render(
    meshes: list[tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]],
    lights: list[_Light],
    camera: Camera,
    method: _MethodArg,
    *,
    map_resolution: _Resolution | None = None,
    normal_offset: float | None = None,
    depth_bias: float | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: _Resolution | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = ...,  # "cpu" (shown as ... by the extension: a converted default)
    threads: int | None = None,
    emission: list[_Color | None] | None = None,
    albedo: _Color | list[_Color] | None = None,
    estimate_error: str | None = None,
    prepared: Prepared | None = None,
    materials: list[tuple[str, tuple[float, float, float], Any, Any] | None] | None = None,
) -> list[EyeResult]:
    """The eye view, one result per light (the first hits shared): first
    hits, then each pixel's visibility with every mesh casting and
    receiving, then the shading (``emission`` each light's radiance or
    irradiance, ``albedo`` per mesh; the core's defaults for None);
    ``prepared`` keeps what the meshes alone make for the next call."""

@final
class Prepared:
    """What renders of one scene built and kept for the next ones: the
    checked triangles and the shadow rays' BVH per light orientation
    (``softshadow.Scene`` holds one). Thread-safe."""

    def __init__(self) -> None: ...
    def clear(self) -> None:
        """Forgets what was kept."""
    @property
    def held(self) -> tuple[bool, int]:
        """Whether the triangles are kept, and how many trees."""

def light_emission(arg: str, value: _Color | None = None) -> list[float]:
    """A light's emission (``arg``: "radiance" or "irradiance") checked:
    finite and >= 0, a number or 3; None gives the default."""

def srgb_to_linear(values: npt.NDArray[np.float64]) -> npt.NDArray[np.float32]:
    """Linear float32 of sRGB-encoded values (any shape), clipped to [0, 1]."""

def irradiance(
    light: _Light,
    points: npt.NDArray[np.float64],
    normals: npt.NDArray[np.float64],
    emission: _Color | None = None,
) -> npt.NDArray[np.float64]:
    """The unshadowed irradiance (N, 3) at points (N, 3) with normals (N, 3)."""

@final
class DepthShadowResult:
    """Depth maps shaded."""

    @property
    def visibility(self) -> npt.NDArray[np.float32]: ...
    @property
    def depth_range(self) -> float | None: ...
    @property
    def timings(self) -> dict[str, float]: ...
    @property
    def method(self) -> _Ran: ...
    @property
    def backend(self) -> str: ...
    @property
    def threads(self) -> int: ...

def capabilities() -> dict[str, MethodInfo]:
    """{method name: MethodInfo} for every method."""

def limits() -> dict[str, Any]:
    """The limits that are not one method's."""

def check_mesh(arg: str, vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.uint32]) -> None:
    """Refuses non-finite vertices and face indices out of range, naming ``arg``."""

def light_frame(light: _Light) -> tuple[list[float], list[float], list[float]]:
    """Validates a light and returns its frame (u, v, n) as unit vectors."""

def shadow_map_from_meshes(
    occ_vertices: npt.NDArray[np.float64],
    occ_faces: npt.NDArray[np.uint32],
    rec_vertices: npt.NDArray[np.float64],
    rec_faces: npt.NDArray[np.uint32],
    light: _Light,
    resolution: _Resolution,
    extent: tuple[float, float] | None,
    method: _MethodArg,
    *,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: _Resolution | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = ...,  # "cpu" (shown as ... by the extension: a converted default)
    threads: int | None = None,
    estimate_error: str | None = None,
) -> MeshShadowResult:
    """Meshes -> light-view maps -> visibility, on ``backend`` ("cpu", "gpu"
    or "auto"). ``method`` is a config, or a name with the loose options."""

def shadow_map_from_scene(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.uint32],
    light: _Light,
    resolution: _Resolution,
    extent: tuple[float, float] | None,
    method: _MethodArg,
    *,
    normal_offset: float | None = None,
    depth_bias: float | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: _Resolution | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = ...,  # "cpu" (shown as ... by the extension: a converted default)
    threads: int | None = None,
    estimate_error: str | None = None,
) -> MeshShadowResult:
    """A scene shadowing itself (every mesh as one) -> light-view maps ->
    visibility, each receiver texel shaded at its own surface point."""

def shadow_map_from_depth(
    occluder_depth: npt.NDArray[np.float32],
    occluder_depth_back: npt.NDArray[np.float32] | None,
    receiver_depth: npt.NDArray[np.float32],
    light_size: tuple[float, float] | None,
    extent: tuple[float, float],
    method: _MethodArg,
    *,
    angular_size: tuple[float, float] | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: _Resolution | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = ...,  # "cpu" (shown as ... by the extension: a converted default)
    threads: int | None = None,
) -> DepthShadowResult:
    """Visibility from depth maps (the occluder maps may have their own
    resolution; the output has the receiver map's)."""

def sample_points(
    light: _Light,
    extent: tuple[float, float],
    resolution: tuple[int, int],
    points: npt.NDArray[np.float64],
    method: _MethodArg,
    *,
    occluder_depth: npt.NDArray[np.float32] | None = None,
    occluder_depth_back: npt.NDArray[np.float32] | None = None,
    occ_vertices: npt.NDArray[np.float64] | None = None,
    occ_faces: npt.NDArray[np.uint32] | None = None,
    occluder_depth_middle: list[npt.NDArray[np.float32]] | None = None,
    threads: int | None = None,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.bool_]]:
    """Visibility at world points (N, 3), and whether each lies inside the map."""

def receiver_points(
    receiver_depth: npt.NDArray[np.float32],
    light: _Light,
    extent: tuple[float, float],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]:
    """World points (M, 3) of the texels with a receiver, and their flat indices."""

class GpuUnavailableError(RuntimeError):
    """backend="gpu" was asked for and no GPU adapter can be opened."""

class TooLargeError(ValueError, MemoryError):
    """A request refused before allocating because it would need too much
    memory. Both a ValueError (a bad argument) and a MemoryError."""

def gpu_available() -> bool:
    """Whether a GPU adapter opens (software ones such as lavapipe count)."""

def gpu_info() -> dict[str, Any]:
    """The adapter backend="gpu" uses."""

def _panic_for_tests(in_worker: bool) -> None:
    """Panics on purpose to test that panics become RuntimeError."""
