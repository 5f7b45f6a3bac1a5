//! The ShadowMapping config and its parts as Python classes (frozen,
//! keyword-only, compared by value, picklable); the values are checked by
//! the core (`methods/shadow_mapping/config.rs`).

use super::convert::{opt_bool, opt_float, opt_int, opt_resolution, opt_string};
use crate::methods::config::{PcssConfig, SmoothiesConfig};
use crate::methods::shadow_mapping::config::{
    check_pcf, DepthBias, EyeSpaceBlur, LiSPSM, Pcf, ShadowMappingConfig,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

fn newargs<'py>(
    py: Python<'py>,
    d: Bound<'py, PyDict>,
) -> (Bound<'py, PyTuple>, Bound<'py, PyDict>) {
    (PyTuple::empty(py), d)
}

/// A constant depth offset, in depth steps of a 24-bit buffer (2⁻²⁴ of the
/// map's depth range).
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "ConstantBias")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyConstantBias(pub DepthBias);

#[pymethods]
impl PyConstantBias {
    #[new]
    #[pyo3(signature = (*, constant))]
    fn new(constant: &Bound<'_, PyAny>) -> PyResult<Self> {
        let c = opt_float("constant", Some(constant))?
            .ok_or_else(|| PyTypeError::new_err("constant: must be a number, got None"))?;
        Ok(PyConstantBias(DepthBias::constant(c)?))
    }
    #[getter]
    fn constant(&self) -> f64 {
        match self.0 {
            DepthBias::Constant { constant } => constant.0,
            _ => unreachable!(),
        }
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("constant", self.constant())?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        format!("ConstantBias(constant={:?})", self.constant())
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

/// glPolygonOffset on the z-buffer's own depth: ``slope`` times the depth's
/// slope per texel plus ``constant`` depth steps (2⁻²⁴).
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "SlopeScaleBias")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PySlopeScaleBias(pub DepthBias);

#[pymethods]
impl PySlopeScaleBias {
    #[new]
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
    #[getter]
    fn constant(&self) -> f64 {
        pair(&self.0).0
    }
    #[getter]
    fn slope(&self) -> f64 {
        pair(&self.0).1
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("constant", self.constant())?;
        d.set_item("slope", self.slope())?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        format!(
            "SlopeScaleBias(constant={:?}, slope={:?})",
            self.constant(),
            self.slope()
        )
    }
}

/// The same offset on a linear depth distribution (the distance along the
/// light's axis), which Scherzer 2005 found best.
#[pyclass(
    frozen,
    eq,
    hash,
    module = "softshadow._core",
    name = "LinearDepthBias"
)]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyLinearDepthBias(pub DepthBias);

#[pymethods]
impl PyLinearDepthBias {
    #[new]
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
    #[getter]
    fn constant(&self) -> f64 {
        pair(&self.0).0
    }
    #[getter]
    fn slope(&self) -> f64 {
        pair(&self.0).1
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("constant", self.constant())?;
        d.set_item("slope", self.slope())?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        format!(
            "LinearDepthBias(constant={:?}, slope={:?})",
            self.constant(),
            self.slope()
        )
    }
}

/// Only faces turned away from the light are written: the map holds the far
/// side of solid casters (closed, consistently wound meshes).
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "BackFaces")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyBackFaces;

#[pymethods]
impl PyBackFaces {
    #[new]
    fn new() -> Self {
        PyBackFaces
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> Bound<'py, PyDict> {
        PyDict::new(py)
    }
    fn __getnewargs_ex__<'py>(&self, py: Python<'py>) -> (Bound<'py, PyTuple>, Bound<'py, PyDict>) {
        newargs(py, PyDict::new(py))
    }
    fn __repr__(&self) -> &'static str {
        "BackFaces()"
    }
}

/// Woo's midpoint: the test depth halfway between the nearest and the
/// second nearest surface.
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "MidpointBias")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyMidpointBias;

#[pymethods]
impl PyMidpointBias {
    #[new]
    fn new() -> Self {
        PyMidpointBias
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> Bound<'py, PyDict> {
        PyDict::new(py)
    }
    fn __getnewargs_ex__<'py>(&self, py: Python<'py>) -> (Bound<'py, PyTuple>, Bound<'py, PyDict>) {
        newargs(py, PyDict::new(py))
    }
    fn __repr__(&self) -> &'static str {
        "MidpointBias()"
    }
}

/// Percentage-closer filtering: ``size``×``size`` bilinear taps one texel
/// apart (a step edge becomes a ramp ``size`` texels wide).
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "PCF")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyPcf(pub Pcf);

#[pymethods]
impl PyPcf {
    #[new]
    #[pyo3(signature = (*, size=None))]
    fn new(size: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(PyPcf(check_pcf(opt_int("size", size)?)?))
    }
    #[getter]
    fn size(&self) -> u32 {
        self.0.size
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("size", self.0.size)?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        format!("PCF(size={})", self.0.size)
    }
}

/// Light-space perspective shadow maps (directional lights): ``n`` the
/// warp's parameter in world units (None: n_opt), ``vector`` "middle"
/// (Scherzer's middle vector of the intersection body) or "camera".
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "LiSPSM")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyLiSPSM(pub LiSPSM);

#[pymethods]
impl PyLiSPSM {
    #[new]
    #[pyo3(signature = (*, n=None, vector=None))]
    fn new(n: Option<&Bound<'_, PyAny>>, vector: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let vector = opt_string("vector", vector)?;
        Ok(PyLiSPSM(LiSPSM::new(
            opt_float("n", n)?,
            vector.as_deref(),
        )?))
    }
    #[getter]
    fn n(&self) -> Option<f64> {
        self.0.n.map(|n| n.0)
    }
    #[getter]
    fn vector(&self) -> &'static str {
        self.0.vector.name()
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("n", self.n())?;
        d.set_item("vector", self.vector())?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        let n = self
            .n()
            .map(|n| format!("{n:?}"))
            .unwrap_or_else(|| "None".into());
        format!("LiSPSM(n={n}, vector='{}')", self.vector())
    }
}

/// The depth-dependent eye-space blur of the shadow image.
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "EyeSpaceBlur")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyEyeSpaceBlur(pub EyeSpaceBlur);

#[pymethods]
impl PyEyeSpaceBlur {
    #[new]
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
    #[getter]
    fn iterations(&self) -> u32 {
        self.0.iterations
    }
    #[getter]
    fn radius(&self) -> f64 {
        self.0.radius.0
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("iterations", self.0.iterations)?;
        d.set_item("radius", self.radius())?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        format!(
            "EyeSpaceBlur(iterations={}, radius={:?})",
            self.0.iterations,
            self.radius()
        )
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

/// Scherzer 2005's practical shadow mapping. See ``capabilities()["shadow_mapping"]``.
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "ShadowMapping")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyShadowMapping(pub ShadowMappingConfig);

#[pymethods]
impl PyShadowMapping {
    #[new]
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
    /// "shadow_mapping", the name given as ``method=``.
    #[getter]
    fn name(&self) -> &'static str {
        "shadow_mapping"
    }
    #[getter]
    fn resolution(&self) -> (usize, usize) {
        self.0.resolution
    }
    #[getter]
    fn bias(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        bias_to_py(py, self.0.bias)
    }
    #[getter]
    fn filter(&self, py: Python<'_>) -> PyResult<Option<Py<PyPcf>>> {
        self.0.filter.map(|f| Py::new(py, PyPcf(f))).transpose()
    }
    #[getter]
    fn warp(&self, py: Python<'_>) -> PyResult<Option<Py<PyLiSPSM>>> {
        self.0.warp.map(|w| Py::new(py, PyLiSPSM(w))).transpose()
    }
    #[getter]
    fn focus(&self) -> bool {
        self.0.focus
    }
    #[getter]
    fn blur(&self, py: Python<'_>) -> PyResult<Option<Py<PyEyeSpaceBlur>>> {
        self.0
            .blur
            .map(|b| Py::new(py, PyEyeSpaceBlur(b)))
            .transpose()
    }
    /// The options as keyword arguments: ``ShadowMapping(**c.to_dict()) == c``.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("resolution", self.resolution())?;
        d.set_item("bias", self.bias(py)?)?;
        d.set_item("filter", self.filter(py)?)?;
        d.set_item("warp", self.warp(py)?)?;
        d.set_item("focus", self.0.focus)?;
        d.set_item("blur", self.blur(py)?)?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let r = |o: Option<Py<PyAny>>| -> PyResult<String> {
            match o {
                None => Ok("None".into()),
                Some(o) => Ok(o.bind(py).repr()?.to_string()),
            }
        };
        Ok(format!(
            "ShadowMapping(resolution=({}, {}), bias={}, filter={}, warp={}, focus={}, blur={})",
            self.0.resolution.0,
            self.0.resolution.1,
            r(Some(self.bias(py)?))?,
            r(self.filter(py)?.map(|p| p.into_any()))?,
            r(self.warp(py)?.map(|p| p.into_any()))?,
            if self.0.focus { "True" } else { "False" },
            r(self.blur(py)?.map(|p| p.into_any()))?,
        ))
    }
}

/// Smoothies (Chan & Durand 2003). See ``capabilities()["smoothies"]``.
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "Smoothies")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PySmoothies(pub SmoothiesConfig);

#[pymethods]
impl PySmoothies {
    #[new]
    #[pyo3(signature = (*, width=None, falloff=None, filter=None, occluder_resolution=None))]
    fn new(
        width: Option<&Bound<'_, PyAny>>,
        falloff: Option<&Bound<'_, PyAny>>,
        filter: Option<&Bound<'_, PyAny>>,
        occluder_resolution: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let falloff = opt_string("falloff", falloff)?;
        let filter = opt_string("filter", filter)?;
        Ok(PySmoothies(SmoothiesConfig::new(
            opt_float("width", width)?,
            falloff.as_deref(),
            filter.as_deref(),
            opt_resolution("occluder_resolution", occluder_resolution)?,
        )?))
    }
    /// "smoothies", the name given as ``method=``.
    #[getter]
    fn name(&self) -> &'static str {
        "smoothies"
    }
    #[getter]
    fn width(&self) -> f64 {
        self.0.width.0
    }
    #[getter]
    fn falloff(&self) -> &'static str {
        self.0.falloff.name()
    }
    #[getter]
    fn filter(&self) -> &'static str {
        "bilinear"
    }
    #[getter]
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.0.occluder_resolution
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("width", self.width())?;
        d.set_item("falloff", self.falloff())?;
        d.set_item("filter", self.filter())?;
        d.set_item("occluder_resolution", self.0.occluder_resolution)?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        let r = self
            .0
            .occluder_resolution
            .map(|(w, h)| format!("({w}, {h})"))
            .unwrap_or_else(|| "None".into());
        format!(
            "Smoothies(width={:?}, falloff='{}', filter='bilinear', occluder_resolution={r})",
            self.width(),
            self.falloff()
        )
    }
}

/// PCSS (Fernando 2005). See ``capabilities()["pcss"]``.
#[pyclass(frozen, eq, hash, module = "softshadow._core", name = "PCSS")]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PyPcss(pub PcssConfig);

#[pymethods]
impl PyPcss {
    #[new]
    #[pyo3(signature = (*, max_taps=None, occluder_resolution=None))]
    fn new(
        max_taps: Option<&Bound<'_, PyAny>>,
        occluder_resolution: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(PyPcss(PcssConfig::new(
            opt_int("max_taps", max_taps)?,
            opt_resolution("occluder_resolution", occluder_resolution)?,
        )?))
    }
    /// "pcss", the name given as ``method=``.
    #[getter]
    fn name(&self) -> &'static str {
        "pcss"
    }
    #[getter]
    fn max_taps(&self) -> u32 {
        self.0.max_taps
    }
    #[getter]
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.0.occluder_resolution
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("max_taps", self.0.max_taps)?;
        d.set_item("occluder_resolution", self.0.occluder_resolution)?;
        Ok(d)
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok(newargs(py, self.to_dict(py)?))
    }
    fn __repr__(&self) -> String {
        let r = self
            .0
            .occluder_resolution
            .map(|(w, h)| format!("({w}, {h})"))
            .unwrap_or_else(|| "None".into());
        format!(
            "PCSS(max_taps={}, occluder_resolution={r})",
            self.0.max_taps
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPcss>()?;
    m.add_class::<PySmoothies>()?;
    m.add_class::<PyShadowMapping>()?;
    m.add_class::<PyConstantBias>()?;
    m.add_class::<PySlopeScaleBias>()?;
    m.add_class::<PyLinearDepthBias>()?;
    m.add_class::<PyBackFaces>()?;
    m.add_class::<PyMidpointBias>()?;
    m.add_class::<PyPcf>()?;
    m.add_class::<PyLiSPSM>()?;
    m.add_class::<PyEyeSpaceBlur>()?;
    Ok(())
}
