//! The single-ray contenders: each crate's BVH built over the same
//! light-space triangles, and its fastest documented any-hit query for the
//! segment o + t d, t in (T0, T1).

use crate::{T0, T1};
use glam::{Vec3, Vec3A};

/// A BVH that answers shadow rays one at a time.
pub trait Contender: Sync + Sized {
    /// What the table shows, after the crate's name and version (from
    /// Cargo.lock) where it is one.
    const NAME: &'static str;
    /// The crate whose version is shown (None: ours).
    const CRATE: Option<&'static str>;
    fn build(tris: &[[Vec3; 3]]) -> Self;
    /// Whether a triangle crosses o + t d for some t in (T0, T1).
    fn occluded(&self, o: Vec3, d: Vec3) -> bool;
}

/// Ours: binned SAH, 4 triangles a leaf, scalar Möller-Trumbore; the
/// traversal that the GPU twin (gpu/exact.wgsl) repeats.
pub struct Ours(softshadow::methods::exact::Bvh);

impl Contender for Ours {
    const NAME: &'static str = "ours, one ray at a time (`Bvh::occluded`)";
    const CRATE: Option<&'static str> = None;
    fn build(tris: &[[Vec3; 3]]) -> Self {
        Ours(softshadow::methods::exact::Bvh::build(tris.to_vec()))
    }
    #[inline]
    fn occluded(&self, o: Vec3, d: Vec3) -> bool {
        self.0.occluded(o, d, T0, T1)
    }
}

/// Möller-Trumbore, two-sided, t in (T0, T1): the same float operations as
/// softshadow's `bvh.rs` (`hit_t`, which is crate-private), for the `bvh`
/// crate, whose own `Ray::intersects_triangle` culls back faces (it misses
/// every triangle seen from behind: wrong for shadows) and rejects
/// determinants under a fixed `f32::EPSILON`.
#[inline]
fn moller_trumbore(t: &[Vec3; 3], o: Vec3, d: Vec3) -> bool {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return false;
    }
    let inv = 1.0 / det;
    let s = o - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let th = e2.dot(q) * inv;
    th > T0 && th < T1
}

/// `bvh`: a binary SAH BVH of one triangle a leaf (nalgebra types); its
/// allocation-free `traverse_iterator` yields the triangles whose box the
/// (infinite) ray enters, the first one hit ends the search.
pub struct SvenstaroBvh {
    bvh: bvh::bvh::Bvh<f32, 3>,
    tris: Vec<BvhTri>,
}

pub struct BvhTri {
    v: [Vec3; 3],
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for BvhTri {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        let p = |v: Vec3| nalgebra::Point3::new(v.x, v.y, v.z);
        let lo = self.v[0].min(self.v[1]).min(self.v[2]);
        let hi = self.v[0].max(self.v[1]).max(self.v[2]);
        bvh::aabb::Aabb::with_bounds(p(lo), p(hi))
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for BvhTri {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

impl Contender for SvenstaroBvh {
    const NAME: &'static str = "`traverse_iterator`, our triangle test";
    const CRATE: Option<&'static str> = Some("bvh");
    fn build(tris: &[[Vec3; 3]]) -> Self {
        let mut tris: Vec<BvhTri> = tris.iter().map(|&v| BvhTri { v, node: 0 }).collect();
        // `build`, not `build_par`: every build here is single-threaded.
        let bvh = bvh::bvh::Bvh::build(&mut tris);
        SvenstaroBvh { bvh, tris }
    }
    #[inline]
    fn occluded(&self, o: Vec3, d: Vec3) -> bool {
        let ray = bvh::ray::Ray::new(
            nalgebra::Point3::new(o.x, o.y, o.z),
            nalgebra::Vector3::new(d.x, d.y, d.z),
        );
        self.bvh
            .traverse_iterator(&ray, &self.tris)
            .any(|t| moller_trumbore(&t.v, o, d))
    }
}

/// `obvhs`: PLOC BVH2 collapsed to a compressed 8-wide BVH (CWBVH, up to 3
/// triangles a leaf), SIMD box tests; `ray_traverse_miss` (its shadow-ray
/// query, used so by its demoscene example) with its own triangle test
/// (`RtTriangle`, precomputed edges and normal), the triangles laid out in
/// the BVH's order as its cornell_box example does.
pub struct Obvhs {
    bvh: obvhs::cwbvh::CwBvh,
    tris: Vec<obvhs::rt_triangle::RtTriangle>,
}

impl Contender for Obvhs {
    const NAME: &'static str = "CWBVH, `ray_traverse_miss`, its `RtTriangle`";
    const CRATE: Option<&'static str> = Some("obvhs");
    fn build(tris: &[[Vec3; 3]]) -> Self {
        let tris: Vec<obvhs::triangle::Triangle> = tris
            .iter()
            .map(|t| obvhs::triangle::Triangle {
                v0: t[0].into(),
                v1: t[1].into(),
                v2: t[2].into(),
            })
            .collect();
        // medium_build: the crate's documented default ("around the same
        // build time as embree but with faster traversal").
        let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &tris,
            obvhs::BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| obvhs::rt_triangle::RtTriangle::from(&tris[i as usize]))
            .collect();
        Obvhs { bvh, tris }
    }
    #[inline]
    fn occluded(&self, o: Vec3, d: Vec3) -> bool {
        let ray = obvhs::ray::Ray::new(Vec3A::from(o), Vec3A::from(d), T0, T1);
        !self
            .bvh
            .ray_traverse_miss(ray, |r, id| self.tris[id].intersect(r))
    }
}

/// `parry3d` (dimforge): its binary BVH (binned SAH, one leaf a triangle);
/// `Bvh::traverse` with an early exit at the first triangle hit (its
/// `TriMesh::intersects_local_ray` is a nearest-hit search), parry's own
/// ray-triangle test. parry3d's math is glam 0.33 (through glamx): the
/// vectors cross as arrays.
pub struct Parry {
    bvh: parry3d::partitioning::Bvh,
    tris: Vec<parry3d::shape::Triangle>,
}

fn pv(v: Vec3) -> parry3d::math::Vector {
    parry3d::math::Vector::new(v.x, v.y, v.z)
}

impl Contender for Parry {
    const NAME: &'static str = "`Bvh::traverse` + early exit, its triangle test";
    const CRATE: Option<&'static str> = Some("parry3d");
    fn build(tris: &[[Vec3; 3]]) -> Self {
        let tris: Vec<parry3d::shape::Triangle> = tris
            .iter()
            .map(|t| parry3d::shape::Triangle::new(pv(t[0]), pv(t[1]), pv(t[2])))
            .collect();
        let boxes: Vec<_> = tris.iter().map(|t| t.local_aabb()).collect();
        let bvh = parry3d::partitioning::Bvh::from_leaves(
            parry3d::partitioning::BvhBuildStrategy::Binned,
            &boxes,
        );
        Parry { bvh, tris }
    }
    #[inline]
    fn occluded(&self, o: Vec3, d: Vec3) -> bool {
        use parry3d::partitioning::TraversalAction;
        use parry3d::query::RayCast;
        let ray = parry3d::query::Ray::new(pv(o), pv(d));
        let mut hit = false;
        self.bvh.traverse(|node| {
            if node.cast_ray(&ray, T1) == f32::MAX {
                TraversalAction::Prune
            } else if let Some(k) = node.leaf_data() {
                let t = self.tris[k as usize].cast_local_ray(&ray, T1, true);
                hit = t.is_some_and(|t| t > T0 && t < T1);
                if hit {
                    TraversalAction::EarlyExit
                } else {
                    TraversalAction::Continue
                }
            } else {
                TraversalAction::Continue
            }
        });
        hit
    }
}
