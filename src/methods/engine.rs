//! How `exact` finds which of a receiver's light samples are hidden: a
//! shadow ray a sample through the BVH (`shadow_rays.rs`, the reference),
//! or each receiver's sample mask from the triangles that cross its light
//! (`masks/`). Both answer the same question on the same shared pattern and
//! differ only on rays that graze an edge (`masks/tests.rs`).

use crate::trace::bvh::Bvh;
use crate::trace::shadow_rays::{visibilities_weighted as traced, Jitter, RayOrigin, Sampling};

/// The way `exact`'s samples are decided.
/// An unset `engine` is resolved by `ExactConfig::engine_for`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Engine {
    /// One shadow ray a light sample (packets of neighbouring receivers).
    Rays,
    /// Each receiver's samples marked by the triangles crossing its light.
    Masks,
}

impl Engine {
    pub const ALL: [Engine; 2] = [Engine::Rays, Engine::Masks];

    /// The name a user passes as `engine=`.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Rays => "rays",
            Engine::Masks => "masks",
        }
    }

    pub fn parse(name: &str) -> Option<Engine> {
        Engine::ALL.into_iter().find(|e| e.name() == name)
    }
}

/// `[V, V_w]` of each receiver (`shadow_rays::visibilities_weighted`'s
/// contract), by `engine`; the masks need the shared pattern, so a
/// per-receiver jitter (the probe's) always traces rays, and distinct
/// samples, so a point light's (every sample at its centre) does too.
pub(crate) fn visibilities_weighted<R: RayOrigin>(
    engine: Engine,
    bvh: &Bvh,
    receivers: &[Option<R>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    s: &Sampling,
    absent: f32,
) -> Vec<[f32; 2]> {
    match engine {
        Engine::Masks if s.jitter == Jitter::Shared => {
            match super::masks::visibilities_weighted(bvh, receivers, order, s, absent) {
                Some((mut v, left)) => {
                    // The receivers whose triangles would have cost more
                    // than their rays: traced, in the order they came.
                    if !left.is_empty() {
                        let sub: Vec<Option<&R>> =
                            left.iter().map(|&k| receivers[k].as_ref()).collect();
                        let at: Vec<usize> = (0..left.len()).collect();
                        let got = traced(bvh, &sub, |j| key(left[j]), &at, s, absent);
                        for (&k, x) in left.iter().zip(got) {
                            v[k] = x;
                        }
                    }
                    v
                }
                None => traced(bvh, receivers, key, order, s, absent),
            }
        }
        _ => traced(bvh, receivers, key, order, s, absent),
    }
}
