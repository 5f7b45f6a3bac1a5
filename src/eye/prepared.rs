//! A scene prepared once for many renders (issue 29, "prepare once, render
//! many"): what an eye-view call builds from the meshes alone, kept for the
//! next call with another camera or light.
//!
//! Kept: the gathered and checked triangles (`SceneTriangles`) and, per
//! orientation of the light's frame, the shape of the BVH the shadow rays
//! traverse. A call whose meshes are the same (the fingerprint below) reads
//! the triangles back and, lit by a light of a kept orientation, refits the
//! kept tree to its own light space (`Bvh::refit`: every box recomputed,
//! no split chosen again) instead of building one. Another camera moves
//! the light space by a scale (a rectangle's depth unit) or refocuses it (a
//! sun's frame), so the kept splits stay near the SAH's; a light turned
//! another way builds its own tree, kept beside (the last `TREES`).
//!
//! Nothing of a call's answer depends on what was kept: a refitted tree
//! gives every ray the answer a fresh build gives (refit.rs), so a call
//! returns the same image with or without a preparation.
//!
//! Same meshes: the count of meshes, their vertex and face counts, and a
//! 128-bit hash of every vertex coordinate's bits and every index, taken
//! at each call (one multiply-rotate per word, in parallel chunks; not
//! timed alone: it sits in the `first_hits` lap, 65-80 ms for the whole
//! lap on 2 000 000 triangles at 640 x 480 in bench_scale's following
//! calls): a mesh changed in place, replaced or appended is another
//! scene, and the preparation starts again. Safe to share between threads:
//! the lock is held to look up and to store, never while building.

use super::gbuffer::SceneTriangles;
use crate::error::Result;
use crate::geom::light_space::Light;
use crate::geom::mesh::MeshRef;
use crate::trace::bvh::Topology;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// Trees kept, one per orientation of the light (the most recent).
const TREES: usize = 4;

/// What identifies a scene's meshes: counts and a hash of their contents.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Fingerprint {
    sizes: Vec<(usize, usize)>,
    hash: [u64; 2],
}

/// The orientation of a light's frame (u, v, n, bit for bit) and its kind:
/// what a kept tree's splits were chosen in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Orientation {
    sun: bool,
    frame: [u64; 9],
}

impl Orientation {
    fn of(light: &Light) -> Orientation {
        let (sun, u, v, n) = match light {
            Light::Area(l) => (false, l.u, l.v, l.n),
            Light::Sun(s) => (true, s.u, s.v, s.n),
            // A sphere's rays are traced in the world's axes.
            Light::Sphere(_) => (false, DVec3::X, DVec3::Y, DVec3::Z),
        };
        let c = [u, v, n].map(|a| a.to_array().map(f64::to_bits));
        Orientation {
            sun,
            frame: std::array::from_fn(|k| c[k / 3][k % 3]),
        }
    }
}

struct Kept {
    meshes: Fingerprint,
    scene: Arc<SceneTriangles>,
    /// Most recent last.
    trees: Vec<(Orientation, Arc<Topology>)>,
}

/// A scene's preparation: empty until a call fills it. Shared by reference
/// between calls (and threads).
#[derive(Default)]
pub struct Prepared {
    kept: Mutex<Option<Kept>>,
}

/// What a call found prepared: its triangles, and the kept tree of its
/// light's orientation, if any.
pub struct Found {
    pub scene: Arc<SceneTriangles>,
    pub tree: Option<Arc<Topology>>,
    meshes: Fingerprint,
    orientation: Orientation,
}

impl std::fmt::Debug for Prepared {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (scene, trees) = self.held();
        write!(f, "Prepared(triangles kept: {scene}, trees: {trees})")
    }
}

impl Prepared {
    /// The triangles of `meshes` (kept, or gathered and checked now and
    /// kept), and the tree kept for `light`'s orientation.
    pub fn find(&self, meshes: &[MeshRef], light: &Light) -> Result<Found> {
        let fingerprint = fingerprint(meshes);
        let orientation = Orientation::of(light);
        {
            let kept = self.lock();
            if let Some(k) = kept.as_ref().filter(|k| k.meshes == fingerprint) {
                let tree = k
                    .trees
                    .iter()
                    .find(|(o, _)| *o == orientation)
                    .map(|(_, t)| t.clone());
                return Ok(Found {
                    scene: k.scene.clone(),
                    tree,
                    meshes: fingerprint,
                    orientation,
                });
            }
        }
        let scene = Arc::new(SceneTriangles::new(meshes)?);
        let mut kept = self.lock();
        if kept.as_ref().is_none_or(|k| k.meshes != fingerprint) {
            *kept = Some(Kept {
                meshes: fingerprint.clone(),
                scene: scene.clone(),
                trees: vec![],
            });
        }
        Ok(Found {
            scene,
            tree: None,
            meshes: fingerprint,
            orientation,
        })
    }

    /// Keeps `tree`, built for what `found` was found for, unless the
    /// preparation moved on to other meshes meanwhile.
    pub fn keep(&self, found: &Found, tree: Arc<Topology>) {
        let mut kept = self.lock();
        let Some(k) = kept.as_mut().filter(|k| k.meshes == found.meshes) else {
            return;
        };
        k.trees.retain(|(o, _)| *o != found.orientation);
        k.trees.push((found.orientation, tree));
        if k.trees.len() > TREES {
            k.trees.remove(0);
        }
    }

    /// Forgets everything kept.
    pub fn clear(&self) {
        *self.lock() = None;
    }

    /// Whether triangles are kept, and how many trees.
    pub fn held(&self) -> (bool, usize) {
        let kept = self.lock();
        (kept.is_some(), kept.as_ref().map_or(0, |k| k.trees.len()))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Kept>> {
        // A panic while holding the lock cannot leave a half-written entry
        // (every write is one assignment): the value is usable.
        self.kept.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The meshes' sizes and a hash of their contents: two independent 64-bit
/// multiply-rotate hashes over every word, in chunks hashed in parallel
/// and combined in order.
fn fingerprint(meshes: &[MeshRef]) -> Fingerprint {
    const CHUNK: usize = 1 << 15;
    let words = |m: &MeshRef| -> Vec<u64> {
        let v = m
            .vertices
            .par_chunks(CHUNK)
            .map(|c| hash_words(c.iter().flat_map(|p| p.map(f64::to_bits))));
        let f = m
            .faces
            .par_chunks(CHUNK)
            .map(|c| hash_words(c.iter().flat_map(|t| t.map(u64::from))));
        v.chain(f).flat_map(|h| h.to_vec()).collect()
    };
    let parts: Vec<u64> = meshes.iter().flat_map(words).collect();
    let h = hash_words(parts.into_iter());
    Fingerprint {
        sizes: meshes
            .iter()
            .map(|m| (m.vertices.len(), m.faces.len()))
            .collect(),
        hash: h,
    }
}

/// Two 64-bit hashes of `words` (multiply, rotate, xor; different odd
/// constants), each finished by a splitmix round.
fn hash_words(words: impl Iterator<Item = u64>) -> [u64; 2] {
    let (mut a, mut b) = (0x243F_6A88_85A3_08D3u64, 0x1319_8A2E_0370_7344u64);
    let mut n = 0u64;
    for w in words {
        a = (a ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
        b = (b ^ w.rotate_left(17))
            .wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            .rotate_left(31);
        n += 1;
    }
    let mix = |mut x: u64| {
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        x ^ (x >> 31)
    };
    [mix(a ^ n), mix(b ^ n.rotate_left(32))]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::AreaLight;
    use crate::methods::exact::Bvh;

    fn light(n: [f64; 3]) -> Light {
        Light::Area(AreaLight::rect([0.0, 3.0, 0.0], n, [0.0, 0.0, 1.0], [1.0, 1.0]).unwrap())
    }

    #[test]
    fn the_same_meshes_find_what_was_kept_and_others_start_again() {
        let mut v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let f = vec![[0u32, 1, 2]];
        let p = Prepared::default();
        let down = light([0.0, -1.0, 0.0]);
        fn mesh<'a>(v: &'a [[f64; 3]], f: &'a [[u32; 3]]) -> Vec<MeshRef<'a>> {
            vec![MeshRef {
                vertices: v,
                faces: f,
            }]
        }
        let found = p.find(&mesh(&v, &f), &down).unwrap();
        assert!(found.tree.is_none());
        p.keep(&found, Arc::new(Bvh::build(vec![]).topology()));
        assert_eq!(p.held(), (true, 1));
        // The same meshes again: the same triangles, the tree kept.
        let again = p.find(&mesh(&v, &f), &down).unwrap();
        assert!(Arc::ptr_eq(&again.scene, &found.scene) && again.tree.is_some());
        // Another orientation: no tree yet.
        assert!(p
            .find(&mesh(&v, &f), &light([0.0, -1.0, 0.1]))
            .unwrap()
            .tree
            .is_none());
        // A vertex moved by one bit: another scene.
        v[1][0] = f64::from_bits(1.0f64.to_bits() + 1);
        let moved = p.find(&mesh(&v, &f), &down).unwrap();
        assert!(!Arc::ptr_eq(&moved.scene, &found.scene) && moved.tree.is_none());
        assert_eq!(p.held(), (true, 0));
        // A tree built for the old meshes is not kept for the new ones.
        p.keep(&found, Arc::new(Bvh::build(vec![]).topology()));
        assert_eq!(p.held(), (true, 0));
        p.clear();
        assert_eq!(p.held(), (false, 0));
    }

    #[test]
    fn the_fingerprint_sees_every_word_and_the_split_into_meshes() {
        let v: Vec<[f64; 3]> = (0..70_000).map(|k| [k as f64, 0.5, -1.0]).collect();
        let f: Vec<[u32; 3]> = (0..70_000u32).map(|k| [k, (k + 1) % 70_000, 0]).collect();
        let one = fingerprint(&[MeshRef {
            vertices: &v,
            faces: &f,
        }]);
        let mut w = v.clone();
        w[69_999][2] = -1.5;
        assert_ne!(
            one,
            fingerprint(&[MeshRef {
                vertices: &w,
                faces: &f
            }])
        );
        let mut g = f.clone();
        g.swap(3, 4);
        assert_ne!(
            one,
            fingerprint(&[MeshRef {
                vertices: &v,
                faces: &g
            }])
        );
        let split = fingerprint(&[
            MeshRef {
                vertices: &v[..10],
                faces: &f[..0],
            },
            MeshRef {
                vertices: &v[10..],
                faces: &f,
            },
        ]);
        assert_ne!(one, split);
        assert_eq!(
            one,
            fingerprint(&[MeshRef {
                vertices: &v,
                faces: &f
            }])
        );
    }
}
