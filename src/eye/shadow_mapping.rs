//! ShadowMapping (Scherzer 2005) in the eye view: its own shadow map of
//! every mesh, from the light's centre (a rectangle: a perspective map) or
//! along its direction (the sun: orthographic, or LiSPSM-warped), then the
//! depth test at each visible point and, if asked, the eye-space blur.
//!
//! The map is fitted to the intersection body B (`geom/body.rs`) when
//! `focus` is on, else to the whole scene's bounds. A directional map's
//! axes follow the view (S and Vp of `geom/shadow_projection.rs`) whenever
//! the view is not along the light, so focusing, LiSPSM and its fallback
//! frame the same body the same way (LiSPSM with the camera's axis as its
//! view vector tends to exactly this map as n grows). A point whose camera-facing normal
//! turns away from the light's centre (or that lies behind a rectangle's
//! plane) gets 0: a renderer's N·L does that before any depth test.

use super::gbuffer::{GBuffer, SceneTriangles};
use super::{EyeCall, EyeImage};
use crate::error::{Error, Result};
use crate::geom::body::{extend_toward_light, view_body, Aabb};
use crate::geom::light_space::Light;
use crate::geom::light_space::{sphere_has_no_space, LightSpace};
use crate::geom::shadow_projection::{ShadowProjection, ViewVector, MIN_SIN_GAMMA};
use crate::geom::sun::SunSpace;
use crate::methods::shadow_mapping::blur::blur;
use crate::methods::shadow_mapping::config::{DepthBias, ShadowMappingConfig};
use crate::methods::shadow_mapping::lookup::{receiver_gradient, Lookup};
use crate::methods::shadow_mapping::raster::{
    scan, setup_triangles, DepthMap, Faces, SetupTri, Toward,
};
use crate::timing::{Stopwatch, Timings};
use glam::DVec3;
use rayon::prelude::*;

/// What the map of an image was.
#[derive(Debug, Clone)]
pub struct ShadowMapInfo {
    pub map: DepthMap,
    pub projection: ShadowProjection,
}

fn toward(light: &Light) -> Toward {
    match light {
        Light::Area(l) => Toward::Point(l.center),
        Light::Sun(s) => Toward::Direction(-s.n),
        Light::Sphere(s) => Toward::Point(s.center),
    }
}

/// The shadow map's projection for `call`.
fn projection(
    call: &EyeCall,
    cfg: &ShadowMappingConfig,
    bounds: &Aabb,
    g: &GBuffer,
) -> Option<ShadowProjection> {
    let cam = call.camera;
    // The nearest and farthest planar depths the image sees: LiSPSM's z_n,
    // z_f, and the focused body's far cut.
    let (zn, zf) = g
        .depth
        .par_iter()
        .filter(|z| z.is_finite())
        .fold(
            || (f64::INFINITY, 0f64),
            |(a, b), &z| (a.min(z as f64), b.max(z as f64)),
        )
        .reduce(
            || (f64::INFINITY, 0f64),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let body = if cfg.focus {
        // Just past the farthest seen surface (f32 depths, rounded down).
        view_body(cam, bounds, zn.is_finite().then_some(zf * (1.0 + 1e-5)))
    } else {
        vec![]
    };
    let body = if body.is_empty() {
        bounds.corners().to_vec()
    } else {
        body
    };
    let tw = toward(call.light);
    let extended = extend_toward_light(&body, bounds, |p| match tw {
        Toward::Direction(d) => (d, f64::INFINITY),
        Toward::Point(c) => ((c - p).normalize_or_zero(), (c - p).length()),
    });
    match call.light {
        // Refused before (`check_light`): no light space.
        Light::Sphere(_) => None,
        Light::Area(l) => ShadowProjection::perspective(l.center, l.n, l.u, l.v, &extended),
        Light::Sun(s) => {
            let l = s.n;
            // The uniform map (and LiSPSM's fallback) follows the camera's
            // axis; the warp follows its own view vector.
            let (x, y) = if l.cross(cam.forward).length() >= MIN_SIN_GAMMA {
                let vp = (cam.forward - cam.forward.dot(l) * l).normalize();
                (l.cross(vp), vp)
            } else {
                (s.u, s.v)
            };
            let view = match cfg.warp.map(|w| w.vector) {
                Some(ViewVector::Middle) => {
                    let m: DVec3 = body.iter().map(|p| *p - cam.eye).sum();
                    m.normalize_or(cam.forward)
                }
                _ => cam.forward,
            };
            let uniform = ShadowProjection::orthographic(l, x, y, &extended)?;
            match cfg.warp {
                None => Some(uniform),
                Some(w) => {
                    if !zn.is_finite() {
                        return Some(uniform);
                    }
                    Some(ShadowProjection::lispsm(
                        l,
                        cam.eye,
                        view,
                        &extended,
                        w.n.map(|n| n.0),
                        zn,
                        zf,
                        uniform,
                    ))
                }
            }
        }
    }
}

/// What both backends share once the G-buffer is known: the per-call
/// geometry (the projection, the clipped and set-up triangles), the image
/// with every pixel that needs no lookup already decided, and the points to
/// look up.
pub(crate) struct Prepared {
    pub projection: ShadowProjection,
    pub triangles: Vec<SetupTri>,
    /// 1 where no surface, 0 where the surface turns away from the light
    /// (or lies behind a rectangle's plane); the looked-up pixels' values
    /// are written over it.
    pub visibility: Vec<f32>,
    /// The pixels to look up, their world points and, with a PCF filter,
    /// their receivers' depth gradients (`lookup::receiver_gradient`).
    pub lookups: Vec<(usize, DVec3, [f32; 2])>,
}

/// Whether pixel `k` of `g` (a surface) gets no light at all: behind a
/// rectangle's plane, or facing away from the light (`tw` its direction).
fn unlit(light: &Light, tw: &Toward, g: &GBuffer, k: usize) -> bool {
    let p = DVec3::from_array(g.position[k]);
    let n = glam::Vec3::from_array(g.normal[k]).as_dvec3();
    let in_front = match light {
        Light::Area(l) => (p - l.center).dot(l.n) > 0.0,
        Light::Sun(_) => true,
        Light::Sphere(s) => s.is_outside(p),
    };
    !in_front || n.dot(tw.at(p)) <= 0.0
}

/// Sets back to 0 the pixels of `v` that get no light (`unlit`), after the
/// eye-space blur (either backend's) has mixed their neighbours into them:
/// they are 0 on every method.
pub(crate) fn keep_unlit_dark(call: &EyeCall, g: &GBuffer, v: &mut [f32]) {
    let tw = toward(call.light);
    for k in g.hits() {
        if unlit(call.light, &tw, g, k) {
            v[k] = 0.0;
        }
    }
}

/// The stages before the map, on the CPU for both backends: `Err(v)` when
/// there is no map to draw (nothing in front of the rectangle), `v` the
/// image.
pub(crate) fn prepare(
    call: &EyeCall,
    cfg: &ShadowMappingConfig,
    scene: &SceneTriangles,
    g: &GBuffer,
    sw: &mut Stopwatch,
) -> Result<std::result::Result<Prepared, Vec<f32>>> {
    if let (Some(_), Light::Area(_)) = (cfg.warp, call.light) {
        return Err(Error::invalid(
            "warp",
            "LiSPSM warps directional lights only (Scherzer 2005 centres on them, §6): a \
             rectangle's map is already a perspective one from its centre, and warping it needs \
             the light's post-perspective space, which this version does not build; use \
             warp=None or a DirectionalLight",
        ));
    }
    let mut visibility = vec![1f32; g.len()];
    let hits = g.hits();
    let bounds = Aabb::of(scene.points()).expect("a checked scene has finite vertices");
    let Some(proj) = projection(call, cfg, &bounds, g) else {
        // No geometry in front of the rectangle: nothing it lights.
        for &k in &hits {
            visibility[k] = 0.0;
        }
        return Ok(Err(visibility));
    };
    sw.lap("focus");
    let tw = toward(call.light);
    let faces = match cfg.bias {
        DepthBias::BackFaces => Faces::BackOnly(tw),
        _ => Faces::All,
    };
    let triangles = setup_triangles(
        &proj,
        &scene.vertices,
        &scene.faces,
        cfg.resolution,
        cfg.bias.offset(),
        faces,
    );
    sw.lap("setup");
    let mut lookups = Vec::with_capacity(hits.len());
    for &k in &hits {
        let p = DVec3::from_array(g.position[k]);
        if unlit(call.light, &tw, g, k) {
            visibility[k] = 0.0;
        } else {
            lookups.push((k, p, [0.0; 2]));
        }
    }
    if cfg.filter.is_some() {
        lookups.par_iter_mut().for_each(|(k, p, gradient)| {
            let n = glam::Vec3::from_array(g.normal[*k]).as_dvec3();
            *gradient = receiver_gradient(&proj, cfg.bias, cfg.resolution, *p, n);
        });
    }
    Ok(Ok(Prepared {
        projection: proj,
        triangles,
        visibility,
        lookups,
    }))
}

/// The visibility of every pixel of `g` (1 where no surface) and the map,
/// on the CPU.
pub(crate) fn render(
    call: &EyeCall,
    cfg: &ShadowMappingConfig,
    scene: &SceneTriangles,
    g: &GBuffer,
    sw: &mut Stopwatch,
) -> Result<(Vec<f32>, Option<ShadowMapInfo>)> {
    let p = match prepare(call, cfg, scene, g, sw)? {
        Ok(p) => p,
        Err(v) => return Ok((v, None)),
    };
    let map = scan(
        &p.triangles,
        cfg.resolution,
        cfg.bias.distribution(),
        cfg.bias == DepthBias::Midpoint,
    );
    sw.lap("raster");
    let lookup = Lookup::new(&map, &p.projection, cfg.bias, cfg.filter);
    let v: Vec<f32> = p
        .lookups
        .par_iter()
        .with_min_len(256)
        .map(|&(_, q, gradient)| lookup.visibility(q, gradient))
        .collect();
    let mut visibility = p.visibility;
    for (&(k, _, _), v) in p.lookups.iter().zip(v) {
        visibility[k] = v;
    }
    sw.lap("shadow");
    if let Some(b) = cfg.blur {
        blur(&b, g.width, g.height, &g.depth, &mut visibility);
        sw.lap("blur");
    }
    Ok((
        visibility,
        Some(ShadowMapInfo {
            map,
            projection: p.projection,
        }),
    ))
}

/// The image of a ShadowMapping call whose visibility is `visibility`
/// (either backend): its light space is the one fitted to the whole scene.
pub(crate) fn image(
    call: &EyeCall,
    scene: &SceneTriangles,
    gbuffer: GBuffer,
    visibility: Vec<f32>,
    timings: Timings,
) -> Result<EyeImage> {
    let light_space = match call.light {
        Light::Area(l) => LightSpace::Area(*l),
        Light::Sun(s) => LightSpace::Sun(SunSpace::fit(*s, scene.points())?),
        Light::Sphere(_) => return Err(sphere_has_no_space()),
    };
    Ok(EyeImage {
        gbuffer,
        visibility,
        weighted: None,
        maps: None,
        light_space: Some(light_space),
        timings,
        estimate: None,
    })
}
