//! The table of methods: their options, defaults, limits, the backends that
//! run them and what they read. Each method's config describes itself
//! (`MethodSpec::info`, in its own module, from the constants its checks use, so
//! the table cannot drift from the checks); the registry lists them in
//! order. The Python package reads it from `_core` and copies nothing.

use super::config::{MAX_PASSES, MAX_SAMPLES};
pub use super::info::{Kind, MethodInfo, OptionInfo, Value};
use crate::geom::light::{MAX_EXTENT, MAX_TEXELS};

/// Limits that are not one method's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Texels per map.
    pub max_texels: usize,
    /// Tangent half-extent of a light-view map.
    pub max_extent: f64,
    /// Occluder depth layers.
    pub max_passes: u32,
    /// Light samples of `exact`.
    pub max_samples: u32,
    /// Worker threads per call (`threads=`).
    pub max_threads: usize,
    /// Largest map side on the GPU backend (0 without one).
    pub gpu_max_side: usize,
    /// The receivers' worth of work every call may spend (`inputs`).
    pub min_receivers: usize,
    /// Weighted gather visits a call may make per receiver (`gather::work`).
    pub visits_per_receiver: f64,
    /// PCSS texel reads a call may plan per receiver (`pcss`).
    pub pcss_reads_per_receiver: f64,
}

pub fn limits() -> Limits {
    Limits {
        max_texels: MAX_TEXELS,
        max_extent: MAX_EXTENT,
        max_passes: MAX_PASSES,
        max_samples: MAX_SAMPLES,
        max_threads: crate::threads::MAX_THREADS,
        gpu_max_side: if cfg!(feature = "gpu") {
            crate::backend::GPU_MAX_SIDE
        } else {
            0
        },
        min_receivers: super::inputs::MIN_RECEIVERS,
        visits_per_receiver: super::gather::work::VISITS_PER_RECEIVER,
        pcss_reads_per_receiver: super::pcss::READS_PER_RECEIVER,
    }
}

/// The methods, in the order a user meets them (the registry's).
pub fn methods() -> Vec<MethodInfo> {
    super::MethodConfig::infos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_name_has_one_row() {
        let names: Vec<_> = methods().iter().map(|m| m.name).collect();
        assert_eq!(names, super::super::METHOD_NAMES);
    }

    /// A default written out as a number in the docs is the default the
    /// config takes (the text is hand-written beside the value).
    #[test]
    fn numeric_default_docs_match_the_defaults() {
        for m in methods() {
            for o in &m.options {
                let lead: String = o
                    .default_doc
                    .chars()
                    .take_while(|c| c.is_ascii_digit() || *c == '.')
                    .collect();
                match (&o.default, lead.parse::<f64>()) {
                    (Value::Int(v), Ok(d)) => assert_eq!(*v as f64, d, "{}.{}", m.name, o.name),
                    (Value::Float(v), Ok(d)) => assert_eq!(*v, d, "{}.{}", m.name, o.name),
                    _ => {}
                }
            }
        }
    }
}
