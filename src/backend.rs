//! Which backend runs a call, and the dispatch to it: the CPU pipelines
//! (`crate::pipeline`, rayon) or the GPU's (`crate::gpu`, wgpu compute).
//! Both take the same inputs and return the same outputs; a Rust user picks
//! one with [`BackendChoice`], the bindings only pass the user's string.
//!
//! Every call resolves its method config here, against the backend that will
//! run it (the GPU has no hierarchy and sums in f32 only), and runs on the
//! worker threads `threads.rs` allows.

use crate::error::{Error, Result};
use crate::geom::light::{check_light_size, is_point, MapGrid};
use crate::geom::light_space::{Light, LightSpace};
use crate::geom::mesh::MeshRef;
use crate::geom::sun::{DirectionalLight, SunSpace};
use crate::methods::config::{check_resolution, CallContext};
use crate::methods::MethodConfig;
use crate::pipeline::{self, MapSettings, ShadowResult, Timings};
use crate::threads;

/// A backend that runs shadow maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Backend {
    /// All cores (rayon); always built.
    Cpu,
    /// wgpu compute (cargo feature `gpu`).
    Gpu,
}

/// What a user asks for: a backend, or `Auto`: the GPU when a real
/// (non-software) adapter is present and runs the call, else the CPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BackendChoice {
    Cpu,
    Gpu,
    Auto,
}

impl Backend {
    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Gpu => "gpu",
        }
    }

    /// The backends this build has.
    pub fn built() -> &'static [Backend] {
        if cfg!(feature = "gpu") {
            &[Backend::Cpu, Backend::Gpu]
        } else {
            &[Backend::Cpu]
        }
    }
}

impl BackendChoice {
    /// `backend=` by name: "cpu", "gpu" or "auto".
    pub fn parse(name: &str) -> Result<BackendChoice> {
        match name {
            "cpu" => Ok(BackendChoice::Cpu),
            "gpu" => Ok(BackendChoice::Gpu),
            "auto" => Ok(BackendChoice::Auto),
            other => Err(Error::invalid(
                "backend",
                format!("must be one of \"cpu\", \"gpu\", \"auto\", got {other:?}"),
            )),
        }
    }

    /// The backend that runs `method` with a light of `light_size`: "auto"
    /// takes a real GPU where the config resolves there (and the light is
    /// not a point, which has no GPU kernel).
    fn pick(self, method: &MethodConfig, ctx: CallContext, light_size: [f64; 2]) -> Backend {
        match self {
            BackendChoice::Cpu => Backend::Cpu,
            BackendChoice::Gpu => Backend::Gpu,
            BackendChoice::Auto => {
                let gpu = CallContext {
                    backend: Backend::Gpu,
                    ..ctx
                };
                if real_gpu() && !is_point(light_size) && method.resolve(&gpu).is_ok() {
                    Backend::Gpu
                } else {
                    Backend::Cpu
                }
            }
        }
    }
}

/// Whether a real (non-software) GPU adapter opens: what "auto" needs.
#[cfg(feature = "gpu")]
pub(crate) fn real_gpu() -> bool {
    crate::gpu::info().is_ok_and(|i| !i.software)
}

#[cfg(not(feature = "gpu"))]
pub(crate) fn real_gpu() -> bool {
    false
}

/// What a GPU request gets from a build without the `gpu` feature.
#[cfg(not(feature = "gpu"))]
pub fn not_built() -> Error {
    Error::gpu_unavailable("this build of softshadow has no GPU backend (cargo feature `gpu`)")
}

/// A call's output with what ran it.
#[derive(Debug, Clone)]
pub struct Run<T> {
    pub output: T,
    /// The config that ran ("auto" resolved, every default filled in).
    pub method: MethodConfig,
    pub backend: Backend,
    /// Worker threads the CPU stages could use.
    pub threads: usize,
    /// What `Auto` with a target decided (light-view maps from meshes).
    pub plan: Option<crate::methods::plan::Plan>,
}

/// A shadow map of meshes: what to compute and where.
#[derive(Debug, Clone, Copy)]
pub struct MeshCall<'a> {
    pub occluders: MeshRef<'a>,
    pub receivers: MeshRef<'a>,
    pub light: &'a Light,
    /// Output (W, H).
    pub resolution: (i64, i64),
    /// Tangent half-extents, or `None` to fit them.
    pub extent: Option<[f64; 2]>,
    pub method: MethodConfig,
    pub backend: BackendChoice,
    /// Worker threads; `None`: SOFTSHADOW_THREADS, else all cores.
    pub threads: Option<i64>,
}

/// Meshes -> light-view maps -> visibility, on the chosen backend.
pub fn shadow_map(call: &MeshCall) -> Result<Run<ShadowResult>> {
    let (w, h) = check_resolution("resolution", call.resolution)?;
    let cap = threads::resolve(call.threads)?;
    let ctx = CallContext {
        backend: Backend::Cpu,
        resolution: (w, h),
        depth_layers: None,
        eye: false,
    };
    let backend = call
        .backend
        .pick(&call.method, ctx, call.light.kernel_size());
    let ctx = CallContext { backend, ..ctx };
    let target = match call.method {
        MethodConfig::Auto(_, t) if !t.is_none() => Some(t),
        _ => None,
    };
    let method = call.method.resolve(&ctx)?;
    let ((output, method, plan), threads) = threads::run_capped(cap, || {
        let space = mesh_space(
            call.light,
            &[("occluders", call.occluders), ("receivers", call.receivers)],
        )?;
        // A sun's map extent is given in world units; the kernels' in tangents.
        let extent = call.extent.map(|e| space.kernel_extent(e));
        let run =
            |method: &MethodConfig, hard: bool, size: (usize, usize), extent: Option<[f64; 2]>| {
                let mut settings = MapSettings::new(size.0, size.1, extent, method);
                settings.hard = hard;
                match backend {
                    Backend::Cpu => {
                        pipeline::from_meshes(call.occluders, call.receivers, &space, &settings)
                    }
                    #[cfg(feature = "gpu")]
                    Backend::Gpu => {
                        crate::gpu::from_meshes(call.occluders, call.receivers, &space, &settings)
                    }
                    #[cfg(not(feature = "gpu"))]
                    Backend::Gpu => Err(not_built()),
                }
            };
        let Some(target) = target else {
            return Ok((run(&method, false, (w, h), extent)?, method, None));
        };
        planned(call, &space, extent, &ctx, &target, run)
    })?;
    Ok(Run {
        output,
        method,
        backend,
        threads,
        plan,
    })
}

/// A mesh call planned for `target` (`methods/plan.rs`): the scene's stats,
/// the plan (after a timed probe for a time budget), for a union setting
/// what its occluders call for (`pipeline/measure.rs`: thin features, the
/// layers tried on coarse maps); then the planned config resolved for the
/// backend and run. The planning time (the probe excluded) is the result's
/// "plan" stage.
fn planned(
    call: &MeshCall,
    space: &LightSpace,
    extent: Option<[f64; 2]>,
    ctx: &CallContext,
    target: &crate::methods::plan::Target,
    run: impl Fn(&MethodConfig, bool, (usize, usize), Option<[f64; 2]>) -> Result<ShadowResult>,
) -> Result<(
    ShadowResult,
    MethodConfig,
    Option<crate::methods::plan::Plan>,
)> {
    use crate::methods::plan::plan;
    let t0 = std::time::Instant::now();
    // The framing every run starts from (its checks, transform and extent
    // fit), on the rule's settings; the planner reads its depth ranges.
    let (w, h) = ctx.resolution;
    let rule = MapSettings::new(w, h, extent, &call.method.resolve(ctx)?);
    let framed = pipeline::frame_scene(
        &call.occluders,
        &call.receivers,
        space,
        &rule,
        &mut pipeline::Stopwatch::new(),
    )?;
    let stats = pipeline::scene_stats(&framed, ctx.resolution);
    let mut p = plan(&stats, target, None);
    let mut probe = None;
    let mut probe_seconds = 0.0;
    if target.time.is_some() && !p.hard {
        // The probe: the cheapest soft setting, timed; kept when nothing
        // better fits the budget.
        let cfg = p.config.resolve(ctx)?;
        let t = std::time::Instant::now();
        let out = run(&cfg, false, (w, h), extent)?;
        probe_seconds = t.elapsed().as_secs_f64();
        p = plan(&stats, target, Some(t0.elapsed().as_secs_f64()));
        probe = Some((cfg, out));
    }
    // The GPU has no hard shadow map: the soft setting runs there.
    if p.hard && ctx.backend == Backend::Gpu {
        p.hard = false;
        if let Some(d) = p.decisions.iter_mut().find(|d| d.name == "hard") {
            d.taken = false;
            d.why
                .push_str("; the GPU backend has no hard shadow map, the soft setting runs");
        }
    }
    if let Some(c) = p.bitmask() {
        // The occluders as the union setting will read them
        // (`pipeline/measure.rs`): thin features on the planned maps where
        // the target asks, the layers tried on coarse maps.
        use crate::geom::light::MapGrid;
        let occ = c.occluder_resolution.unwrap_or((w, h));
        let fitted = [framed.grid.tx, framed.grid.ty];
        let front = if p.thin_matters(target) {
            let grid = MapGrid::new(occ.0, occ.1, fitted)?;
            Some(pipeline::thin_features(
                &framed,
                call.occluders.faces,
                &grid,
            ))
        } else {
            None
        };
        p.refine_thin(front, occ);
        let eighth = |n: usize| (n / 8).clamp(16.min(n), n);
        let quarter = |n: usize| (n / 4).clamp(64.min(n), n);
        let coarse = MapGrid::new(eighth(w), eighth(h), fitted)?;
        let coarse_occ = MapGrid::new(quarter(occ.0), quarter(occ.1), fitted)?;
        let kernel = |gaps| {
            MethodConfig::Bitmask(crate::methods::config::BitmaskConfig {
                samples: 256,
                passes: Some(2),
                occluder_resolution: Some((coarse_occ.width, coarse_occ.height)),
                gaps,
                // Without the hierarchy: at the coarse maps building its
                // levels costs more than it saves (bunny_floating, 32² x
                // 64²: 2.4 ms with, 1.0 ms without per try).
                hierarchy: Some(false),
            })
            .resolve(&CallContext {
                backend: Backend::Cpu,
                resolution: (coarse.width, coarse.height),
                ..*ctx
            })
            .map(|k| k.kernel())
        };
        use crate::methods::bitmask::Gaps;
        let tries = pipeline::layer_tries(
            &framed,
            (call.occluders.faces, call.receivers.faces),
            (coarse, coarse_occ),
            (kernel(Gaps::Closed)?, kernel(Gaps::Open)?),
            crate::methods::config::MAX_PASSES,
        );
        p.set_layers(tries.passes, tries.surfaces, &tries.peeled, &tries.changes);
        // Only a plan that chose closed gaps may open them (a user's
        // Bitmask(gaps="open") never reaches the planner).
        p.set_gaps((c.gaps == Gaps::Closed).then_some(tries.gap_change));
    }
    drop(framed);
    let cfg = p.config.resolve(ctx)?;
    let planning = t0.elapsed().as_secs_f64() - probe_seconds;
    let mut out = match probe {
        Some((probe_cfg, out)) if probe_cfg == cfg => out,
        _ => run(&cfg, p.hard, (w, h), extent)?,
    };
    out.timings.insert(0, ("plan", planning));
    p.config = cfg;
    Ok((out, cfg, Some(p)))
}

/// A shadow map of a scene where every mesh casts and receives shadows.
#[derive(Debug, Clone, Copy)]
pub struct SceneCall<'a> {
    /// Every mesh, as one.
    pub scene: MeshRef<'a>,
    pub light: &'a Light,
    pub resolution: (i64, i64),
    pub extent: Option<[f64; 2]>,
    pub method: MethodConfig,
    /// The map methods' self-shadowing biases (see `eye/maps.rs`).
    pub bias: crate::eye::Bias,
    pub backend: BackendChoice,
    pub threads: Option<i64>,
}

/// A self-shadowing scene -> light-view maps -> visibility (the CPU: its
/// receiver texels are shaded as points, which the GPU twin of the eye view
/// does not cover yet).
pub fn scene_shadow_map(call: &SceneCall) -> Result<Run<ShadowResult>> {
    let (w, h) = check_resolution("resolution", call.resolution)?;
    let cap = threads::resolve(call.threads)?;
    if call.backend == BackendChoice::Gpu {
        return Err(Error::invalid(
            "backend",
            "the light-view maps of a scene shadowing itself run on the CPU only in this version; \
             use backend=\"cpu\"",
        ));
    }
    let ctx = CallContext {
        backend: Backend::Cpu,
        resolution: (w, h),
        depth_layers: None,
        eye: false,
    };
    let method = call.method.resolve(&ctx)?;
    let (output, threads) = threads::run_capped(cap, || {
        let space = mesh_space(call.light, &[("meshes", call.scene)])?;
        let extent = call.extent.map(|e| space.kernel_extent(e));
        let settings = MapSettings::new(w, h, extent, &method);
        pipeline::from_scene(call.scene, &space, &settings, &call.bias)
    })?;
    Ok(Run {
        output,
        method,
        backend: Backend::Cpu,
        threads,
        plan: None,
    })
}

/// The light space of a scene made of `meshes` (each with the name errors
/// give it): a sun's depth origin and range are fitted to their vertices
/// (checked first: a non-finite vertex is named, not folded into the bounds).
pub fn mesh_space(light: &Light, meshes: &[(&str, MeshRef)]) -> Result<LightSpace> {
    if let Light::Sun(_) = light {
        for (arg, m) in meshes {
            m.validate(arg)?;
        }
    }
    let verts = meshes
        .iter()
        .flat_map(|(_, m)| m.vertices.iter())
        .map(|p| glam::DVec3::from_array(*p));
    light.space_for(verts)
}

/// Depth maps the user rendered: what to shade and where.
#[derive(Debug, Clone, Copy)]
pub struct DepthCall<'a> {
    /// The receiver map's grid, which the output shares.
    pub grid: MapGrid,
    /// The occluder maps' grid (same extent, their own resolution).
    pub occluder_grid: MapGrid,
    /// A rectangle's (width, height) in the depths' unit; ignored for
    /// orthographic maps.
    pub light_size: [f64; 2],
    /// `Some(angular_size)`: orthographic maps of a directional light of
    /// that angular size (degrees): depths from the depth origin, extents
    /// in world units (see `geom/sun.rs`).
    pub sun: Option<[f64; 2]>,
    pub front: &'a [f32],
    pub back: Option<&'a [f32]>,
    pub receiver: &'a [f32],
    pub method: MethodConfig,
    pub backend: BackendChoice,
    pub threads: Option<i64>,
}

/// Orthographic depth maps as the kernels read them: the sun's space with
/// the depth origin at depth 0 and the maps' farthest depth as its range,
/// the maps in kernel depths, the grids in kernel tangents, the light's
/// kernel size. Depths must be finite and >= 0, or +inf where empty.
#[allow(clippy::type_complexity)]
pub fn orthographic_maps(
    call: &DepthCall,
    angular_size: [f64; 2],
) -> Result<(SunSpace, MapGrid, MapGrid, [f64; 2], Vec<Vec<f32>>)> {
    let sun = DirectionalLight::new([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], angular_size)?;
    let maps: Vec<(&str, &[f32])> = [
        ("occluder_depth", call.front),
        ("receiver_depth", call.receiver),
    ]
    .into_iter()
    .chain(call.back.map(|b| ("occluder_depth_back", b)))
    .collect();
    let mut range = 0f64;
    for (arg, m) in &maps {
        if let Some(k) = m.iter().position(|z| !(*z >= 0.0)) {
            return Err(Error::invalid(
                *arg,
                format!(
                    "orthographic depths must be >= 0 (from the depth origin) or +inf where \
                     empty; texel {k} holds {}",
                    m[k]
                ),
            ));
        }
        range = range.max(crate::geom::units::farthest(m));
    }
    let space = SunSpace::new(sun, glam::DVec3::ZERO, range);
    let kernel: Vec<Vec<f32>> = maps
        .iter()
        .map(|(_, m)| {
            m.iter()
                .map(|&z| space.kernel_depth(z as f64) as f32)
                .collect()
        })
        .collect();
    let s = LightSpace::Sun(space);
    let grid = |g: &MapGrid| MapGrid::new(g.width, g.height, s.kernel_extent([g.tx, g.ty]));
    Ok((
        space,
        grid(&call.grid)?,
        grid(&call.occluder_grid)?,
        sun.kernel_size(),
        kernel,
    ))
}

/// What shading depth maps returns.
#[derive(Debug, Clone)]
pub struct DepthOutput {
    pub visibility: Vec<f32>,
    pub timings: Timings,
    /// For orthographic maps: the depth range their kernel space used
    /// (`ShadowMap.sample` rebuilds the space from it).
    pub depth_range: Option<f64>,
}

/// Depth maps -> visibility, on the chosen backend.
pub fn shadow_map_from_depth(call: &DepthCall) -> Result<Run<DepthOutput>> {
    let cap = threads::resolve(call.threads)?;
    // Orthographic maps: the same shading on their kernel-space twins.
    let ortho = call.sun.map(|a| orthographic_maps(call, a)).transpose()?;
    let (grid, occluder_grid, light_size) = match &ortho {
        Some((_, g, og, size, _)) => (*g, *og, *size),
        None => (
            call.grid,
            call.occluder_grid,
            check_light_size("light_size", call.light_size)?,
        ),
    };
    let (front, receiver, back) = match &ortho {
        Some((.., m)) => (&m[0][..], &m[1][..], m.get(2).map(|b| &b[..])),
        None => (call.front, call.receiver, call.back),
    };
    let layers = 1 + back.is_some() as u32;
    let og = &occluder_grid;
    let ctx = CallContext {
        backend: Backend::Cpu,
        resolution: (grid.width, grid.height),
        depth_layers: Some((layers, (og.width, og.height))),
        eye: false,
    };
    let backend = call.backend.pick(&call.method, ctx, light_size);
    let method = call.method.resolve(&CallContext { backend, ..ctx })?;
    let kernel = method.kernel();
    let (g, f, b, r) = (&grid, front, back, receiver);
    let ((visibility, timings), threads) = threads::run_capped(cap, || match backend {
        Backend::Cpu => pipeline::from_depth(g, og, light_size, f, b, r, kernel),
        #[cfg(feature = "gpu")]
        Backend::Gpu => crate::gpu::from_depth(g, og, light_size, f, b, r, kernel),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(not_built()),
    })?;
    let output = DepthOutput {
        visibility,
        timings,
        depth_range: ortho.map(|(space, ..)| space.depth_range),
    };
    Ok(Run {
        output,
        method,
        backend,
        threads,
        plan: None,
    })
}

/// Visibility at world points from a shadow map's occluders (the CPU: points
/// are few and scattered). `method` is the config the map ran with.
pub fn sample_points(
    grid: &MapGrid,
    light: &LightSpace,
    occluders: pipeline::OccluderSource,
    points: &[[f64; 3]],
    method: &MethodConfig,
    threads: Option<i64>,
) -> Result<(Vec<f32>, Vec<bool>)> {
    let cap = threads::resolve(threads)?;
    let kernel = method.kernel();
    threads::run_capped(cap, || {
        pipeline::sample_points(grid, light, occluders, points, kernel)
    })
    .map(|(v, _)| v)
}
