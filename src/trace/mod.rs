//! The ray engine: what every accurate answer goes through. A bounding
//! volume hierarchy over triangles (`bvh.rs`: binned SAH, Wald 2007; its
//! refit where only the light or camera moved, `bvh/refit.rs`), collapsed
//! to four-wide nodes (`bvh_wide.rs`; Wald et al. 2008); shadow rays as
//! segments o + t d, t in (t0, t1), any hit, by a watertight test (Woop,
//! Benthin & Wald 2013: `bvh::hit_t`) behind slab tests that rounding
//! cannot fool (`bvh::EXIT_SLACK`; Ize 2013), traced eight neighbouring receivers at a time (`packet.rs`:
//! AVX2 or AVX-512 lanes, each lane the scalar ray's operations; Wald et al.
//! 2001) after a shaft test culls what is clear (`shaft.rs`); the stratified
//! light samples and the per-receiver loop (`shadow_rays.rs`), and where a
//! ray leaves a surface (`ray_start.rs`). Camera rays' nearest hits go
//! through the same tree (`Bvh::nearest`).
//!
//! Used by the methods (`exact`'s rays and masks, the probe), the eye view
//! (its first hits, the error estimates) and the GPU twins (which upload
//! the same nodes); it names none of them. Issue 51 is its project: rays
//! at Embree's speed.

pub mod bvh;
mod bvh_node;
pub(crate) mod bvh_wide;
pub(crate) mod packet;
pub(crate) mod ray_start;
pub(crate) mod shadow_rays;
pub(crate) mod shaft;
