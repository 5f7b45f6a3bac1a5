//! Shadow methods, and their registry. Each method is one module behind
//! [`ShadowMethod`], configured by one typed config that describes itself in
//! the same module (`config::MethodSpec`: name, string form, resolution,
//! capabilities row); every method writes the same outputs (visibility per
//! receiver texel, or per receiver point). `capabilities.rs` publishes the
//! table of methods, options, defaults and limits.
//!
//! The registry is this file: a method is declared here once, by its module
//! (`pub mod`) and its line of `methods!`, `Variant(Config => Kernel)`,
//! which makes its `MethodConfig` variant, its name, the dispatch and its
//! capabilities row, and its `Method` variant, the kernel a resolved config
//! runs (`registry.rs`). Both types are the method module's own: the config
//! implements `config::MethodSpec`, the kernel `kernel::Kernel` (what it
//! reads, how its work is bounded, its implementation). The configs' and
//! kernels' modules never name this file, so the registry imports them
//! without a circle. A line marked `keywords` is a config with a keyword
//! form (`keywords.rs`): the bindings make its Python class from it, with
//! no code of the method's.

pub mod auto_config;
pub mod bitmask;
pub mod capabilities;
pub mod config;
pub mod engine;
pub mod exact;
pub(crate) mod gather;
pub mod info;
pub mod inputs;
pub mod kernel;
pub mod keywords;
pub(crate) mod masks;
pub mod pcf;
mod pcf_disk;
pub mod pcss;
mod pcss_weighted;
pub mod point_light;
pub(crate) mod probe;
mod registry;
pub mod shadow_mapping;
pub mod smoothies;
pub mod ssm;
pub mod target;

pub use auto_config::{auto_rule, AutoConfig};
pub use bitmask::{BitmaskConfig, BitmaskKernel, HIERARCHY_DEFAULT_BITMASK};
pub use exact::{Exact, ExactConfig};
pub use gather::{Hierarchy, HIERARCHY};
pub use inputs::{is_receiver, EyePoints, Input, LightPoint, ShadowInputs, ShadowMethod};
pub use kernel::Kernel;
pub use pcss::{Pcss, PcssConfig};
pub use shadow_mapping::config::ShadowMappingConfig;
pub use smoothies::config::SmoothiesConfig;
pub use smoothies::method::SmoothiesKernel;
pub use ssm::{SsmConfig, SsmKernel, HIERARCHY_DEFAULT_SSM};

registry::methods! {
    Ssm(SsmConfig => ssm::SsmKernel, keywords),
    Bitmask(BitmaskConfig => bitmask::BitmaskKernel, keywords),
    Exact(ExactConfig => exact::Exact, keywords),
    /// Fernando 2005's percentage-closer soft shadows (`pcss.rs`).
    Pcss(PcssConfig => pcss::Pcss, keywords),
    /// Chan & Durand 2003's smoothies (`smoothies/`).
    Smoothies(SmoothiesConfig => smoothies::method::SmoothiesKernel, keywords),
    /// Scherzer 2005's practical shadow mapping (hard shadows from the
    /// light's centre or direction; `shadow_mapping/`).
    ShadowMapping(ShadowMappingConfig => ShadowMappingConfig),
    Auto(AutoConfig),
}

impl Method {
    /// Whether the method only traces triangles (reads no occluder maps):
    /// `exact`.
    pub fn traces(&self) -> bool {
        self.reads_input(Input::OccluderTriangles) && !self.reads_input(Input::OccluderLayers)
    }

    /// Whether the method reads `input`.
    pub fn reads_input(&self, input: Input) -> bool {
        self.reads().contains(&input)
    }
}

/// Visibility of every receiver texel: the method's, or for a point light
/// (size 0) on the map methods the hard shadow they converge to.
pub fn shade_map(method: Method, inputs: &ShadowInputs) -> Vec<f32> {
    if inputs.light_shape.is_point() && method.reads_input(Input::OccluderLayers) {
        point_light::visibility_map(inputs)
    } else {
        method.implementation().visibility_map(inputs)
    }
}

/// Runs `shade` (a call of `method` on `inputs`: `shade_map`, `shade_points`
/// or a method's own entry), refusing a call whose cost grows with a
/// parameter rather than with what the answer needs: a bound known before
/// any receiver is shaded (`Kernel::check_cost`: PCSS's texel reads); the
/// gather kernels' visits (`Kernel::visit_cost`), counted as they are made (`gather::meter::metered`) and
/// stopped past `gather::work::visit_limit` (a number a receiver),
/// naming `arg`, the option whose size drove them. `pts`: the receivers,
/// or None for the receiver map's texels.
pub fn bounded<T>(
    method: Method,
    inputs: &ShadowInputs,
    pts: Option<&[LightPoint]>,
    arg: &str,
    shade: impl FnOnce() -> T,
) -> crate::error::Result<T> {
    let Some(cost) = method
        .visit_cost()
        .filter(|_| !inputs.light_shape.is_point())
    else {
        method.check_cost(inputs, pts)?;
        return Ok(shade());
    };
    let receivers = match pts {
        Some(p) => p.iter().filter(|p| is_receiver(p.z)).count(),
        None => inputs.receiver.iter().filter(|&&z| is_receiver(z)).count(),
    };
    let limit = gather::work::visit_limit(cost, receivers);
    let (v, visits) = gather::meter::metered(limit, shade);
    if visits > limit {
        return Err(gather::work::refusal(cost, inputs, receivers, arg));
    }
    Ok(v)
}

/// Visibility at receiver points, as `shade_map`.
pub fn shade_points(method: Method, inputs: &ShadowInputs, pts: &[LightPoint]) -> Vec<f32> {
    if inputs.light_shape.is_point() && method.reads_input(Input::OccluderLayers) {
        point_light::visibility_points(inputs, pts)
    } else {
        method.implementation().visibility_points(inputs, pts)
    }
}

/// The eye view's points shaded by `method` (`ShadowMethod::visibility_eye`):
/// the visibility, and the weighted one where the kernel has it and `eye`
/// asks for it.
pub fn shade_eye(
    method: Method,
    inputs: &ShadowInputs,
    eye: &EyePoints,
) -> (Vec<f32>, Option<Vec<f32>>) {
    method.implementation().visibility_eye(inputs, eye)
}

/// A texel-aligned square plate over a parallel floor, whose visibility has
/// a closed form: the methods' shared accuracy check.
#[cfg(test)]
pub(crate) mod plate_case {
    use super::{LightPoint, ShadowInputs, ShadowMethod};
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;
    use crate::trace::shadow_rays::{RayOrigin, SurfacePoint};
    use glam::Vec3;

    /// Largest |V - V_exact| of `method` on an n x n map of a plate covering
    /// tangent [-1/4, 1/4]^2 at depth 2 over a floor at depth 4 (light 1 x 1).
    /// The plate's edges fall on texel edges, so the occluder map holds it
    /// exactly and any error is the method's.
    pub fn max_error(method: &dyn ShadowMethod, n: usize) -> f64 {
        mean_and_max_error(method, n, LightShape::rect([1.0, 1.0])).1
    }

    /// The mean and largest |V - V_exact| of `method` on the plate of
    /// `max_error` under a light of `shape`: the unit square, or the disk
    /// of radius 1/2 (whose occluded part is a rectangle's overlap with
    /// it, `light_shape::disk::rect_overlap`).
    pub fn mean_and_max_error(
        method: &dyn ShadowMethod,
        n: usize,
        shape: LightShape,
    ) -> (f64, f64) {
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let (zo, zr, a) = (2.0f64, 4.0f64, 0.25f64);
        let front: Vec<f32> = (0..n * n)
            .map(|k| {
                let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                if x.abs() < a && y.abs() < a {
                    zo as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver = vec![zr as f32; n * n];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: shape,
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let v = method.visibility_map(&inputs);
        // The back-projection of the plate seen from the floor point at
        // tangent c is k [-a - c, a - c], k = zr zo / (zr - zo), on the light
        // [-1/2, 1/2] (per axis).
        let k = zr * zo / (zr - zo);
        let ov = |c: f64| {
            ((k * (a - c) + 0.5).clamp(0.0, 1.0) - (k * (-a - c) + 0.5).clamp(0.0, 1.0)).max(0.0)
        };
        let span = |c: f64| [k * (-a - c), k * (a - c)];
        let (mut max, mut sum) = (0f64, 0f64);
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (grid.x_of(i), grid.y_of(j));
                let exact = match shape {
                    LightShape::Disk { radius } => {
                        let hidden =
                            crate::geom::light_shape::disk::rect_overlap(radius, span(x), span(y));
                        1.0 - hidden / shape.area()
                    }
                    LightShape::Rect { .. } => 1.0 - ov(x) * ov(y),
                };
                let e = (v[j * n + i] as f64 - exact).abs();
                max = max.max(e);
                sum += e;
            }
        }
        (sum / (n * n) as f64, max)
    }

    /// A surface point P (kernel space) with unit normal n, weighted as
    /// `eye::rays::RayStart` weighs: max(n · (y - P), 0) P_z / r⁴.
    #[derive(Clone, Copy)]
    pub struct Surface {
        pub p: Vec3,
        pub n: Vec3,
    }

    impl RayOrigin for Surface {
        fn bounds(&self) -> (Vec3, Vec3) {
            (self.p, self.p)
        }
        fn origin(&self, _x: f32, _y: f32) -> Vec3 {
            self.p
        }
        fn weight(&self, x: f32, y: f32) -> f32 {
            let d = Vec3::new(x, y, 0.0) - self.p;
            let r2 = d.length_squared();
            self.n.dot(d).max(0.0) * self.p.z / (r2 * r2)
        }
        fn surface(&self) -> Option<SurfacePoint> {
            // n · ((x, y, 0) - p) = -n · p + x n_x + y n_y.
            Some(SurfacePoint {
                p: self.p,
                side: [-self.n.dot(self.p), self.n.x, self.n.y],
            })
        }
    }

    /// The plate of `max_error` over the floor, the floor's points as
    /// Lambertian receivers of one tilted normal: their weighted visibility
    /// (the methods' for the shaded image) against the integral.
    pub struct WeightedPlate {
        pub grid: MapGrid,
        pub front: Vec<f32>,
        pub pts: Vec<LightPoint>,
        pub surfaces: Vec<Option<Surface>>,
        /// The unit square (`new`) or the disk of radius 1/2 (`under`).
        pub shape: LightShape,
    }

    impl WeightedPlate {
        /// The same plate under `shape`: the unit square or the disk of
        /// radius 1/2 inscribed in it.
        pub fn under(self, shape: LightShape) -> WeightedPlate {
            WeightedPlate { shape, ..self }
        }

        /// On an n x n map, the receivers' normal `normal` (toward the
        /// light, -Z; tilted, it weighs the light's halves unevenly).
        pub fn new(n: usize, normal: Vec3) -> WeightedPlate {
            let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
            let front = (0..n * n)
                .map(|k| {
                    let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                    if x.abs() < 0.25 && y.abs() < 0.25 {
                        2.0
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            let pts: Vec<LightPoint> = (0..n * n)
                .map(|k| LightPoint {
                    x: grid.x_of(k % n) as f32,
                    y: grid.y_of(k / n) as f32,
                    z: 4.0,
                })
                .collect();
            let normal = normal.normalize();
            let surfaces = pts
                .iter()
                .map(|q| {
                    Some(Surface {
                        p: Vec3::new(q.x * q.z, q.y * q.z, q.z),
                        n: normal,
                    })
                })
                .collect();
            WeightedPlate {
                grid,
                front,
                pts,
                surfaces,
                shape: LightShape::rect([1.0, 1.0]),
            }
        }

        /// Under the plate's light.
        pub fn inputs(&self) -> ShadowInputs<'_> {
            ShadowInputs {
                grid: self.grid,
                occluder_grid: self.grid,
                light_shape: self.shape,
                receiver: &[],
                occluder_layers: vec![&self.front],
                occluder_triangles: None,
            }
        }

        /// Point k's weighted visibility by a 400² grid of the light (its
        /// points on the disk, under one): the light point y is hidden where the segment to it crosses depth 2
        /// inside the plate ((P + y)/2 within ±1/2).
        pub fn integral(&self, k: usize) -> f64 {
            let s = self.surfaces[k].as_ref().unwrap();
            let m = 400;
            let (mut lit, mut all) = (0f64, 0f64);
            for i in 0..m {
                for j in 0..m {
                    let x = (i as f32 + 0.5) / m as f32 - 0.5;
                    let y = (j as f32 + 0.5) / m as f32 - 0.5;
                    let off = matches!(self.shape, LightShape::Disk { .. }) && x * x + y * y > 0.25;
                    if off {
                        continue;
                    }
                    let w = f64::from(s.weight(x, y));
                    all += w;
                    let (hx, hy) = (0.5 * (s.p.x + x), 0.5 * (s.p.y + y));
                    if !(hx.abs() < 0.5 && hy.abs() < 0.5) {
                        lit += w;
                    }
                }
            }
            lit / all
        }

        /// The largest |weighted - integral| and |plain - integral| over the
        /// penumbra points of plain `v` and weighted `w` (asserting
        /// that the others keep V), and how many there are.
        pub fn errors(&self, v: &[f32], w: &[f32]) -> (f64, f64, usize) {
            let (mut worst, mut plain_worst, mut penumbra) = (0f64, 0f64, 0);
            for k in 0..self.pts.len() {
                if v[k] <= 0.0 || v[k] >= 1.0 {
                    assert_eq!(w[k], v[k], "at {k}");
                    continue;
                }
                let want = self.integral(k);
                penumbra += 1;
                worst = worst.max((f64::from(w[k]) - want).abs());
                plain_worst = plain_worst.max((f64::from(v[k]) - want).abs());
            }
            (worst, plain_worst, penumbra)
        }
    }
}
