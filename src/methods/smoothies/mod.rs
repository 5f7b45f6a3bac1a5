//! Chan & Durand 2003, "Rendering Fake Soft Shadows with Smoothies", as
//! published (§3, §3.1, Fig. 11), on the CPU, in the kernels' light space
//! (light centred at the origin in z = 0, tangent (x/z, y/z), planar depth z).
//!
//! 1. The shadow map: `front`, the nearest occluder depth per texel (given).
//!    The paper's shadow map holds the whole scene, receivers included, and
//!    its depth r behind a smoothie is what sizes the penumbra; pass
//!    [`shadow_map`] (front and receiver merged) to reproduce that. Where
//!    `front` is inf the remap has nothing to divide by and the smoothie
//!    keeps its linear alpha (a penumbra of width t).
//! 2. Silhouette edges w.r.t. the light's centre (`silhouette.rs`).
//! 3. Smoothie edges and corners of width t in the image plane (`construct.rs`),
//!    t = width (L/2) / b_ref, b_ref the median depth of the silhouette
//!    edges' midpoints, per axis (Lu across u, Lv across v). Under a disk
//!    of radius ρ, L = 2ρ on both: the penumbra across a straight edge is
//!    the diameter wide whatever the edge's direction. Its profile across
//!    the edge is a circular segment's area, not a line, but the smoothies'
//!    linear alpha kept under a disk erred less against Mitsuba than that
//!    profile on all six calibration scenes and four of six held-out ones
//!    (docs/methods/smoothies.md): the ramp is not the method's error.
//! 4. The smoothie buffer: depth and remapped alpha alpha / (1 - b/r), minimum
//!    blending (`buffer.rs`).
//! 5. The lookup: umbra from the shadow map, penumbra from the smoothie
//!    buffer, 2x2 tent, falloff (`lookup.rs`).
//!
//! A fake soft shadow: an outer penumbra only, the umbra is the hard shadow's
//! and does not shrink as the light grows (§2.1, §5).

mod buffer;
pub mod config;
mod construct;
pub(crate) mod lookup;
pub mod method;
mod silhouette;
#[cfg(test)]
mod tests;

use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::plane_gradient::Plane;
use crate::methods::LightPoint;
pub(crate) use construct::Shape;
use glam::DVec3;
use rayon::prelude::*;

/// The falloff applied to the filtered visibility v in [0, 1] (§3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Falloff {
    /// v' = v: the linear alpha of the smoothies.
    Linear,
    /// v' = (1 - cos(pi v)) / 2: the sinusoidal falloff the paper takes from
    /// Parker et al. and Haines (a 1D texture there), smooth at both ends of
    /// the penumbra, below v under 1/2 and above it over 1/2.
    Sine,
}

impl Falloff {
    pub const ALL: [Falloff; 2] = [Falloff::Linear, Falloff::Sine];

    pub fn name(self) -> &'static str {
        match self {
            Falloff::Linear => "linear",
            Falloff::Sine => "sine",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        Falloff::ALL.into_iter().find(|f| f.name() == s)
    }

    /// The falloff of a visibility in [0, 1] (clamped).
    #[inline]
    pub fn apply(self, v: f32) -> f32 {
        let v = v.clamp(0.0, 1.0);
        match self {
            Falloff::Linear => v,
            Falloff::Sine => {
                if v <= 0.0 || v >= 1.0 {
                    v
                } else {
                    ((1.0 - (std::f64::consts::PI * v as f64).cos()) * 0.5) as f32
                }
            }
        }
    }
}

/// The method's options: the smoothies' width (dimensionless: 1 matches a
/// real penumbra of the light's size for blockers at the reference depth,
/// larger simulates a larger light, §6) and the falloff.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Smoothies {
    pub width: f64,
    pub falloff: Falloff,
}

/// What building the smoothie buffer did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SmoothieStats {
    /// Object-space silhouette edges found (before clipping to the map).
    pub silhouette_edges: usize,
    /// Smoothie corners built (convex silhouette vertices joining two edges,
    /// and the special-case vertices with more edges).
    pub corners: usize,
    /// Smoothie texels rasterized and not discarded behind a blocker.
    pub texels: usize,
}

/// The smoothie buffer on the shadow map's grid: per texel the depth of the
/// smoothie whose alpha won the minimum (inf where none) and that alpha (1
/// where none).
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothieBuffer {
    pub depth: Vec<f32>,
    pub alpha: Vec<f32>,
    pub stats: SmoothieStats,
}

/// Steps 2-3's output: the smoothies (q space, width `t`) and the stats
/// known before rasterizing (`texels` is step 4's).
pub(crate) struct Built {
    pub shapes: Vec<Shape>,
    pub t: f64,
    pub stats: SmoothieStats,
}

/// The paper's shadow map from the project's maps on one grid: the nearer of
/// the front occluder depth and the receiver depth, texel by texel.
pub fn shadow_map(front: &[f32], receiver: &[f32]) -> Vec<f32> {
    front
        .iter()
        .zip(receiver)
        .map(|(&f, &r)| if r < f { r } else { f })
        .collect()
}

impl Smoothies {
    /// The smoothies' width t in tangent units across u and across v, for
    /// the silhouette of these occluders; None without a silhouette, a
    /// light, or a positive width.
    pub fn tangent_width(
        &self,
        light_shape: LightShape,
        verts: &[DVec3],
        faces: &[[u32; 3]],
    ) -> Option<[f64; 2]> {
        let sil = silhouette::silhouette(verts, faces);
        let t = self.q_width(&sil, light_shape)?;
        let [lx, ly] = light_shape.extent();
        Some([t * lx, t * ly])
    }

    /// t in the image plane scaled by the light's size (construct.rs).
    fn q_width(&self, sil: &silhouette::Silhouette, light: LightShape) -> Option<f64> {
        let light = light.extent();
        let light_ok = light.iter().all(|l| l.is_finite() && *l > 0.0);
        if !(light_ok && self.width.is_finite() && self.width > 0.0) {
            return None;
        }
        let b_ref = construct::reference_depth(sil)?;
        let t = self.width / (2.0 * b_ref);
        (t.is_finite() && t > 0.0).then_some(t)
    }

    /// Steps 2-3: the silhouette and its smoothies on `grid` (width t in q
    /// units, 0 and no shapes without a width), with the stats they give.
    /// Shared by the CPU's step 4 (`buffer`) and the GPU's (`gpu/smoothies.rs`).
    pub(crate) fn smoothies(
        &self,
        grid: &MapGrid,
        light_shape: LightShape,
        verts: &[DVec3],
        faces: &[[u32; 3]],
    ) -> Built {
        let sil = silhouette::silhouette(verts, faces);
        let mut stats = SmoothieStats {
            silhouette_edges: sil.edges.len(),
            ..Default::default()
        };
        let Some(t) = self.q_width(&sil, light_shape) else {
            return Built {
                shapes: vec![],
                t: 0.0,
                stats,
            };
        };
        let smoothies = construct::build(&sil, grid, light_shape.extent(), t);
        stats.corners = smoothies.corners;
        Built {
            shapes: smoothies.shapes,
            t,
            stats,
        }
    }

    /// Steps 2-4: the silhouette, the smoothies and the smoothie buffer on
    /// `grid`, remapped against the shadow map `front` (H x W on `grid`).
    pub fn buffer(
        &self,
        grid: &MapGrid,
        light_shape: LightShape,
        front: &[f32],
        verts: &[DVec3],
        faces: &[[u32; 3]],
    ) -> SmoothieBuffer {
        assert_eq!(front.len(), grid.len(), "front must be H x W on the grid");
        let built = self.smoothies(grid, light_shape, verts, faces);
        let mut buf = SmoothieBuffer {
            depth: vec![f32::INFINITY; grid.len()],
            alpha: vec![1.0; grid.len()],
            stats: built.stats,
        };
        if built.shapes.is_empty() {
            return buf;
        }
        buf.stats.texels = buffer::rasterize(
            grid,
            light_shape.extent(),
            front,
            &built.shapes,
            built.t,
            &mut buf.depth,
            &mut buf.alpha,
        );
        buf
    }

    /// Step 5 at receiver points in light space, each tested on its
    /// tangent plane `planes[i]` ((0, 0) where missing: `lookup.rs`).
    pub fn visibility_points(
        &self,
        grid: &MapGrid,
        front: &[f32],
        buffer: &SmoothieBuffer,
        points: &[LightPoint],
        planes: &[Plane],
    ) -> Vec<f32> {
        check(grid, front, buffer);
        points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let plane = planes.get(i).copied().unwrap_or([0.0; 2]);
                lookup::at_point(grid, front, buffer, self.falloff, p.x, p.y, p.z, plane)
            })
            .collect()
    }

    /// receiver: planar depth per texel of `grid` (inf where none), shaded at texel centres.
    pub fn visibility_map(
        &self,
        grid: &MapGrid,
        front: &[f32],
        buffer: &SmoothieBuffer,
        receiver: &[f32],
    ) -> Vec<f32> {
        check(grid, front, buffer);
        assert_eq!(
            receiver.len(),
            grid.len(),
            "receiver must be H x W on the grid"
        );
        receiver
            .par_iter()
            .enumerate()
            .map(|(k, &z)| lookup::at_texel(front, buffer, self.falloff, k, z))
            .collect()
    }
}

fn check(grid: &MapGrid, front: &[f32], buffer: &SmoothieBuffer) {
    assert_eq!(front.len(), grid.len(), "front must be H x W on the grid");
    assert!(
        buffer.depth.len() == grid.len() && buffer.alpha.len() == grid.len(),
        "the smoothie buffer must be on the grid"
    );
}
