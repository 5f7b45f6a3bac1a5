//! Light-view maps of a scene where every mesh casts and receives shadows
//! (`soft_shadow_map` of `Scene(meshes=...)`): the receiver map is the
//! nearest surface seen from the light, and every receiver texel is shaded
//! at its own surface point as the eye view shades a pixel's (`crate::eye`):
//! `exact` with offset shadow rays, the map methods with the biases and the
//! tangent-plane bound, every mesh an occluder, the texel's own included.
//!
//! A texel's point is the light's ray through the texel centre at the
//! receiver map's depth; its normal the face's there (the face rasterized
//! nearest), turned toward the light.

use crate::error::Result;
use crate::eye::{maps, rays, Bias};
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::light_view::estimate;
use crate::raster::Prepared;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::frame::{frame_scene, light_space_triangles, FramedScene, MapSettings, ShadowResult};
use crate::timing::Stopwatch;

/// Soft shadow map of a scene shadowing itself.
pub fn from_scene(
    scene: MeshRef,
    light: &LightSpace,
    s: &MapSettings,
    bias: &Bias,
) -> Result<ShadowResult> {
    let mut sw = Stopwatch::new();
    let FramedScene {
        occ_ls,
        rec_ls: _,
        grid,
        occluder_grid,
        near,
        unit,
        light_shape,
    } = frame_scene(&scene, &scene, light, s, &mut sw)?;
    let prepared = Prepared::with_faces(&grid, &occ_ls, scene.faces, near);
    let (receiver, faces) = prepared.nearest_faces();
    sw.lap("raster_receivers");
    // The receiver texels' world points and light-facing normals.
    let texels: Vec<usize> = (0..grid.len()).filter(|&k| faces[k].is_some()).collect();
    let (points, normals): (Vec<[f64; 3]>, Vec<[f32; 3]>) = texels
        .par_iter()
        .map(|&k| {
            let z = receiver[k] as f64 * unit;
            let p = light.point_at(grid.x_of(k % grid.width), grid.y_of(k / grid.width), z);
            let f = scene.faces[faces[k].unwrap_or(0) as usize];
            let [a, b, c] = f.map(|i| DVec3::from_array(scene.vertices[i as usize]));
            let n = (b - a).cross(c - a).normalize_or_zero();
            let toward = match light {
                LightSpace::Area(l) => l.center - p,
                LightSpace::Sun(s) => -s.light.n,
            };
            let n = if n.dot(toward) < 0.0 { -n } else { n };
            (p.to_array(), n.as_vec3().to_array())
        })
        .unzip();
    sw.lap("receiver_points");
    // The estimate's rays meet every triangle, as `exact`'s (copied before
    // the map methods take the light-space vertices).
    let traced = s
        .estimate
        .map(|how| (how, light_space_triangles(&occ_ls, scene.faces)));
    let mut visibility = vec![1f32; grid.len()];
    let (front, back, middle) = if s.method.traces() {
        let tris: Vec<[Vec3; 3]> = light_space_triangles(&occ_ls, scene.faces);
        sw.lap("triangles");
        let starts = rays::ray_starts(light, unit, &points, &normals);
        let (samples, probe, engine) = match s.method.rays() {
            Some(rays) if !light_shape.is_point() => rays,
            _ => (1, None, crate::methods::engine::Engine::Rays),
        };
        // Keys are texel indices, as the light-view exact's.
        let keyed: Vec<Option<rays::RayStart>> = {
            let mut all = vec![None; grid.len()];
            for (&k, st) in texels.iter().zip(starts) {
                all[k] = st;
            }
            all
        };
        let order = crate::trace::shadow_rays::tile_order(grid.width, grid.height);
        let probe = probe.map(|samples| rays::Probe {
            samples,
            size: (grid.width, grid.height),
        });
        let v = rays::visibility(
            light_shape,
            tris,
            &keyed,
            |k| k as u64,
            &order,
            (samples, engine),
            probe,
        );
        for &k in &texels {
            visibility[k] = v[k];
        }
        sw.lap("shadow");
        (None, None, vec![])
    } else {
        let tris = maps::LightTriangles {
            verts: occ_ls,
            faces: scene.faces,
        };
        let pts_ls: Vec<DVec3> = points
            .par_iter()
            .map(|p| light.to_light(DVec3::from_array(*p)))
            .collect();
        let shaded = maps::shade(
            light,
            unit,
            light_shape,
            &tris,
            occluder_grid,
            s.passes,
            s.method,
            &points,
            &pts_ls,
            &normals,
            bias,
            "occluder_resolution",
            false,
            &mut sw,
        )?;
        for (&k, v) in texels.iter().zip(shaded.visibility) {
            visibility[k] = v;
        }
        // The layers come back in the user's depth already.
        let mut layers = shaded.maps.layers;
        let back = (s.passes >= 2).then(|| layers.pop()).flatten();
        let front = Some(layers.remove(0));
        (front, back, layers)
    };
    let estimate = traced.map(|(how, tris)| {
        let spent = sw.timings.iter().map(|t| t.1).sum();
        // Ray starts and keys as `exact`'s above: texel indices, segments
        // from the offset starts (t0 = 0).
        let mut origins = vec![None; grid.len()];
        let starts = rays::ray_starts(light, unit, &points, &normals);
        for (&k, st) in texels.iter().zip(starts) {
            origins[k] = st;
        }
        let at = estimate::Receivers {
            size: (grid.width, grid.height),
            origins: &origins,
            t0: 0.0,
        };
        let samples = estimate::reference_samples(s.method);
        let e = estimate::estimate(&at, light_shape, tris, &visibility, samples, (how, spent));
        sw.lap("estimate");
        e
    });
    let mut out = ShadowResult {
        grid,
        occluder_grid,
        visibility,
        receiver,
        occluder_front: None,
        occluder_middle: vec![],
        occluder_back: None,
        timings: sw.timings,
        light_space: *light,
        estimate,
    }
    .in_user_units(unit);
    out.occluder_front = front;
    out.occluder_middle = middle;
    out.occluder_back = back;
    Ok(out)
}
