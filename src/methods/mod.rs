//! Shadow methods. Each method is one module behind [`ShadowMethod`]; every
//! method reads the same inputs (the light-view maps) and writes the same
//! outputs (visibility per receiver texel, or per receiver point).

pub mod bitmask;
pub mod exact;
mod gather;

pub use gather::Hierarchy;
pub mod ssm;

use crate::error::{Error, Result};
use crate::light::MapGrid;
use glam::Vec3;

/// What every method reads: the light-view maps and the light's size.
#[derive(Debug, Clone)]
pub struct ShadowInputs<'a> {
    /// The output grid, which the receiver map shares.
    pub grid: MapGrid,
    /// The occluder maps' grid: the same extent, its own resolution (coarser
    /// occluder maps cost less; the paper notes large lights need fewer texels).
    pub occluder_grid: MapGrid,
    /// Full light width along u and height along v (world units).
    pub light_size: [f64; 2],
    /// Receiver planar depth per texel, `inf` where there is no receiver.
    pub receiver: &'a [f32],
    /// Occluder depth layers: the front (nearest) map, then the back (farthest) one.
    pub occluder_layers: Vec<&'a [f32]>,
    /// Occluder triangles in light space, for the methods that trace them.
    pub occluder_triangles: Option<&'a [[Vec3; 3]]>,
}

/// A receiver point in light space: tangent coordinates and planar depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightPoint {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// The interface of a shadow method.
pub trait ShadowMethod: Sync {
    /// Visibility of the light (fraction of its area) for every receiver texel;
    /// 1 where there is no receiver. Row-major (H, W).
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32>;
    /// Visibility at receiver points given in light space.
    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32>;
}

/// The methods a user can pick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Soft shadow maps, Atty et al. 2005, as published (additive
    /// micro-patches); `hierarchy` reads coarser occluder texels where the
    /// penumbra is wide (off by default: the paper has none).
    Ssm {
        hierarchy: bool,
        precision: ssm::Precision,
    },
    /// Ray casting against the occluder triangles with stratified light samples.
    Exact { samples: u32 },
    /// Micro-patches marking light samples in a bit mask per receiver (OR);
    /// `hierarchy` as for Ssm (on by default).
    Bitmask { samples: u32, hierarchy: bool },
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

/// Default light samples per receiver for the sampling methods.
pub const DEFAULT_SAMPLES: u32 = 256;
/// The most light samples per receiver we accept.
pub const MAX_SAMPLES: u32 = 1 << 16;

impl Method {
    /// The method named `name`; `samples` is for the sampling methods only,
    /// `hierarchy` for the occluder-map methods only, `precision` for "ssm"
    /// only (the others count samples in integers).
    pub fn parse(
        name: &str,
        samples: Option<u32>,
        hierarchy: Option<bool>,
        precision: Option<&str>,
    ) -> Result<Self> {
        let precision = match precision {
            None => None,
            Some(p) => Some(ssm::Precision::parse(p).ok_or_else(|| {
                Error::invalid(
                    "precision",
                    format!("must be one of \"f32\", \"f64\", \"f16\", \"f16-batched\", got {p:?}"),
                )
            })?),
        };
        if name != "ssm" && precision.is_some() {
            return Err(Error::invalid(
                "precision",
                "applies to \"ssm\" (sums of occlusions); the other methods count samples exactly",
            ));
        }
        let method = match name {
            "ssm" => Method::Ssm {
                hierarchy: hierarchy.unwrap_or(false),
                precision: precision.unwrap_or_default(),
            },
            "exact" => Method::Exact {
                samples: samples.unwrap_or(DEFAULT_SAMPLES),
            },
            "bitmask" => Method::Bitmask {
                samples: samples.unwrap_or(DEFAULT_SAMPLES),
                hierarchy: hierarchy.unwrap_or(true),
            },
            other => {
                return Err(Error::invalid(
                    "method",
                    format!("unknown method {other:?}; available: \"ssm\", \"bitmask\", \"exact\""),
                ))
            }
        };
        if method.traces_triangles() && hierarchy.is_some() {
            return Err(Error::invalid(
                "hierarchy",
                "applies to the occluder-map methods (\"ssm\", \"bitmask\"), not to \"exact\"",
            ));
        }
        match (method, samples) {
            (Method::Ssm { .. }, Some(_)) => Err(Error::invalid(
                "samples",
                "applies to the sampling methods (\"bitmask\", \"exact\"), not to \"ssm\"",
            )),
            (Method::Exact { samples }, _) if samples == 0 || samples > MAX_SAMPLES => {
                Err(Error::invalid(
                    "samples",
                    format!("must be in [1, {MAX_SAMPLES}], got {samples}"),
                ))
            }
            (Method::Bitmask { samples, .. }, _) if !bitmask::SAMPLE_COUNTS.contains(&samples) => {
                Err(Error::invalid(
                    "samples",
                    format!(
                        "bitmask takes one of {:?} samples, got {samples}",
                        bitmask::SAMPLE_COUNTS
                    ),
                ))
            }
            _ => Ok(method),
        }
    }

    /// The name a user passes as `method=`.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Ssm { .. } => "ssm",
            Method::Exact { .. } => "exact",
            Method::Bitmask { .. } => "bitmask",
        }
    }

    /// Whether the method reads the occluder triangles (not the occluder maps).
    pub fn traces_triangles(&self) -> bool {
        matches!(self, Method::Exact { .. })
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
            Method::Exact { samples } => Box::new(exact::Exact { samples }),
            Method::Bitmask { samples, hierarchy } => Box::new(bitmask::Bitmask::new(
                samples,
                hierarchy.then_some(HIERARCHY),
            )),
        }
    }
}

/// A texel-aligned square plate over a parallel floor, whose visibility has
/// a closed form: the methods' shared accuracy check.
#[cfg(test)]
pub(crate) mod plate_case {
    use super::{MapGrid, ShadowInputs, ShadowMethod};

    /// Largest |V - V_exact| of `method` on an n x n map of a plate covering
    /// tangent [-1/4, 1/4]^2 at depth 2 over a floor at depth 4 (light 1 x 1).
    /// The plate's edges fall on texel edges, so the occluder map holds it
    /// exactly and any error is the method's.
    pub fn max_error(method: &dyn ShadowMethod, n: usize) -> f64 {
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
            light_size: [1.0, 1.0],
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
        let mut max = 0f64;
        for j in 0..n {
            for i in 0..n {
                let exact = 1.0 - ov(grid.x_of(i)) * ov(grid.y_of(j));
                max = max.max((v[j * n + i] as f64 - exact).abs());
            }
        }
        max
    }
}

/// The bunny's maps that `benchmarks/dump_maps.py` writes to /tmp, timed by
/// the kernels' ignored bench tests.
#[cfg(test)]
pub(crate) mod bench_data {
    use super::{MapGrid, ShadowInputs, ShadowMethod};

    fn read(p: &str) -> Vec<f32> {
        std::fs::read(p)
            .unwrap_or_else(|e| panic!("{p}: {e}; run python benchmarks/dump_maps.py first"))
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    }

    /// Median seconds of `runs` runs of `method` on the dumped maps, and a
    /// checksum of the result.
    pub fn time(method: &dyn ShadowMethod, runs: usize) -> (f64, f64) {
        let (front, back, rec) = (
            read("/tmp/front.f32"),
            read("/tmp/back.f32"),
            read("/tmp/rec.f32"),
        );
        let grid = MapGrid::new(256, 256, [0.3137646436112252, 0.3050549377029778]).unwrap();
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_size: [1.0, 1.0],
            receiver: &rec,
            occluder_layers: vec![&front, &back],
            occluder_triangles: None,
        };
        let mut ts = vec![];
        let mut sum = 0.0;
        for _ in 0..runs {
            let t = std::time::Instant::now();
            let v = method.visibility_map(&inputs);
            ts.push(t.elapsed().as_secs_f64());
            sum = v.iter().map(|&x| x as f64).sum::<f64>();
        }
        ts.sort_by(|a, b| a.total_cmp(b));
        (ts[runs / 2], sum)
    }
}
