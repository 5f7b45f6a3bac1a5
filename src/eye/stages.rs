//! The eye view's stages as one interface, implemented by the CPU
//! (`CpuEye`, here) and by the GPU (`crate::gpu::eye::GpuEye`): the
//! orchestrator (`crate::pipeline::eye_view`) runs one sequence of stages
//! on either, so a stage is added once and both backends give the same
//! answers from the same framing (framing.rs).

use super::call::EyeCall;
use super::framing::Framed;
use super::gbuffer::{self, GBuffer, SceneTriangles};
use super::maps::{self, LightTriangles, MapShading};
use super::{rays, shadow_mapping, sphere_rays};
use crate::backend::Backend;
use crate::error::Result;
use crate::geom::camera::Camera;
use crate::geom::light::MapGrid;
use crate::geom::sphere_light::SphereLight;
use crate::methods::engine::Engine;
use crate::methods::exact::Bvh;
use crate::methods::shadow_mapping::config::ShadowMappingConfig;
use crate::methods::MethodConfig;
use crate::timing::{Stopwatch, Timings};

/// The stages of the eye view on one backend. Each returns what the next
/// reads; stage times go to `sw` (the device's own, where it has them, are
/// kept by the implementation and handed over by `timings`).
pub trait EyeStages {
    /// The backend the configs resolve for.
    const BACKEND: Backend;

    /// Refuses, before any work, a call this backend cannot run (the map
    /// methods: a hard light or a config the GPU has no kernel for).
    fn check(&self, call: &EyeCall) -> Result<()>;

    /// What each pixel sees: the G-buffer.
    fn first_hits(&mut self, camera: &Camera, scene: &SceneTriangles) -> Result<GBuffer>;

    /// ShadowMapping's visibility of every pixel of `g` (1 where no surface).
    fn shadow_mapping(
        &mut self,
        call: &EyeCall,
        cfg: &ShadowMappingConfig,
        scene: &SceneTriangles,
        g: &GBuffer,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>>;

    /// `exact`: the visibility of each visible point of `f` from `samples`
    /// stratified shadow rays through `bvh` (the triangles that can shadow
    /// a visible point, built once a call: the error estimate and `Auto`'s
    /// further runs trace it too); with a `probe` of so many samples, only
    /// at the points a first pass is unsure of (`methods/probe.rs`). Beside
    /// it, where the backend weights its samples (the CPU), each point's
    /// weighted visibility (`rays::visibility_weighted`). `sampled`:
    /// the samples, the probe's and the engine (`exact_samples`).
    fn trace(
        &mut self,
        f: &Framed,
        bvh: &Bvh,
        camera: &Camera,
        sampled: (u32, Option<u32>, Engine),
        sw: &mut Stopwatch,
    ) -> Result<(Vec<f32>, Option<Vec<f32>>)>;

    /// `exact` under a sphere (`sphere_rays.rs`): each pixel of `hits` (flat
    /// indices into `g`) traced over the cap it sees through `bvh` (every
    /// triangle relative to the sphere's centre, `sphere_rays::sphere_bvh`),
    /// its visibility and weighted visibility; with a `probe`, only where a
    /// first pass is unsure (the CPU's).
    #[allow(clippy::too_many_arguments)]
    fn trace_sphere(
        &mut self,
        bvh: &Bvh,
        light: &SphereLight,
        g: &GBuffer,
        hits: &[usize],
        samples: u32,
        probe: Option<u32>,
        sw: &mut Stopwatch,
    ) -> Result<Vec<[f32; 2]>>;

    /// The map methods: the occluder layers of `tris` on `grid`, and the
    /// visibility of each visible point of `f` read from them (and its
    /// weighted visibility where the method weighs its samples).
    fn shade_maps(
        &mut self,
        call: &EyeCall,
        f: &Framed,
        tris: &LightTriangles,
        grid: MapGrid,
        method: &MethodConfig,
        sw: &mut Stopwatch,
    ) -> Result<MapShading>;

    /// The call's stage times: the host's laps `host` with the device's.
    fn timings(&mut self, host: Timings) -> Timings;
}

/// The eye view's stages on all CPU cores.
pub struct CpuEye;

impl EyeStages for CpuEye {
    const BACKEND: Backend = Backend::Cpu;

    fn check(&self, _call: &EyeCall) -> Result<()> {
        Ok(())
    }

    fn first_hits(&mut self, camera: &Camera, scene: &SceneTriangles) -> Result<GBuffer> {
        Ok(gbuffer::first_hits(camera, scene))
    }

    fn shadow_mapping(
        &mut self,
        call: &EyeCall,
        cfg: &ShadowMappingConfig,
        scene: &SceneTriangles,
        g: &GBuffer,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>> {
        shadow_mapping::render(call, cfg, scene, g, sw).map(|(v, _map)| v)
    }

    fn trace(
        &mut self,
        f: &Framed,
        bvh: &Bvh,
        camera: &Camera,
        (samples, probe, engine): (u32, Option<u32>, Engine),
        _sw: &mut Stopwatch,
    ) -> Result<(Vec<f32>, Option<Vec<f32>>)> {
        let starts = rays::ray_starts(&f.space, f.unit, &f.points, &f.normals);
        let order = rays::tiled(&f.hits, camera.width, camera.height);
        // Each point's jitter key is its pixel (as on the GPU).
        let both = rays::visibility_weighted(
            bvh,
            f.light_shape,
            &starts,
            |k| f.hits[k] as u64,
            &order,
            (samples, engine),
            probe.map(|samples| rays::Probe {
                samples,
                size: (camera.width, camera.height),
            }),
        );
        Ok(both.into_iter().map(|[v, w]| (v, w)).unzip())
            .map(|(v, w): (Vec<f32>, Vec<f32>)| (v, Some(w)))
    }

    fn trace_sphere(
        &mut self,
        bvh: &Bvh,
        light: &SphereLight,
        g: &GBuffer,
        hits: &[usize],
        samples: u32,
        probe: Option<u32>,
        _sw: &mut Stopwatch,
    ) -> Result<Vec<[f32; 2]>> {
        Ok(sphere_rays::sphere_visibility(
            bvh, light, g, hits, samples, probe,
        ))
    }

    fn shade_maps(
        &mut self,
        call: &EyeCall,
        f: &Framed,
        tris: &LightTriangles,
        grid: MapGrid,
        method: &MethodConfig,
        sw: &mut Stopwatch,
    ) -> Result<MapShading> {
        maps::shade(
            &f.space,
            f.unit,
            f.light_shape,
            tris,
            grid,
            method.passes(),
            method.kernel(),
            &f.points,
            &f.pts_ls,
            &f.normals,
            &call.bias,
            call.map_size_arg(),
            true,
            sw,
        )
    }

    fn timings(&mut self, host: Timings) -> Timings {
        host
    }
}
