"""The calls: the light view's :func:`soft_shadow_map` (from meshes) and
:func:`soft_shadow_map_from_depth` (from light-view depth maps), both
returning a :class:`~softshadow.results.ShadowMap`; the eye view's
:func:`render`, returning an :class:`~softshadow.results.Image`; and the GPU
queries :func:`gpu_available` and :func:`gpu_info`.

Each call converts its arguments' types and hands them to ``_core``, which
builds the method config (a typed config, or a name with loose options),
resolves it for the call, checks every value, and runs it on the chosen
backend (``backend=`` is passed through): ``"cpu"`` (all cores), ``"gpu"``
(wgpu; never falls back: no adapter raises
:class:`~softshadow.errors.GpuUnavailableError`) or ``"auto"`` (the GPU when
a real, non-software adapter is present and runs the call, else the CPU).
``SOFTSHADOW_GPU=off`` in the environment hides every adapter.

The eye view (:func:`render`): a scene seen through a
:class:`softshadow.Camera`, every mesh casting and receiving shadows (its own
included), lit by a :class:`RectLight` or a :class:`DirectionalLight`. The
core casts the pixel-centre rays (the G-buffer), then shades each pixel's
surface point with the method: ``exact`` traces shadow rays, the map methods
read light-view occluder maps focused on what the camera sees. See
docs/eye_view.md. Every image also holds the direct lighting of Lambertian
surfaces, unshadowed and times the visibility (``Image.unshadowed``,
``Image.shaded``; docs/shading.md).
"""

from __future__ import annotations

import numbers
from typing import Any, Literal

import numpy as np

from . import _core
from . import _validate as check
from .lights import LIGHT_TYPES, DirectionalLight, Light, RectLight
from .methods import MethodConfig
from .results import Image, ShadowMap, plan_from_core
from .scene import Camera, Scene


def soft_shadow_map(
    scene: Scene,
    light: Light,
    *,
    resolution: int | tuple[int, int] = 256,
    extent: float | tuple[float, float] | None = None,
    method: str | MethodConfig = "ssm",
    backend: str = "cpu",
    threads: int | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: int | tuple[int, int] | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    normal_offset: float | None = None,
    depth_bias: float | None = None,
    estimate_error: bool | Literal["timed", "fixed"] = False,
) -> ShadowMap:
    """Soft shadow map of ``scene``'s occluders on its receivers, or of a
    scene shadowing itself.

    Parameters
    ----------
    scene, light
        The geometry and the light: a rectangle, a disk (``bitmask`` keeps
        its samples on the disk, ``exact`` samples it; ``"auto"`` takes
        ``bitmask``, the default ``"ssm"`` refuses it), or a
        :class:`DirectionalLight`, whose maps are orthographic (world
        half-extents; depth from the plane across the light touching the
        scene, ``sm.depth_origin``). With the split scene
        (``Scene(occluders=..., receivers=...)``) occluders shadow receivers
        and nothing shadows itself (the paper's setting). With
        ``Scene(meshes=...)`` every mesh casts and receives: the receiver map
        is the nearest surface seen from the light, and each of its texels is
        shaded at its own surface point as :func:`softshadow.render` shades a
        pixel's (``exact`` with offset shadow rays, the map methods with the
        biases ``normal_offset`` and ``depth_bias``, in texels, and the
        tangent-plane bound; CPU only); ``sample`` is then not available.
    resolution
        ``int`` for a square map or ``(W, H)``. The receiver map shares it, and
        the occluder maps unless the method's ``occluder_resolution`` says
        otherwise.
    extent
        Tangent half-extents ``(tx, ty)`` of the map (a number means both).
        ``None`` fits them to where the occluders' shadows (umbra and penumbra)
        can fall on the receivers: an occluder point at tangent ``x`` and depth
        ``z`` shadows at most ``|x| + (Lx/2)(1/z - 1/z_far)`` away from the
        light's axis, ``z_far`` being the farthest receiver depth; the extent is
        the largest such bound over occluder vertices (exact for triangles), cut
        to the receivers' own extent, or to the occluders' own where that is
        wider (by no more than the largest penumbra reach): the map methods
        see only occluders inside the map, and one just outside the
        receivers can shadow them. Fitting needs every occluder vertex in
        front of the light's plane. Tangent half-extents are at most
        ``softshadow.limits()["max_extent"]``.
        Geometry at or behind the light's plane casts no shadow (it is
        clipped), and an occluder at or beyond a receiver's depth does not
        shadow that receiver.
    method
        A typed config, ``Ssm(...)``, ``Bitmask(...)``, ``Exact(...)``,
        ``PCSS(...)``, ``Smoothies(...)`` or ``Auto()``, or a method's name
        (``"ssm"``, ``"bitmask"``, ``"exact"``, ``"pcss"``, ``"smoothies"``,
        ``"auto"``) with its options given beside it (``method="bitmask",
        samples=64`` is ``method=Bitmask(samples=64)``). ``"ssm"``: soft shadow
        maps as published (Atty et al. 2005). ``"bitmask"``: the micro-patches
        mark the light samples they hide in a bit mask per receiver, merged by
        OR (Schwarz & Stamminger 2007). ``"exact"``: ray casting against the
        occluder triangles with stratified, deterministically jittered light
        samples. ``"pcss"``: percentage-closer soft shadows (Fernando 2005);
        ``"smoothies"``: Chan & Durand 2003 (docs/methods/). ``"auto"``:
        ``"ssm"`` with two passes and occluder maps at a quarter of
        ``resolution`` (at least 64), the settings the study found furthest
        ahead of ray tracing at equal error. ``ShadowMapping`` reads a camera:
        it is the eye view's (:func:`render`). The result's ``method`` is the
        config that ran. :func:`softshadow.capabilities` lists every method
        and option with its default, limits and the backends that restrict it.
    passes, samples, occluder_resolution, hierarchy, precision
        The options of a method given by name (refused beside a typed config,
        and where they do not apply): ``passes``, the occluder depth layers
        (1, the front; 2, front and back, §3.5; 3 to 8 adds layers found by
        depth peeling; default 2); ``samples``, light samples per receiver
        (``bitmask``: 16, 64, 256 or 1024; ``exact``: up to
        ``limits()["max_samples"]``; default 256);
        ``occluder_resolution``, the occluder maps' resolution (default: the
        output's; coarser maps cost much less, their error is §4.1.1's);
        ``hierarchy``, the occluder min/max pyramid (default on for
        ``bitmask`` on the CPU, off for ``ssm`` and on the GPU, which has
        none); ``precision``, how ``ssm`` sums occlusions (``"f32"``
        two-level sums, ``"f64"``, ``"f16"`` emulated FP16 blending,
        ``"f16-batched"`` the paper's sqrt(M) batches; see
        ``python -m softshadow.experiments.fp16`` and docs/precision/fp16.md).
    backend
        ``"cpu"`` (all cores); ``"gpu"``: rasterization, shading and the
        merge of the layers on the GPU (wgpu, Vulkan), for every method, with
        one upload of the set-up triangles (and, for ``"exact"``, of the BVH
        built on the CPU) and one readback. It never falls back: no adapter
        raises ``GpuUnavailableError``. ``"auto"``: the GPU when a real
        (non-software) one is present, else the CPU. ``timings`` then hold the device's stages
        (``gpu_*``, from timestamp queries where the adapter has them).
        The result's ``backend`` says which ran.
    threads
        Worker threads the core may use for this call (1 to
        ``softshadow.limits()["max_threads"]``); default:
        ``SOFTSHADOW_THREADS`` from the environment, else every core. The
        result does not depend on it.
    estimate_error
        Keyword-only. Also estimate the map's error (``sm.error_estimate``),
        as :func:`render` does for an image: exact rays (1024 light samples;
        for ``exact``, four times its own) from a random subset of the
        receiver texels, in 4 x 2 tiles, three quarters of them in the map's
        shadow, each texel's samples keyed as ``exact`` keys them; the mean
        |V - V_ref| over those the rays find in shadow, with a 95% interval
        (docs/accuracy.md). ``True`` (or ``"timed"``): as many texels as fit
        in a tenth of the call; ``"fixed"``: 1024 texels whatever the time,
        the same estimate for the same inputs. Always on, fixed, for
        ``Auto(error=...)`` and ``Auto(time=...)`` of a split scene, whose
        run is repeated with ``exact`` (more samples) while the estimate's
        upper end misses the target (docs/methods/auto.md). The estimate
        traces on the CPU whatever the backend.

    The light's size must lie within about [1e-30, 1e30] times the receivers'
    depth (the kernels compute in f32, in a depth unit near the receivers'
    depth, so any scale of scene works), or (0, 0): a point light, whose
    shadow is the hard shadow map the methods converge to.
    Bad values raise ValueError or TypeError naming the argument; a map too
    large to allocate raises :class:`softshadow.TooLargeError` (a ValueError
    and a MemoryError) before allocating; an internal error raises
    RuntimeError and leaves the module usable.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: must be a softshadow.Scene, got {type(scene).__name__}")
    if not isinstance(light, LIGHT_TYPES):
        raise TypeError(f"light: must be a softshadow light, got {type(light).__name__}")
    ext = None if extent is None else check.pair("extent", extent)
    (ov, of), (rv, rf) = scene.occluder_mesh, scene.receiver_mesh
    loose: dict[str, Any] = dict(
        estimate_error=_draw(estimate_error),
        passes=passes,
        samples=samples,
        occluder_resolution=occluder_resolution,
        hierarchy=hierarchy,
        precision=precision,
        backend=backend,
        threads=threads,
    )
    if scene.split:
        if normal_offset is not None or depth_bias is not None:
            raise TypeError("normal_offset: the biases are for scenes shadowing themselves (Scene(meshes=...))")
        r = _core.shadow_map_from_meshes(ov, of, rv, rf, light._core_args(), resolution, ext, method, **loose)
    else:
        r = _core.shadow_map_from_scene(
            ov,
            of,
            light._core_args(),
            resolution,
            ext,
            method,
            normal_offset=normal_offset,
            depth_bias=depth_bias,
            **loose,
        )
    return ShadowMap(
        visibility=r.visibility,
        receiver_depth=r.receiver_depth,
        occluder_depth=r.occluder_depth,
        occluder_depth_back=r.occluder_depth_back,
        light=light,
        extent=r.extent,
        method=r.method,
        extent_fitted=extent is None,
        timings=dict(r.timings),
        occluder_depth_middle=tuple(r.occluder_depth_middle),
        backend=r.backend,
        threads=r.threads,
        _occluder_mesh=(ov, of) if r.occluder_depth is None else None,
        self_shadowing=not scene.split,
        depth_origin=r.depth_origin,
        depth_range=r.depth_range,
        plan=plan_from_core(r.plan, r.method, r.planned_method),
        error_estimate=r.error_estimate,
    )


def _draw(estimate_error: object) -> str | None:
    """The core's draw for ``estimate_error`` (``True`` is "timed"; a bad
    name is refused by the core, naming the argument)."""
    if not isinstance(estimate_error, (bool, str)):
        raise TypeError(f'estimate_error: must be True, False, "timed" or "fixed", got {type(estimate_error).__name__}')
    return ("timed" if estimate_error else None) if isinstance(estimate_error, bool) else estimate_error


def soft_shadow_map_from_depth(
    occluder_depth: np.ndarray,
    receiver_depth: np.ndarray,
    *,
    light_size: Any = None,
    extent: Any,
    angular_size: Any = None,
    occluder_depth_back: np.ndarray | None = None,
    method: str | MethodConfig = "ssm",
    backend: str = "cpu",
    threads: int | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: int | tuple[int, int] | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
) -> ShadowMap:
    """Soft shadow map from light-view depth maps rendered by the caller.

    The maps follow the package's conventions (see :class:`ShadowMap`): planar
    depth, float, ``inf`` where empty, over one extent. The occluder maps may
    have their own resolution (both of one shape); the output has the
    receiver map's. With
    ``occluder_depth_back`` the result is the two-pass one. ``light_size`` is the
    light's (width, height) in the depth's units; ``extent`` the maps' tangent
    half-extents. The result's ``light`` is the canonical light of that size
    (center at the origin, normal +z, up +y), so ``sample`` takes points in that
    frame. ``method``, its options, ``backend`` and ``threads`` are as
    for :func:`soft_shadow_map` (``passes`` and ``occluder_resolution``, when
    given, must match the maps given) (``"gpu"``: the maps go up
    once, the shading runs on the device, the visibility comes back).

    Depths may be any float32 value > 0 (subnormal to 3.4e38) or +inf; NaN,
    zero and negative depths are refused (ValueError naming the map). Any
    real float array is accepted (converted to C-contiguous float32); integer
    and complex arrays raise TypeError. ``light_size`` must lie within
    about [1e-30, 1e30] times the receivers' depth, or be (0, 0) for a
    point light (hard shadows).

    Orthographic maps of a directional light: pass ``angular_size`` (full
    angles in degrees, see :class:`DirectionalLight`) instead of
    ``light_size``; depths are then distances >= 0 from the depth origin
    along the light's direction (+inf where empty) and ``extent`` the maps'
    half-extents in world units. The result's ``light`` is the directional
    light of that size travelling along +z (up +y), its depth origin at the
    world origin, so ``sample`` takes points in that frame.
    """
    rec = check.depth_map("receiver_depth", receiver_depth)
    front = check.depth_map("occluder_depth", occluder_depth)
    back = None if occluder_depth_back is None else check.depth_map("occluder_depth_back", occluder_depth_back)
    if (light_size is None) == (angular_size is None):
        raise TypeError("light_size: pass either light_size (a rectangle's) or angular_size (a directional light's)")
    size = None if light_size is None else check.pair("light_size", light_size)
    angles = None if angular_size is None else check.pair("angular_size", angular_size)
    ext = check.pair("extent", extent)
    r = _core.shadow_map_from_depth(
        front,
        back,
        rec,
        size,
        ext,
        method,
        angular_size=angles,
        passes=passes,
        samples=samples,
        occluder_resolution=occluder_resolution,
        hierarchy=hierarchy,
        precision=precision,
        backend=backend,
        threads=threads,
    )
    return ShadowMap(
        visibility=r.visibility,
        receiver_depth=rec,
        occluder_depth=front,
        occluder_depth_back=back,
        light=(
            RectLight.canonical(size)
            if size is not None
            else DirectionalLight(direction=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0), angular_size=angles)
        ),
        extent=ext,
        method=r.method,
        extent_fitted=False,
        timings=dict(r.timings),
        backend=r.backend,
        threads=r.threads,
        depth_origin=None if size is not None else (0.0, 0.0, 0.0),
        depth_range=r.depth_range,
    )


def render(
    scene: Scene,
    light: Light | list[Light] | tuple[Light, ...],
    camera: Camera,
    method: str | MethodConfig = "auto",
    *,
    map_resolution: Any = None,
    normal_offset: float | None = None,
    depth_bias: float | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: Any = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = "cpu",
    threads: int | None = None,
    albedo: Any = None,
    estimate_error: bool | Literal["timed", "fixed"] = False,
) -> Image:
    """Renders the visibility and shaded images of ``scene`` under ``light`` seen by ``camera``.

    ``light`` is one light, or a list of up to ``limits()["lights"]`` lights.
    With a list each light is rendered as a call with it alone would render
    it (its own method plan, maps focused on what it lights; the first hits
    are computed once), ``img.visibility`` is (L, H, W), one channel per
    light in order, ``shaded`` and ``unshadowed`` are the sums over the
    lights, and ``img.parts`` holds each light's own image.

    Every mesh casts and receives shadows, its own included (the far side of
    a closed mesh is in its own umbra). A :class:`RectLight` or
    :class:`DiskLight` lights its ``n`` side only: points at or behind its
    plane get 0. A :class:`DiskLight` takes ``exact``, ``bitmask`` and
    ``shadow_mapping``, a :class:`SphereLight` ``exact`` on the CPU only;
    the other methods refuse them with the reason (docs/lights.md).

    The image also holds the direct lighting of Lambertian surfaces
    (docs/shading.md): ``unshadowed = albedo / pi * E``, E the irradiance
    from the light's ``radiance`` (or the sun's ``irradiance``) in closed
    form at the pixel's point and geometric normal (facing the camera), and
    ``shaded`` the shadowed direct light: ``exact``, ``bitmask``, ``ssm``
    and ``pcss`` weigh each of their samples (rays, light samples,
    micro-patches, filter cells) by what it adds to the irradiance
    (cos θ cos θ' / r^2), so ``shaded = unshadowed * V_w`` with V_w the
    share of the irradiance the clear ones carry; ``smoothies`` and
    ``shadow_mapping`` shade with ``unshadowed * visibility``, which weights
    every part of the light alike (exact where a pixel is fully lit or in
    umbra). ``img.albedo`` is the albedo shaded
    with: each mesh's colours, materials and textures read by
    :meth:`Scene.from_trimesh`, or ``albedo=``. The shading runs on the CPU
    after the visibility, on every backend.

    method
        A config or name, as for :func:`soft_shadow_map`. ``exact`` traces
        stratified shadow rays from each pixel's surface point, offset off
        the surface as Mitsuba's ``spawn_ray_to`` does. The default
        (``"auto"``, ``Auto()``) runs ``Exact(samples=256, probe=16)`` on the
        CPU (only the pixels a 16-sample probe is unsure of trace all 256)
        and ``Exact(samples=256)`` on the GPU (docs/methods/auto.md). The map
        methods (``ssm``, ``bitmask``, ``auto`` with ``ssm``'s options)
        rasterize light-view occluder layers of every mesh, focused on what
        the camera sees, and shade each pixel at its own point.
        ``Auto(error=e)`` plans for the eye view's error
        (mean |V - V_ref| over the pixels, :func:`softshadow.metrics.compare_images`):
        the rule's maps where their measured error is within ``e``, else
        ``exact`` with the samples its measured error law asks for;
        ``img.plan`` says why (docs/methods/auto.md).
    map_resolution
        The light-view maps' (W, H); by default chosen so that a texel
        covers about one pixel's footprint (the median over the image). A
        config's ``occluder_resolution`` overrides it.
    normal_offset, depth_bias
        The map methods' self-shadowing biases in texels (defaults in the
        core, see docs/eye_view.md): the surface point moves
        ``normal_offset`` texels along its normal, then ``depth_bias``
        texels toward the light.
    backend
        ``"cpu"`` (default), ``"gpu"`` or ``"auto"``: on the GPU the first
        hits, the shadow rays, the occluder layers and the gather at the
        pixels' points run on the device, with the same answers (see
        docs/gpu.md; hard lights on the map methods stay on the CPU).
    albedo
        Keyword-only. The meshes' diffuse albedo: a number (grey) or an RGB
        triple for every mesh, or a sequence with one number or triple per
        mesh of ``scene.meshes`` (three numbers are always one RGB triple).
        Values in [0, 1]. It overrides the meshes' own colours
        (``scene.materials``). Default (``None``): each mesh's colours, or
        0.8 grey (the core's default) for a mesh without any.
    estimate_error
        Keyword-only. Also estimate the image's error (``img.error_estimate``):
        exact stratified rays (256 light samples; for ``exact``, four times
        its own) at a random subset of the visible pixels, three quarters of
        them in the image's shadow; the mean |V - V_ref| over those the rays
        find in shadow, with a 95% interval (docs/accuracy.md). ``True`` (or
        ``"timed"``): as many pixels as fit in a tenth of the call, so the
        estimate depends on the machine's speed; ``"fixed"``: 1024 pixels
        whatever the time, the same estimate for the same inputs. Always on,
        fixed, for ``Auto(error=...)`` and ``Auto(time=...)``.

    Bad values raise ValueError or TypeError naming the argument.
    """
    draw = _draw(estimate_error)
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: must be a softshadow.Scene, got {type(scene).__name__}")
    several = not isinstance(light, LIGHT_TYPES)
    lights = _lights(light)
    if not isinstance(camera, Camera):
        raise TypeError(f"camera: must be a softshadow.Camera, got {type(camera).__name__}")
    runs = _core.render(
        scene.meshes,
        [lt._core_args() for lt in lights],
        camera,
        method,
        map_resolution=map_resolution,
        normal_offset=None if normal_offset is None else _number("normal_offset", normal_offset),
        depth_bias=None if depth_bias is None else _number("depth_bias", depth_bias),
        passes=passes,
        samples=samples,
        occluder_resolution=occluder_resolution,
        hierarchy=hierarchy,
        precision=precision,
        backend=backend,
        threads=threads,
        emission=[lt._emission() for lt in lights],
        albedo=check.color(albedo),
        estimate_error=draw,
        prepared=scene.prepared,
        materials=_materials(scene),
    )
    parts = tuple(_image(r, lt, camera) for r, lt in zip(runs, lights, strict=True))
    if not several:
        return parts[0]
    return _sum_of(parts, camera)


def _materials(scene: Scene) -> list[Any] | None:
    """The meshes' materials as the core takes them (a mesh appended to
    ``scene.meshes`` after the scene was made has none); None when no mesh
    has one. The core checks each against its mesh, naming
    ``materials[k]``."""
    materials = list(scene.materials[: len(scene.meshes)])
    materials += [None] * (len(scene.meshes) - len(materials))
    if all(m is None for m in materials):
        return None
    return [None if m is None else m.to_core() for m in materials]


def _lights(value: Any) -> list[Light]:
    """One light, or a list or tuple of them, as a list; TypeError or
    ValueError naming ``light`` (``light[k]``) otherwise."""
    if isinstance(value, LIGHT_TYPES):
        return [value]
    if not isinstance(value, (list, tuple)):
        raise TypeError(f"light: must be a light or a list of lights, got {type(value).__name__}")
    if not value:
        raise ValueError("light: the list of lights is empty")
    if len(value) > _core.limits()["lights"]:
        raise ValueError(f"light: at most {_core.limits()['lights']} lights in one call, got {len(value)}")
    for k, lt in enumerate(value):
        if not isinstance(lt, LIGHT_TYPES):
            raise TypeError(f"light[{k}]: must be a softshadow light, got {type(lt).__name__}")
    return list(value)


def _image(r: Any, light: Light, camera: Camera) -> Image:
    """One light's image from the core's result."""
    return Image(
        visibility=r.visibility,
        shaded=r.shaded,
        unshadowed=r.unshadowed,
        depth=r.depth,
        position=r.position,
        normal=r.normal,
        mesh_id=r.mesh_id,
        shadow_maps=tuple(r.shadow_maps),
        map_extent=r.map_extent,
        method=r.method,
        camera=camera,
        light=light,
        timings=dict(r.timings),
        backend=r.backend,
        threads=r.threads,
        depth_origin=r.depth_origin,
        depth_range=r.depth_range,
        plan=plan_from_core(r.plan, r.method, r.planned_method),
        error_estimate=r.error_estimate,
        albedo=r.albedo,
    )


def _one(value: Any) -> tuple[Any, ...]:
    """A part's light or method (one each) as a tuple of one."""
    return value if isinstance(value, tuple) else (value,)


def _sum_of(parts: tuple[Image, ...], camera: Camera) -> Image:
    """Several lights' images as one: visibility (L, H, W), the shading
    summed (in float64, rounded once), the first part's G-buffer (they share
    it), timings summed per stage."""
    timings: dict[str, float] = {}
    for p in parts:
        for stage, seconds in p.timings.items():
            timings[stage] = timings.get(stage, 0.0) + seconds
    first = parts[0]
    shaded = np.zeros(first.shaded.shape, np.float64)
    unshadowed = np.zeros(first.unshadowed.shape, np.float64)
    for p in parts:
        shaded += p.shaded
        unshadowed += p.unshadowed
    methods: tuple[MethodConfig, ...] = tuple(m for p in parts for m in _one(p.method))
    lights: tuple[Light, ...] = tuple(lt for p in parts for lt in _one(p.light))
    return Image(
        visibility=np.stack([p.visibility for p in parts]),
        shaded=shaded.astype(np.float32),
        unshadowed=unshadowed.astype(np.float32),
        depth=first.depth,
        position=first.position,
        normal=first.normal,
        mesh_id=first.mesh_id,
        shadow_maps=(),
        map_extent=None,
        method=methods,
        camera=camera,
        light=lights,
        timings=timings,
        backend=first.backend,
        threads=first.threads,
        albedo=first.albedo,
        parts=parts,
    )


def gpu_available() -> bool:
    """Whether ``backend="gpu"`` can run here: a GPU adapter opens (a software
    one such as Mesa's lavapipe counts; see :func:`gpu_info`)."""
    return bool(_core.gpu_available())


def gpu_info() -> dict[str, Any]:
    """The adapter ``backend="gpu"`` uses: ``name``, ``backend`` (the graphics
    API, "vulkan"), ``device_type`` ("discrete_gpu", "integrated_gpu",
    "virtual_gpu", "cpu" or "other"), ``driver`` and ``software`` (True for a
    CPU renderer like lavapipe, which ``backend="auto"`` does not pick).
    Raises GpuUnavailableError when there is none."""
    return dict(_core.gpu_info())


def _number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: must be a number, got {type(value).__name__}")
    return float(value)
