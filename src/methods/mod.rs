//! Shadow methods, and their registry. Each method is one module behind
//! [`ShadowMethod`], configured by one typed config that describes itself in
//! the same module (`config::MethodSpec`: name, string form, resolution,
//! capabilities row); every method writes the same outputs (visibility per
//! receiver texel, or per receiver point). `capabilities.rs` publishes the
//! table of methods, options, defaults and limits.
//!
//! The registry is this file: a method is declared here once, by its module
//! (`pub mod`), its line of `methods!` (which makes its `MethodConfig`
//! variant, its name, the dispatch and its capabilities row:
//! `registry.rs`) and its kernel (`Method`: the options that change what it
//! computes, what it reads, its implementation). The configs' modules never
//! name this file, so the registry imports them without a circle. A line
//! marked `keywords` is a config with a keyword form (`keywords.rs`): the
//! bindings make its Python class from it, with no code of the method's.

pub mod auto_config;
pub mod bitmask;
pub mod bvh;
mod bvh_node;
pub(crate) mod bvh_wide;
pub mod capabilities;
pub mod config;
pub mod engine;
pub mod exact;
pub(crate) mod gather;
pub mod info;
pub mod inputs;
pub mod keywords;
pub(crate) mod masks;
pub(crate) mod packet;
pub mod pcf;
mod pcf_disk;
pub mod pcss;
mod pcss_weighted;
pub mod point_light;
pub(crate) mod probe;
mod registry;
pub mod shadow_mapping;
pub(crate) mod shadow_rays;
pub(crate) mod shaft;
pub mod smoothies;
pub mod ssm;
pub mod target;

pub use auto_config::{auto_rule, AutoConfig};
pub use bitmask::{BitmaskConfig, HIERARCHY_DEFAULT_BITMASK};
pub use exact::ExactConfig;
pub use gather::Hierarchy;
pub use inputs::{is_receiver, Input, LightPoint, ShadowInputs, ShadowMethod};
pub use pcss::PcssConfig;
pub use shadow_mapping::config::ShadowMappingConfig;
pub use smoothies::config::SmoothiesConfig;
pub use ssm::{SsmConfig, HIERARCHY_DEFAULT_SSM};

registry::methods! {
    Ssm(SsmConfig, keywords),
    Bitmask(BitmaskConfig, keywords),
    Exact(ExactConfig, keywords),
    /// Fernando 2005's percentage-closer soft shadows (`pcss.rs`).
    Pcss(PcssConfig, keywords),
    /// Chan & Durand 2003's smoothies (`smoothies/`).
    Smoothies(SmoothiesConfig, keywords),
    /// Scherzer 2005's practical shadow mapping (hard shadows from the
    /// light's centre or direction; `shadow_mapping/`).
    ShadowMapping(ShadowMappingConfig),
    Auto(AutoConfig),
}

/// A method's kernel, with the options that change what it computes (the
/// options that change what it reads, layers and their resolution, are the
/// pipeline's: see `config.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Soft shadow maps, Atty et al. 2005, as published (additive
    /// micro-patches); `hierarchy` reads coarser occluder texels where the
    /// penumbra is wide (off by default: the paper has none).
    Ssm {
        hierarchy: bool,
        precision: ssm::Precision,
    },
    /// Ray casting against the occluder triangles with stratified light
    /// samples; with a probe, only where a first pass is unsure (`probe.rs`).
    Exact {
        samples: u32,
        probe: Option<u32>,
        engine: engine::Engine,
    },
    /// Micro-patches marking light samples in a bit mask per receiver (OR);
    /// `hierarchy` as for Ssm (on by default); `gaps` how neighbouring
    /// micro-patches meet (closed: connected micro-quads).
    Bitmask {
        samples: u32,
        hierarchy: bool,
        gaps: bitmask::Gaps,
    },
    /// Scherzer 2005's shadow mapping: its own map and depth test
    /// (`shadow_mapping/`, the eye view only).
    ShadowMapping(shadow_mapping::config::ShadowMappingConfig),
    /// Smoothies (Chan & Durand 2003) from the front layer and the
    /// occluders' silhouette.
    Smoothies {
        width: shadow_mapping::config::Real,
        falloff: smoothies::Falloff,
    },
    /// PCSS (Fernando 2005) on the front layer.
    Pcss { max_taps: u32 },
}

/// The level choice of the occluder hierarchy: a texel may back-project onto
/// at most this fraction of the light's width, seen from the receiver it is
/// nearest to. Measured with bitmask (256 samples, two passes) against
/// Mitsuba on the study's scenes (`benchmarks/bench_hierarchy.py`): at 3% the
/// error moves by at most 0.001 while 512² maps take 1.2-4.4x less time; at
/// 6% the error grew by up to 0.003 (a coarse texel misplaces an edge by half
/// its back-projection), at 12.5% by up to 0.02.
pub const HIERARCHY: Hierarchy = Hierarchy {
    max_texel_on_light: 0.03,
};

impl Method {
    /// The name a user passes as `method=`.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Ssm { .. } => "ssm",
            Method::Exact { .. } => "exact",
            Method::Bitmask { .. } => "bitmask",
            Method::ShadowMapping(_) => "shadow_mapping",
            Method::Smoothies { .. } => "smoothies",
            Method::Pcss { .. } => "pcss",
        }
    }

    /// What the method reads of the occluders.
    pub fn reads(&self) -> &'static [Input] {
        match self {
            Method::Ssm { .. } | Method::Bitmask { .. } | Method::Pcss { .. } => {
                &[Input::OccluderLayers]
            }
            Method::Exact { .. } => &[Input::OccluderTriangles],
            Method::ShadowMapping(_) => &[Input::SceneTriangles, Input::Camera],
            Method::Smoothies { .. } => &[Input::OccluderLayers, Input::OccluderTriangles],
        }
    }

    /// Whether the method only traces triangles (reads no occluder maps):
    /// `exact`.
    pub fn traces(&self) -> bool {
        self.reads_input(Input::OccluderTriangles) && !self.reads_input(Input::OccluderLayers)
    }

    /// Whether the kernel tests its texels on each receiver point's tangent
    /// plane where the eye view gives one (`geom/plane_gradient.rs`): the
    /// methods whose taps reach texels beside the point's, PCSS's boxes and
    /// the smoothies' tent. (The gather methods bound a receiver by its
    /// tangent plane already, and ShadowMapping has its own.)
    pub fn tests_planes(&self) -> bool {
        matches!(self, Method::Pcss { .. } | Method::Smoothies { .. })
    }

    /// Whether the method reads `input`.
    pub fn reads_input(&self, input: Input) -> bool {
        self.reads().contains(&input)
    }

    /// f32 maps the kernel keeps per occluder layer, each of the occluder
    /// grid's size: for the gather methods the 1/depth copy and its nearest
    /// and farthest bounds (`gather/hierarchy.rs`), and for connected
    /// micro-quads their corner 1/depths and those corners' reciprocals
    /// from the receivers' common plane (4 each); a hierarchy's levels add
    /// a third. Other methods: one map.
    pub fn kernel_maps_per_layer(&self) -> usize {
        let (maps, hierarchy): (usize, bool) = match *self {
            Method::Bitmask {
                hierarchy, gaps, ..
            } => (
                if gaps == bitmask::Gaps::Closed { 11 } else { 3 },
                hierarchy,
            ),
            Method::Ssm { hierarchy, .. } => (3, hierarchy),
            _ => (1, false),
        };
        if hierarchy {
            maps + maps.div_ceil(3)
        } else {
            maps
        }
    }

    pub fn implementation(&self) -> Box<dyn ShadowMethod> {
        match *self {
            Method::Ssm {
                hierarchy,
                precision,
            } => Box::new(ssm::Ssm {
                hierarchy: hierarchy.then_some(HIERARCHY),
                precision,
            }),
            Method::Exact {
                samples,
                probe,
                engine,
            } => Box::new(exact::Exact {
                samples,
                probe,
                engine,
            }),
            Method::Bitmask {
                samples,
                hierarchy,
                gaps,
            } => Box::new(bitmask::Bitmask::new(
                samples,
                gaps,
                hierarchy.then_some(HIERARCHY),
            )),
            // Refused outside the eye view when the config is resolved.
            Method::ShadowMapping(_) => unreachable!("ShadowMapping has no light-view kernel"),
            Method::Smoothies { width, falloff } => Box::new(smoothies::Smoothies {
                width: width.0,
                falloff,
            }),
            Method::Pcss { max_taps } => Box::new(pcss::Pcss { max_taps }),
        }
    }
}

impl MethodConfig {
    /// The kernel of a config; resolve it first for the backend's defaults.
    pub fn kernel(&self) -> Method {
        match *self {
            MethodConfig::Ssm(c) => Method::Ssm {
                hierarchy: c.hierarchy.unwrap_or(HIERARCHY_DEFAULT_SSM),
                precision: c.precision,
            },
            MethodConfig::Bitmask(c) => Method::Bitmask {
                samples: c.samples,
                hierarchy: c.hierarchy.unwrap_or(HIERARCHY_DEFAULT_BITMASK),
                gaps: c.gaps,
            },
            MethodConfig::Exact(c) => Method::Exact {
                samples: c.samples,
                probe: c.probe,
                // Resolved configs hold their engine; an unresolved one's is
                // the CPU's in the light view (the eye view resolves first).
                engine: c.engine_for(crate::backend::Backend::Cpu, false),
            },
            MethodConfig::Pcss(c) => Method::Pcss {
                max_taps: c.max_taps,
            },
            MethodConfig::Smoothies(c) => Method::Smoothies {
                width: c.width,
                falloff: c.falloff,
            },
            MethodConfig::ShadowMapping(c) => Method::ShadowMapping(c),
            // What "auto" always resolves to.
            MethodConfig::Auto(a) => MethodConfig::Ssm(a.given).kernel(),
        }
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
/// parameter rather than with what the answer needs: PCSS's texel reads,
/// bounded before any receiver is shaded (`Pcss::check_reads`); the gather
/// kernels' visits, counted as they are made (`gather::meter::metered`) and
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
    match method {
        Method::Pcss { max_taps } => {
            pcss::Pcss { max_taps }.check_reads(inputs, pts)?;
            Ok(shade())
        }
        Method::Ssm { .. } | Method::Bitmask { .. } if !inputs.light_shape.is_point() => {
            let receivers = match pts {
                Some(p) => p.iter().filter(|p| is_receiver(p.z)).count(),
                None => inputs.receiver.iter().filter(|&&z| is_receiver(z)).count(),
            };
            let limit = gather::work::visit_limit(method, receivers);
            let (v, visits) = gather::meter::metered(limit, shade);
            if visits > limit {
                return Err(gather::work::refusal(method, inputs, receivers, arg));
            }
            Ok(v)
        }
        _ => Ok(shade()),
    }
}

/// Visibility at receiver points, as `shade_map`.
pub fn shade_points(method: Method, inputs: &ShadowInputs, pts: &[LightPoint]) -> Vec<f32> {
    if inputs.light_shape.is_point() && method.reads_input(Input::OccluderLayers) {
        point_light::visibility_points(inputs, pts)
    } else {
        method.implementation().visibility_points(inputs, pts)
    }
}

/// `shade_points`, and beside it each point's weighted visibility seen from
/// `receivers` (its surface point and tangent plane: the share of its
/// irradiance each part of the light gives, `RayOrigin::weight`) where the
/// method has them (`bitmask`'s samples: `bitmask/weighted.rs`; `ssm`'s
/// micro-patches: `ssm/weighted.rs`); `None` for the others.
pub(crate) fn shade_points_weighted<R: shadow_rays::RayOrigin + Copy + Sync>(
    method: Method,
    inputs: &ShadowInputs,
    pts: &[LightPoint],
    receivers: &[Option<R>],
) -> (Vec<f32>, Option<Vec<f32>>) {
    match method {
        Method::Bitmask {
            samples,
            hierarchy,
            gaps,
        } if !inputs.light_shape.is_point() => {
            let m = bitmask::Bitmask::new(samples, gaps, hierarchy.then_some(HIERARCHY));
            let (v, w) = m.weighted_points(inputs, pts, receivers);
            (v, Some(w))
        }
        Method::Ssm {
            hierarchy,
            precision,
        } if !inputs.light_shape.is_point() => {
            let m = ssm::Ssm {
                hierarchy: hierarchy.then_some(HIERARCHY),
                precision,
            };
            let (v, w) = m.weighted_points(inputs, pts, receivers);
            (v, Some(w))
        }
        _ => (shade_points(method, inputs, pts), None),
    }
}

/// A texel-aligned square plate over a parallel floor, whose visibility has
/// a closed form: the methods' shared accuracy check.
#[cfg(test)]
pub(crate) mod plate_case {
    use super::shadow_rays::{RayOrigin, SurfacePoint};
    use super::{LightPoint, ShadowInputs, ShadowMethod};
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;
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
