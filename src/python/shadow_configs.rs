//! The ShadowMapping config and its parts as Python classes (frozen,
//! keyword-only, compared by value, picklable: see `config_class.rs`); the
//! values are checked by the core (`methods/shadow_mapping/config.rs`).
//! ShadowMapping is registered by the list of `configs.rs`; this file
//! registers the parts.

use super::config_class::config_class;
use super::convert::{opt_bool, opt_float, opt_int, opt_resolution, opt_string};
use crate::methods::shadow_mapping::config::{
    check_pcf, DepthBias, EyeSpaceBlur, LiSPSM, Pcf, ShadowMappingConfig,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

config_class! {
    /// A constant depth offset, in depth steps of a 24-bit buffer (2⁻²⁴ of the
    /// map's depth range).
    class PyConstantBias(DepthBias) as "ConstantBias";
    #[pyo3(signature = (*, constant))]
    fn new(constant: &Bound<'_, PyAny>) -> PyResult<Self> {
        let c = opt_float("constant", Some(constant))?
            .ok_or_else(|| PyTypeError::new_err("constant: must be a number, got None"))?;
        Ok(PyConstantBias(DepthBias::constant(c)?))
    }
    options {
        constant: f64 = |c, py| match c.0 {
            DepthBias::Constant { constant } => constant.0,
            _ => unreachable!(),
        };
    }
}

fn pair(b: &DepthBias) -> (f64, f64) {
    match *b {
        DepthBias::SlopeScale { constant, slope } | DepthBias::LinearDepth { constant, slope } => {
            (constant.0, slope.0)
        }
        _ => unreachable!(),
    }
}

config_class! {
    /// glPolygonOffset on the z-buffer's own depth: ``slope`` times the depth's
    /// slope per texel plus ``constant`` depth steps (2⁻²⁴).
    class PySlopeScaleBias(DepthBias) as "SlopeScaleBias";
    #[pyo3(signature = (*, constant=None, slope=None))]
    fn new(
        constant: Option<&Bound<'_, PyAny>>,
        slope: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(PySlopeScaleBias(DepthBias::slope_scale(
            opt_float("constant", constant)?,
            opt_float("slope", slope)?,
        )?))
    }
    options {
        constant: f64 = |c, py| pair(&c.0).0;
        slope: f64 = |c, py| pair(&c.0).1;
    }
}

config_class! {
    /// The same offset on a linear depth distribution (the distance along the
    /// light's axis), which Scherzer 2005 found best.
    class PyLinearDepthBias(DepthBias) as "LinearDepthBias";
    #[pyo3(signature = (*, constant=None, slope=None))]
    fn new(
    constant: Option<&Bound<'_, PyAny>>,
    slope: Option<&Bound<'_, PyAny>>,
) -> PyResult<Self> {
    Ok(PyLinearDepthBias(DepthBias::linear_depth(
        opt_float("constant", constant)?,
        opt_float("slope", slope)?,
    )?))
}
    options {
        constant: f64 = |c, py| pair(&c.0).0;
        slope: f64 = |c, py| pair(&c.0).1;
    }
}

config_class! {
    /// Only faces turned away from the light are written: the map holds the far
    /// side of solid casters (closed, consistently wound meshes).
    class PyBackFaces as "BackFaces";
    #[pyo3(signature = ())]
    fn new() -> PyResult<Self> {
        Ok(PyBackFaces)
    }
    options {}
}

config_class! {
    /// Woo's midpoint: the test depth halfway between the nearest and the
    /// second nearest surface.
    class PyMidpointBias as "MidpointBias";
    #[pyo3(signature = ())]
    fn new() -> PyResult<Self> {
        Ok(PyMidpointBias)
    }
    options {}
}

config_class! {
    /// Percentage-closer filtering: ``size``×``size`` bilinear taps one texel
    /// apart (a step edge becomes a ramp ``size`` texels wide).
    class PyPcf(Pcf) as "PCF";
    #[pyo3(signature = (*, size=None))]
    fn new(size: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(PyPcf(check_pcf(opt_int("size", size)?)?))
    }
    options {
        size: u32 = |c, py| c.0.size;
    }
}

config_class! {
    /// Light-space perspective shadow maps (directional lights): ``n`` the
    /// warp's parameter in world units (None: n_opt), ``vector`` "middle"
    /// (Scherzer's middle vector of the intersection body) or "camera".
    class PyLiSPSM(LiSPSM) as "LiSPSM";
    #[pyo3(signature = (*, n=None, vector=None))]
    fn new(n: Option<&Bound<'_, PyAny>>, vector: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let vector = opt_string("vector", vector)?;
        Ok(PyLiSPSM(LiSPSM::new(
            opt_float("n", n)?,
            vector.as_deref(),
        )?))
    }
    options {
        n: Option<f64> = |c, py| c.0.n.map(|n| n.0);
        vector: &'static str = |c, py| c.0.vector.name();
    }
}

config_class! {
    /// The depth-dependent eye-space blur of the shadow image.
    class PyEyeSpaceBlur(EyeSpaceBlur) as "EyeSpaceBlur";
    #[pyo3(signature = (*, iterations=None, radius=None))]
    fn new(
        iterations: Option<&Bound<'_, PyAny>>,
        radius: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(PyEyeSpaceBlur(EyeSpaceBlur::new(
            opt_int("iterations", iterations)?,
            opt_float("radius", radius)?,
        )?))
    }
    options {
        iterations: u32 = |c, py| c.0.iterations;
        radius: f64 = |c, py| c.0.radius.0;
    }
}

fn bias_of(v: &Bound<'_, PyAny>) -> PyResult<DepthBias> {
    if let Ok(c) = v.cast::<PyConstantBias>() {
        return Ok(c.get().0);
    }
    if let Ok(c) = v.cast::<PySlopeScaleBias>() {
        return Ok(c.get().0);
    }
    if let Ok(c) = v.cast::<PyLinearDepthBias>() {
        return Ok(c.get().0);
    }
    if v.cast::<PyBackFaces>().is_ok() {
        return Ok(DepthBias::BackFaces);
    }
    if v.cast::<PyMidpointBias>().is_ok() {
        return Ok(DepthBias::Midpoint);
    }
    Err(PyTypeError::new_err(format!(
        "bias: must be ConstantBias, SlopeScaleBias, LinearDepthBias, BackFaces or MidpointBias, got {}",
        v.get_type().name()?
    )))
}

fn bias_to_py(py: Python<'_>, b: DepthBias) -> PyResult<Py<PyAny>> {
    Ok(match b {
        DepthBias::Constant { .. } => Py::new(py, PyConstantBias(b))?.into_any(),
        DepthBias::SlopeScale { .. } => Py::new(py, PySlopeScaleBias(b))?.into_any(),
        DepthBias::LinearDepth { .. } => Py::new(py, PyLinearDepthBias(b))?.into_any(),
        DepthBias::BackFaces => Py::new(py, PyBackFaces)?.into_any(),
        DepthBias::Midpoint => Py::new(py, PyMidpointBias)?.into_any(),
    })
}

/// An optional part of the config: None, or an instance of `T`.
fn part<T, U>(
    arg: &str,
    class: &str,
    v: Option<&Bound<'_, PyAny>>,
    get: impl Fn(&T) -> U,
) -> PyResult<Option<U>>
where
    T: pyo3::PyClass<Frozen = pyo3::pyclass::boolean_struct::True> + Sync,
{
    match v.filter(|v| !v.is_none()) {
        None => Ok(None),
        Some(v) => match v.cast::<T>() {
            Ok(c) => Ok(Some(get(c.get()))),
            Err(_) => Err(PyTypeError::new_err(format!(
                "{arg}: must be {class} or None, got {}",
                v.get_type().name()?
            ))),
        },
    }
}

config_class! {
    /// Scherzer 2005's practical shadow mapping. See ``capabilities()["shadow_mapping"]``.
    class PyShadowMapping(ShadowMappingConfig) as "ShadowMapping", name "shadow_mapping";
    #[pyo3(signature = (*, resolution=None, bias=None, filter=None, warp=None, focus=None, blur=None))]
    fn new(
        resolution: Option<&Bound<'_, PyAny>>,
        bias: Option<&Bound<'_, PyAny>>,
        filter: Option<&Bound<'_, PyAny>>,
        warp: Option<&Bound<'_, PyAny>>,
        focus: Option<&Bound<'_, PyAny>>,
        blur: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let bias = bias.filter(|b| !b.is_none()).map(bias_of).transpose()?;
        Ok(PyShadowMapping(ShadowMappingConfig::new(
            opt_resolution("resolution", resolution)?,
            bias,
            part::<PyPcf, _>("filter", "PCF", filter, |c| c.0)?,
            part::<PyLiSPSM, _>("warp", "LiSPSM", warp, |c| c.0)?,
            opt_bool("focus", focus)?,
            part::<PyEyeSpaceBlur, _>("blur", "EyeSpaceBlur", blur, |c| c.0)?,
        )?))
    }
    options {
        resolution: (usize, usize) = |c, py| c.0.resolution;
        bias: Py<PyAny> = |c, py| bias_to_py(py, c.0.bias)?;
        filter: Option<Py<PyPcf>> = |c, py| c.0.filter.map(|f| Py::new(py, PyPcf(f))).transpose()?;
        warp: Option<Py<PyLiSPSM>> = |c, py| c.0.warp.map(|w| Py::new(py, PyLiSPSM(w))).transpose()?;
        focus: bool = |c, py| c.0.focus;
        blur: Option<Py<PyEyeSpaceBlur>> =
            |c, py| c.0.blur.map(|b| Py::new(py, PyEyeSpaceBlur(b))).transpose()?;
    }
}

/// Registers the parts; their names, for `_core.__all__`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<Vec<String>> {
    let py = m.py();
    let parts = [
        py.get_type::<PyConstantBias>(),
        py.get_type::<PySlopeScaleBias>(),
        py.get_type::<PyLinearDepthBias>(),
        py.get_type::<PyBackFaces>(),
        py.get_type::<PyMidpointBias>(),
        py.get_type::<PyPcf>(),
        py.get_type::<PyLiSPSM>(),
        py.get_type::<PyEyeSpaceBlur>(),
    ];
    parts
        .iter()
        .map(|t| {
            let name = t.name()?.to_string();
            m.add(name.as_str(), t)?;
            Ok(name)
        })
        .collect()
}
