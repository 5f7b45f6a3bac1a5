//! The lights as Python classes (`softshadow.RectLight`,
//! `softshadow.DirectionalLight`), like `Camera`: frozen, compared and
//! hashed by value, picklable, their frames and value checks the core's
//! (`geom::light::RectLight`, `geom::sun::DirectionalLight`) and their
//! emission checked by the core's shading (`eye::shading::emission`).
//!
//! A light's emission is RGB (a number is grey): a rectangle's `radiance`
//! (uniform, Lambertian, on its `n` side only) and the sun's `irradiance`
//! (on a surface facing it). Only the eye view's shaded images read it;
//! visibility never does.

use super::convert::Light;
use super::convert::{opt_float, vector};
use super::errors;
use super::eye::{irradiance, light_emission};
use crate::geom::light::AreaLight;
use crate::geom::sphere_light::SphereLight;
use crate::geom::sun::DirectionalLight;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// A number (both components) or a pair of numbers.
fn pair(arg: &str, value: &Bound<'_, PyAny>) -> PyResult<[f64; 2]> {
    let py = value.py();
    let real = py.import("numbers")?.getattr("Real")?;
    if value.is_instance(&real)? && !value.is_instance_of::<pyo3::types::PyBool>() {
        let x: f64 = value.extract()?;
        return Ok([x, x]);
    }
    vector::<2>(arg, value)
}

/// An emission as the core reads it: NumPy values as plain numbers and
/// lists, anything else as given (the core names its type).
fn color<'py>(value: Option<&Bound<'py, PyAny>>) -> PyResult<Option<Bound<'py, PyAny>>> {
    fn plain<'py>(v: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let py = v.py();
        let np = py.import("numpy")?;
        if v.is_instance(&np.getattr("ndarray")?)? || v.is_instance(&np.getattr("generic")?)? {
            return v.call_method0("tolist");
        }
        if v.is_instance_of::<pyo3::types::PyList>() || v.is_instance_of::<PyTuple>() {
            let items: Vec<Bound<'py, PyAny>> =
                v.try_iter()?.map(|i| plain(&i?)).collect::<PyResult<_>>()?;
            return Ok(pyo3::types::PyList::new(py, items)?.into_any());
        }
        Ok(v.clone())
    }
    value.filter(|v| !v.is_none()).map(plain).transpose()
}

/// Points or normals (N, 3) of reals as C-contiguous float64.
fn rows3<'py>(arg: &str, value: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let np = value.py().import("numpy")?;
    let a = np.call_method1("asarray", (value,))?;
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    if !"fiu".contains(kind.as_str()) || kind.len() != 1 {
        let dtype = a.getattr("dtype")?.str()?.to_string();
        return Err(PyTypeError::new_err(format!(
            "{arg}: must be real numbers, got dtype {dtype}"
        )));
    }
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        let shape = PyTuple::new(value.py(), &shape)?.repr()?.to_string();
        return Err(PyValueError::new_err(format!(
            "{arg}: must have shape (N, 3), got {shape}"
        )));
    }
    np.call_method1("ascontiguousarray", (a, "float64"))?
        .extract()
}

fn array3<'py>(py: Python<'py>, v: glam::DVec3) -> Bound<'py, PyAny> {
    numpy::PyArray1::from_slice(py, &v.to_array()).into_any()
}

/// A light's values as its constructor takes them: the positional
/// arguments, then the emission (keyword-only), each with its name.
type Fields<'a> = [(&'static str, &'a [f64])];

/// Bits that compare and hash as the values do (0.0 and -0.0 alike).
fn key(fields: &Fields) -> Vec<u64> {
    fields
        .iter()
        .flat_map(|(_, v)| v.iter())
        .map(|&x| if x == 0.0 { 0 } else { x.to_bits() })
        .collect()
}

fn hash_of(fields: &Fields) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key(fields).hash(&mut h);
    h.finish()
}

/// Pickling through the constructor: the positional fields, the last one
/// by keyword.
fn newargs<'py>(
    py: Python<'py>,
    fields: &Fields,
) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
    let (last, positional) = fields.split_last().expect("a light has fields");
    let args = positional
        .iter()
        .map(|(_, v)| value(py, v))
        .collect::<PyResult<Vec<_>>>()?;
    let kw = PyDict::new(py);
    kw.set_item(last.0, value(py, last.1)?)?;
    Ok((PyTuple::new(py, args)?, kw))
}

/// A field as Python holds it: a number (a radius), or a tuple.
fn value<'py>(py: Python<'py>, v: &[f64]) -> PyResult<Bound<'py, PyAny>> {
    match v {
        [x] => Ok(pyo3::types::PyFloat::new(py, *x).into_any()),
        _ => Ok(PyTuple::new(py, v)?.into_any()),
    }
}

/// `Class(name=(x, y, z), ...)`, each value as Python writes it.
fn repr(py: Python<'_>, class: &str, fields: &Fields) -> PyResult<String> {
    let parts = fields
        .iter()
        .map(|(name, v)| Ok(format!("{name}={}", value(py, v)?.repr()?)))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(format!("{class}({})", parts.join(", ")))
}

/// A rectangular area light that emits uniformly over its whole rectangle.
///
/// Frame: ``n = normalize(normal)`` points from the light into the scene,
/// ``v = normalize(up - (up . n) n)`` and ``u = n x v``. ``size`` is the full
/// width along ``u`` and the full height along ``v`` (a number: both).
///
/// ``radiance`` (keyword-only) is the radiance it emits, uniform and
/// Lambertian, on its ``n`` side only: a number (grey) or an RGB triple, each
/// finite and >= 0; ``None`` takes the core's default, 1.0. Stored as an RGB
/// triple. Only the eye view's shaded images read it (docs/shading.md).
///
/// Raises ValueError for a non-finite center, a zero-length ``normal`` or
/// ``up``, an ``up`` within 1e-6 rad of parallel to ``normal``, a size that
/// is neither finite and > 0 nor (0, 0), or a negative or non-finite
/// ``radiance``. Size (0, 0) is a point light: every method then gives the
/// hard shadow map, the limit they converge to as the size shrinks (it has
/// no area, so it lights no shaded image).
#[pyclass(frozen, module = "softshadow._core", name = "RectLight")]
#[derive(Clone)]
pub struct PyRectLight {
    center: [f64; 3],
    normal: [f64; 3],
    up: [f64; 3],
    size: [f64; 2],
    radiance: [f64; 3],
    pub light: AreaLight,
}

#[pymethods]
impl PyRectLight {
    #[new]
    #[pyo3(signature = (center, normal, up, size=None, *, radiance=None))]
    fn new(
        center: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        up: &Bound<'_, PyAny>,
        size: Option<&Bound<'_, PyAny>>,
        radiance: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let c = vector::<3>("center", center)?;
        let n = vector::<3>("normal", normal)?;
        let u = vector::<3>("up", up)?;
        let s = match size {
            Some(s) => pair("size", s)?,
            None => [1.0, 1.0],
        };
        let light = errors::guard(|| Ok(AreaLight::rect(c, n, u, s)?))?;
        let radiance = light_emission("radiance", color(radiance)?)?;
        Ok(PyRectLight {
            center: c,
            normal: n,
            up: u,
            size: s,
            radiance,
            light,
        })
    }

    /// The light that depth-map input is expressed in: center at the
    /// origin, ``n = +z``, ``v = +y`` (so ``u = -x``).
    #[classmethod]
    fn canonical(_cls: &Bound<'_, pyo3::types::PyType>, size: &Bound<'_, PyAny>) -> PyResult<Self> {
        let py = size.py();
        let zero = (0.0, 0.0, 0.0).into_pyobject(py)?.into_any();
        let z = (0.0, 0.0, 1.0).into_pyobject(py)?.into_any();
        let y = (0.0, 1.0, 0.0).into_pyobject(py)?.into_any();
        Self::new(&zero, &z, &y, Some(size), None)
    }

    #[getter]
    fn center(&self) -> (f64, f64, f64) {
        self.center.into()
    }
    #[getter]
    fn normal(&self) -> (f64, f64, f64) {
        self.normal.into()
    }
    #[getter]
    fn up(&self) -> (f64, f64, f64) {
        self.up.into()
    }
    #[getter]
    fn size(&self) -> (f64, f64) {
        self.size.into()
    }
    #[getter]
    fn radiance(&self) -> (f64, f64, f64) {
        self.radiance.into()
    }
    /// Unit vector along the light's width (map columns grow along it).
    #[getter]
    fn u<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.u)
    }
    /// Unit vector along the light's height (map rows grow against it).
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.v)
    }
    /// Unit normal from the rectangle into the scene.
    #[getter]
    fn n<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.n)
    }
    /// Width times height.
    #[getter]
    fn area(&self) -> f64 {
        self.size[0] * self.size[1]
    }
    /// The four corners (4, 3): (-u,-v), (+u,-v), (+u,+v), (-u,+v).
    fn corners<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let c = glam::DVec3::from_array(self.center);
        let hu = 0.5 * self.size[0] * self.light.u;
        let hv = 0.5 * self.size[1] * self.light.v;
        let k = [c - hu - hv, c + hu - hv, c + hu + hv, c - hu + hv];
        let a = Array2::from_shape_vec((4, 3), k.iter().flat_map(|p| p.to_array()).collect())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any())
    }
    /// The unshadowed irradiance (N, 3) float64, RGB, radiance included, at
    /// world ``points`` (N, 3) on surfaces with ``normals`` (N, 3; any
    /// length, not zero), in closed form: Lambert's polygon formula after
    /// clipping the rectangle to each point's upper hemisphere (0 at or
    /// behind its plane). No shadows: :func:`softshadow.render` multiplies
    /// by the visibility. See docs/shading.md.
    fn irradiance_at<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: &Bound<'py, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        let p = rows3("points", points)?;
        let n = rows3("normals", normals)?;
        let e = self.radiance.into_pyobject(py)?.into_any();
        irradiance(py, self.core_light(), p, n, Some(e))
    }
    fn _core_args(&self) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 2]) {
        (self.center, self.normal, self.up, self.size)
    }
    fn _emission(&self) -> (f64, f64, f64) {
        self.radiance.into()
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyRectLight>()
            .is_ok_and(|o| key(&self.fields()) == key(&o.get().fields()))
    }
    fn __hash__(&self) -> u64 {
        hash_of(&self.fields())
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        newargs(py, &self.fields())
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        repr(py, "RectLight", &self.fields())
    }
}

impl PyRectLight {
    fn core_light(&self) -> Light {
        Light::Rect(self._core_args())
    }
    fn fields(&self) -> [(&'static str, &[f64]); 5] {
        [
            ("center", &self.center),
            ("normal", &self.normal),
            ("up", &self.up),
            ("size", &self.size),
            ("radiance", &self.radiance),
        ]
    }
}

/// A directional light (the sun): a rectangle of directions at infinity.
///
/// Frame: ``n = normalize(direction)`` is the direction the light travels,
/// ``v = normalize(up - (up . n) n)``, ``u = n x v``. The light is the set of
/// travel directions ``n + x u + y v`` with ``|x| <= tan(a_u / 2)`` and
/// ``|y| <= tan(a_v / 2)``, uniform in (x, y); ``angular_size = (a_u, a_v)``
/// are full angles in degrees (the sun is about 0.53; a number: both).
/// ``(0, 0)`` is a hard directional light. Its light-view maps are
/// orthographic (see docs/conventions.md).
///
/// ``irradiance`` (keyword-only) is the irradiance on a surface facing the
/// sun: a number (grey) or an RGB triple, each finite and >= 0; ``None``
/// takes the core's default, 1.0. Stored as an RGB triple. The shaded
/// images take the cosine toward the sun's centre and ignore its angular
/// size there (a relative error below ``a**2 / 4`` for a disc of angular
/// radius ``a`` above the horizon; docs/shading.md).
///
/// Raises ValueError for a non-finite or zero ``direction`` or ``up``, an
/// ``up`` parallel to ``direction``, an angle that is negative, NaN, or
/// beyond 179 degrees (and one zero angle beside a non-zero one), or a
/// negative or non-finite ``irradiance``.
#[pyclass(frozen, module = "softshadow._core", name = "DirectionalLight")]
#[derive(Clone)]
pub struct PyDirectionalLight {
    direction: [f64; 3],
    up: [f64; 3],
    angular_size: [f64; 2],
    irradiance: [f64; 3],
    pub light: DirectionalLight,
}

#[pymethods]
impl PyDirectionalLight {
    #[new]
    #[pyo3(signature = (direction, up, angular_size=None, *, irradiance=None))]
    fn new(
        direction: &Bound<'_, PyAny>,
        up: &Bound<'_, PyAny>,
        angular_size: Option<&Bound<'_, PyAny>>,
        irradiance: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let d = vector::<3>("direction", direction)?;
        let u = vector::<3>("up", up)?;
        let a = match angular_size {
            Some(a) => pair("angular_size", a)?,
            None => [0.53, 0.53],
        };
        let light = errors::guard(|| Ok(DirectionalLight::new(d, u, a)?))?;
        let irradiance = light_emission("irradiance", color(irradiance)?)?;
        Ok(PyDirectionalLight {
            direction: d,
            up: u,
            angular_size: a,
            irradiance,
            light,
        })
    }

    #[getter]
    fn direction(&self) -> (f64, f64, f64) {
        self.direction.into()
    }
    #[getter]
    fn up(&self) -> (f64, f64, f64) {
        self.up.into()
    }
    #[getter]
    fn angular_size(&self) -> (f64, f64) {
        self.angular_size.into()
    }
    #[getter]
    fn irradiance(&self) -> (f64, f64, f64) {
        self.irradiance.into()
    }
    /// Unit vector along the first angle (map columns grow along it).
    #[getter]
    fn u<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.u)
    }
    /// Unit vector along the second angle (map rows grow against it).
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.v)
    }
    /// The direction the light travels (unit).
    #[getter]
    fn n<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.n)
    }
    /// The unshadowed irradiance (N, 3) float64, RGB, irradiance included,
    /// at world ``points`` (N, 3) on surfaces with ``normals`` (N, 3; any
    /// length, not zero): ``irradiance * max(0, n . s)``. No shadows:
    /// :func:`softshadow.render` multiplies by the visibility. See
    /// docs/shading.md.
    fn irradiance_at<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: &Bound<'py, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        let p = rows3("points", points)?;
        let n = rows3("normals", normals)?;
        let e = self.irradiance.into_pyobject(py)?.into_any();
        irradiance(py, Light::Sun(self._core_args()), p, n, Some(e))
    }
    fn _core_args(&self) -> ([f64; 3], [f64; 3], [f64; 2]) {
        (self.direction, self.up, self.angular_size)
    }
    fn _emission(&self) -> (f64, f64, f64) {
        self.irradiance.into()
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyDirectionalLight>()
            .is_ok_and(|o| key(&self.fields()) == key(&o.get().fields()))
    }
    fn __hash__(&self) -> u64 {
        hash_of(&self.fields())
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        newargs(py, &self.fields())
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        repr(py, "DirectionalLight", &self.fields())
    }
}

impl PyDirectionalLight {
    fn fields(&self) -> [(&'static str, &[f64]); 4] {
        [
            ("direction", &self.direction),
            ("up", &self.up),
            ("angular_size", &self.angular_size),
            ("irradiance", &self.irradiance),
        ]
    }
}

/// A disk-shaped area light that emits uniformly over its whole disk.
///
/// The disk of ``radius`` about ``center``, perpendicular to ``normal``,
/// which points from the light into the scene. Its light-view maps' frame
/// (``u``, ``v``) is chosen by the core: ``up`` is the world axis least
/// aligned with ``normal`` (a disk looks the same turned about its axis).
///
/// ``radiance`` (keyword-only) is the radiance it emits, uniform and
/// Lambertian, on its ``n`` side only: a number (grey) or an RGB triple, each
/// finite and >= 0; ``None`` takes the core's default, 1.0.
///
/// Raises ValueError for a non-finite center, a zero-length or non-finite
/// ``normal``, a radius that is not finite and > 0, or a negative or
/// non-finite ``radiance``.
#[pyclass(frozen, module = "softshadow._core", name = "DiskLight")]
#[derive(Clone)]
pub struct PyDiskLight {
    center: [f64; 3],
    normal: [f64; 3],
    radius: [f64; 1],
    radiance: [f64; 3],
    pub light: AreaLight,
}

#[pymethods]
impl PyDiskLight {
    #[new]
    #[pyo3(signature = (center, normal, radius, *, radiance=None))]
    fn new(
        center: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        radius: &Bound<'_, PyAny>,
        radiance: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let c = vector::<3>("center", center)?;
        let n = vector::<3>("normal", normal)?;
        let r = radius_of(radius)?;
        let light = errors::guard(|| Ok(AreaLight::disk(c, n, r)?))?;
        let radiance = light_emission("radiance", color(radiance)?)?;
        Ok(PyDiskLight {
            center: c,
            normal: n,
            radius: [r],
            radiance,
            light,
        })
    }

    #[getter]
    fn center(&self) -> (f64, f64, f64) {
        self.center.into()
    }
    #[getter]
    fn normal(&self) -> (f64, f64, f64) {
        self.normal.into()
    }
    #[getter]
    fn radius(&self) -> f64 {
        self.radius[0]
    }
    #[getter]
    fn radiance(&self) -> (f64, f64, f64) {
        self.radiance.into()
    }
    /// The frame's first unit vector in the disk's plane (map columns grow
    /// along it).
    #[getter]
    fn u<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.u)
    }
    /// The frame's second unit vector in the disk's plane (map rows grow
    /// against it).
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.v)
    }
    /// Unit normal from the disk into the scene.
    #[getter]
    fn n<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array3(py, self.light.n)
    }
    /// pi radius^2.
    #[getter]
    fn area(&self) -> f64 {
        self.light.shape.area()
    }
    /// The unshadowed irradiance (N, 3) float64, RGB, radiance included, at
    /// world ``points`` (N, 3) on surfaces with ``normals`` (N, 3; any
    /// length, not zero): the disk's form factor, clipped to each point's
    /// upper hemisphere (0 at or behind its plane). See docs/shading.md.
    fn irradiance_at<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: &Bound<'py, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        let p = rows3("points", points)?;
        let n = rows3("normals", normals)?;
        let e = self.radiance.into_pyobject(py)?.into_any();
        irradiance(py, Light::Disk(self._core_args()), p, n, Some(e))
    }
    fn _core_args(&self) -> ([f64; 3], [f64; 3], f64) {
        (self.center, self.normal, self.radius[0])
    }
    fn _emission(&self) -> (f64, f64, f64) {
        self.radiance.into()
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyDiskLight>()
            .is_ok_and(|o| key(&self.fields()) == key(&o.get().fields()))
    }
    fn __hash__(&self) -> u64 {
        hash_of(&self.fields())
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        newargs(py, &self.fields())
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        repr(py, "DiskLight", &self.fields())
    }
}

impl PyDiskLight {
    fn fields(&self) -> [(&'static str, &[f64]); 4] {
        [
            ("center", &self.center),
            ("normal", &self.normal),
            ("radius", &self.radius),
            ("radiance", &self.radiance),
        ]
    }
}

/// A spherical area light that emits uniformly over its whole surface.
///
/// Seen from a point outside it, it is the cap of directions within
/// ``asin(radius / d)`` of its centre, d the distance to the centre. It has
/// no plane to project light-view maps in: its shadows are traced
/// (``render`` with ``exact``, or ``auto``, which takes ``exact``); the map
/// methods refuse it with the reason.
///
/// ``radiance`` (keyword-only): as for :class:`RectLight`.
///
/// Raises ValueError for a non-finite center, a radius that is not finite
/// and > 0, or a negative or non-finite ``radiance``.
#[pyclass(frozen, module = "softshadow._core", name = "SphereLight")]
#[derive(Clone)]
pub struct PySphereLight {
    center: [f64; 3],
    radius: [f64; 1],
    radiance: [f64; 3],
}

#[pymethods]
impl PySphereLight {
    #[new]
    #[pyo3(signature = (center, radius, *, radiance=None))]
    fn new(
        center: &Bound<'_, PyAny>,
        radius: &Bound<'_, PyAny>,
        radiance: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let c = vector::<3>("center", center)?;
        let r = radius_of(radius)?;
        errors::guard(|| Ok(SphereLight::new(c, r)?))?;
        let radiance = light_emission("radiance", color(radiance)?)?;
        Ok(PySphereLight {
            center: c,
            radius: [r],
            radiance,
        })
    }

    #[getter]
    fn center(&self) -> (f64, f64, f64) {
        self.center.into()
    }
    #[getter]
    fn radius(&self) -> f64 {
        self.radius[0]
    }
    #[getter]
    fn radiance(&self) -> (f64, f64, f64) {
        self.radiance.into()
    }
    /// 4 pi radius^2.
    #[getter]
    fn area(&self) -> f64 {
        4.0 * std::f64::consts::PI * self.radius[0] * self.radius[0]
    }
    /// The unshadowed irradiance (N, 3) float64, RGB, radiance included, at
    /// world ``points`` (N, 3) on surfaces with ``normals`` (N, 3; any
    /// length, not zero): the visible cap's form factor, clipped to each
    /// point's upper hemisphere (0 inside the sphere). See docs/shading.md.
    fn irradiance_at<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: &Bound<'py, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        let p = rows3("points", points)?;
        let n = rows3("normals", normals)?;
        let e = self.radiance.into_pyobject(py)?.into_any();
        irradiance(py, Light::Sphere(self._core_args()), p, n, Some(e))
    }
    fn _core_args(&self) -> ([f64; 3], f64) {
        (self.center, self.radius[0])
    }
    fn _emission(&self) -> (f64, f64, f64) {
        self.radiance.into()
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PySphereLight>()
            .is_ok_and(|o| key(&self.fields()) == key(&o.get().fields()))
    }
    fn __hash__(&self) -> u64 {
        hash_of(&self.fields())
    }
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        newargs(py, &self.fields())
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        repr(py, "SphereLight", &self.fields())
    }
}

impl PySphereLight {
    fn fields(&self) -> [(&'static str, &[f64]); 3] {
        [
            ("center", &self.center),
            ("radius", &self.radius),
            ("radiance", &self.radiance),
        ]
    }
}

/// A radius: a real number (not a bool, not None), or a TypeError naming
/// `radius` (`convert::opt_float`'s check); the core checks its value.
fn radius_of(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    opt_float("radius", Some(value))?
        .ok_or_else(|| PyTypeError::new_err("radius: must be a number, got NoneType"))
}
